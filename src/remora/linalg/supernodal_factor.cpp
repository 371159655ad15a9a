#include "remora/linalg/supernodal_factor.h"

#ifdef REMORA_WITH_GPL_SOLVERS
#include <algorithm>
#include <string>

#include "remora/common/error.h"
#include "remora/linalg/lapack.h"

namespace remora {

namespace {

struct Structure {
  const int *super, *pi, *px, *s;
};

Structure structure_of(const cholmod_factor& f, int n) {
  if (!f.is_super || f.super == nullptr || f.pi == nullptr || f.px == nullptr || f.s == nullptr ||
      f.Perm == nullptr)
    throw InvalidArgument("supernodal factorization: the analysis is not supernodal (analyse "
                          "with CHOLMOD_SUPERNODAL first)");
  if (static_cast<int>(f.n) != n)
    throw InvalidArgument("supernodal factorization: the analysis has " + std::to_string(f.n) +
                          " rows, the matrix " + std::to_string(n));
  return {static_cast<const int*>(f.super), static_cast<const int*>(f.pi),
          static_cast<const int*>(f.px), static_cast<const int*>(f.s)};
}

// Subtracts from `block` (a supernode's, `rows` rows, its columns below `k2`, its rows' places in
// `map`) the update of supernode d from d's rows at index `first` of its list on: the products of
// those rows of d's block with the ones among the supernode's columns, formed in `c` (BLAS) and
// scattered. Returns the index of d's first row past the supernode's columns.
int subtract_update(const Structure& st, const double* lx, int d, int first, int k2,
                    const std::vector<int>& map, std::vector<int>& relative, double* c,
                    double* block, int rows) {
  const double one = 1.0, zero = 0.0;
  const int pdi = st.pi[d], pdend = st.pi[d + 1], ndrow = pdend - pdi;
  const int ndcol = st.super[d + 1] - st.super[d];
  int past = first;
  while (past < pdend && st.s[past] < k2) ++past;
  const int ndrow1 = past - first, ndrow2 = pdend - first, ndrow3 = ndrow2 - ndrow1;
  const double* ld = lx + st.px[d] + (first - pdi);
  dsyrk_("L", "N", &ndrow1, &ndcol, &one, ld, &ndrow, &zero, c, &ndrow2);
  if (ndrow3 > 0)
    dgemm_("N", "T", &ndrow3, &ndrow1, &ndcol, &one, ld + ndrow1, &ndrow, ld, &ndrow, &zero,
           c + ndrow1, &ndrow2);
  for (int i = 0; i < ndrow2; ++i)
    relative[static_cast<std::size_t>(i)] = map[static_cast<std::size_t>(st.s[first + i])];
  for (int j = 0; j < ndrow1; ++j) {
    double* column = block + static_cast<std::size_t>(relative[static_cast<std::size_t>(j)]) *
                                 static_cast<std::size_t>(rows);
    const double* cj = c + static_cast<std::size_t>(j) * static_cast<std::size_t>(ndrow2);
    for (int i = j; i < ndrow2; ++i) column[relative[static_cast<std::size_t>(i)]] -= cj[i];
  }
  return past;
}

} // namespace

SupernodalNumeric::SupernodalNumeric(const cholmod_factor& symbolic, const int* colptr,
                                     const int* rowind, int n)
    : n_(n) {
  const Structure st = structure_of(symbolic, n);
  const auto* perm = static_cast<const int*>(symbolic.Perm);
  std::vector<int> inverse(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) inverse[static_cast<std::size_t>(perm[k])] = k;
  // P A Pᵀ's lower triangle: entry (i, j) of A goes to column min(i', j'), row max(i', j').
  colptr_.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int e = colptr[j]; e < colptr[j + 1]; ++e)
      ++colptr_[static_cast<std::size_t>(std::min(inverse[static_cast<std::size_t>(rowind[e])],
                                                  inverse[static_cast<std::size_t>(j)])) +
                1];
  for (int j = 0; j < n; ++j) colptr_[static_cast<std::size_t>(j) + 1] += colptr_[j];
  row_.resize(static_cast<std::size_t>(colptr_.back()));
  source_.resize(row_.size());
  std::vector<int> next(colptr_.begin(), colptr_.end() - 1);
  for (int j = 0; j < n; ++j)
    for (int e = colptr[j]; e < colptr[j + 1]; ++e) {
      const int a = inverse[static_cast<std::size_t>(rowind[e])];
      const int b = inverse[static_cast<std::size_t>(j)];
      const auto at = static_cast<std::size_t>(next[static_cast<std::size_t>(std::min(a, b))]++);
      row_[at] = std::max(a, b);
      source_[at] = e;
    }
  // Workspace: a descendant d's update has at most (rows − columns)² entries.
  super_of_.resize(static_cast<std::size_t>(n));
  std::size_t update = 0;
  int rows = 0;
  for (std::size_t k = 0; k < symbolic.nsuper; ++k) {
    std::fill(super_of_.begin() + st.super[k], super_of_.begin() + st.super[k + 1],
              static_cast<int>(k));
    const int below = (st.pi[k + 1] - st.pi[k]) - (st.super[k + 1] - st.super[k]);
    update = std::max(update, static_cast<std::size_t>(below) * static_cast<std::size_t>(below));
    rows = std::max(rows, st.pi[k + 1] - st.pi[k]);
  }
  update_.resize(update);
  map_.resize(static_cast<std::size_t>(n));
  relative_.resize(static_cast<std::size_t>(rows));
  head_.resize(symbolic.nsuper);
  next_.resize(symbolic.nsuper);
  pos_.resize(symbolic.nsuper);
}

