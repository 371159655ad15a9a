// A sparse Cholesky factorization on two threads: one level of nested dissection around CHOLMOD
// (paper §5: the editor's k-harmonic systems, factored once per region).
//
// A separator S (separator.h: one level of a breadth-first search of the matrix graph, or the top
// of a given order's elimination tree) splits the rows into two halves that do not couple:
//
//       [ A₁  0   C₁ ]
//   K = [ 0   A₂  C₂ ]      each half bordered by S, M_i = [A_i C_i; C_iᵀ K_SS] = L_i L_iᵀ, is
//       [ C₁ᵀ C₂ᵀ K_SS]     ordered with S last (by CAMD, or by the given order), analysed by
//                           CHOLMOD and factored on its thread by supernodal_factor.h.
//
// The trailing block of L_i is the factor of K_SS − C_iᵀA_i⁻¹C_i, so the Schur complement of S is
// L₁L₁ᵀ + L₂L₂ᵀ − K_SS (symmetric positive definite whenever K is), factored densely. A solve is a
// forward sweep of each half, the dense solve of S, and a backward sweep of each half, the halves
// on two threads. The result is that of one factorization of K to round-off.
//
// SplitCholesky exists only in builds with the GPL solvers (CHOLMOD); its separators
// (separator.h) in every build. Not thread-safe: one object per thread.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "remora/linalg/separator.h"

namespace remora {

class SplitCholesky {
public:
  SplitCholesky();
  ~SplitCholesky();
  SplitCholesky(const SplitCholesky&) = delete;
  SplitCholesky& operator=(const SplitCholesky&) = delete;

  /// Splits the symmetric pattern of `a` (compressed; lower triangle read) and analyses both
  /// halves, with coarser supernodes than CHOLMOD's defaults when `coarse_supernodes`
  /// (solver.cpp). Without `keys`, the separator is a breadth-first level and each half's rows,
  /// then the separator's, are ordered by CAMD. With `keys` (one per row of `a`; ties by row;
  /// Solver::set_order_keys) the separator is the top of their elimination tree and the halves
  /// follow its postorder (tree_separator), or, when that cut does not balance or is longer than
  /// `max_separator_rows`, a breadth-first level with the halves in the keys' order. Returns
  /// false, keeping nothing, when `a` is not compressed or no separator of at most
  /// `max_separator_rows` rows balances the graph; the caller then factors `a` as one. Throws
  /// InvalidArgument when `keys` is neither empty nor one per row.
  bool analyze(const Eigen::SparseMatrix<double>& a, int max_separator_rows, bool coarse_supernodes,
               const std::vector<int>& keys = {});
  /// The numbers of `a`, which has the pattern given to analyze(). Returns false when `a` is not
  /// positive definite; throws NumericalError when CHOLMOD fails otherwise (out of memory), and
  /// InvalidArgument for another pattern.
  bool factorize(const Eigen::SparseMatrix<double>& a);
  /// X with A X = B, B of n rows. Throws InvalidArgument before a successful factorize() or for
  /// another row count.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b);

  std::size_t factor_nonzeros() const;
  std::size_t factor_bytes() const;
  int separator_rows() const;
  /// Whether the separator is the top of the keys' elimination tree (tree_separator), not a
  /// breadth-first level.
  bool cut_by_tree() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace remora
