// The solver suite: every solver agrees with a direct one on the same k-harmonic systems, the
// numbers-only refactorization reuses the analysis, failures are errors and never garbage, and
// reverse Cuthill-McKee shrinks the band of a scrambled grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>
#include <thread>

#include "remora/common/error.h"
#include "remora/linalg/blas_threads.h"
#include "remora/linalg/kharmonic.h"
#include "remora/linalg/nested_dissection.h"
#include "remora/linalg/solver.h"
#include "remora/linalg/split_cholesky.h"
#include "remora/mesh/primitives.h"

extern "C" { // OpenBLAS's, when it is the BLAS (blas_threads.cpp)
int openblas_get_num_threads() __attribute__((weak));
void openblas_set_num_threads(int) __attribute__((weak));
}

namespace remora {
namespace {

/// A k-harmonic system on a sphere: the cap z > 0.6 is handle 0, z < -0.6 fixed, the rest free
/// (about 60 % of the vertices: 1,500 of icosphere(4), 6,100 of (5), 24,600 of (6)).
KHarmonicSystem sphere_system(int k, AreaWeights areas, int subdivisions = 4) {
  const Mesh mesh = make_icosphere(subdivisions);
  Region region{std::vector<int>(mesh.n_vertices(), Region::kFree)};
  for (auto v : mesh.vertices()) {
    const double z = mesh.point(v)[2];
    if (z > 0.6) region.label[static_cast<std::size_t>(v.idx())] = 0;
    if (z < -0.6) region.label[static_cast<std::size_t>(v.idx())] = Region::kFixed;
  }
  return assemble_kharmonic(mesh, region, {.k = k, .areas = areas});
}

Eigen::MatrixXd block_rhs(const KHarmonicSystem& s) {
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(s.coupling.cols(), 3);
  std::mt19937 rng(1);
  for (Eigen::Index i = 0; i < c.rows(); ++i)
    for (int j = 0; j < 3; ++j) c(i, j) = static_cast<double>(rng() % 1000) / 1000.0;
  return s.rhs(c);
}

double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / b.norm();
}

TEST(Solver, EverySolverAgreesWithTheDirectOneOnTheSymmetricSystem) {
  for (int k = 1; k <= 3; ++k) {
    const KHarmonicSystem s = sphere_system(k, AreaWeights::Mean);
    const Eigen::MatrixXd b = block_rhs(s);
    auto reference = make_solver({.name = "ldlt"});
    reference->compute(s.matrix);
    const Eigen::MatrixXd x = reference->solve(b);
    EXPECT_LE((s.matrix * x - b).norm() / b.norm(), 1e-10);
    std::vector<SolverOptions> all;
    for (const std::string& name : solver_names()) all.push_back({.name = name});
    all.push_back({.name = "cg", .preconditioner = "ichol"});
#ifdef REMORA_WITH_GPL_SOLVERS
    all.push_back({.name = "cholmod", .ordering = "metis"});
#endif
    for (SolverOptions o : all) {
      o.tolerance = 1e-12;
      auto solver = make_solver(o);
      SCOPED_TRACE(::testing::Message() << solver->name() << " k " << k);
      solver->compute(s.matrix);
      EXPECT_LE(relative_difference(solver->solve(b), x), 1e-8);
    }
  }
}

TEST(Solver, BlasThreadsScopeHoldsOpenBlasAtOneThreadAndRestoresItsCount) {
  const auto get = &openblas_get_num_threads;
  const auto set = &openblas_set_num_threads;
#ifdef REMORA_LINKED_OPENBLAS
  ASSERT_TRUE(blas_threads_held()) << "the build linked OpenBLAS (pthreads), but the scope is off";
#endif
  if (!blas_threads_held()) GTEST_SKIP() << "the BLAS is not OpenBLAS built with pthreads";
  const int before = get();
  set(2);
  if (get() != 2) GTEST_SKIP() << "OpenBLAS runs one thread at most here";
  {
    const BlasThreadsScope outer;
    EXPECT_EQ(get(), 1);
    { const BlasThreadsScope inner; }
    EXPECT_EQ(get(), 1) << "an inner scope's end must not restore the count";
    // A scope on another thread that ends while this one is open.
    std::thread([&] { const BlasThreadsScope other; }).join();
    EXPECT_EQ(get(), 1);
  }
  EXPECT_EQ(get(), 2);
  // Overlapping, not nested: the first to open ends first.
  auto first = std::make_unique<BlasThreadsScope>();
  auto second = std::make_unique<BlasThreadsScope>();
  first.reset();
  EXPECT_EQ(get(), 1) << "a scope is still open";
  second.reset();
  EXPECT_EQ(get(), 2);
  // A count set while a scope is open stands.
  int changed = 0;
  {
    const BlasThreadsScope scope;
    set(3);
    changed = get(); // 3 where OpenBLAS allows it
  }
  if (changed != 1) {
    EXPECT_EQ(get(), changed) << "the count found at the start came back";
  }
  set(2);
  // The direct solver factors and solves inside a scope; the count is back afterwards.
  const KHarmonicSystem system = sphere_system(2, AreaWeights::Mean);
  const auto solver = make_solver({});
  solver->compute(system.matrix);
  const Eigen::MatrixXd b = Eigen::MatrixXd::Ones(system.matrix.rows(), 3);
  EXPECT_LT((system.matrix * solver->solve(b) - b).norm(), 1e-8 * b.norm());
  EXPECT_EQ(get(), 2);
  set(before);
}

TEST(Solver, UnsymmetricSystemIsSolvedByLuAndBicgstab) {
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mixed);
  const KHarmonicSystem scaled = sphere_system(2, AreaWeights::MixedSymmetric);
  const Eigen::MatrixXd b = block_rhs(s), b_scaled = block_rhs(scaled);
  auto reference = make_solver({.name = "ldlt"});
  reference->compute(scaled.matrix);
  const Eigen::MatrixXd x = reference->solve(b_scaled); // the same solution (rows scaled)
  for (const std::string name : {"lu", "bicgstab"}) {
    auto solver = make_solver({.name = name, .tolerance = 1e-13});
    SCOPED_TRACE(name);
    solver->compute(s.matrix);
    EXPECT_LE(relative_difference(solver->solve(b), x), 1e-8);
  }
}

