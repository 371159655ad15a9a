#include "remora/linalg/split_cholesky.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <memory>
#include <numeric>
#include <string>

#include "remora/common/error.h"
#include "remora/common/parallel.h"

#ifdef REMORA_WITH_GPL_SOLVERS
#include <cholmod.h>

#include "remora/linalg/cholmod_settings.h"
#include "remora/linalg/lapack.h"
#include "remora/linalg/supernodal_factor.h"
#include "remora/linalg/supernodal_solve.h"
#endif

namespace remora {

#ifdef REMORA_WITH_GPL_SOLVERS

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// Runs body(0) and body(1) on two threads (CHOLMOD's own OpenMP regions nested in them run on
// one thread), and rethrows what either threw.
template <class Body>
void on_both_halves(Body&& body) {
  std::exception_ptr error[2];
  parallel_blocks(2, 2, [&](std::size_t i) {
    try {
      body(static_cast<int>(i));
    } catch (...) {
      error[i] = std::current_exception();
    }
  });
  for (const auto& e : error)
    if (e) std::rethrow_exception(e);
}

// b = l b or lᵀ b (transpose 'T'), l lower triangular, b a column-major block of leading
// dimension ld.
void lower_times(const Eigen::MatrixXd& l, char transpose, double* b, int columns, int ld) {
  const int s = static_cast<int>(l.rows());
  const double one = 1.0;
  if (s > 0 && columns > 0)
    dtrmm_("L", "L", &transpose, "N", &s, &columns, &one, l.data(), &s, b, &ld);
}

// FNV-1a over a compressed matrix's column starts and row indices: factorize() checks the pattern
// it is given against the analysed one.
std::uint64_t pattern_hash(const Sparse& a) {
  std::uint64_t h = 1469598103934665603ULL;
  const auto mix = [&h](const int* p, Eigen::Index count) {
    for (Eigen::Index k = 0; k < count; ++k) {
      h ^= static_cast<std::uint32_t>(p[k]);
      h *= 1099511628211ULL;
    }
  };
  mix(a.outerIndexPtr(), a.outerSize() + 1);
  mix(a.innerIndexPtr(), a.nonZeros());
  return h;
}

} // namespace

// Named, not anonymous: SplitCholesky::Impl holds it (GCC's -Wsubobject-linkage in unity builds).
namespace split_detail {

// One half bordered by the separator: local rows 0..n−1 are the half's, n..n+s−1 the separator's.
struct Half {
  cholmod_common c{};
  cholmod_factor* factor = nullptr;
  std::unique_ptr<SupernodalNumeric> numeric; // factor's numeric factorization
  std::vector<int> rows;                      // the global row of each local row of the half
  int n = 0;
  std::vector<int> colptr, rowind; // lower triangle of the bordered matrix, CSC
  std::vector<double> values;
  std::vector<Eigen::Index> source; // each value's index in the global matrix's values
  std::vector<int> order;           // the separator row at each of the factor's trailing rows
  Eigen::MatrixXd lss;              // the factor's trailing s × s block (lower triangular)
  // lss lssᵀ = K_SS − C_iᵀ A_i⁻¹ C_i until summed, as R Rᵀ (upper triangle) with R = J lss J,
  // J the reversal of the rows: (lss lssᵀ)(a, b) = (R Rᵀ)(s−1−a, s−1−b).
  Eigen::MatrixXd product;
  // A solve's bordered right-hand side in the factor's order, rows interleaved
  // (supernodal_solve.h); t = lss × its tail.
  std::vector<double> work;
  Eigen::MatrixXd t;

  Half() {
    cholmod_start(&c);
    c.print = 0; // failures are reported by our exceptions, not on stdout
  }
  ~Half() {
    cholmod_free_factor(&factor, &c);
    cholmod_finish(&c);
  }
  Half(const Half&) = delete;
  Half& operator=(const Half&) = delete;

  int size() const { return static_cast<int>(colptr.size()) - 1; }
  int separator_rows() const { return size() - n; }

  cholmod_sparse view() {
    return lower_view(static_cast<std::size_t>(size()), rowind.size(), colptr.data(), rowind.data(),
                      values.data());
  }

