// Separators that split a symmetric system into two halves (separator.h).
#include "remora/linalg/separator.h"

#include <algorithm>
#include <cstdlib>
#include <numeric>

namespace remora {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// The graph of a symmetric pattern (lower triangle of `a`), without its diagonal, as CSR.
struct Graph {
  std::vector<int> begin, next;
};

Graph adjacency(const Sparse& a) {
  const int n = static_cast<int>(a.rows());
  std::vector<int> degree(static_cast<std::size_t>(n), 0);
  for (int j = 0; j < a.outerSize(); ++j)
    for (Sparse::InnerIterator it(a, j); it; ++it)
      if (it.row() > j) {
        ++degree[static_cast<std::size_t>(it.row())];
        ++degree[static_cast<std::size_t>(j)];
      }
  Graph g;
  g.begin.assign(static_cast<std::size_t>(n) + 1, 0);
  for (int i = 0; i < n; ++i) g.begin[i + 1] = g.begin[i] + degree[i];
  g.next.resize(static_cast<std::size_t>(g.begin[n]));
  std::vector<int> fill(g.begin.begin(), g.begin.end() - 1);
  for (int j = 0; j < a.outerSize(); ++j)
    for (Sparse::InnerIterator it(a, j); it; ++it)
      if (const int r = static_cast<int>(it.row()); r > j) {
        g.next[static_cast<std::size_t>(fill[r]++)] = j;
        g.next[static_cast<std::size_t>(fill[j]++)] = r;
      }
  return g;
}

// Breadth-first levels from `start` (-1: not reached); returns how many rows were reached and
// sets `last` to the last one reached (one of the farthest).
int bfs_levels(const Graph& g, int start, std::vector<int>& level, int& last) {
  std::fill(level.begin(), level.end(), -1);
  std::vector<int> queue;
  queue.reserve(level.size());
  queue.push_back(start);
  level[static_cast<std::size_t>(start)] = 0;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int v = queue[head];
    for (int k = g.begin[v]; k < g.begin[v + 1]; ++k)
      if (const int w = g.next[static_cast<std::size_t>(k)]; level[w] < 0) {
        level[w] = level[v] + 1;
        queue.push_back(w);
      }
  }
  last = queue.back();
  return static_cast<int>(queue.size());
}

} // namespace

Separator level_separator(const Sparse& a) {
  const int n = static_cast<int>(a.rows());
  if (n < 3 || a.cols() != a.rows()) return {};
  const Graph g = adjacency(a);
  // The largest connected component is split by a level; the others join one half whole.
  std::vector<int> level(static_cast<std::size_t>(n), -1), queue;
  std::vector<char> seen(level.size(), 0);
  // Each component's breadth-first search from its first row ends at one of the rows farthest
  // from it: the largest component's is where its levels start (a pseudo-peripheral row).
  int far = -1, largest_size = 0, last = 0;
  for (int v = 0; v < n; ++v) {
    if (seen[static_cast<std::size_t>(v)]) continue;
    queue.assign(1, v);
    seen[static_cast<std::size_t>(v)] = 1;
    for (std::size_t head = 0; head < queue.size(); ++head)
      for (int k = g.begin[queue[head]]; k < g.begin[queue[head] + 1]; ++k)
        if (const int w = g.next[static_cast<std::size_t>(k)]; !seen[static_cast<std::size_t>(w)]) {
          seen[static_cast<std::size_t>(w)] = 1;
          queue.push_back(w);
        }
    if (static_cast<int>(queue.size()) > largest_size) {
      largest_size = static_cast<int>(queue.size());
      far = queue.back();
    }
  }
  bfs_levels(g, far, level, last);   // thin, balanced levels
  const int rest = n - largest_size; // rows of the other components
  const int depth = level[static_cast<std::size_t>(last)] + 1;
  std::vector<int> count(static_cast<std::size_t>(depth), 0);
  for (const int l : level)
    if (l >= 0) ++count[static_cast<std::size_t>(l)];
  // The thinnest level that balances; of equally thin ones, and of the two sides for the other
  // components, the most balanced.
  int best = -1, rest_side = 1, best_gap = 0;
  for (int m = 1, below = count[0]; m + 1 < depth; below += count[m], ++m) {
    const int above = largest_size - below - count[m];
    for (int side = 0; side < 2; ++side) {
      const int halves[2] = {below + (side == 0 ? rest : 0), above + (side == 1 ? rest : 0)};
      if (std::min(halves[0], halves[1]) < 0.4 * (halves[0] + halves[1])) continue;
      const int gap = std::abs(halves[0] - halves[1]);
      if (best < 0 || count[m] < count[best] || (count[m] == count[best] && gap < best_gap)) {
        best = m;
        rest_side = side;
        best_gap = gap;
      }
    }
  }
  if (best < 0) return {};
  Separator s;
  s.part.resize(static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) {
    const int l = level[static_cast<std::size_t>(v)];
    const unsigned char p = l < 0      ? static_cast<unsigned char>(rest_side)
                            : l < best ? 0
                            : l > best ? 1
                                       : 2;
    s.part[static_cast<std::size_t>(v)] = p;
    if (p == 2)
      ++s.separator_rows;
    else
      ++s.rows[p];
  }
  return s;
}