TEST(Solver, RefactorizationReusesTheAnalysis) {
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mean);
  const Eigen::MatrixXd b = block_rhs(s);
  for (const std::string& name : solver_names()) {
    if (name == "bicgstab" || name == "lu") continue;
    auto solver = make_solver({.name = name, .tolerance = 1e-12});
    SCOPED_TRACE(name);
    solver->compute(s.matrix);
    const Eigen::MatrixXd x = solver->solve(b);
    const SparseMatrix doubled = 2.0 * s.matrix;
    solver->factorize(doubled); // same pattern, new values
    EXPECT_LE(relative_difference(solver->solve(b), 0.5 * x), 1e-8);
  }
}

// A drag solves many times on one factor, with any number of columns (3 for x, y, z; 3 + 4h for
// the editor's basis functions; 1): each answer is right, and owns its storage (the direct
// solvers keep their workspace between calls).
TEST(Solver, RepeatedSolvesWithChangingColumnCountsStayRightAndIndependent) {
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mean);
  const Eigen::MatrixXd b3 = block_rhs(s);
  Eigen::MatrixXd b7(b3.rows(), 7);
  b7 << b3, -b3, b3.col(0) + b3.col(1);
  const Eigen::MatrixXd b1 = b3.col(2);
  for (const std::string& name : solver_names()) {
    if (name == "bicgstab" || name == "lu" || name == "cg") continue; // direct solvers
    auto solver = make_solver({.name = name, .tolerance = 1e-12});
    SCOPED_TRACE(name);
    solver->compute(s.matrix);
    const Eigen::MatrixXd x3 = solver->solve(b3);
    const Eigen::MatrixXd x7 = solver->solve(b7);
    const Eigen::MatrixXd x1 = solver->solve(b1);
    const Eigen::MatrixXd x3_again = solver->solve(b3);
    EXPECT_LE((s.matrix * x3 - b3).norm() / b3.norm(), 1e-9);
    EXPECT_LE((s.matrix * x7 - b7).norm() / b7.norm(), 1e-9);
    EXPECT_LE((s.matrix * x1 - b1).norm() / b1.norm(), 1e-9);
    EXPECT_LE(relative_difference(x7.leftCols(3), x3), 1e-12);
    EXPECT_LE(relative_difference(x7.middleCols(3, 3), -x3), 1e-12);
    EXPECT_LE(relative_difference(x1, x3.col(2)), 1e-12);
    EXPECT_EQ(x3_again, x3);
  }
}

TEST(Solver, IterativeSolversReportIterationsAndUseTheStartValue) {
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mean);
  const Eigen::MatrixXd b = block_rhs(s);
  auto cg = make_solver({.name = "cg", .tolerance = 1e-10});
  cg->compute(s.matrix);
  const Eigen::MatrixXd x = cg->solve(b);
  const int cold = cg->stats().iterations;
  EXPECT_GT(cold, 10);
  EXPECT_LE(cg->stats().residual, 1e-10);
  const Eigen::MatrixXd close = x + 1e-6 * Eigen::MatrixXd::Ones(x.rows(), x.cols());
  cg->solve(b, &close);
  EXPECT_LT(cg->stats().iterations, cold);
}