  // The half's rows, then the separator's, each part by CAMD or, given `keys` (one per local
  // row), by increasing key; then CHOLMOD's supernodal analysis of exactly that order (no
  // postorder: it may move a row of the half behind the separator's). False if a row of the half
  // still ended among the trailing rows.
  bool analyze(bool coarse, const std::vector<int>& keys) {
    cholmod_sparse m = view();
    std::vector<int> perm(static_cast<std::size_t>(size()));
    if (keys.empty()) {
      std::vector<int> member(static_cast<std::size_t>(size()), 1);
      std::fill(member.begin(), member.begin() + n, 0);
      if (!cholmod_camd(&m, nullptr, 0, member.data(), perm.data(), &c))
        throw NumericalError("cholmod: the constrained ordering failed (out of memory?)");
    } else {
      std::iota(perm.begin(), perm.end(), 0);
      const auto by_key = [&](int a, int b) {
        const int ka = keys[static_cast<std::size_t>(a)], kb = keys[static_cast<std::size_t>(b)];
        return ka < kb || (ka == kb && a < b);
      };
      std::sort(perm.begin(), perm.begin() + n, by_key);
      std::sort(perm.begin() + n, perm.end(), by_key);
    }
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_GIVEN;
    c.postorder = 0;
    c.supernodal = CHOLMOD_SUPERNODAL;
    set_supernodes(c, coarse);
    factor = cholmod_analyze_p(&m, perm.data(), nullptr, 0, &c);
    if (factor == nullptr)
      throw NumericalError("cholmod: the symbolic analysis failed (out of memory?)");
    numeric = std::make_unique<SupernodalNumeric>(*factor, colptr.data(), rowind.data(), size());
    const int* p = static_cast<const int*>(factor->Perm);
    order.resize(static_cast<std::size_t>(separator_rows()));
    for (int k = n; k < size(); ++k) {
      if (p[k] < n) return false;
      order[static_cast<std::size_t>(k - n)] = p[k] - n;
    }
    return true;
  }

  // The numbers, the factor, and its trailing block and that block's product with itself.
  // False when the half is not positive definite.
  bool factorize(const double* global_values) {
    for (std::size_t k = 0; k < values.size(); ++k) values[k] = global_values[source[k]];
    if (!numeric->factorize(*factor, values.data(), c)) return false;
    const int s = separator_rows();
    lss.setZero(s, s);
    const auto* super = static_cast<const int*>(factor->super);
    const auto* pi = static_cast<const int*>(factor->pi);
    const auto* px = static_cast<const int*>(factor->px);
    const auto* srow = static_cast<const int*>(factor->s);
    const auto* x = static_cast<const double*>(factor->x);
    for (std::size_t k = 0; k < factor->nsuper; ++k) {
      const int rows_of_node = pi[k + 1] - pi[k];
      for (int j = std::max(super[k], n); j < super[k + 1]; ++j)
        for (int r = j - super[k]; r < rows_of_node; ++r)
          lss(srow[pi[k] + r] - n, j - n) = x[px[k] + (j - super[k]) * rows_of_node + r];
    }
    product = lss.reverse(); // upper triangular: LAPACK's dlauum forms R Rᵀ in s³/3 flops
    int info = 0;
    if (s > 0) dlauum_("U", &s, product.data(), &s, &info);
    return true;
  }

  // Forward: work = L⁻¹ P [b_i; 0]; t = lss × its trailing rows = −C_iᵀ A_i⁻¹ b_i.
  void forward(const Eigen::MatrixXd& b) {
    const auto columns = static_cast<std::size_t>(b.cols());
    const auto* perm = static_cast<const int*>(factor->Perm);
    work.assign(static_cast<std::size_t>(size()) * columns, 0.0);
    for (int k = 0; k < size(); ++k) { // row k of the factor's order is local row perm[k]
      const int l = perm[k];
      if (l >= n) continue; // the separator's rows of [b_i; 0]
      const int g = rows[static_cast<std::size_t>(l)];
      for (std::size_t col = 0; col < columns; ++col)
        work[static_cast<std::size_t>(k) * columns + col] = b(g, static_cast<Eigen::Index>(col));
    }
    supernodal_forward(*factor, work.data(), static_cast<int>(columns));
    const int s = separator_rows();
    t.resize(s, static_cast<Eigen::Index>(columns));
    for (int r = 0; r < s; ++r)
      for (std::size_t col = 0; col < columns; ++col)
        t(r, static_cast<Eigen::Index>(col)) =
            work[static_cast<std::size_t>(n + r) * columns + col];
    lower_times(lss, 'N', t.data(), static_cast<int>(t.cols()), static_cast<int>(t.rows()));
  }

