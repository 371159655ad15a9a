// The solver suite on the paper's Table 1 set-up (§5.3), as Google Benchmark cases: the bundled
// bunny remeshed with the defaults, a geodesic disc around the vertex nearest the centroid with
// its inner 5 % as the handle and N free vertices, the rest fixed; thin plate (k = 2), mean
// areas (SPD). `remora bench solvers` prints the same figures as a table next to the paper's,
// with the iterative solvers and the multigrid; this file is for tracking the direct solvers'
// costs over time. Results go to docs/benchmarks.md with the machine.
#include <algorithm>
#include <map>
#include <memory>
#include <string>

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

} // namespace