TEST(Solver, FailuresAreErrorsNeverGarbage) {
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mean);
  const Eigen::MatrixXd b = block_rhs(s);
  auto cg = make_solver({.name = "cg", .max_iterations = 3});
  cg->compute(s.matrix);
  try {
    cg->solve(b);
    ADD_FAILURE() << "cg with 3 iterations converged";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("no convergence after 3 iterations"), std::string::npos)
        << e.what();
  }
  // An indefinite matrix: every Cholesky-type solver refuses it.
  const SparseMatrix indefinite = -s.matrix;
  for (const std::string& name : solver_names()) {
    if (name == "cg" || name == "bicgstab" || name == "lu") continue;
    auto solver = make_solver({.name = name});
    SCOPED_TRACE(name);
    EXPECT_THROW(solver->compute(indefinite), NumericalError);
  }
  EXPECT_THROW(make_solver({.name = "magic"}), InvalidArgument);
  EXPECT_THROW(make_solver({.name = "cg", .preconditioner = "magic"}), InvalidArgument);
  EXPECT_THROW(make_solver({.name = "", .ordering = "magic"}), InvalidArgument);
  auto ldlt = make_solver({.name = "ldlt"});
  ldlt->compute(s.matrix);
  EXPECT_THROW(ldlt->solve(Eigen::MatrixXd::Zero(3, 1)), InvalidArgument);
  Eigen::MatrixXd nan = b;
  nan(0, 0) = std::nan("");
  EXPECT_THROW(ldlt->solve(nan), InvalidArgument);
}

TEST(Solver, BandTooWideIsRefusedBeforeAllocating) {
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mean);
  auto banded = make_solver({.name = "banded", .max_band_bytes = 1000});
  try {
    banded->analyze(s.matrix);
    ADD_FAILURE() << "no error";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("half-bandwidth"), std::string::npos) << e.what();
  }
}

TEST(Solver, ReverseCuthillMcKeeShrinksTheBandOfAScrambledGrid) {
  const int nx = 30, ny = 20;
  const int n = nx * ny;
  std::vector<int> scramble(static_cast<std::size_t>(n));
  std::iota(scramble.begin(), scramble.end(), 0);
  std::shuffle(scramble.begin(), scramble.end(), std::mt19937(4));
  std::vector<Eigen::Triplet<double>> t;
  auto id = [&](int i, int j) { return scramble[static_cast<std::size_t>(j * nx + i)]; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      t.emplace_back(id(i, j), id(i, j), 4.0);
      if (i + 1 < nx) {
        t.emplace_back(id(i, j), id(i + 1, j), -1.0);
        t.emplace_back(id(i + 1, j), id(i, j), -1.0);
      }
      if (j + 1 < ny) {
        t.emplace_back(id(i, j), id(i, j + 1), -1.0);
        t.emplace_back(id(i, j + 1), id(i, j), -1.0);
      }
    }
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  const std::vector<int> perm = reverse_cuthill_mckee(a);
  std::vector<int> sorted = perm;
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < n; ++i) ASSERT_EQ(sorted[static_cast<std::size_t>(i)], i);
  std::vector<int> position(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    position[static_cast<std::size_t>(perm[static_cast<std::size_t>(i)])] = i;
  int band = 0, scrambled = 0;
  for (int j = 0; j < n; ++j)
    for (SparseMatrix::InnerIterator it(a, j); it; ++it) {
      scrambled = std::max(scrambled, std::abs(static_cast<int>(it.row()) - j));
      band = std::max(band, std::abs(position[static_cast<std::size_t>(it.row())] -
                                     position[static_cast<std::size_t>(j)]));
    }
  EXPECT_GT(scrambled, 300);
  EXPECT_LE(band, ny + 1); // the short side of the grid, plus one
}

// ---- The two-half factorization (split_cholesky.h) -----------------------------------------

// Whether a symmetric matrix couples a row of part 0 with one of part 1.
bool couples_the_halves(const SparseMatrix& a, const Separator& s) {
  for (int j = 0; j < a.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(a, j); it; ++it)
      if (s.part[static_cast<std::size_t>(it.row())] + s.part[static_cast<std::size_t>(j)] == 1)
        return true;
  return false;
}