  // Backward, with the separator's values xs (in separator order): the half's rows of x.
  void backward(const Eigen::MatrixXd& xs, Eigen::MatrixXd& x) {
    const int s = separator_rows();
    const auto columns = static_cast<std::size_t>(xs.cols());
    Eigen::MatrixXd ordered(s, xs.cols());
    for (int a = 0; a < s; ++a) ordered.row(a) = xs.row(order[static_cast<std::size_t>(a)]);
    lower_times(lss, 'T', ordered.data(), static_cast<int>(ordered.cols()), s);
    for (int r = 0; r < s; ++r)
      for (std::size_t col = 0; col < columns; ++col)
        work[static_cast<std::size_t>(n + r) * columns + col] =
            ordered(r, static_cast<Eigen::Index>(col));
    supernodal_backward(*factor, work.data(), static_cast<int>(columns));
    const auto* perm = static_cast<const int*>(factor->Perm);
    for (int k = 0; k < size(); ++k) { // Pᵀ: local row perm[k] is row k of the factor's order
      const int l = perm[k];
      if (l >= n) continue;
      const int g = rows[static_cast<std::size_t>(l)];
      for (std::size_t col = 0; col < columns; ++col)
        x(g, static_cast<Eigen::Index>(col)) = work[static_cast<std::size_t>(k) * columns + col];
    }
  }
};

} // namespace split_detail

using split_detail::Half;

struct SplitCholesky::Impl {
  Half half[2];
  std::vector<int> separator; // global rows of the separator
  struct Entry {
    int row, col;
    Eigen::Index source;
  };
  std::vector<Entry> separator_entries; // K_SS's lower triangle, in separator rows
  Eigen::Index n = 0, nonzeros = 0;
  Eigen::MatrixXd schur;     // the Schur complement's Cholesky factor (lower triangle)
  std::uint64_t pattern = 0; // pattern_hash() of the analysed matrix
  bool factored = false;
  bool by_tree = false; // the separator is tree_separator's

  // The bordered matrix of half i: its pattern and where each value comes from.
  void build_half(const Sparse& a, const std::vector<int>& local, int i) {
    Half& h = half[i];
    const int size = h.n + static_cast<int>(separator.size());
    // Entries (row ≥ col, local) counted per column, placed, then sorted within each column.
    std::vector<std::pair<int, int>> entries; // (local row, local column) of each used entry
    std::vector<Eigen::Index> sources;
    for (int j = 0; j < a.outerSize(); ++j)
      for (Sparse::InnerIterator it(a, j); it; ++it) {
        if (it.row() < j) continue;
        const int lr = local[static_cast<std::size_t>(2 * it.row() + i)];
        const int lc = local[static_cast<std::size_t>(2 * j + i)];
        if (lr < 0 || lc < 0) continue;
        entries.emplace_back(std::max(lr, lc), std::min(lr, lc));
        sources.push_back(&it.valueRef() - a.valuePtr());
      }
    h.colptr.assign(static_cast<std::size_t>(size) + 1, 0);
    for (const auto& e : entries) ++h.colptr[static_cast<std::size_t>(e.second) + 1];
    for (int j = 0; j < size; ++j) h.colptr[j + 1] += h.colptr[j];
    std::vector<std::pair<int, Eigen::Index>> placed(entries.size());
    std::vector<int> next(h.colptr.begin(), h.colptr.end() - 1);
    for (std::size_t k = 0; k < entries.size(); ++k)
      placed[static_cast<std::size_t>(next[entries[k].second]++)] = {entries[k].first, sources[k]};
    for (int j = 0; j < size; ++j)
      std::sort(placed.begin() + h.colptr[j], placed.begin() + h.colptr[j + 1]);
    h.rowind.resize(placed.size());
    h.source.resize(placed.size());
    h.values.assign(placed.size(), 0.0);
    for (std::size_t k = 0; k < placed.size(); ++k) {
      h.rowind[k] = placed[k].first;
      h.source[k] = placed[k].second;
    }
  }
};