namespace {

// The rows by increasing key, ties by row: counted when the keys are small (a base's order), else
// sorted.
std::vector<int> sorted_by_key(const std::vector<int>& keys) {
  const auto n = static_cast<int>(keys.size());
  std::vector<int> order(keys.size());
  const auto [low, high] = std::minmax_element(keys.begin(), keys.end());
  if (*low >= 0 && *high < 16 * n) {
    std::vector<int> start(static_cast<std::size_t>(*high) + 2, 0);
    for (const int k : keys) ++start[static_cast<std::size_t>(k) + 1];
    for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
    for (int v = 0; v < n; ++v)
      order[static_cast<std::size_t>(
          start[static_cast<std::size_t>(keys[static_cast<std::size_t>(v)])]++)] = v;
  } else {
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int x, int y) {
      const int kx = keys[static_cast<std::size_t>(x)], ky = keys[static_cast<std::size_t>(y)];
      return kx < ky || (kx == ky && x < y);
    });
  }
  return order;
}

// A postorder of the forest `parent` (of positions; children in order, so each subtree is
// contiguous), as a key per row: key[order[k]] is position k's place in it.
std::vector<int> postorder_keys(const std::vector<int>& parent, const std::vector<int>& order) {
  const auto n = static_cast<int>(parent.size());
  std::vector<int> first_child(parent.size(), -1), next_sibling(parent.size(), -1);
  for (int k = n - 1; k >= 0; --k)
    if (const int p = parent[static_cast<std::size_t>(k)]; p >= 0) {
      next_sibling[static_cast<std::size_t>(k)] = first_child[static_cast<std::size_t>(p)];
      first_child[static_cast<std::size_t>(p)] = k;
    }
  std::vector<int> keys(parent.size()), stack;
  int next = 0;
  for (int root = 0; root < n; ++root) {
    if (parent[static_cast<std::size_t>(root)] >= 0) continue;
    stack.push_back(root);
    while (!stack.empty()) {
      const int k = stack.back();
      if (const int c = first_child[static_cast<std::size_t>(k)]; c >= 0) {
        first_child[static_cast<std::size_t>(k)] = next_sibling[static_cast<std::size_t>(c)];
        stack.push_back(c);
      } else {
        stack.pop_back();
        keys[static_cast<std::size_t>(order[k])] = next++;
      }
    }
  }
  return keys;
}
} // namespace

// Each position's earlier neighbours are gathered first, so that the sweep reads them in sequence.
std::vector<int> elimination_tree(const Sparse& a, const std::vector<int>& position) {
  const std::size_t n = position.size();
  std::vector<int> begin(n + 1, 0);
  for (int j = 0; j < a.outerSize(); ++j)
    for (Sparse::InnerIterator it(a, j); it; ++it)
      if (it.row() > j)
        ++begin[static_cast<std::size_t>(std::max(position[static_cast<std::size_t>(it.row())],
                                                  position[static_cast<std::size_t>(j)])) +
                1];
  for (std::size_t k = 0; k < n; ++k) begin[k + 1] += begin[k];
  std::vector<int> earlier(static_cast<std::size_t>(begin[n])),
      fill(begin.begin(), begin.end() - 1);
  for (int j = 0; j < a.outerSize(); ++j)
    for (Sparse::InnerIterator it(a, j); it; ++it)
      if (it.row() > j) {
        const int x = position[static_cast<std::size_t>(it.row())],
                  y = position[static_cast<std::size_t>(j)];
        earlier[static_cast<std::size_t>(fill[static_cast<std::size_t>(std::max(x, y))]++)] =
            std::min(x, y);
      }
  std::vector<int> parent(n, -1), ancestor(n, -1);
  for (std::size_t k = 0; k < n; ++k)
    for (int e = begin[k]; e < begin[k + 1]; ++e)
      for (int i = earlier[static_cast<std::size_t>(e)]; i != -1 && i < static_cast<int>(k);) {
        const int next = ancestor[static_cast<std::size_t>(i)];
        ancestor[static_cast<std::size_t>(i)] = static_cast<int>(k);
        if (next == -1) parent[static_cast<std::size_t>(i)] = static_cast<int>(k);
        i = next;
      }
  return parent;
}