// A split of a's rows into two halves that do not couple, within 40/60 of each other, and a
// separator whose count is its rows'.
void expect_a_balanced_split(const SparseMatrix& a, const Separator& s) {
  const auto n = static_cast<int>(a.rows());
  ASSERT_EQ(s.part.size(), static_cast<std::size_t>(n));
  EXPECT_FALSE(couples_the_halves(a, s));
  EXPECT_EQ(s.rows[0] + s.rows[1] + s.separator_rows, n);
  EXPECT_EQ(std::count(s.part.begin(), s.part.end(), 2), s.separator_rows);
  EXPECT_GE(std::min(s.rows[0], s.rows[1]), 0.4 * (s.rows[0] + s.rows[1]));
}

// The block-diagonal matrix [a 0; 0 b].
SparseMatrix block_diagonal(const SparseMatrix& a, const SparseMatrix& b) {
  std::vector<Eigen::Triplet<double>> t;
  for (const SparseMatrix* block : {&a, &b})
    for (int j = 0; j < block->outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(*block, j); it; ++it) {
        const auto shift = static_cast<int>(block == &a ? 0 : a.rows());
        t.emplace_back(static_cast<int>(it.row()) + shift, j + shift, it.value());
      }
  SparseMatrix both(a.rows() + b.rows(), a.cols() + b.cols());
  both.setFromTriplets(t.begin(), t.end());
  return both;
}

TEST(SplitCholesky, TheSeparatorDecouplesTwoBalancedHalves) {
  const KHarmonicSystem big = sphere_system(2, AreaWeights::Mean, 5);
  const Separator s = level_separator(big.matrix);
  const auto n = static_cast<int>(big.matrix.rows());
  expect_a_balanced_split(big.matrix, s);
  EXPECT_LT(s.separator_rows, n / 10); // a band across the sphere, not a slab of it

  // A second component (a small sphere's rows) joins one half whole.
  const KHarmonicSystem small = sphere_system(2, AreaWeights::Mean, 3);
  const auto m = static_cast<int>(small.matrix.rows());
  const SparseMatrix both = block_diagonal(big.matrix, small.matrix);
  const Separator two = level_separator(both);
  ASSERT_EQ(two.part.size(), static_cast<std::size_t>(n + m));
  EXPECT_FALSE(couples_the_halves(both, two));
  for (int v = n; v < n + m; ++v) ASSERT_EQ(two.part[static_cast<std::size_t>(v)], two.part[n]);
  EXPECT_NE(two.part[n], 2);

  // A star has no balanced level: every path goes through its centre.
  SparseMatrix star(50, 50);
  for (int v = 0; v < 50; ++v) star.insert(v, v) = 50.0;
  for (int v = 1; v < 50; ++v) star.insert(v, 0) = -1.0;
  EXPECT_TRUE(level_separator(star).part.empty());
}

// A path of seven rows in a nested-dissection order made by hand (its middle row last, each
// half's middle before it): elimination_tree() gives that order's tree, and a coupling added
// from the first row to the last across the middle raises the first row to the root, after
// which every coupled pair lies on one root path.
TEST(SplitCholesky, AHandMadeDissectionKeepsItsTreeWhenARowBridgesItsSeparator) {
  constexpr int n = 7;
  const std::vector<int> keys = {0, 2, 1, 6, 3, 5, 4}; // row → position
  const auto path = [](bool bridged) {
    std::vector<Eigen::Triplet<double>> t;
    for (int v = 0; v < n; ++v) t.emplace_back(v, v, 2.0);
    for (int v = 1; v < n; ++v) {
      t.emplace_back(v, v - 1, -1.0);
      t.emplace_back(v - 1, v, -1.0);
    }
    if (bridged) {
      t.emplace_back(0, n - 1, -1.0);
      t.emplace_back(n - 1, 0, -1.0);
    }
    SparseMatrix a(n, n);
    a.setFromTriplets(t.begin(), t.end());
    return a;
  };
  const std::vector<int> tree = elimination_tree(path(false), keys);
  EXPECT_EQ(tree, (std::vector<int>{2, 2, 6, 5, 5, 6, -1})); // parent by position
  std::vector<int> same = keys;
  EXPECT_EQ(raise_to_common_ancestors(path(false), 1, tree, same), 0);
  EXPECT_EQ(same, keys);
  std::vector<int> raised = keys;
  EXPECT_EQ(raise_to_common_ancestors(path(true), 1, tree, raised), 1);
  EXPECT_EQ(raised, (std::vector<int>{6, 2, 1, 6, 3, 5, 4})); // row 0 joins the separator
  // Within two steps the bridge couples more pairs; every one ends on one root path.
  std::vector<int> two = keys;
  EXPECT_GT(raise_to_common_ancestors(path(true), 2, tree, two), 0);
  const SparseMatrix a = path(true), a2 = SparseMatrix(a * a);
  for (int j = 0; j < n; ++j)
    for (SparseMatrix::InnerIterator it(a2, j); it; ++it) {
      int p = two[std::size_t(j)], q = two[std::size_t(it.row())];
      if (p > q) std::swap(p, q);
      while (p >= 0 && p < q) p = tree[std::size_t(p)];
      EXPECT_EQ(p, q) << "rows " << j << " and " << it.row();
    }
}