SplitCholesky::SplitCholesky() : impl_(std::make_unique<Impl>()) {}
SplitCholesky::~SplitCholesky() = default;

bool SplitCholesky::analyze(const Sparse& a, int max_separator_rows, bool coarse_supernodes,
                            const std::vector<int>& keys) {
  impl_ = std::make_unique<Impl>();
  Impl& m = *impl_;
  if (!a.isCompressed()) return false;
  if (!keys.empty() && static_cast<Eigen::Index>(keys.size()) != a.rows())
    throw InvalidArgument("cholmod: " + std::to_string(keys.size()) + " order keys for " +
                          std::to_string(a.rows()) + " rows; give one per row or none");
  Separator split = keys.empty() ? Separator{} : tree_separator(a, keys);
  m.by_tree = !split.part.empty() && split.separator_rows <= max_separator_rows;
  if (!m.by_tree) {
    split = level_separator(a);
    split.keys = keys;
  }
  if (split.part.empty() || split.separator_rows > max_separator_rows) return false;
  m.n = a.rows();
  m.nonzeros = a.nonZeros();
  m.pattern = pattern_hash(a);
  // local[2v + i]: row v's local row in half i (-1: not in it)
  std::vector<int> local(static_cast<std::size_t>(2 * m.n), -1);
  for (int v = 0; v < m.n; ++v) {
    const int p = split.part[static_cast<std::size_t>(v)];
    if (p == 2) continue;
    Half& h = m.half[p];
    local[static_cast<std::size_t>(2 * v + p)] = h.n++;
    h.rows.push_back(v);
  }
  for (int v = 0; v < m.n; ++v)
    if (split.part[static_cast<std::size_t>(v)] == 2) {
      const int s = static_cast<int>(m.separator.size());
      for (int i = 0; i < 2; ++i) local[static_cast<std::size_t>(2 * v + i)] = m.half[i].n + s;
      m.separator.push_back(v);
    }
  for (int j = 0; j < a.outerSize(); ++j)
    for (Sparse::InnerIterator it(a, j); it; ++it)
      if (it.row() >= j && split.part[static_cast<std::size_t>(it.row())] == 2 &&
          split.part[static_cast<std::size_t>(j)] == 2)
        m.separator_entries.push_back({local[static_cast<std::size_t>(2 * it.row())] - m.half[0].n,
                                       local[static_cast<std::size_t>(2 * j)] - m.half[0].n,
                                       &it.valueRef() - a.valuePtr()});
  bool ordered[2] = {false, false};
  on_both_halves([&](int i) {
    m.build_half(a, local, i);
    std::vector<int> half_keys;
    if (const std::vector<int>& order = split.keys; !order.empty()) {
      const Half& h = m.half[i];
      half_keys.resize(static_cast<std::size_t>(h.size()));
      for (int l = 0; l < h.n; ++l)
        half_keys[static_cast<std::size_t>(l)] = order[static_cast<std::size_t>(h.rows[l])];
      for (std::size_t r = 0; r < m.separator.size(); ++r)
        half_keys[static_cast<std::size_t>(h.n) + r] =
            order[static_cast<std::size_t>(m.separator[r])];
    }
    ordered[i] = m.half[i].analyze(coarse_supernodes, half_keys);
  });
  if (!ordered[0] || !ordered[1]) {
    impl_ = std::make_unique<Impl>();
    return false;
  }
  return true;
}

