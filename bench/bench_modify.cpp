// What CHOLMOD's Modify module (GPL, in the same library as the supernodal factor) would give a
// region changed by a stroke, on the Grown regions of bench_solvers.cpp: the bunny's
// 31,000-vertex disc grown by the next `added` vertices by distance, or shrunk by its last
// `removed` ones (an erase stroke at the rim). Each keeps the old region's factor as a simplicial
// LDLᵀ and modifies it:
//   modify_updown  the grown system G = M0 + Δ, M0 the old system bordered by the identity on the
//                  added rows; Δ (nonzero on the added rows and columns only) split by a dense
//                  eigendecomposition on the rows it touches into C₊C₊ᵀ − C₋C₋ᵀ, then
//                  cholmod_updown (update, then downdate) — the eigendecomposition is timed too;
//   modify_rowadd  the same M0, then one cholmod_rowadd per added vertex, each row holding its
//                  couplings to the rows present;
//   modify_rowdel  the old system, then one cholmod_rowdel per removed vertex.
// Each then solves 7 right-hand sides and checks them against the changed system's own factor
// (counter max_error, relative). The old simplicial factor is made outside the timed loop; its
// cost is the counter simplicial_ms. Compare with grow_afresh (a fresh supernodal factor and 7
// solves); shrink_afresh is the same for the erased region. Results: docs/solvers.md.
#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <benchmark/benchmark.h>

#include "bench_regions.h"
#include "remora/linalg/solver.h"

#ifdef REMORA_WITH_GPL_SOLVERS
#include <cholmod.h>

#include "remora/linalg/cholmod_settings.h"

namespace {

using remora::SparseMatrix;

// One cholmod_common for the file, set for simplicial LDLᵀ with AMD (the Modify module's input).
struct Cholmod {
  cholmod_common c{};
  Cholmod() {
    cholmod_start(&c);
    c.supernodal = CHOLMOD_SIMPLICIAL;
    c.final_ll = 0;
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_AMD;
    c.postorder = 1;
  }
  ~Cholmod() { cholmod_finish(&c); }
  Cholmod(const Cholmod&) = delete;
  Cholmod& operator=(const Cholmod&) = delete;
};

Cholmod& cm() {
  static Cholmod instance;
  return instance;
}

void check(bool ok, const char* what) {
  if (!ok || cm().c.status < CHOLMOD_OK) throw std::runtime_error(std::string(what) + " failed");
}

// The lower triangle of `a`, compressed: what lower_view() shows CHOLMOD.
SparseMatrix lower_of(const SparseMatrix& a) {
  SparseMatrix l = a.triangularView<Eigen::Lower>();
  l.makeCompressed();
  return l;
}

cholmod_sparse view_of(SparseMatrix& l) {
  return remora::lower_view(static_cast<std::size_t>(l.rows()),
                            static_cast<std::size_t>(l.nonZeros()), l.outerIndexPtr(),
                            l.innerIndexPtr(), l.valuePtr());
}

// `a` with the rows and columns in `rows` replaced by the identity's.
SparseMatrix decoupled(const SparseMatrix& a, const std::vector<Eigen::Index>& rows) {
  std::vector<char> out(static_cast<std::size_t>(a.rows()), 0);
  for (const Eigen::Index r : rows) out[static_cast<std::size_t>(r)] = 1;
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(a.nonZeros()));
  for (Eigen::Index j = 0; j < a.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(a, j); it; ++it)
      if (!out[static_cast<std::size_t>(it.row())] && !out[static_cast<std::size_t>(j)])
        t.emplace_back(static_cast<int>(it.row()), static_cast<int>(j), it.value());
  for (const Eigen::Index r : rows) t.emplace_back(static_cast<int>(r), static_cast<int>(r), 1.0);
  SparseMatrix m(a.rows(), a.cols());
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

// A simplicial LDLᵀ factor of `values` on the AMD analysis of `pattern` (same size).
struct Factor {
  cholmod_factor* f = nullptr;
  std::vector<int> position; ///< position[row] = the row's index in L's order
  double factor_ms = 0;
  ~Factor() { cholmod_free_factor(&f, &cm().c); }
};

std::unique_ptr<Factor> simplicial(const SparseMatrix& pattern, const SparseMatrix& values) {
  auto out = std::make_unique<Factor>();
  const auto t0 = std::chrono::steady_clock::now();
  SparseMatrix lp = lower_of(pattern), lv = lower_of(values);
  cholmod_sparse p = view_of(lp), v = view_of(lv);
  out->f = cholmod_analyze(&p, &cm().c);
  check(out->f != nullptr, "cholmod_analyze");
  check(cholmod_factorize(&v, out->f, &cm().c) != 0, "cholmod_factorize");
  out->factor_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const auto* perm = static_cast<const int*>(out->f->Perm);
  out->position.resize(out->f->n);
  for (std::size_t k = 0; k < out->f->n; ++k)
    out->position[static_cast<std::size_t>(perm[k])] = static_cast<int>(k);
  return out;
}

Eigen::MatrixXd solve(cholmod_factor* f, const Eigen::MatrixXd& rhs) {
  cholmod_dense b = remora::dense_view(rhs.data(), static_cast<std::size_t>(rhs.rows()),
                                       static_cast<std::size_t>(rhs.cols()));
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, f, &b, &cm().c);
  check(x != nullptr, "cholmod_solve");
  Eigen::MatrixXd out =
      Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), rhs.rows(), rhs.cols());
  cholmod_free_dense(&x, &cm().c);
  return out;
}