bool SupernodalNumeric::factorize(cholmod_factor& factor, const double* values,
                                  cholmod_common& common) {
  const Structure st = structure_of(factor, n_);
  if (factor.xtype == CHOLMOD_PATTERN &&
      !cholmod_change_factor(CHOLMOD_REAL, true, true, true, true, &factor, &common))
    throw NumericalError("supernodal factorization: CHOLMOD could not allocate the factor (out "
                         "of memory?)");
  auto* lx = static_cast<double*>(factor.x);
  const double one = 1.0;
  std::fill(head_.begin(), head_.end(), -1);
  for (int s = 0; s < static_cast<int>(factor.nsuper); ++s) {
    const int k1 = st.super[s], k2 = st.super[s + 1], nscol = k2 - k1;
    const int psi = st.pi[s], nsrow = st.pi[s + 1] - psi;
    double* block = lx + st.px[s];
    for (int k = 0; k < nsrow; ++k) map_[static_cast<std::size_t>(st.s[psi + k])] = k;
    // A's columns.
    std::fill(block, block + static_cast<std::size_t>(nsrow) * nscol, 0.0);
    for (int j = k1; j < k2; ++j) {
      double* column = block + static_cast<std::size_t>(j - k1) * nsrow;
      for (int e = colptr_[static_cast<std::size_t>(j)];
           e < colptr_[static_cast<std::size_t>(j) + 1]; ++e)
        column[map_[static_cast<std::size_t>(row_[static_cast<std::size_t>(e)])]] +=
            values[source_[static_cast<std::size_t>(e)]];
    }
    // The updates of the supernodes below s whose next rows are s's columns.
    for (int d = head_[static_cast<std::size_t>(s)]; d != -1;) {
      const int following = next_[static_cast<std::size_t>(d)];
      const int pdi = st.pi[d], pdend = st.pi[d + 1];
      const int pdi2 = subtract_update(st, lx, d, pdi + pos_[static_cast<std::size_t>(d)], k2, map_,
                                       relative_, update_.data(), block, nsrow);
      pos_[static_cast<std::size_t>(d)] = pdi2 - pdi;
      if (pdi2 < pdend) {
        const int t = super_of_[static_cast<std::size_t>(st.s[pdi2])];
        next_[static_cast<std::size_t>(d)] = head_[static_cast<std::size_t>(t)];
        head_[static_cast<std::size_t>(t)] = d;
      }
      d = following;
    }
    // The supernode's own factor: its diagonal block, then the rows below it.
    int info = 0;
    dpotrf_("L", &nscol, block, &nsrow, &info);
    if (info != 0) {
      factor.minor = static_cast<std::size_t>(k1 + info - 1);
      return false;
    }
    const int below = nsrow - nscol;
    if (below > 0) {
      dtrsm_("R", "L", "T", "N", &below, &nscol, &one, block, &nsrow, block + nscol, &nsrow);
      pos_[static_cast<std::size_t>(s)] = nscol;
      const int t = super_of_[static_cast<std::size_t>(st.s[psi + nscol])];
      next_[static_cast<std::size_t>(s)] = head_[static_cast<std::size_t>(t)];
      head_[static_cast<std::size_t>(t)] = s;
    }
  }
  factor.minor = static_cast<std::size_t>(n_);
  return true;
}

} // namespace remora
#endif
