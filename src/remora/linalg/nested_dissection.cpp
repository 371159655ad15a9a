#include "remora/linalg/nested_dissection.h"

#include <algorithm>
#include <numeric>
#include <string>

#include "remora/common/error.h"

#ifdef REMORA_WITH_GPL_SOLVERS
#include <cholmod.h>

#include "remora/linalg/cholmod_settings.h"
#endif

namespace remora {

std::vector<int> nested_dissection_keys(const Eigen::SparseMatrix<double>& a) {
  if (a.rows() != a.cols())
    throw InvalidArgument("nested_dissection_keys: the matrix is " + std::to_string(a.rows()) +
                          " x " + std::to_string(a.cols()) + "; give a square one");
#ifdef REMORA_WITH_GPL_SOLVERS
  const auto n = static_cast<std::size_t>(a.rows());
  if (n == 0) return {};
  Eigen::SparseMatrix<double> lower = a.triangularView<Eigen::Lower>();
  lower.makeCompressed();
  cholmod_sparse view = lower_view(n, static_cast<std::size_t>(lower.nonZeros()),
                                   lower.outerIndexPtr(), lower.innerIndexPtr(), nullptr);
  std::vector<int> perm(n), keys(n);
  cholmod_common c;
  cholmod_start(&c);
  c.print = 0;
  const int ok = cholmod_metis(&view, nullptr, 0, 1, perm.data(), &c);
  const int status = c.status;
  cholmod_finish(&c);
  if (status == CHOLMOD_NOT_INSTALLED) return {}; // a CHOLMOD built without METIS
  if (!ok) throw NumericalError("nested dissection: METIS failed (out of memory?)");
  for (std::size_t k = 0; k < n; ++k) keys[static_cast<std::size_t>(perm[k])] = static_cast<int>(k);
  return keys;
#else
  return {};
#endif
}

int raise_to_common_ancestors(const Eigen::SparseMatrix<double>& graph, int k,
                              const std::vector<int>& tree, std::vector<int>& keys) {
  const auto n = static_cast<std::size_t>(graph.rows());
  const auto m = static_cast<int>(tree.size());
  if (graph.rows() != graph.cols() || keys.size() != n || k < 1)
    throw InvalidArgument(
        "raise_to_common_ancestors: give a square graph, k >= 1 and a key per row");
  // first[p]: the lowest position of p's subtree, which holds first[p] … p (a postorder).
  std::vector<int> first(tree.size()), size(tree.size(), 1);
  std::iota(first.begin(), first.end(), 0);
  for (int p = 0; p < m; ++p) {
    const int q = tree[static_cast<std::size_t>(p)];
    if (q < 0) continue;
    if (q <= p || q >= m)
      throw InvalidArgument("raise_to_common_ancestors: a parent below its child in the tree");
    size[static_cast<std::size_t>(q)] += size[static_cast<std::size_t>(p)];
    first[static_cast<std::size_t>(q)] =
        std::min(first[static_cast<std::size_t>(q)], first[static_cast<std::size_t>(p)]);
  }
  for (int p = 0; p < m; ++p)
    if (p - first[static_cast<std::size_t>(p)] + 1 != size[static_cast<std::size_t>(p)])
      throw InvalidArgument("raise_to_common_ancestors: the tree is not postordered");
  for (const int key : keys)
    if (key < 0 || key >= m)
      throw InvalidArgument("raise_to_common_ancestors: a key is not a position of the tree");
  const auto on_one_path = [&](int p, int q) {
    if (p > q) std::swap(p, q);
    return first[static_cast<std::size_t>(q)] <= p; // q is p or above it
  };
  const auto common = [&](int p, int q) {
    while (p != q && p >= 0 && q >= 0)
      (p < q ? p : q) = tree[static_cast<std::size_t>(p < q ? p : q)];
    return p == q ? p : -1; // -1: in two trees
  };
  // One pass: a raise keeps every pair that was on one root path on one (the raised row moves up
  // its own root path), so a row's pairs, all on one path after its scan, stay so.
  std::vector<int> seen(n, -1), frontier, next;
  int raised = 0;
  for (int v = 0; v < static_cast<int>(n); ++v) {
    seen[static_cast<std::size_t>(v)] = v;
    frontier.assign(1, v);
    for (int step = 0; step < k; ++step) { // the rows within k steps of v, each once
      next.clear();
      for (const int x : frontier)
        for (Eigen::SparseMatrix<double>::InnerIterator it(graph, x); it; ++it) {
          const auto u = static_cast<int>(it.row());
          if (seen[static_cast<std::size_t>(u)] == v) continue;
          seen[static_cast<std::size_t>(u)] = v;
          next.push_back(u);
          const int p = keys[static_cast<std::size_t>(v)], q = keys[static_cast<std::size_t>(u)];
          if (on_one_path(p, q)) continue;
          const int c = common(p, q);
          if (c < 0) continue;                               // in two trees of the old order
          keys[static_cast<std::size_t>(p < q ? v : u)] = c; // the lower row goes up
          ++raised;
        }
      frontier.swap(next);
    }
  }
  return raised;
}

Eigen::SparseMatrix<double> ring_pattern(const Eigen::SparseMatrix<double>& minus_w, int k) {
  if (minus_w.rows() != minus_w.cols() || k < 1)
    throw InvalidArgument("ring_pattern: give a square matrix and k >= 1");
  Eigen::SparseMatrix<double> one = minus_w;
  for (Eigen::Index e = 0; e < one.nonZeros(); ++e) one.valuePtr()[e] = 1.0;
  Eigen::SparseMatrix<double> p = one;
  for (int i = 1; i < k; ++i) p = (p * one).eval();
  return p;
}

} // namespace remora