#ifdef REMORA_WITH_GPL_SOLVERS
bool is_a_permutation(std::vector<int> keys) {
  std::sort(keys.begin(), keys.end());
  for (std::size_t k = 0; k < keys.size(); ++k)
    if (keys[k] != static_cast<int>(k)) return false;
  return true;
}

// The keys of a system's rows in the order of its mesh (the base's order, as the editor gives
// them).
std::vector<int> region_keys(const std::vector<int>& mesh_keys, const KHarmonicSystem& s) {
  std::vector<int> keys(s.free_vertices.size());
  for (std::size_t r = 0; r < keys.size(); ++r)
    keys[r] = mesh_keys[static_cast<std::size_t>(s.free_vertices[r])];
  return keys;
}

// The base's order (nested_dissection.h) of a region: the rows of one mesh-wide order, as the
// editor gives them (Editor::prepare_regions). Its tree separator cuts the region into halves that do
// not couple, and its keys are a postorder of the tree. A forest, shared keys and keys too large
// to count give splits that do not couple either.
TEST(SplitCholesky, TheTreeOfANestedDissectionGivesAThinSeparator) {
  const Mesh mesh = make_icosphere(5);
  const KHarmonicAssembler assembler(mesh);
  const std::vector<int> base = nested_dissection_keys(ring_pattern(assembler.minus_w(), 2));
  ASSERT_EQ(base.size(), mesh.n_vertices());
  EXPECT_TRUE(is_a_permutation(base));
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mean, 5);
  const Separator tree = tree_separator(s.matrix, region_keys(base, s));
  const auto n = static_cast<int>(s.matrix.rows());
  expect_a_balanced_split(s.matrix, tree);
  EXPECT_LT(tree.separator_rows, std::sqrt(16.0 * n)); // under the solver's cap
  // The keys: a permutation in which every row comes before its neighbours in the separator.
  ASSERT_EQ(tree.keys.size(), static_cast<std::size_t>(n));
  EXPECT_TRUE(is_a_permutation(tree.keys));
  for (int j = 0; j < n; ++j)
    for (SparseMatrix::InnerIterator it(s.matrix, j); it; ++it)
      if (tree.part[static_cast<std::size_t>(j)] == 2 &&
          tree.part[static_cast<std::size_t>(it.row())] != 2) {
        ASSERT_LT(tree.keys[static_cast<std::size_t>(it.row())],
                  tree.keys[static_cast<std::size_t>(j)]);
      }
  // Two systems side by side (a forest), keys shared by pairs of rows (a bake's carried order),
  // and keys too large to count (sorted instead): splits that do not couple.
  const KHarmonicSystem small = sphere_system(2, AreaWeights::Mean, 3);
  const SparseMatrix both = block_diagonal(s.matrix, small.matrix);
  std::vector<int> both_keys = region_keys(base, s);
  for (Eigen::Index r = 0; r < small.matrix.rows(); ++r)
    both_keys.push_back(static_cast<int>(base.size() + static_cast<std::size_t>(r)));
  expect_a_balanced_split(both, tree_separator(both, both_keys));
  std::vector<int> shared = region_keys(base, s), large = shared;
  for (int& k : shared) k /= 2;
  for (int& k : large) k = 100 * k + 7;
  expect_a_balanced_split(s.matrix, tree_separator(s.matrix, shared));
  const Separator sorted_cut = tree_separator(s.matrix, large);
  EXPECT_EQ(sorted_cut.part, tree.part); // the same order, counted or sorted
  EXPECT_EQ(sorted_cut.keys, tree.keys);
  // A chain (a path graph in its own order) has no two subtrees to balance.
  SparseMatrix path(50, 50);
  for (int v = 0; v < 50; ++v) path.insert(v, v) = 4.0;
  for (int v = 1; v < 50; ++v) path.insert(v, v - 1) = -1.0;
  std::vector<int> in_order(50);
  std::iota(in_order.begin(), in_order.end(), 0);
  EXPECT_TRUE(tree_separator(path, in_order).part.empty());
  EXPECT_TRUE(tree_separator(s.matrix, std::vector<int>(3, 0)).part.empty()); // wrong count
}