Separator tree_separator(const Sparse& a, const std::vector<int>& keys) {
  const int n = static_cast<int>(a.rows());
  if (n < 3 || a.cols() != a.rows() || static_cast<int>(keys.size()) != n) return {};
  const std::vector<int> order = sorted_by_key(keys);
  std::vector<int> position(order.size());
  for (int k = 0; k < n; ++k) position[static_cast<std::size_t>(order[k])] = k;
  const std::vector<int> parent = elimination_tree(a, position);
  // Subtree sizes (a parent comes after its children) and each node's largest child.
  std::vector<int> size(order.size(), 1), heavy(order.size(), -1);
  for (int k = 0; k < n; ++k)
    if (const int p = parent[static_cast<std::size_t>(k)]; p >= 0) {
      size[static_cast<std::size_t>(p)] += size[static_cast<std::size_t>(k)];
      if (heavy[p] < 0 || size[static_cast<std::size_t>(k)] > size[heavy[p]]) heavy[p] = k;
    }
  // Down the largest tree from its root along the largest child while that child holds more
  // than 60 % of the rows not yet in the separator: the separator is this path, every subtree
  // hanging from it couples only to the path (its ancestors) and joins one half.
  int top = -1;
  for (int k = 0; k < n; ++k)
    if (parent[static_cast<std::size_t>(k)] < 0 && (top < 0 || size[k] > size[top])) top = k;
  std::vector<char> on_path(order.size(), 0);
  int path = 0;
  for (int k = top;; k = heavy[k]) {
    on_path[static_cast<std::size_t>(k)] = 1;
    ++path;
    const int h = heavy[k];
    if (h < 0) return {}; // a chain: no two subtrees to balance
    if (size[h] <= 0.6 * (n - path)) break;
  }
  // The subtrees off the path (and the other trees), largest first, each to the smaller half.
  std::vector<int> pieces;
  for (int k = 0; k < n; ++k) {
    const int p = parent[static_cast<std::size_t>(k)];
    if (!on_path[static_cast<std::size_t>(k)] && (p < 0 || on_path[static_cast<std::size_t>(p)]))
      pieces.push_back(k);
  }
  std::sort(pieces.begin(), pieces.end(), [&](int x, int y) { return size[x] > size[y]; });
  std::vector<unsigned char> side(order.size(), 2);
  Separator s;
  for (const int root : pieces) {
    const unsigned char half = s.rows[0] <= s.rows[1] ? 0 : 1;
    side[static_cast<std::size_t>(root)] = half;
    s.rows[half] += size[root];
  }
  if (std::min(s.rows[0], s.rows[1]) < 0.4 * (s.rows[0] + s.rows[1])) return {};
  // A subtree's rows take its root's side (children before parents, so from the top down).
  s.part.resize(static_cast<std::size_t>(n));
  for (int k = n - 1; k >= 0; --k) {
    const int p = parent[static_cast<std::size_t>(k)];
    if (side[static_cast<std::size_t>(k)] == 2 && !on_path[static_cast<std::size_t>(k)] && p >= 0)
      side[static_cast<std::size_t>(k)] = side[static_cast<std::size_t>(p)];
    s.part[static_cast<std::size_t>(order[k])] = side[static_cast<std::size_t>(k)];
  }
  s.separator_rows = path;
  // The tree's postorder as the rows' keys: the halves' factors then find their supernodes as
  // consecutive columns.
  s.keys = postorder_keys(parent, order);
  return s;
}

} // namespace remora
