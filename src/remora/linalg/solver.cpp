#include "remora/linalg/solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <queue>
#include <utility>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <fmt/core.h>

#ifdef REMORA_WITH_GPL_SOLVERS
#include <Eigen/CholmodSupport>
#include <Eigen/UmfPackSupport>

#include "remora/linalg/cholmod_settings.h"
#endif

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/linalg/blas_threads.h"
#include "remora/linalg/split_cholesky.h"

extern "C" {
// LAPACK (OpenBLAS): Cholesky factorization and solve of a symmetric positive definite band matrix.
void dpbtrf_(const char* uplo, const int* n, const int* kd, double* ab, const int* ldab, int* info);
void dpbtrs_(const char* uplo, const int* n, const int* kd, const int* nrhs, const double* ab,
             const int* ldab, double* b, const int* ldb, int* info);
}

namespace remora {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

void require_square(const Sparse& a, const std::string& who) {
  if (a.rows() != a.cols() || a.rows() == 0)
    throw InvalidArgument(who + ": the matrix must be square and non-empty (got " +
                          std::to_string(a.rows()) + " x " + std::to_string(a.cols()) + ")");
}

void require_rhs(Eigen::Index n, const Eigen::MatrixXd& b, const std::string& who) {
  if (b.rows() != n)
    throw InvalidArgument(who + ": the right-hand side has " + std::to_string(b.rows()) +
                          " rows for a system of dimension " + std::to_string(n));
  if (!b.allFinite()) throw InvalidArgument(who + ": the right-hand side has a NaN or Inf entry");
}

void require_finite(const Sparse& a, const std::string& who) {
  for (Eigen::Index k = 0; k < a.nonZeros(); ++k)
    if (!std::isfinite(a.valuePtr()[k]))
      throw InvalidArgument(who + ": the matrix has a NaN or Inf entry");
}

std::string not_spd(const std::string& who) {
  return who +
         ": the matrix is not positive definite (a support component without a fixed vertex, "
         "degenerate geometry, or the unsymmetric system given to a Cholesky solver); use the "
         "'mean' or 'mixed-symmetric' areas with Cholesky, or the 'lu' solver";
}

// ---- Eigen's simplicial Cholesky (ldlt, llt) ---------------------------------------------------

template <class Base>
struct Exposed : Base {
  Eigen::Index factor_nonzeros() const { return this->m_matrix.nonZeros(); }
};

template <class Factorization>
class SimplicialSolver final : public Solver {
public:
  explicit SimplicialSolver(std::string name) : name_(std::move(name)) {}
  std::string name() const override { return name_; }
  bool needs_spd() const override { return true; }
  void analyze(const Sparse& a) override {
    require_square(a, name_);
    factorization_.analyzePattern(a);
    n_ = a.rows();
  }
  void factorize(const Sparse& a) override {
    require_finite(a, name_);
    factorization_.factorize(a);
    bool ok = factorization_.info() == Eigen::Success;
    if constexpr (requires { factorization_.vectorD(); })
      ok = ok && factorization_.vectorD().minCoeff() > 0;
    if (!ok) throw NumericalError(not_spd(name_));
    stats_.factor_nonzeros = static_cast<std::size_t>(factorization_.factor_nonzeros());
    stats_.factor_bytes = stats_.factor_nonzeros * (sizeof(double) + sizeof(int)) +
                          static_cast<std::size_t>(n_ + 1) * sizeof(int) * 3;
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b, const Eigen::MatrixXd*) override {
    require_rhs(n_, b, name_);
    return factorization_.solve(b);
  }

private:
  std::string name_;
  Exposed<Factorization> factorization_;
  Eigen::Index n_ = 0;
};

// ---- CHOLMOD supernodal and UMFPACK (GPL) ---------------------------------------------------

#ifdef REMORA_WITH_GPL_SOLVERS
struct ExposedCholmod : Eigen::CholmodSupernodalLLT<Sparse, Eigen::Lower> {
  const cholmod_factor* factor() const {
    return static_cast<const cholmod_factor*>(m_cholmodFactor);
  }
};

class CholmodSolver final : public Solver {
public:
  CholmodSolver(bool metis, int threads)
      : metis_(metis), threads_(threads > 0 ? threads : omp_get_max_threads()) {}
  std::string name() const override { return metis_ ? "cholmod (metis)" : "cholmod"; }
  bool needs_spd() const override { return true; }
  void analyze(const Sparse& a) override {
    require_square(a, "cholmod");
    release();
    n_ = a.rows();
    // Two halves on two threads (split_cholesky.h) when both threads are free: not inside an
    // active OpenMP region, where the halves would run one after the other.
    if (!metis_ && threads_ >= 2 && omp_get_active_level() == 0 && n_ >= kSplitRows) {
      auto split = std::make_unique<SplitCholesky>();
      // The dense blocks hold five s × s doubles at once while factoring: s ≤ √(16 n) keeps them
      // under 640 bytes per row (docs/limits.md).
      const double max_rows = std::min(double(kMaxSeparatorRows), std::sqrt(16.0 * double(n_)));
      // CHOLMOD's default supernodes: the halves' own numeric factorization (supernodal_factor.h)
      // pays little per supernode, and the coarse ones' explicit zeros cost memory and solves.
      if (split->analyze(a, static_cast<int>(max_rows), false, keys_)) {
        split_ = std::move(split);
        return;
      }
    }
    if (!keys_.empty() && static_cast<Eigen::Index>(keys_.size()) != n_)
      throw InvalidArgument("cholmod: " + std::to_string(keys_.size()) + " order keys for " +
                            std::to_string(n_) + " rows; give one per row or none");
    llt_ = std::make_unique<ExposedCholmod>();
    cholmod_common& c = llt_->cholmod();
    c.nmethods = 1;
    c.method[0].ordering = metis_ ? CHOLMOD_METIS : CHOLMOD_AMD;
    c.postorder = 1;
    c.print = 0; // failures are reported by our exception, not on stdout
    set_supernodes(c, a.rows() <= kCoarseSupernodesRows);
    llt_->analyzePattern(a);
  }
  void factorize(const Sparse& a) override {
    require_finite(a, "cholmod");
    factored_ = false;
    if (split_) {
      const BlasThreadsScope one_blas_thread; // a core for each half
      if (!split_->factorize(a)) throw NumericalError(not_spd("cholmod"));
      stats_.factor_nonzeros = split_->factor_nonzeros();
      stats_.factor_bytes = split_->factor_bytes();
      stats_.separator_rows = split_->separator_rows();
      stats_.keyed_order = !keys_.empty();
      stats_.tree_cut = split_->cut_by_tree();
      factored_ = true;
      return;
    }
    if (!llt_) throw InvalidArgument("cholmod: factorize() before analyze()");
    // The analysis's flop count: a small factor runs the BLAS on one thread (blas_threads.h).
    small_ = llt_->cholmod().fl < kThreadedBlasFlops;
    std::optional<BlasThreadsScope> one_blas_thread;
    if (small_) one_blas_thread.emplace();
    // CHOLMOD 3 opens an OpenMP region of 4 threads for small loops of every supernode (zeroing,
    // scattering); their wake-ups doubled a small factorization (docs/solvers.md). A large one
    // keeps them, and its BLAS threads.
    if (small_)
      with_serial_openmp([&] { llt_->factorize(a); });
    else
      llt_->factorize(a);
    const cholmod_factor* l = llt_->factor();
    if (llt_->info() != Eigen::Success || l == nullptr || l->minor < l->n)
      throw NumericalError(not_spd("cholmod"));
    stats_.factor_nonzeros = l->xsize;
    stats_.separator_rows = 0;
    stats_.keyed_order = stats_.tree_cut = false;
    stats_.factor_bytes = l->xsize * sizeof(double) + l->ssize * sizeof(SuiteSparse_long) +
                          static_cast<std::size_t>(l->n) * 4 * sizeof(SuiteSparse_long);
    factored_ = true;
  }
  // cholmod_solve2 with the solution and workspace kept between calls: a drag solves once per
  // handle move, and each call then allocates nothing (Eigen's wrapper allocates and copies).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b, const Eigen::MatrixXd*) override {
    require_rhs(n_, b, "cholmod");
    if (!factored_) throw InvalidArgument("cholmod: solve() before factorize()");
    if (b.cols() == 0) return Eigen::MatrixXd(n_, 0);
    if (split_) {
      const BlasThreadsScope one_blas_thread;
      return split_->solve(b);
    }
    cholmod_factor* l = const_cast<cholmod_factor*>(llt_->factor());
    cholmod_dense rhs = dense_view(b.data(), static_cast<std::size_t>(b.rows()),
                                   static_cast<std::size_t>(b.cols()));
    cholmod_common& c = llt_->cholmod();
    std::optional<BlasThreadsScope> one_blas_thread;
    if (small_) one_blas_thread.emplace();
    if (!cholmod_solve2(CHOLMOD_A, l, &rhs, nullptr, &x_, nullptr, &y_, &e_, &c) || x_ == nullptr)
      throw NumericalError("cholmod: the solve failed (out of memory?)");
    return Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x_->x), b.rows(), b.cols());
  }
  void set_order_keys(std::vector<int> keys) override { keys_ = std::move(keys); }
  ~CholmodSolver() override { release(); }
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

