// The solver suite on the paper's Table 1 set-up (§5.3), as Google Benchmark cases: the bundled
// bunny remeshed with the defaults, a geodesic disc around the vertex nearest the centroid with
// its inner 5 % as the handle and N free vertices, the rest fixed; thin plate (k = 2), mean
// areas (SPD). `remora bench solvers` prints the same figures as a table next to the paper's,
// with the iterative solvers and the multigrid; this file is for tracking the direct solvers'
// costs over time, and what keeping a region's factor when a stroke grows the region would
// give (grow_*). Results go to docs/benchmarks.md and docs/solvers.md with the machine.
#include <algorithm>
#include <map>
#include <memory>
#include <string>

#include <Eigen/Cholesky>
#include <benchmark/benchmark.h>

#include "remora/geometry/selection.h"
#include "remora/linalg/kharmonic.h"
#include "remora/linalg/solver.h"
#include "remora/mesh/io.h"
#include "remora/remesh/remesh.h"

namespace {

using remora::KHarmonicSystem;

struct Problem {
  KHarmonicSystem system;
  Eigen::MatrixXd rhs; ///< x, y, z of a handle translation
};

const remora::Mesh& remeshed_bunny() {
  static const remora::Mesh mesh = [] {
    remora::RemeshOptions options;
    options.compute_report = false;
    return remora::remesh(remora::read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh,
                          options)
        .mesh;
  }();
  return mesh;
}

// The system with `free_count` free vertices, built once per size.
const Problem& problem(int free_count) {
  static std::map<int, std::unique_ptr<Problem>> cache;
  auto& slot = cache[free_count];
  if (slot) return *slot;
  const remora::Mesh& mesh = remeshed_bunny();
  const remora::VertexHandle seed = remora::central_vertex(mesh);
  const auto handle = static_cast<std::size_t>(free_count) / 19; // 5 % of the disc
  const std::vector<int> order =
      remora::geodesic_order(mesh, seed, handle + static_cast<std::size_t>(free_count));
  remora::Region region = remora::Region::all_fixed(mesh.n_vertices());
  for (std::size_t i = 0; i < order.size(); ++i)
    region.label[static_cast<std::size_t>(order[i])] = i < handle ? 0 : remora::Region::kFree;
  slot = std::make_unique<Problem>();
  slot->system = remora::assemble_kharmonic(mesh, region, {.k = 2});
  Eigen::MatrixXd constrained = slot->system.gather_constrained(remora::positions_matrix(mesh));
  for (std::size_t c = 0; c < slot->system.constrained_vertices.size(); ++c)
    if (region.label[static_cast<std::size_t>(slot->system.constrained_vertices[c])] == 0)
      constrained.row(static_cast<Eigen::Index>(c)) += Eigen::RowVector3d(0.01, 0.005, -0.008);
  slot->rhs = slot->system.rhs(constrained);
  return *slot;
}

remora::SolverOptions options_for(const std::string& name) {
  remora::SolverOptions options;
  options.name = name;
  if (name == "cholmod-metis") {
    options.name = "cholmod";
    options.ordering = "metis";
  }
  return options;
}

bool available(benchmark::State& state, const std::string& name) {
  const auto names = remora::solver_names();
  const std::string base = options_for(name).name;
  if (std::find(names.begin(), names.end(), base) != names.end()) return true;
  state.SkipWithError((name + " is not in this build").c_str());
  return false;
}

// Analysis + numerical factorization of a fresh solver (what a new region costs).
void precompute(benchmark::State& state, const std::string& name) {
  if (!available(state, name)) return;
  const Problem& p = problem(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto solver = remora::make_solver(options_for(name));
    solver->compute(p.system.matrix);
    benchmark::DoNotOptimize(solver);
  }
  state.counters["free"] = static_cast<double>(p.system.matrix.rows());
}

// The numerical factorization again, the analysis kept (new values on the same pattern).
void refactor(benchmark::State& state, const std::string& name) {
  if (!available(state, name)) return;
  const Problem& p = problem(static_cast<int>(state.range(0)));
  auto solver = remora::make_solver(options_for(name));
  solver->compute(p.system.matrix);
  for (auto _ : state) solver->factorize(p.system.matrix);
}

// Three solutions (x, y, z) as one block, the factor kept: one handle move.
void solve3(benchmark::State& state, const std::string& name) {
  if (!available(state, name)) return;
  const Problem& p = problem(static_cast<int>(state.range(0)));
  auto solver = remora::make_solver(options_for(name));
  solver->compute(p.system.matrix);
  for (auto _ : state) benchmark::DoNotOptimize(solver->solve(p.rhs));
  state.counters["factor_MB"] = static_cast<double>(solver->stats().factor_bytes) / 1e6;
}

// The editor's move: the 7 basis functions of one handle (rest, affine part) solved once, then
// a move is the product with its 7 × 3 coefficient matrix.
void basis_move(benchmark::State& state) {
  const Problem& p = problem(static_cast<int>(state.range(0)));
  auto solver = remora::make_solver();
  solver->compute(p.system.matrix);
  Eigen::MatrixXd rhs7(p.rhs.rows(), 7);
  for (Eigen::Index c = 0; c < 7; ++c)
    rhs7.col(c) = p.rhs.col(c % 3) * (1.0 + 0.1 * static_cast<double>(c));
  const Eigen::MatrixXd basis = solver->solve(rhs7);
  Eigen::Matrix<double, 7, 3> coefficients = Eigen::Matrix<double, 7, 3>::Random();
  for (auto _ : state) {
    Eigen::MatrixXd x = basis * coefficients;
    benchmark::DoNotOptimize(x.data());
    coefficients(6, 0) += 1e-9;
  }
}

// A region grown by a stroke: the disc's 31,000 free vertices and then `added` more (the next
// ones by distance, as a brush's crescent adds them). What the grown region's factor and 7
// basis solves cost afresh, against keeping the old region's factor and bordering it with the
// added rows: X = A_FF⁻¹ A_FA (one block solve of `added` columns), the Schur complement
// S = A_AA − A_AF X (dense, Cholesky), and the grown system's solves by block elimination.
// A principal submatrix: the grown region's rows and columns of F are the old system's.
struct Grown {
  const Problem* old = nullptr;
  KHarmonicSystem system;
  std::vector<Eigen::Index> old_rows, added_rows; ///< rows of the grown system: F's, the added
  Eigen::MatrixXd rhs7;                           ///< 7 right-hand sides of the grown system
};

const Grown& grown(int added) {
  static std::map<int, std::unique_ptr<Grown>> cache;
  auto& slot = cache[added];
  if (slot) return *slot;
  constexpr int kFree = 31000;
  slot = std::make_unique<Grown>();
  slot->old = &problem(kFree);
  const remora::Mesh& mesh = remeshed_bunny();
  const auto handle = static_cast<std::size_t>(kFree) / 19;
  const std::vector<int> order = remora::geodesic_order(
      mesh, remora::central_vertex(mesh), handle + static_cast<std::size_t>(kFree + added));
  remora::Region region = remora::Region::all_fixed(mesh.n_vertices());
  for (std::size_t i = 0; i < order.size(); ++i)
    region.label[static_cast<std::size_t>(order[i])] = i < handle ? 0 : remora::Region::kFree;
  slot->system = remora::assemble_kharmonic(mesh, region, {.k = 2});
  for (std::size_t r = 0; r < slot->system.free_vertices.size(); ++r) {
    const int v = slot->system.free_vertices[r];
    (slot->old->system.row_of[static_cast<std::size_t>(v)] >= 0 ? slot->old_rows : slot->added_rows)
        .push_back(static_cast<Eigen::Index>(r));
  }
  slot->rhs7 = Eigen::MatrixXd::Random(slot->system.matrix.rows(), 7);
  return *slot;
}

void grow_afresh(benchmark::State& state) {
  const Grown& g = grown(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto solver = remora::make_solver();
    solver->compute(g.system.matrix);
    benchmark::DoNotOptimize(solver->solve(g.rhs7));
  }
}

void grow_schur(benchmark::State& state) {
  const Grown& g = grown(static_cast<int>(state.range(0)));
  auto solver = remora::make_solver();
  solver->compute(g.old->system.matrix); // the old region's factor, kept
  const auto nf = static_cast<Eigen::Index>(g.old_rows.size());
  const auto na = static_cast<Eigen::Index>(g.added_rows.size());
  Eigen::MatrixXd x;
  for (auto _ : state) {
    // A_FA and A_AA from the grown system's columns of the added vertices.
    Eigen::MatrixXd border = Eigen::MatrixXd::Zero(nf, na), corner = Eigen::MatrixXd::Zero(na, na);
    std::vector<Eigen::Index> slot(static_cast<std::size_t>(g.system.matrix.rows()), -1);
    for (Eigen::Index i = 0; i < nf; ++i) slot[static_cast<std::size_t>(g.old_rows[i])] = i;
    for (Eigen::Index a = 0; a < na; ++a) slot[static_cast<std::size_t>(g.added_rows[a])] = nf + a;
    for (Eigen::Index a = 0; a < na; ++a)
      for (remora::SparseMatrix::InnerIterator it(g.system.matrix, g.added_rows[a]); it; ++it) {
        const Eigen::Index r = slot[static_cast<std::size_t>(it.row())];
        if (r < nf)
          border(r, a) = it.value();
        else
          corner(r - nf, a) = it.value();
      }
    const Eigen::MatrixXd solved = solver->solve(border); // A_FF⁻¹ A_FA
    const Eigen::LLT<Eigen::MatrixXd> schur(corner - border.transpose() * solved);
    // The grown system's 7 solves by block elimination.
    Eigen::MatrixXd bf(nf, 7), ba(na, 7);
    for (Eigen::Index i = 0; i < nf; ++i) bf.row(i) = g.rhs7.row(g.old_rows[i]);
    for (Eigen::Index a = 0; a < na; ++a) ba.row(a) = g.rhs7.row(g.added_rows[a]);
    const Eigen::MatrixXd y = solver->solve(bf);
    const Eigen::MatrixXd z = schur.solve(ba - border.transpose() * y);
    x.resize(nf + na, 7);
    x.topRows(nf) = y - solved * z;
    x.bottomRows(na) = z;
    benchmark::DoNotOptimize(x.data());
  }
  // The same numbers as the grown system's own solve (rows in the order F, added).
  auto reference = remora::make_solver();
  reference->compute(g.system.matrix);
  const Eigen::MatrixXd expected = reference->solve(g.rhs7);
  double error = 0;
  for (Eigen::Index i = 0; i < nf; ++i)
    error = std::max(error, (x.row(i) - expected.row(g.old_rows[i])).cwiseAbs().maxCoeff());
  for (Eigen::Index a = 0; a < na; ++a)
    error = std::max(error, (x.row(nf + a) - expected.row(g.added_rows[a])).cwiseAbs().maxCoeff());
  state.counters["max_error"] = error / expected.cwiseAbs().maxCoeff();
  state.counters["added"] = static_cast<double>(na);
}

void added_sizes(benchmark::internal::Benchmark* b) {
  b->Arg(30)->Arg(100)->Arg(300)->Arg(1000)->Unit(benchmark::kMillisecond);
}

void sizes(benchmark::internal::Benchmark* b) {
  b->Arg(15000)->Arg(31000)->Unit(benchmark::kMillisecond);
}

BENCHMARK_CAPTURE(precompute, cholmod, std::string("cholmod"))->Apply(sizes);
BENCHMARK_CAPTURE(precompute, cholmod_metis, std::string("cholmod-metis"))->Apply(sizes);
BENCHMARK_CAPTURE(precompute, llt_libigl_path, std::string("llt"))->Apply(sizes);
BENCHMARK_CAPTURE(precompute, ldlt, std::string("ldlt"))->Apply(sizes);
BENCHMARK_CAPTURE(refactor, cholmod, std::string("cholmod"))->Apply(sizes);
BENCHMARK_CAPTURE(refactor, llt_libigl_path, std::string("llt"))->Apply(sizes);
BENCHMARK_CAPTURE(solve3, cholmod, std::string("cholmod"))->Apply(sizes);
BENCHMARK_CAPTURE(solve3, cholmod_metis, std::string("cholmod-metis"))->Apply(sizes);
BENCHMARK_CAPTURE(solve3, llt_libigl_path, std::string("llt"))->Apply(sizes);
BENCHMARK_CAPTURE(solve3, ldlt, std::string("ldlt"))->Apply(sizes);
BENCHMARK_CAPTURE(solve3, banded, std::string("banded"))->Apply(sizes);
BENCHMARK(basis_move)->Apply(sizes);
BENCHMARK(grow_afresh)->Apply(added_sizes);
BENCHMARK(grow_schur)->Apply(added_sizes);

} // namespace