// Whether positions p and q lie on one root path of `tree` (parent by position).
bool on_one_root_path(const std::vector<int>& tree, int p, int q) {
  if (p > q) std::swap(p, q);
  while (p >= 0 && p < q) p = tree[static_cast<std::size_t>(p)];
  return p == q;
}

// A bake's patch across the base's top separator, as new rows bridging two rows on its two
// sides: raised to common ancestors, every coupled pair of rows lies on one root path of the old
// tree again, and the tree cut separates the changed pattern. Trees that are not postordered and
// keys out of range are refused.
TEST(SplitCholesky, RowsBridgingASeparatorAreRaisedIntoIt) {
  const Mesh mesh = make_icosphere(5);
  const KHarmonicAssembler assembler(mesh);
  const SparseMatrix pattern = ring_pattern(assembler.minus_w(), 2);
  std::vector<int> keys = nested_dissection_keys(pattern);
  const std::vector<int> tree = elimination_tree(pattern, keys);
  const auto n = static_cast<int>(pattern.rows());
  ASSERT_EQ(tree.size(), static_cast<std::size_t>(n));
  // Two neighbours of the separator's last row on either side of it (on no common root path).
  const int top = static_cast<int>(std::max_element(keys.begin(), keys.end()) - keys.begin());
  std::vector<int> around;
  for (SparseMatrix::InnerIterator it(pattern, top); it; ++it) around.push_back(int(it.row()));
  int ends[2] = {-1, -1};
  for (const int a : around)
    for (const int b : around)
      if (ends[0] < 0 && !on_one_root_path(tree, keys[std::size_t(a)], keys[std::size_t(b)]))
        ends[0] = a, ends[1] = b;
  ASSERT_GE(ends[0], 0) << "no two rows on either side of the top separator";
  // Five new rows in a chain from one end to the other, keyed from the nearer end.
  std::vector<Eigen::Triplet<double>> entries;
  for (int j = 0; j < n; ++j)
    for (SparseMatrix::InnerIterator it(pattern, j); it; ++it)
      entries.emplace_back(static_cast<int>(it.row()), j, 1.0);
  const int added = 5;
  std::vector<int> chain = {ends[0]};
  for (int i = 0; i < added; ++i) {
    chain.push_back(n + i);
    const int key = keys[static_cast<std::size_t>(ends[i < 3 ? 0 : 1])];
    keys.push_back(key);
  }
  chain.push_back(ends[1]);
  for (std::size_t i = 0; i + 1 < chain.size(); ++i) {
    entries.emplace_back(chain[i], chain[i + 1], 1.0);
    entries.emplace_back(chain[i + 1], chain[i], 1.0);
  }
  for (int i = 0; i < added; ++i) entries.emplace_back(n + i, n + i, 1.0);
  SparseMatrix changed(n + added, n + added);
  changed.setFromTriplets(entries.begin(), entries.end());
  const auto coupled_off_path = [&](const std::vector<int>& k) {
    int off = 0;
    for (int j = 0; j < changed.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(changed, j); it; ++it)
        off += !on_one_root_path(tree, k[static_cast<std::size_t>(it.row())],
                                 k[static_cast<std::size_t>(j)]);
    return off;
  };
  EXPECT_EQ(coupled_off_path(keys), 2); // the chain's middle link, both ways
  const std::vector<int> carried = keys;
  const int raised = raise_to_common_ancestors(changed, 1, tree, keys);
  EXPECT_GT(raised, 0);
  EXPECT_EQ(coupled_off_path(keys), 0);
  for (std::size_t v = 0; v < keys.size(); ++v) // only up, to ancestors
    ASSERT_TRUE(keys[v] >= carried[v] && on_one_root_path(tree, keys[v], carried[v])) << v;
  const Separator cut = tree_separator(changed, keys);
  expect_a_balanced_split(changed, cut);
  EXPECT_LT(cut.separator_rows, std::sqrt(16.0 * (n + added)));
  std::vector<int> unchanged = nested_dissection_keys(pattern);
  EXPECT_EQ(raise_to_common_ancestors(assembler.minus_w(), 2, tree, unchanged),
            0); // nothing to raise
  // Refused: a parent below its child, a tree that is not a postorder, a key of no position.
  std::vector<int> three = {0, 1, 2};
  const SparseMatrix identity = SparseMatrix(Eigen::MatrixXd::Identity(3, 3).sparseView());
  EXPECT_THROW(raise_to_common_ancestors(identity, 1, {2, -1, 1}, three), InvalidArgument);
  EXPECT_THROW(raise_to_common_ancestors(identity, 1, {2, -1, -1}, three), InvalidArgument);
  std::vector<int> beyond = {0, 1, 3};
  EXPECT_THROW(raise_to_common_ancestors(identity, 1, {2, 2, -1}, beyond), InvalidArgument);
}