private:
  // Drops the factor of the last analysis (either kind) and the solve's workspace.
  void release() {
    if (llt_) {
      cholmod_common& c = llt_->cholmod();
      cholmod_free_dense(&x_, &c);
      cholmod_free_dense(&y_, &c);
      cholmod_free_dense(&e_, &c);
    }
    llt_.reset();
    split_.reset();
    factored_ = false;
    stats_ = SolverStats{};
  }
  // Coarser supernodes (set_supernodes) for one factor of up to kCoarseSupernodesRows rows (CHOLMOD
  // pays its per-supernode costs there; the split halves keep the defaults). Merging stores
  // explicit zeros, and on large systems the memory grows by much more than the factor speeds
  // up, so larger systems keep the defaults, on whose fill the region memory estimate of
  // docs/limits.md is sized (measurements: docs/solvers.md, "The factor of a region").
  static constexpr Eigen::Index kCoarseSupernodesRows = 200000;
  // Below this many flops (the analysis's estimate) the factor and its solves hold the BLAS at
  // one thread (blas_threads.h): there one thread is faster, and an idle second BLAS thread would
  // spin and slow the editor's own threads after it; above it two threads factor faster
  // (measurements: docs/solvers.md, "The factor of a region").
  static constexpr double kThreadedBlasFlops = 4e9;
  // Systems of kSplitRows rows or more are factored in two halves on two threads when a separator
  // of at most kMaxSeparatorRows rows balances them (split_cholesky.h, docs/solvers.md).
  static constexpr Eigen::Index kSplitRows = 8000;
  static constexpr int kMaxSeparatorRows = 3000;
  bool metis_;
  int threads_;
  std::vector<int> keys_;                // set_order_keys()
  std::unique_ptr<SplitCholesky> split_; // the two-half factor, or
  std::unique_ptr<ExposedCholmod> llt_;  // the one factor
  bool factored_ = false;
  bool small_ = true;
  Eigen::Index n_ = 0;
  cholmod_dense* x_ = nullptr; // solution, reused by cholmod_solve2
  cholmod_dense* y_ = nullptr; // workspace
  cholmod_dense* e_ = nullptr; // workspace
};
#endif

