#include "remora/linalg/supernodal_solve.h"

#ifdef REMORA_WITH_GPL_SOLVERS
#include <algorithm>
#include <cstddef>
#include <vector>

#include "remora/common/cpu.h"
#include "remora/common/error.h"

// The loops below ask for vectorization (`omp simd`: the reductions may be reordered), which the
// sanitizer builds' -O1 does not do; clang warns that it was not done.
//
// The sweeps are compiled for the baseline instruction set and for AVX2 with FMA, the kernels
// inlined into each, and the processor chooses at run time (common/cpu.h, docs/solvers.md).
#if defined(__clang__)
#pragma clang diagnostic push
#pragma clang diagnostic ignored "-Wpass-failed"
#endif

namespace remora {

namespace {

/// A supernode's columns, rows and block (CHOLMOD's layout: column-major, nsrow × nscol, the
/// first nscol rows those of the columns themselves, in order).
struct Supernode {
  int first = 0, columns = 0, rows = 0; // first column, nscol, nsrow
  const int* row = nullptr;             // the block's rows in the factor's order
  const double* block = nullptr;
  const double* column(int j) const { return block + static_cast<std::size_t>(j) * rows; }
};

struct Blocks {
  const int *super, *pi, *px, *s;
  const double* x;
  Supernode operator()(std::size_t k) const {
    Supernode n;
    n.first = super[k];
    n.columns = super[k + 1] - super[k];
    n.rows = pi[k + 1] - pi[k];
    n.row = s + pi[k];
    n.block = x + px[k];
    return n;
  }
};

Blocks blocks_of(const cholmod_factor& f) {
  if (!f.is_super || !f.is_ll || f.xtype != CHOLMOD_REAL || f.x == nullptr || f.super == nullptr)
    throw InvalidArgument("supernodal solve: the factor is not a numeric real supernodal LLᵀ "
                          "(factor it with CHOLMOD_SUPERNODAL first)");
  return {static_cast<const int*>(f.super), static_cast<const int*>(f.pi),
          static_cast<const int*>(f.px), static_cast<const int*>(f.s),
          static_cast<const double*>(f.x)};
}

// Within a supernode the right-hand sides are copied into `v`, one column after another (v[c·r +
// i]: row i of the block, column c, r its rows), so that every inner loop runs down a column of
// the block and of v at once. Columns of the block go four at a time: each value of v is read and
// written once for four columns of L.

/// Copies the supernode's rows of x into v: its own rows, and the rows below them (zero for the
/// forward sweep, which sums into them).
[[gnu::always_inline]] inline void load(const Supernode& n, const double* x, int cols, bool below,
                                        std::vector<double>& v) {
  const auto r = static_cast<std::size_t>(n.rows);
  v.resize(static_cast<std::size_t>(cols) * r);
  for (int i = 0; i < n.rows; ++i) {
    const bool own = i < n.columns;
    const double* xr =
        x + static_cast<std::size_t>(own ? n.first + i : n.row[i]) * static_cast<std::size_t>(cols);
    for (int c = 0; c < cols; ++c)
      v[static_cast<std::size_t>(c) * r + static_cast<std::size_t>(i)] = own || below ? xr[c] : 0.0;
  }
}

template <int C>
[[gnu::always_inline]] inline void forward(const cholmod_factor& f, double* x, int columns) {
  const int cols = C > 0 ? C : columns;
  const Blocks blocks = blocks_of(f);
  thread_local std::vector<double> v;
  for (std::size_t k = 0; k < f.nsuper; ++k) {
    const Supernode n = blocks(k);
    const int r = n.rows;
    load(n, x, cols, false, v);
    // v's own rows become y (L₁₁ y = b), the rows below −L₂₁ y.
    int j = 0;
    for (; j < n.columns; j += 4) {
      const int w = std::min(4, n.columns - j);
      for (int c = 0; c < cols; ++c) {
        double* vc = v.data() + static_cast<std::size_t>(c) * static_cast<std::size_t>(r);
        for (int a = j; a < j + w; ++a) { // the group's own triangle
          const double* l = n.column(a);
          vc[a] /= l[a];
          for (int i = a + 1; i < j + w; ++i) vc[i] -= l[i] * vc[a];
        }
        if (w < 4) { // the last columns, one at a time
          for (int a = j; a < j + w; ++a) {
            const double* l = n.column(a);
            const double y = vc[a];
#pragma omp simd
            for (int i = j + w; i < r; ++i) vc[i] -= l[i] * y;
          }
          continue;
        }
        const double *l0 = n.column(j), *l1 = n.column(j + 1), *l2 = n.column(j + 2),
                     *l3 = n.column(j + 3);
        const double y0 = vc[j], y1 = vc[j + 1], y2 = vc[j + 2], y3 = vc[j + 3];
#pragma omp simd
        for (int i = j + 4; i < r; ++i) vc[i] -= l0[i] * y0 + l1[i] * y1 + l2[i] * y2 + l3[i] * y3;
      }
    }
    for (int i = 0; i < r; ++i) {
      const bool own = i < n.columns;
      double* xr = x + static_cast<std::size_t>(own ? n.first + i : n.row[i]) *
                           static_cast<std::size_t>(cols);
      for (int c = 0; c < cols; ++c) {
        const double value = v[static_cast<std::size_t>(c) * static_cast<std::size_t>(r) +
                               static_cast<std::size_t>(i)];
        xr[c] = own ? value : xr[c] + value;
      }
    }
  }
}

template <int C>
[[gnu::always_inline]] inline void backward(const cholmod_factor& f, double* x, int columns) {
  const int cols = C > 0 ? C : columns;
  const Blocks blocks = blocks_of(f);
  thread_local std::vector<double> v;
  for (std::size_t k = f.nsuper; k-- > 0;) {
    const Supernode n = blocks(k);
    const int r = n.rows;
    load(n, x, cols, true, v);
    // From the last column back: v_j = (v_j − Σ_{i>j} L_ij v_i) / L_jj, the rows below j final.
    for (int end = n.columns; end > 0;) {
      const int j = std::max(0, end - 4), w = end - j;
      for (int c = 0; c < cols; ++c) {
        double* vc = v.data() + static_cast<std::size_t>(c) * static_cast<std::size_t>(r);
        if (w == 4) {
          const double *l0 = n.column(j), *l1 = n.column(j + 1), *l2 = n.column(j + 2),
                       *l3 = n.column(j + 3);
          double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
#pragma omp simd reduction(+ : s0, s1, s2, s3)
          for (int i = end; i < r; ++i) {
            s0 += l0[i] * vc[i];
            s1 += l1[i] * vc[i];
            s2 += l2[i] * vc[i];
            s3 += l3[i] * vc[i];
          }
          vc[j] -= s0, vc[j + 1] -= s1, vc[j + 2] -= s2, vc[j + 3] -= s3;
        } else {
          for (int a = j; a < end; ++a) {
            const double* l = n.column(a);
            double s = 0.0;
#pragma omp simd reduction(+ : s)
            for (int i = end; i < r; ++i) s += l[i] * vc[i];
            vc[a] -= s;
          }
        }
        for (int a = end - 1; a >= j; --a) { // the group's own triangle
          const double* l = n.column(a);
          for (int i = a + 1; i < end; ++i) vc[a] -= l[i] * vc[i];
          vc[a] /= l[a];
        }
      }
      end = j;
    }
    for (int i = 0; i < n.columns; ++i) {
      double* xr = x + static_cast<std::size_t>(n.first + i) * static_cast<std::size_t>(cols);
      for (int c = 0; c < cols; ++c)
        xr[c] = v[static_cast<std::size_t>(c) * static_cast<std::size_t>(r) +
                  static_cast<std::size_t>(i)];
    }
  }
}

/// One sweep; 3 columns (the nonlinear deformer's) in code compiled for that count.
[[gnu::always_inline]] inline void sweep(bool forward_sweep, const cholmod_factor& f, double* x,
                                         int columns) {
  if (forward_sweep)
    columns == 3 ? forward<3>(f, x, columns) : forward<0>(f, x, columns);
  else
    columns == 3 ? backward<3>(f, x, columns) : backward<0>(f, x, columns);
}

void sweep_baseline(bool forward_sweep, const cholmod_factor& f, double* x, int columns) {
  sweep(forward_sweep, f, x, columns);
}

REMORA_AVX2 void sweep_avx2(bool forward_sweep, const cholmod_factor& f, double* x, int columns) {
  sweep(forward_sweep, f, x, columns);
}

} // namespace

void supernodal_forward(const cholmod_factor& factor, double* x, int columns) {
  use_avx2() ? sweep_avx2(true, factor, x, columns) : sweep_baseline(true, factor, x, columns);
}

void supernodal_backward(const cholmod_factor& factor, double* x, int columns) {
  use_avx2() ? sweep_avx2(false, factor, x, columns) : sweep_baseline(false, factor, x, columns);
}

} // namespace remora

#if defined(__clang__)
#pragma clang diagnostic pop
#endif
#endif
