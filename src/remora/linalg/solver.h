// Sparse linear solvers behind one small interface, chosen by name (paper §5 compares them):
// analyze (ordering, symbolic factorization), factorize (numbers), then solve as many right-hand
// sides as needed, as one block. Factor once, solve many: an edit factors its system once and
// solves for every handle move or basis function.
//
//   name        matrix       method
//   cholmod     SPD          CHOLMOD supernodal Cholesky, AMD or METIS ordering (GPL module;
//                            only when built with REMORA_WITH_GPL_SOLVERS, then the default);
//                            with AMD, two threads and 8,000 rows or more, two halves around a
//                            separator on two threads when a thin one balances them
//                            (split_cholesky.h)
//   ldlt        SPD          Eigen SimplicialLDLT, AMD ordering (the permissive default)
//   llt         SPD          Eigen SimplicialLLT, AMD ordering (what libigl's
//                            min_quad_with_fixed uses; kept as the yardstick)
//   banded      SPD          reverse Cuthill-McKee + LAPACK band Cholesky (dpbtrf/dpbtrs), the
//                            paper's direct solver (§5.3)
//   cg          SPD          conjugate gradients, Jacobi or incomplete-Cholesky preconditioner
//   bicgstab    any          BiCGSTAB with a Jacobi preconditioner, for the unsymmetric system
//   lu          any          UMFPACK (GPL build) or Eigen SparseLU
// Iterative solvers throw NumericalError when they miss the tolerance, direct ones when the
// matrix is not positive definite (or singular), always with a message that says what to do.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

namespace remora {

struct SolverOptions {
  std::string name;                      ///< empty = default_solver_name()
  std::string ordering = "amd";          ///< cholmod: "amd" or "metis"
  std::string preconditioner = "jacobi"; ///< cg: "jacobi" or "ichol"
  double tolerance = 1e-10;              ///< iterative: relative residual |b - Ax| / |b| per column
  int max_iterations = 0;                ///< iterative: 0 = 10 × the dimension
  /// banded: refuse when the band storage would exceed this many bytes (the band of a large
  /// surface mesh grows like sqrt(n), its storage like n^1.5).
  std::size_t max_band_bytes = std::size_t(4) << 30;
  /// cholmod (amd): with 2 threads or more, a system of 8,000 rows or more is factored as two
  /// halves around a separator, one per thread, when a thin separator balances them
  /// (split_cholesky.h); 1 = CHOLMOD's one factor.
  int threads = 0; ///< 0 = all hardware threads
};

struct SolverStats {
  int iterations = 0;           ///< iterative: the most any column needed in the last solve
  double residual = 0.0;        ///< iterative: the largest relative residual of the last solve
  std::size_t factor_bytes = 0; ///< direct: memory of the factor (values and indices)
  std::size_t factor_nonzeros = 0;
  int bandwidth = 0;        ///< banded: half-bandwidth after the ordering
  int separator_rows = 0;   ///< cholmod: the separator's rows when factored in two halves, else 0
  bool keyed_order = false; ///< cholmod: the halves followed set_order_keys()
  bool tree_cut = false;    ///< cholmod: the separator is the top of that order's tree
};

class Solver {
public:
  virtual ~Solver() = default;
  virtual std::string name() const = 0;
  /// Whether the method needs a symmetric positive definite matrix.
  virtual bool needs_spd() const = 0;
  /// Ordering and symbolic analysis from the sparsity pattern of `a` (square).
  virtual void analyze(const Eigen::SparseMatrix<double>& a) = 0;
  /// Numerical factorization (or preconditioner) of `a`, which must have the pattern given to
  /// analyze(); call again when only the values change.
  virtual void factorize(const Eigen::SparseMatrix<double>& a) = 0;
  void compute(const Eigen::SparseMatrix<double>& a) {
    analyze(a);
    factorize(a);
  }
  /// Solves A X = B for every column of B. `guess` (iterative solvers only) is the start value.
  virtual Eigen::MatrixXd solve(const Eigen::MatrixXd& b,
                                const Eigen::MatrixXd* guess = nullptr) = 0;
  virtual SolverStats stats() const { return stats_; }
  /// A fill-reducing order for the next analyze(): a key per row, the rows taken by increasing
  /// key (ties by row), e.g. a nested dissection of a larger graph restricted to the system's
  /// rows (nested_dissection.h). Empty: the solver orders the rows itself. Only `cholmod`'s two
  /// halves use it: they are cut at the top of the order's elimination tree and each follows the
  /// tree's postorder (separator.h), or, when that cut does not balance, cut at a breadth-first
  /// level and each ordered by the keys; the other solvers and `cholmod`'s one factor ignore the
  /// keys. analyze() throws InvalidArgument when the keys are not one per row.
  virtual void set_order_keys(std::vector<int> keys) { (void)keys; }

protected:
  SolverStats stats_;
};

/// The solver named by options.name (see the table above); throws InvalidArgument for an
/// unknown name or option, naming the ones available in this build.
std::unique_ptr<Solver> make_solver(const SolverOptions& options = {});

/// "cholmod" when built with the GPL solvers, else "ldlt".
std::string default_solver_name();

/// The names make_solver() accepts in this build.
std::vector<std::string> solver_names();

/// A reverse Cuthill-McKee ordering of the symmetric pattern of `a`: perm[new] = old. Each
/// connected component starts from a pseudo-peripheral vertex; neighbours by increasing degree.
std::vector<int> reverse_cuthill_mckee(const Eigen::SparseMatrix<double>& a);

} // namespace remora