// ---- LU (unsymmetric) ----------------------------------------------------------------------

template <class Factorization>
class LuSolver final : public Solver {
public:
  std::string name() const override { return "lu"; }
  bool needs_spd() const override { return false; }
  void analyze(const Sparse& a) override {
    require_square(a, "lu");
    lu_.analyzePattern(a);
    n_ = a.rows();
  }
  void factorize(const Sparse& a) override {
    require_finite(a, "lu");
    lu_.factorize(a);
    if (lu_.info() != Eigen::Success)
      throw NumericalError("lu: the matrix is singular (a support component without a fixed "
                           "vertex, or degenerate geometry)");
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b, const Eigen::MatrixXd*) override {
    require_rhs(n_, b, "lu");
    return lu_.solve(b);
  }

private:
  Factorization lu_;
  Eigen::Index n_ = 0;
};

// ---- Iterative solvers -----------------------------------------------------------------------

template <class Iteration>
class IterativeSolver final : public Solver {
public:
  IterativeSolver(std::string name, bool spd, const SolverOptions& options)
      : name_(std::move(name)), spd_(spd), options_(options) {}
  std::string name() const override { return name_; }
  bool needs_spd() const override { return spd_; }
  // Eigen's iterations keep a view of the matrix: hold a copy so that the caller's may go.
  void analyze(const Sparse& a) override {
    require_square(a, name_);
    matrix_ = a;
    iteration_.analyzePattern(matrix_);
    n_ = a.rows();
  }
  void factorize(const Sparse& a) override {
    require_finite(a, name_);
    matrix_ = a;
    iteration_.factorize(matrix_);
    if (iteration_.info() != Eigen::Success)
      throw NumericalError(name_ + ": the preconditioner could not be built (a zero or negative "
                                   "pivot); try the jacobi preconditioner or a direct solver");
    iteration_.setTolerance(options_.tolerance);
    iteration_.setMaxIterations(options_.max_iterations > 0 ? options_.max_iterations
                                                            : static_cast<int>(10 * n_));
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b, const Eigen::MatrixXd* guess) override {
    require_rhs(n_, b, name_);
    if (guess && (guess->rows() != b.rows() || guess->cols() != b.cols()))
      throw InvalidArgument(name_ + ": the start value has the wrong shape");
    Eigen::MatrixXd x(b.rows(), b.cols());
    stats_.iterations = 0;
    stats_.residual = 0;
    for (Eigen::Index c = 0; c < b.cols(); ++c) {
      if (b.col(c).squaredNorm() == 0) {
        x.col(c).setZero();
        continue;
      }
      if (guess)
        x.col(c) = iteration_.solveWithGuess(b.col(c), guess->col(c));
      else
        x.col(c) = iteration_.solve(b.col(c));
      stats_.iterations = std::max(stats_.iterations, static_cast<int>(iteration_.iterations()));
      stats_.residual = std::max(stats_.residual, iteration_.error());
      if (iteration_.info() != Eigen::Success || !x.col(c).allFinite())
        throw NumericalError(fmt::format(
            "{}: no convergence after {} iterations (relative residual {:.3g}, tolerance {:.3g}); "
            "raise the iteration limit, use a better preconditioner, or a direct solver",
            name_, iteration_.iterations(), iteration_.error(), options_.tolerance));
    }
    return x;
  }

private:
  std::string name_;
  bool spd_;
  SolverOptions options_;
  Sparse matrix_;
  Iteration iteration_;
  Eigen::Index n_ = 0;
};