bool SplitCholesky::factorize(const Sparse& a) {
  Impl& m = *impl_;
  m.factored = false;
  if (m.half[0].factor == nullptr) throw InvalidArgument("cholmod: factorize() before analyze()");
  if (!a.isCompressed()) {
    Sparse compressed = a;
    compressed.makeCompressed();
    return factorize(compressed);
  }
  if (a.rows() != m.n || a.nonZeros() != m.nonzeros || pattern_hash(a) != m.pattern)
    throw InvalidArgument("cholmod: factorize() needs the pattern given to analyze()");
  bool definite[2] = {false, false};
  on_both_halves([&](int i) { definite[i] = m.half[i].factorize(a.valuePtr()); });
  if (!definite[0] || !definite[1]) return false;
  // K_SS − Σ C_iᵀ A_i⁻¹ C_i = Σ lss_i lss_iᵀ − K_SS, in separator order.
  const int s = static_cast<int>(m.separator.size());
  Eigen::MatrixXd& schur = m.schur;
  schur.setZero(s, s);
  for (Half& h : m.half) {
    for (int j = 0; j < s; ++j) // the upper triangle of R Rᵀ: entry (i, j) is (s−1−i, s−1−j)
      for (int i = 0; i <= j; ++i) {
        const int r = h.order[static_cast<std::size_t>(s - 1 - i)];
        const int c = h.order[static_cast<std::size_t>(s - 1 - j)];
        schur(r, c) += h.product(i, j);
        if (r != c) schur(c, r) += h.product(i, j);
      }
    h.product = Eigen::MatrixXd();
  }
  for (const auto& e : m.separator_entries) {
    const double v = a.valuePtr()[e.source];
    schur(e.row, e.col) -= v;
    if (e.row != e.col) schur(e.col, e.row) -= v;
  }
  int info = 0;
  if (s > 0) dpotrf_("L", &s, schur.data(), &s, &info);
  m.factored = info == 0;
  return m.factored;
}

Eigen::MatrixXd SplitCholesky::solve(const Eigen::MatrixXd& b) {
  Impl& m = *impl_;
  if (!m.factored) throw InvalidArgument("cholmod: solve() before a successful factorize()");
  if (b.rows() != m.n)
    throw InvalidArgument("cholmod: the right-hand side has " + std::to_string(b.rows()) +
                          " rows for a system of dimension " + std::to_string(m.n));
  if (b.cols() == 0) return Eigen::MatrixXd(b.rows(), 0);
  on_both_halves([&](int i) { m.half[i].forward(b); });
  const int s = static_cast<int>(m.separator.size());
  Eigen::MatrixXd xs(s, b.cols());
  for (int r = 0; r < s; ++r) xs.row(r) = b.row(m.separator[static_cast<std::size_t>(r)]);
  for (const Half& h : m.half)
    for (int r = 0; r < s; ++r) xs.row(h.order[static_cast<std::size_t>(r)]) += h.t.row(r);
  const int columns = static_cast<int>(b.cols());
  int info = 0;
  if (s > 0 && columns > 0) dpotrs_("L", &s, &columns, m.schur.data(), &s, xs.data(), &s, &info);
  Eigen::MatrixXd x(b.rows(), b.cols());
  on_both_halves([&](int i) { m.half[i].backward(xs, x); });
  for (int r = 0; r < s; ++r) x.row(m.separator[static_cast<std::size_t>(r)]) = xs.row(r);
  return x;
}

std::size_t SplitCholesky::factor_nonzeros() const {
  const std::size_t s = impl_->separator.size();
  std::size_t count = s * (s + 1) / 2; // the Schur complement's factor
  for (const Half& h : impl_->half)
    if (h.factor != nullptr) count += h.factor->xsize;
  return count;
}

std::size_t SplitCholesky::factor_bytes() const {
  const std::size_t s = impl_->separator.size();
  std::size_t bytes = 3 * s * s * sizeof(double); // the Schur factor and the two blocks
  for (const Half& h : impl_->half)
    if (h.factor != nullptr)
      bytes += h.factor->xsize * sizeof(double) + h.factor->ssize * sizeof(int) +
               h.factor->n * 4 * sizeof(int);
  return bytes;
}

bool SplitCholesky::cut_by_tree() const {
  return impl_->by_tree;
}

int SplitCholesky::separator_rows() const {
  return static_cast<int>(impl_->separator.size());
}

#endif

} // namespace remora
