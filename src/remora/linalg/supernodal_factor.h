// The numeric Cholesky factorization L Lᵀ = P A Pᵀ on CHOLMOD's supernodal symbolic analysis
// (split_cholesky.h's halves; paper §5: factor once per region). The algorithm is CHOLMOD's
// left-looking supernodal one: for each supernode in turn, A's columns are scattered into its
// block, the updates of the supernodes below it that reach its columns are formed (BLAS dsyrk and
// dgemm) and subtracted, and the block is factored (dpotrf, dtrsm). What differs is around it:
// A's entries are scattered from a permuted copy of its pattern made once per analysis (CHOLMOD
// transposes A twice per factorization), and nothing opens an OpenMP region. Debian's CHOLMOD
// opens a region for the small loops of every supernode, inside the halves' two-thread region a
// nested one, and each costs libgomp a team's allocation and a futex call: about a third of a
// half's factorization on this VM (docs/solvers.md).
//
// The factor is CHOLMOD's own object (its x allocated here), so its solves, the sweeps of
// supernodal_solve.h and cholmod_free_factor() take it as they take one from cholmod_factorize().
//
// Only in builds with the GPL solvers (CHOLMOD).
#pragma once

#ifdef REMORA_WITH_GPL_SOLVERS
#include <cstddef>
#include <vector>

#include <cholmod.h>

namespace remora {

class SupernodalNumeric {
public:
  /// For the symbolic factor `symbolic` (cholmod_analyze_p with CHOLMOD_SUPERNODAL) of the n × n
  /// symmetric matrix whose lower triangle (row ≥ column, each column's rows in any order) is
  /// the compressed columns `colptr` (n + 1 entries), `rowind`. Throws InvalidArgument for a
  /// factor that is not supernodal or not n × n.
  SupernodalNumeric(const cholmod_factor& symbolic, const int* colptr, const int* rowind, int n);

  /// L of the matrix with `values` (in `rowind`'s order) into factor.x (allocated on the first
  /// call through `common`), which must be the analysis given to the constructor. True on
  /// success (factor.minor = n); false when a pivot is not positive (factor.minor: its column in
  /// the factor's order; the factor is then not usable). Throws NumericalError when CHOLMOD
  /// cannot allocate the factor's values.
  bool factorize(cholmod_factor& factor, const double* values, cholmod_common& common);

private:
  int n_ = 0;
  std::vector<int> colptr_, row_;      // P A Pᵀ's lower triangle by the factor's columns
  std::vector<int> source_;            // each entry's index in the constructor's values
  std::vector<int> super_of_;          // the supernode of each column
  std::vector<int> map_, relative_;    // workspace: a row's place in the current supernode
  std::vector<int> head_, next_, pos_; // the supernodes waiting to update each supernode
  std::vector<double> update_;         // workspace: one descendant's update
};

} // namespace remora
#endif