// ---- Banded Cholesky (paper §5.3) --------------------------------------------------------------

class BandedSolver final : public Solver {
public:
  explicit BandedSolver(const SolverOptions& options) : options_(options) {}
  std::string name() const override { return "banded"; }
  bool needs_spd() const override { return true; }
  void analyze(const Sparse& a) override {
    require_square(a, "banded");
    n_ = static_cast<int>(a.rows());
    perm_ = reverse_cuthill_mckee(a);
    inverse_.assign(perm_.size(), 0);
    for (std::size_t i = 0; i < perm_.size(); ++i)
      inverse_[static_cast<std::size_t>(perm_[i])] = static_cast<int>(i);
    kd_ = 0;
    for (int j = 0; j < a.outerSize(); ++j)
      for (Sparse::InnerIterator it(a, j); it; ++it)
        kd_ = std::max(kd_, std::abs(inverse_[static_cast<std::size_t>(it.row())] -
                                     inverse_[static_cast<std::size_t>(j)]));
    stats_.bandwidth = kd_;
    const std::size_t bytes =
        static_cast<std::size_t>(kd_ + 1) * static_cast<std::size_t>(n_) * sizeof(double);
    if (bytes > options_.max_band_bytes)
      throw NumericalError(fmt::format(
          "banded: after reverse Cuthill-McKee the half-bandwidth is {} and the band would take "
          "{:.1f} GB (limit {:.1f} GB); use cholmod or ldlt, whose fill is far smaller",
          kd_, static_cast<double>(bytes) / 1e9,
          static_cast<double>(options_.max_band_bytes) / 1e9));
  }
  void factorize(const Sparse& a) override {
    require_finite(a, "banded");
    const int ld = kd_ + 1;
    band_.assign(static_cast<std::size_t>(ld) * static_cast<std::size_t>(n_), 0.0);
    // Lower band storage: A(i, j) with j <= i <= j + kd at band_[(i - j) + j * ld], permuted.
    for (int j = 0; j < a.outerSize(); ++j)
      for (Sparse::InnerIterator it(a, j); it; ++it) {
        const int pi = inverse_[static_cast<std::size_t>(it.row())];
        const int pj = inverse_[static_cast<std::size_t>(j)];
        if (pi < pj) continue;
        band_[static_cast<std::size_t>(pi - pj) +
              static_cast<std::size_t>(pj) * static_cast<std::size_t>(ld)] = it.value();
      }
    int info = 0;
    dpbtrf_("L", &n_, &kd_, band_.data(), &ld, &info);
    if (info != 0) throw NumericalError(not_spd("banded"));
    stats_.factor_nonzeros = band_.size();
    stats_.factor_bytes = band_.size() * sizeof(double);
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b, const Eigen::MatrixXd*) override {
    require_rhs(n_, b, "banded");
    Eigen::MatrixXd x(b.rows(), b.cols());
    for (int i = 0; i < n_; ++i) x.row(i) = b.row(perm_[static_cast<std::size_t>(i)]);
    const int ld = kd_ + 1, nrhs = static_cast<int>(b.cols());
    int info = 0;
    dpbtrs_("L", &n_, &kd_, &nrhs, band_.data(), &ld, x.data(), &n_, &info);
    if (info != 0) throw NumericalError("banded: dpbtrs failed with info " + std::to_string(info));
    Eigen::MatrixXd out(b.rows(), b.cols());
    for (int i = 0; i < n_; ++i) out.row(perm_[static_cast<std::size_t>(i)]) = x.row(i);
    return out;
  }

private:
  SolverOptions options_;
  int n_ = 0, kd_ = 0;
  std::vector<int> perm_, inverse_;
  std::vector<double> band_;
};