// max |x − reference| / max |reference| over `rows` (all rows when empty).
double relative_error(const Eigen::MatrixXd& x, const SparseMatrix& a, const Eigen::MatrixXd& rhs,
                      const std::vector<Eigen::Index>& rows) {
  auto reference = remora::make_solver();
  reference->compute(a);
  const Eigen::MatrixXd expected = reference->solve(rhs);
  double error = 0;
  for (const Eigen::Index r : rows)
    error = std::max(error, (x.row(r) - expected.row(r)).cwiseAbs().maxCoeff());
  return error / expected.cwiseAbs().maxCoeff();
}

using remora_bench::Grown;
using remora_bench::grown;
using remora_bench::problem;

// Δ = G − M0 as C₊C₊ᵀ − C₋C₋ᵀ, rows in L's order: the eigendecomposition of Δ on the rows it
// touches (the added rows and the old rows coupled to them).
struct Split {
  cholmod_sparse* plus = nullptr;
  cholmod_sparse* minus = nullptr;
  ~Split() {
    cholmod_free_sparse(&plus, &cm().c);
    cholmod_free_sparse(&minus, &cm().c);
  }
};

cholmod_sparse* columns(const Eigen::MatrixXd& v, const std::vector<Eigen::Index>& rows,
                        const std::vector<int>& position, std::size_t n) {
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), v.cols());
  for (std::size_t t = 0; t < rows.size(); ++t)
    full.row(position[static_cast<std::size_t>(rows[t])]) = v.row(static_cast<Eigen::Index>(t));
  cholmod_dense d = remora::dense_view(full.data(), n, static_cast<std::size_t>(v.cols()));
  cholmod_sparse* s = cholmod_dense_to_sparse(&d, 1, &cm().c);
  check(s != nullptr, "cholmod_dense_to_sparse");
  return s;
}

