// The solver suite on the paper's Table 1 set-up (§5.3), as Google Benchmark cases: the bundled
// bunny remeshed with the defaults, a geodesic disc around the vertex nearest the centroid with
// its inner 5 % as the handle and N free vertices, the rest fixed; thin plate (k = 2), mean
// areas (SPD). `remora bench solvers` prints the same figures as a table next to the paper's,
// with the iterative solvers and the multigrid; this file is for tracking the direct solvers'
// costs over time, and what keeping a region's factor when a stroke grows the region would
// give (grow_*; CHOLMOD's row addition, row deletion and update/downdate: bench_modify.cpp).
// The regions are bench_regions.h's. Results go to docs/benchmarks.md and docs/solvers.md with
// the machine.
#include <algorithm>
#include <map>
#include <memory>
#include <string>

#include <Eigen/Cholesky>
#include <benchmark/benchmark.h>

#include "bench_regions.h"
#include "remora/linalg/solver.h"

namespace {

using remora_bench::Grown;
using remora_bench::grown;
using remora_bench::Problem;
using remora_bench::problem;

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

// What the grown region's factor and 7 basis solves cost afresh, against keeping the old
// region's factor and bordering it with the added rows: X = A_FF⁻¹ A_FA (one block solve of
// `added` columns), the Schur complement S = A_AA − A_AF X (dense, Cholesky), and the grown
// system's solves by block elimination.
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