// ---- Reverse Cuthill-McKee ---------------------------------------------------------------------

using Adjacency = std::vector<std::vector<int>>;

// The pattern of A + Aᵀ without the diagonal: each row's neighbours, sorted, without repeats.
Adjacency symmetric_adjacency(const Sparse& a) {
  const auto n = static_cast<int>(a.rows());
  Adjacency adjacent(static_cast<std::size_t>(n));
  for (int j = 0; j < a.outerSize(); ++j)
    for (Sparse::InnerIterator it(a, j); it; ++it) {
      const int i = static_cast<int>(it.row());
      if (i == j) continue;
      adjacent[static_cast<std::size_t>(i)].push_back(j);
      adjacent[static_cast<std::size_t>(j)].push_back(i);
    }
  for (auto& adj : adjacent) {
    std::sort(adj.begin(), adj.end());
    adj.erase(std::unique(adj.begin(), adj.end()), adj.end());
  }
  return adjacent;
}

// Breadth-first level structures of a graph, one component at a time.
class Levels {
public:
  explicit Levels(const Adjacency& adjacent) : adjacent_(adjacent), level_(adjacent.size(), -1) {}

  /// The levels from `root` over its component, whose levels must be unset; returns the depth
  /// of the last level.
  int build(int root) {
    touched_.clear();
    touched_.push_back(root);
    level_[static_cast<std::size_t>(root)] = 0;
    for (std::size_t q = 0; q < touched_.size(); ++q) {
      const int u = touched_[q];
      for (int w : adjacent_[static_cast<std::size_t>(u)])
        if (level_[static_cast<std::size_t>(w)] < 0) {
          level_[static_cast<std::size_t>(w)] = level_[static_cast<std::size_t>(u)] + 1;
          touched_.push_back(w);
        }
    }
    return level_[static_cast<std::size_t>(touched_.back())];
  }