void split_difference(const Grown& g, const std::vector<int>& position, Split& out) {
  const SparseMatrix& a = g.system.matrix;
  std::vector<Eigen::Index> touched(g.added_rows);
  std::vector<char> in(static_cast<std::size_t>(a.rows()), 0);
  for (const Eigen::Index r : g.added_rows) in[static_cast<std::size_t>(r)] = 2;
  for (const Eigen::Index r : g.added_rows)
    for (SparseMatrix::InnerIterator it(a, r); it; ++it)
      if (in[static_cast<std::size_t>(it.row())] == 0) {
        in[static_cast<std::size_t>(it.row())] = 1;
        touched.push_back(it.row());
      }
  std::vector<Eigen::Index> slot(static_cast<std::size_t>(a.rows()), -1);
  for (std::size_t t = 0; t < touched.size(); ++t)
    slot[static_cast<std::size_t>(touched[t])] = static_cast<Eigen::Index>(t);
  const auto m = static_cast<Eigen::Index>(touched.size());
  Eigen::MatrixXd delta = Eigen::MatrixXd::Zero(m, m);
  for (const Eigen::Index r : g.added_rows) { // the added columns, and their transposes
    const Eigen::Index j = slot[static_cast<std::size_t>(r)];
    for (SparseMatrix::InnerIterator it(a, r); it; ++it) {
      const Eigen::Index i = slot[static_cast<std::size_t>(it.row())];
      delta(i, j) = it.value();
      delta(j, i) = it.value();
    }
    delta(j, j) -= 1.0; // M0 holds the identity there
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(delta);
  const double floor = 1e-14 * eig.eigenvalues().cwiseAbs().maxCoeff();
  std::vector<Eigen::Index> pos, neg;
  for (Eigen::Index k = 0; k < m; ++k) (eig.eigenvalues()(k) > floor ? pos : neg).push_back(k);
  auto scaled = [&](const std::vector<Eigen::Index>& ks, double sign) {
    Eigen::MatrixXd c(m, static_cast<Eigen::Index>(ks.size()));
    for (std::size_t q = 0; q < ks.size(); ++q)
      c.col(static_cast<Eigen::Index>(q)) =
          eig.eigenvectors().col(ks[q]) * std::sqrt(std::max(0.0, sign * eig.eigenvalues()(ks[q])));
    return c;
  };
  const auto n = static_cast<std::size_t>(a.rows());
  out.plus = columns(scaled(pos, 1.0), touched, position, n);
  out.minus = columns(scaled(neg, -1.0), touched, position, n);
}

void modify_updown(benchmark::State& state) {
  const Grown& g = grown(static_cast<int>(state.range(0)));
  const SparseMatrix bordered = decoupled(g.system.matrix, g.added_rows);
  const auto old = simplicial(g.system.matrix, bordered);
  Eigen::MatrixXd x;
  double rank = 0;
  for (auto _ : state) {
    state.PauseTiming();
    cholmod_factor* f = cholmod_copy_factor(old->f, &cm().c);
    state.ResumeTiming();
    Split split;
    split_difference(g, old->position, split);
    check(cholmod_updown(1, split.plus, f, &cm().c) != 0, "cholmod_updown (update)");
    check(cholmod_updown(0, split.minus, f, &cm().c) != 0, "cholmod_updown (downdate)");
    x = solve(f, g.rhs7);
    rank = static_cast<double>(split.plus->ncol + split.minus->ncol);
    state.PauseTiming();
    cholmod_free_factor(&f, &cm().c);
    state.ResumeTiming();
  }
  std::vector<Eigen::Index> all(static_cast<std::size_t>(g.system.matrix.rows()));
  for (std::size_t r = 0; r < all.size(); ++r) all[r] = static_cast<Eigen::Index>(r);
  state.counters["max_error"] = relative_error(x, g.system.matrix, g.rhs7, all);
  state.counters["rank"] = rank;
  state.counters["simplicial_ms"] = old->factor_ms;
}

void modify_rowadd(benchmark::State& state) {
  const Grown& g = grown(static_cast<int>(state.range(0)));
  const SparseMatrix& a = g.system.matrix;
  const auto old = simplicial(a, decoupled(a, g.added_rows));
  const auto n = static_cast<std::size_t>(a.rows());
  Eigen::MatrixXd x;
  for (auto _ : state) {
    state.PauseTiming();
    cholmod_factor* f = cholmod_copy_factor(old->f, &cm().c);
    state.ResumeTiming();
    std::vector<char> present(n, 1);
    for (const Eigen::Index r : g.added_rows) present[static_cast<std::size_t>(r)] = 0;
    for (const Eigen::Index r : g.added_rows) {
      present[static_cast<std::size_t>(r)] = 1; // its couplings to the rows present, itself
      std::size_t nnz = 0;
      for (SparseMatrix::InnerIterator it(a, r); it; ++it)
        nnz += present[static_cast<std::size_t>(it.row())];
      cholmod_sparse* col = cholmod_allocate_sparse(n, 1, nnz, 0, 1, 0, CHOLMOD_REAL, &cm().c);
      auto* ci = static_cast<int*>(col->i);
      auto* cx = static_cast<double*>(col->x);
      int k = 0;
      for (SparseMatrix::InnerIterator it(a, r); it; ++it)
        if (present[static_cast<std::size_t>(it.row())]) {
          ci[k] = old->position[static_cast<std::size_t>(it.row())];
          cx[k++] = it.value();
        }
      static_cast<int*>(col->p)[1] = k;
      const auto at = static_cast<std::size_t>(old->position[static_cast<std::size_t>(r)]);
      check(cholmod_rowadd(at, col, f, &cm().c) != 0, "cholmod_rowadd");
      cholmod_free_sparse(&col, &cm().c);
    }
    x = solve(f, g.rhs7);
    state.PauseTiming();
    cholmod_free_factor(&f, &cm().c);
    state.ResumeTiming();
  }
  std::vector<Eigen::Index> all(n);
  for (std::size_t r = 0; r < n; ++r) all[r] = static_cast<Eigen::Index>(r);
  state.counters["max_error"] = relative_error(x, a, g.rhs7, all);
  state.counters["simplicial_ms"] = old->factor_ms;
}

// An erase stroke at the rim: the disc's 31,000 free vertices less their last `removed` by
// distance, which become fixed. Its matrix is the old one's principal submatrix.
struct Shrunk {
  remora::KHarmonicSystem system;
  std::vector<Eigen::Index> kept_rows, removed_rows; ///< rows of the old system
  Eigen::MatrixXd rhs7;                              ///< on the old system's rows, 0 where removed
};

const Shrunk& shrunk(int removed) {
  static std::map<int, std::unique_ptr<Shrunk>> cache;
  auto& slot = cache[removed];
  if (slot) return *slot;
  const auto& old = problem(remora_bench::kGrownFrom).system;
  slot = std::make_unique<Shrunk>();
  const auto handle = static_cast<std::size_t>(remora_bench::kGrownFrom) / 19;
  slot->system =
      remora_bench::disc(handle, static_cast<std::size_t>(remora_bench::kGrownFrom - removed))
          .system;
  for (std::size_t r = 0; r < old.free_vertices.size(); ++r) {
    const int v = old.free_vertices[r];
    (slot->system.row_of[static_cast<std::size_t>(v)] >= 0 ? slot->kept_rows : slot->removed_rows)
        .push_back(static_cast<Eigen::Index>(r));
  }
  slot->rhs7 = Eigen::MatrixXd::Random(old.matrix.rows(), 7);
  for (const Eigen::Index r : slot->removed_rows) slot->rhs7.row(r).setZero();
  return *slot;
}

void modify_rowdel(benchmark::State& state) {
  const Shrunk& s = shrunk(static_cast<int>(state.range(0)));
  const SparseMatrix& a = problem(remora_bench::kGrownFrom).system.matrix;
  const auto old = simplicial(a, a);
  Eigen::MatrixXd x;
  for (auto _ : state) {
    state.PauseTiming();
    cholmod_factor* f = cholmod_copy_factor(old->f, &cm().c);
    state.ResumeTiming();
    for (const Eigen::Index r : s.removed_rows)
      check(cholmod_rowdel(static_cast<std::size_t>(old->position[static_cast<std::size_t>(r)]),
                           nullptr, f, &cm().c) != 0,
            "cholmod_rowdel");
    x = solve(f, s.rhs7);
    state.PauseTiming();
    cholmod_free_factor(&f, &cm().c);
    state.ResumeTiming();
  }
  // Against the erased region's own system, assembled afresh (its rows in the old order).
  const Eigen::Index nk = static_cast<Eigen::Index>(s.kept_rows.size());
  Eigen::MatrixXd rhs(nk, 7), mine(nk, 7);
  const auto& old_system = problem(remora_bench::kGrownFrom).system;
  for (Eigen::Index k = 0; k < nk; ++k) {
    const int v = old_system.free_vertices[static_cast<std::size_t>(s.kept_rows[k])];
    const Eigen::Index row = s.system.row_of[static_cast<std::size_t>(v)];
    rhs.row(row) = s.rhs7.row(s.kept_rows[k]);
    mine.row(row) = x.row(s.kept_rows[k]);
  }
  std::vector<Eigen::Index> all(static_cast<std::size_t>(nk));
  for (std::size_t r = 0; r < all.size(); ++r) all[r] = static_cast<Eigen::Index>(r);
  state.counters["max_error"] = relative_error(mine, s.system.matrix, rhs, all);
  state.counters["simplicial_ms"] = old->factor_ms;
}

void shrink_afresh(benchmark::State& state) {
  const Shrunk& s = shrunk(static_cast<int>(state.range(0)));
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(s.system.matrix.rows(), 7);
  for (auto _ : state) {
    auto solver = remora::make_solver();
    solver->compute(s.system.matrix);
    benchmark::DoNotOptimize(solver->solve(rhs));
  }
}

void changed_sizes(benchmark::internal::Benchmark* b) {
  b->Arg(30)->Arg(100)->Arg(300)->Arg(1000)->Unit(benchmark::kMillisecond)->Iterations(3);
}

BENCHMARK(modify_updown)->Apply(changed_sizes);
BENCHMARK(modify_rowadd)->Apply(changed_sizes);
BENCHMARK(modify_rowdel)->Apply(changed_sizes);
BENCHMARK(shrink_afresh)->Apply(changed_sizes);

} // namespace

#endif // REMORA_WITH_GPL_SOLVERS