// In the base's order the halves solve as one factor does; keys of the wrong count are refused.
TEST(SplitCholesky, HalvesInTheBasesOrderSolveAsOneFactorDoes) {
  const Mesh mesh = make_icosphere(5);
  const KHarmonicAssembler assembler(mesh);
  for (int k = 1; k <= 3; ++k) {
    SCOPED_TRACE(::testing::Message() << "k " << k);
    const std::vector<int> base = nested_dissection_keys(ring_pattern(assembler.minus_w(), k));
    const KHarmonicSystem s = sphere_system(k, AreaWeights::Mean, 5);
    std::vector<int> keys = region_keys(base, s);
    const Eigen::MatrixXd b = block_rhs(s);
    auto reference = make_solver({.name = "ldlt"});
    reference->compute(s.matrix);
    const Eigen::MatrixXd x = reference->solve(b);
    SplitCholesky split;
    ASSERT_TRUE(split.analyze(s.matrix, 5000, true, keys));
    ASSERT_TRUE(split.factorize(s.matrix));
    EXPECT_LE(relative_difference(split.solve(b), x), 1e-9);
    keys.pop_back();
    EXPECT_THROW(split.analyze(s.matrix, 5000, true, keys), InvalidArgument);
  }
  EXPECT_THROW(nested_dissection_keys(SparseMatrix(3, 4)), InvalidArgument);
  // Through the solver's interface, on two threads (a system over the split's row threshold):
  // the same solution, cut by the tree.
  const Mesh fine = make_icosphere(6);
  const std::vector<int> base =
      nested_dissection_keys(ring_pattern(KHarmonicAssembler(fine).minus_w(), 2));
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mean, 6);
  std::vector<int> keys = region_keys(base, s);
  const Eigen::MatrixXd b = block_rhs(s);
  auto reference = make_solver({.name = "ldlt"});
  reference->compute(s.matrix);
  auto solver = make_solver({.name = "cholmod", .threads = 2});
  solver->set_order_keys(keys);
  solver->compute(s.matrix);
  EXPECT_TRUE(solver->stats().keyed_order);
  EXPECT_TRUE(solver->stats().tree_cut);
  EXPECT_GT(solver->stats().separator_rows, 0);
  EXPECT_LE(relative_difference(solver->solve(b), reference->solve(b)), 1e-9);
  keys.pop_back();
  solver->set_order_keys(keys);
  EXPECT_THROW(solver->analyze(s.matrix), InvalidArgument);
}

TEST(SplitCholesky, TwoHalvesSolveAsOneFactorDoes) {
  for (int k = 1; k <= 3; ++k) {
    SCOPED_TRACE(::testing::Message() << "k " << k);
    const KHarmonicSystem s = sphere_system(k, AreaWeights::Mean, 5);
    Eigen::MatrixXd b(s.matrix.rows(), 7);
    const Eigen::MatrixXd b3 = block_rhs(s);
    b << b3, -b3, b3.col(0) - 2.0 * b3.col(1);
    auto reference = make_solver({.name = "ldlt"});
    reference->compute(s.matrix);
    const Eigen::MatrixXd x = reference->solve(b);
    for (const bool coarse : {true, false}) {
      SCOPED_TRACE(coarse ? "coarse supernodes" : "CHOLMOD's supernodes");
      SplitCholesky split;
      ASSERT_TRUE(split.analyze(s.matrix, 5000, coarse));
      EXPECT_GT(split.separator_rows(), 0);
      EXPECT_THROW(split.solve(b), InvalidArgument); // not factored yet
      ASSERT_TRUE(split.factorize(s.matrix));
      const Eigen::MatrixXd y = split.solve(b);
      EXPECT_LE(relative_difference(y, x), 1e-9);
      EXPECT_LE((s.matrix * y - b).norm() / b.norm(), 1e-10);
      EXPECT_LE(relative_difference(split.solve(b.col(2)), x.col(2)), 1e-9);
      // Three columns: the sweeps' own code for x, y and z (supernodal_solve.cpp).
      EXPECT_LE(relative_difference(split.solve(b.middleCols(2, 3)), x.middleCols(2, 3)), 1e-9);
      EXPECT_EQ(split.solve(Eigen::MatrixXd(b.rows(), 0)).cols(), 0);
      EXPECT_THROW(split.solve(b.topRows(10)), InvalidArgument);
      const SparseMatrix doubled = 2.0 * s.matrix; // new numbers, same analysis
      ASSERT_TRUE(split.factorize(doubled));
      EXPECT_LE(relative_difference(split.solve(b), 0.5 * x), 1e-9);
    }
  }
}