  /// The vertex of level `depth` of the last build with the smallest degree (the first visited
  /// among equals).
  int smallest_degree_at(int depth, const std::vector<int>& degree) const {
    int best = -1;
    for (int u : touched_)
      if (level_[static_cast<std::size_t>(u)] == depth &&
          (best < 0 ||
           degree[static_cast<std::size_t>(u)] < degree[static_cast<std::size_t>(best)]))
        best = u;
    return best;
  }

  /// Unsets the levels of the last build.
  void clear() {
    for (int u : touched_) level_[static_cast<std::size_t>(u)] = -1;
  }

private:
  const Adjacency& adjacent_;
  std::vector<int> level_;   // -1 where unset
  std::vector<int> touched_; // the last build's component, in visiting order
};

// A pseudo-peripheral vertex of seed's component (George & Liu): from seed, jump to a
// smallest-degree vertex of the last level while the eccentricity grows (at most 8 jumps).
// Leaves every level unset.
int pseudo_peripheral_root(int seed, const std::vector<int>& degree, Levels& levels) {
  int root = seed, depth = levels.build(root);
  for (int tries = 0; tries < 8; ++tries) {
    const int best = levels.smallest_degree_at(depth, degree);
    levels.clear();
    const int next_depth = levels.build(best);
    if (next_depth <= depth) break;
    root = best;
    depth = next_depth;
  }
  levels.clear();
  return root;
}

// Appends root's component to `order` in Cuthill-McKee order (breadth first, each vertex's
// unnumbered neighbours by increasing degree, then index), marking it in `numbered`.
void cuthill_mckee(int root, const Adjacency& adjacent, const std::vector<int>& degree,
                   std::vector<char>& numbered, std::vector<int>& order) {
  const std::size_t start = order.size();
  order.push_back(root);
  numbered[static_cast<std::size_t>(root)] = 1;
  std::vector<int> next;
  for (std::size_t q = start; q < order.size(); ++q) {
    next.clear();
    for (int w : adjacent[static_cast<std::size_t>(order[q])])
      if (!numbered[static_cast<std::size_t>(w)]) {
        numbered[static_cast<std::size_t>(w)] = 1;
        next.push_back(w);
      }
    std::sort(next.begin(), next.end(), [&](int x, int y) {
      const int dx = degree[static_cast<std::size_t>(x)], dy = degree[static_cast<std::size_t>(y)];
      return dx != dy ? dx < dy : x < y;
    });
    order.insert(order.end(), next.begin(), next.end());
  }
}

} // namespace

