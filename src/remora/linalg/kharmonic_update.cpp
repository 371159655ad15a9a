// KHarmonicAssembler after a local change of its mesh (kharmonic.h): what the change did not reach
// is copied from the earlier assembler, the rest computed as the full constructor computes it.
#include <algorithm>
#include <atomic>
#include <future>
#include <string>
#include <utility>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/linalg/kharmonic.h"

namespace remora {

namespace {

// Per vertex: 1 where it is changed or shares a face with a changed vertex. The column of W, the
// area and the one-ring of any other vertex come from faces whose corners and points are the
// earlier ones.
std::vector<char> reached(const Mesh& mesh, const std::vector<char>& changed) {
  std::vector<char> out(changed);
  for (std::size_t v = 0; v < changed.size(); ++v)
    if (changed[v])
      for (const FaceHandle f : mesh.vf_range(VertexHandle(static_cast<int>(v))))
        for (const VertexHandle w : mesh.fv_range(f)) out[static_cast<std::size_t>(w.idx())] = 1;
  return out;
}

// The entries of column v of W: the cotan weight of each edge out of v and the diagonal, the
// diagonal summed in edge order as weights_matrix() sums it (the same bits); sorted by row.
void weight_column(const Mesh& mesh, VertexHandle v, std::vector<std::pair<int, double>>& out) {
  thread_local std::vector<std::pair<int, int>> edges; // (edge, neighbour)
  edges.clear();
  out.clear();
  if (mesh.status(v).deleted()) return;
  for (auto h = mesh.cvoh_iter(v); h.is_valid(); ++h) {
    const EdgeHandle e = mesh.edge_handle(*h);
    if (!mesh.status(e).deleted()) edges.emplace_back(e.idx(), mesh.to_vertex_handle(*h).idx());
  }
  if (edges.empty()) return;
  std::sort(edges.begin(), edges.end());
  double diagonal = 0.0;
  for (const auto& [e, w] : edges) {
    const double weight = cotan_weight(mesh, EdgeHandle(e));
    diagonal -= weight;
    out.emplace_back(w, weight);
  }
  out.emplace_back(v.idx(), diagonal);
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
}

void check_update_sizes(const Mesh& mesh, std::size_t previous_vertices,
                        const std::vector<int>& previous_of, const std::vector<char>& changed) {
  const std::size_t n = mesh.n_vertices();
  if (previous_of.size() != n || changed.size() != n)
    throw InvalidArgument("k-harmonic assembler update: " + std::to_string(previous_of.size()) +
                          " earlier vertices and " + std::to_string(changed.size()) +
                          " change flags for a mesh of " + std::to_string(n) +
                          " vertices; give one of each per vertex");
  for (std::size_t v = 0; v < n; ++v)
    if (!changed[v] &&
        (previous_of[v] < 0 || static_cast<std::size_t>(previous_of[v]) >= previous_vertices))
      throw InvalidArgument("k-harmonic assembler update: vertex " + std::to_string(v) +
                            " is marked unchanged but its earlier vertex " +
                            std::to_string(previous_of[v]) + " is not one of the " +
                            std::to_string(previous_vertices) +
                            " earlier vertices; mark it changed");
}

// The current vertex of each earlier vertex that an unchanged vertex was (-1: none). current()
// of an earlier vertex without one gives 0 and records the broken contract: no throw inside a
// parallel loop.
class Renumbering {
public:
  Renumbering(const std::vector<int>& previous_of, const std::vector<char>& changed,
              std::size_t previous_vertices)
      : current_of_(previous_vertices, -1) {
    for (std::size_t v = 0; v < changed.size(); ++v)
      if (!changed[v]) current_of_[static_cast<std::size_t>(previous_of[v])] = static_cast<int>(v);
  }
  int current(int earlier) const {
    const int v = current_of_[static_cast<std::size_t>(earlier)];
    if (v < 0) broken_ = true;
    return std::max(v, 0);
  }
  bool broken() const { return broken_; }

private:
  std::vector<int> current_of_;
  mutable std::atomic<bool> broken_{false};
};

// Sizes −W for `mesh` (n × n) and its column starts: a dirty column's entries counted on the
// mesh, a copied one's taken from `earlier`.
void size_columns(const Mesh& mesh, const std::vector<char>& dirty,
                  const std::vector<int>& previous_of, const SparseMatrix& earlier, int threads,
                  SparseMatrix& minus_w) {
  const std::size_t n = mesh.n_vertices();
  const auto size = static_cast<Eigen::Index>(n);
  minus_w.resize(size, size);
  int* outer = minus_w.outerIndexPtr();
  outer[0] = 0;
  parallel_for(n, threads, [&](std::size_t v) {
    int count = 0;
    if (dirty[v]) {
      const VertexHandle vh(static_cast<int>(v));
      if (!mesh.status(vh).deleted())
        for (auto h = mesh.cvoh_iter(vh); h.is_valid(); ++h)
          count += mesh.status(mesh.edge_handle(*h)).deleted() ? 0 : 1;
      count += count > 0 ? 1 : 0;
    } else {
      const int o = previous_of[v];
      count = earlier.outerIndexPtr()[o + 1] - earlier.outerIndexPtr()[o];
    }
    outer[v + 1] = count;
  });
  for (std::size_t v = 0; v < n; ++v) outer[v + 1] += outer[v];
  minus_w.resizeNonZeros(outer[n]);
}

// Column o of `earlier` into rows/values from `at`, its rows renumbered; sorted again only where
// the renumbering moved a neighbour past another (the splice moves the last vertices into the
// places it frees). `entries`: scratch.
void copy_column(const SparseMatrix& earlier, int o, const Renumbering& renumbering, std::size_t at,
                 int* rows, double* values, std::vector<std::pair<int, double>>& entries) {
  const int begin = earlier.outerIndexPtr()[o], end = earlier.outerIndexPtr()[o + 1];
  bool sorted = true;
  for (int k = begin; k < end; ++k) {
    const std::size_t e = at + static_cast<std::size_t>(k - begin);
    rows[e] = renumbering.current(earlier.innerIndexPtr()[k]);
    values[e] = earlier.valuePtr()[k];
    sorted = sorted && (k == begin || rows[e - 1] < rows[e]);
  }
  if (sorted) return;
  entries.clear();
  for (std::size_t e = at; e < at + static_cast<std::size_t>(end - begin); ++e)
    entries.emplace_back(rows[e], values[e]);
  std::sort(entries.begin(), entries.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  for (std::size_t k = 0; k < entries.size(); ++k) {
    rows[at + k] = entries[k].first;
    values[at + k] = entries[k].second;
  }
}

// The entries of −W into the columns size_columns() made: a dirty column computed on the mesh,
// a copied one from `earlier`.
void fill_columns(const Mesh& mesh, const std::vector<char>& dirty,
                  const std::vector<int>& previous_of, const SparseMatrix& earlier,
                  const Renumbering& renumbering, int threads, SparseMatrix& minus_w) {
  const int* outer = minus_w.outerIndexPtr();
  int* rows = minus_w.innerIndexPtr();
  double* values = minus_w.valuePtr();
  parallel_for(mesh.n_vertices(), threads, [&](std::size_t v) {
    thread_local std::vector<std::pair<int, double>> entries;
    const auto at = static_cast<std::size_t>(outer[v]);
    if (dirty[v]) {
      weight_column(mesh, VertexHandle(static_cast<int>(v)), entries);
      for (std::size_t k = 0; k < entries.size(); ++k) {
        rows[at + k] = entries[k].first;
        values[at + k] = -entries[k].second;
      }
      return;
    }
    copy_column(earlier, previous_of[v], renumbering, at, rows, values, entries);
  });
}

} // namespace

KHarmonicAssembler::KHarmonicAssembler(const Mesh& mesh, const KHarmonicAssembler& previous,
                                       const std::vector<int>& previous_of,
                                       const std::vector<char>& changed, int threads)
    : threads_(threads) {
  check_update_sizes(mesh, previous.vertex_count(), previous_of, changed);
  const std::size_t n = mesh.n_vertices();
  const std::vector<char> dirty = reached(mesh, changed);
  // Earlier vertex -> vertex, for the unchanged ones. The neighbours of a vertex that no changed
  // vertex touches are unchanged (each shares a face with it), so its copy needs only these.
  const Renumbering renumbering(previous_of, changed, previous.vertex_count());

  // The areas, the one-rings and the components on another thread, −W here.
  auto rest = std::async(threads == 1 ? std::launch::deferred : std::launch::async, [&] {
    area_.resize(static_cast<Eigen::Index>(n));
    offsets_.assign(n + 1, 0);
    for (std::size_t v = 0; v < n; ++v) {
      const VertexHandle vh(static_cast<int>(v));
      if (dirty[v]) {
        area_[static_cast<Eigen::Index>(v)] = vertex_area_mixed(mesh, vh);
        for (const VertexHandle w : mesh.vv_range(vh)) adjacent_.push_back(w.idx());
      } else {
        const auto o = static_cast<std::size_t>(previous_of[v]);
        area_[static_cast<Eigen::Index>(v)] = previous.area_[static_cast<Eigen::Index>(o)];
        for (int a = previous.offsets_[o]; a < previous.offsets_[o + 1]; ++a)
          adjacent_.push_back(renumbering.current(previous.adjacent_[static_cast<std::size_t>(a)]));
      }
      offsets_[v + 1] = static_cast<int>(adjacent_.size());
    }
    inverse_areas();
    find_components(mesh);
  });

  size_columns(mesh, dirty, previous_of, previous.minus_w_, threads, minus_w_);
  fill_columns(mesh, dirty, previous_of, previous.minus_w_, renumbering, threads, minus_w_);
  rest.get();
  if (renumbering.broken())
    throw Error("k-harmonic assembler update: a neighbour of an unchanged vertex has no vertex in "
                "the new mesh; a vertex was marked unchanged though its faces changed");
}

} // namespace remora