// Two components: the small one joins a half whole, and the solve is that of each component.
TEST(SplitCholesky, ASecondComponentIsSolvedWithItsHalf) {
  const KHarmonicSystem big = sphere_system(1, AreaWeights::Mean, 5);
  const KHarmonicSystem small = sphere_system(1, AreaWeights::Mean, 3);
  const auto n = static_cast<int>(big.matrix.rows());
  const auto m = static_cast<int>(small.matrix.rows());
  const SparseMatrix both = block_diagonal(big.matrix, small.matrix);
  Eigen::MatrixXd b(n + m, 3);
  b << block_rhs(big), block_rhs(small);
  SplitCholesky split;
  ASSERT_TRUE(split.analyze(both, 5000, true));
  ASSERT_TRUE(split.factorize(both));
  const Eigen::MatrixXd x = split.solve(b);
  EXPECT_LE((both * x - b).norm() / b.norm(), 1e-10);
}

TEST(SplitCholesky, RefusesWhatOneFactorRefuses) {
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mean, 5);
  SplitCholesky split;
  EXPECT_FALSE(split.analyze(s.matrix, 1, true)); // no separator that thin
  ASSERT_TRUE(split.analyze(s.matrix, 5000, true));
  const SparseMatrix indefinite = -s.matrix;
  EXPECT_FALSE(split.factorize(indefinite));
  SparseMatrix other = s.matrix;
  other.coeffRef(5, 0) += 1.0; // one entry more
  other.coeffRef(0, 5) += 1.0;
  other.makeCompressed();
  EXPECT_THROW(split.factorize(other), InvalidArgument);
  // As many entries, in other places: column 0 loses its last entry, column 1 gains one.
  std::vector<Eigen::Triplet<double>> moved;
  for (int j = 0; j < s.matrix.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(s.matrix, j); it; ++it)
      moved.emplace_back(static_cast<int>(it.row()), j, it.value());
  int far = 0; // a row not coupled with row 1
  while (s.matrix.coeff(far, 1) != 0.0) ++far;
  const auto last_of_0 = std::find_if(moved.rbegin(), moved.rend(),
                                      [](const auto& e) { return e.col() == 0 && e.row() != 0; });
  moved.erase(std::next(last_of_0).base());
  moved.emplace_back(far, 1, 0.0);
  SparseMatrix shuffled(s.matrix.rows(), s.matrix.cols());
  shuffled.setFromTriplets(moved.begin(), moved.end());
  ASSERT_EQ(shuffled.nonZeros(), s.matrix.nonZeros());
  EXPECT_THROW(split.factorize(shuffled), InvalidArgument);
}

// Through make_solver: cholmod factors a large system in two halves when it has two threads, and
// as one on one thread; both give the same solution.
TEST(Solver, CholmodFactorsALargeSystemInTwoHalvesOnTwoThreads) {
  const KHarmonicSystem s = sphere_system(2, AreaWeights::Mean, 6);
  const Eigen::MatrixXd b = block_rhs(s);
  auto one = make_solver({.name = "cholmod", .threads = 1});
  auto two = make_solver({.name = "cholmod", .threads = 2});
  one->compute(s.matrix);
  two->compute(s.matrix);
  EXPECT_EQ(one->stats().separator_rows, 0);
  EXPECT_GT(two->stats().separator_rows, 0);
  const Eigen::MatrixXd x = one->solve(b);
  EXPECT_LE((s.matrix * x - b).norm() / b.norm(), 1e-10);
  EXPECT_LE(relative_difference(two->solve(b), x), 1e-9);
  EXPECT_EQ(two->solve(Eigen::MatrixXd(b.rows(), 0)).cols(), 0);
  // The same object analyses a small system (one factor), then the large one again.
  const KHarmonicSystem small = sphere_system(2, AreaWeights::Mean);
  two->compute(small.matrix);
  EXPECT_EQ(two->stats().separator_rows, 0);
  EXPECT_LE(relative_difference(small.matrix * two->solve(block_rhs(small)), block_rhs(small)),
            1e-10);
  two->analyze(s.matrix);
  EXPECT_THROW(two->solve(b), InvalidArgument); // analysed, not factored
  two->factorize(s.matrix);
  EXPECT_GT(two->stats().separator_rows, 0);
  EXPECT_LE(relative_difference(two->solve(b), x), 1e-9);
  const SparseMatrix indefinite = -s.matrix;
  try {
    two->factorize(indefinite);
    ADD_FAILURE() << "an indefinite matrix was factored";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("not positive definite"), std::string::npos) << e.what();
  }
}
#endif

} // namespace
} // namespace remora