std::vector<int> reverse_cuthill_mckee(const Sparse& a) {
  const auto n = static_cast<int>(a.rows());
  const Adjacency adjacent = symmetric_adjacency(a);
  std::vector<int> degree(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < adjacent.size(); ++i)
    degree[i] = static_cast<int>(adjacent[i].size());
  Levels levels(adjacent);
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(n));
  std::vector<char> numbered(static_cast<std::size_t>(n), 0);
  for (int seed = 0; seed < n; ++seed) {
    if (numbered[static_cast<std::size_t>(seed)]) continue;
    cuthill_mckee(pseudo_peripheral_root(seed, degree, levels), adjacent, degree, numbered, order);
  }
  std::reverse(order.begin(), order.end());
  return order;
}

std::string default_solver_name() {
#ifdef REMORA_WITH_GPL_SOLVERS
  return "cholmod";
#else
  return "ldlt";
#endif
}

std::vector<std::string> solver_names() {
  std::vector<std::string> names = {"ldlt", "llt", "banded", "cg", "bicgstab", "lu"};
#ifdef REMORA_WITH_GPL_SOLVERS
  names.insert(names.begin(), "cholmod");
#endif
  return names;
}

std::unique_ptr<Solver> make_solver(const SolverOptions& options) {
  const std::string name = options.name.empty() ? default_solver_name() : options.name;
  if (options.ordering != "amd" && options.ordering != "metis")
    throw InvalidArgument("solver ordering '" + options.ordering +
                          "' is unknown; use amd or metis");
  if (!(options.tolerance > 0) || !std::isfinite(options.tolerance))
    throw InvalidArgument("solver tolerance must be positive and finite");
  if (options.max_iterations < 0) throw InvalidArgument("solver max_iterations must be >= 0");
  if (options.threads < 0) throw InvalidArgument("solver threads must be >= 0 (0 = all)");
  using AmdLdlt = Eigen::SimplicialLDLT<Sparse, Eigen::Lower, Eigen::AMDOrdering<int>>;
  using AmdLlt = Eigen::SimplicialLLT<Sparse, Eigen::Lower, Eigen::AMDOrdering<int>>;
  if (name == "ldlt") return std::make_unique<SimplicialSolver<AmdLdlt>>("ldlt");
  if (name == "llt") return std::make_unique<SimplicialSolver<AmdLlt>>("llt");
  if (name == "banded") return std::make_unique<BandedSolver>(options);
  if (name == "cg") {
    if (options.preconditioner == "jacobi")
      return std::make_unique<IterativeSolver<Eigen::ConjugateGradient<
          Sparse, Eigen::Lower | Eigen::Upper, Eigen::DiagonalPreconditioner<double>>>>(
          "cg (jacobi)", true, options);
    if (options.preconditioner == "ichol")
      return std::make_unique<IterativeSolver<Eigen::ConjugateGradient<
          Sparse, Eigen::Lower | Eigen::Upper,
          Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::AMDOrdering<int>>>>>(
          "cg (ichol)", true, options);
    throw InvalidArgument("cg preconditioner '" + options.preconditioner +
                          "' is unknown; use jacobi or ichol");
  }
  if (name == "bicgstab")
    return std::make_unique<
        IterativeSolver<Eigen::BiCGSTAB<Sparse, Eigen::DiagonalPreconditioner<double>>>>(
        "bicgstab", false, options);
#ifdef REMORA_WITH_GPL_SOLVERS
  if (name == "cholmod")
    return std::make_unique<CholmodSolver>(options.ordering == "metis", options.threads);
  if (name == "lu") return std::make_unique<LuSolver<Eigen::UmfPackLU<Sparse>>>();
#else
  if (name == "lu")
    return std::make_unique<LuSolver<Eigen::SparseLU<Sparse, Eigen::COLAMDOrdering<int>>>>();
#endif
  std::string known;
  for (const auto& n : solver_names()) known += (known.empty() ? "" : ", ") + n;
  throw InvalidArgument("unknown solver '" + name + "'; this build has: " + known);
}

} // namespace remora
