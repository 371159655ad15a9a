#include "remora/mesh/refine.h"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "remora/common/error.h"

namespace remora {

RefineResult refine_region(Mesh& mesh, const std::vector<int>& region, double max_length,
                           std::size_t max_vertices) {
  if (!(max_length > 0.0))
    throw InvalidArgument(fmt::format("refine: the edge length must be > 0, not {}", max_length));
  const auto n = static_cast<int>(mesh.n_vertices());
  std::vector<char> in(mesh.n_vertices(), 0);
  for (const int v : region) {
    if (v < 0 || v >= n)
      throw InvalidArgument(
          fmt::format("refine: vertex {} is out of range (the mesh has {} vertices)", v, n));
    in[static_cast<std::size_t>(v)] = 1;
  }
  const auto inside = [&](EdgeHandle e) {
    const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    return in[static_cast<std::size_t>(mesh.from_vertex_handle(h).idx())] &&
           in[static_cast<std::size_t>(mesh.to_vertex_handle(h).idx())];
  };
  const Mesh before = mesh; // to leave the mesh as it was when the limit is passed
  RefineResult result;
  for (;;) {
    std::vector<std::pair<double, int>> long_edges;
    for (const EdgeHandle e : mesh.edges())
      if (inside(e)) {
        const double length = mesh.calc_edge_length(e);
        if (length > max_length) long_edges.emplace_back(length, e.idx());
      }
    if (long_edges.empty()) break;
    std::sort(long_edges.begin(), long_edges.end(), std::greater<>());
    for (const auto& [length, idx] : long_edges) {
      const EdgeHandle e(idx); // still one of the edge's halves: split() keeps the handle
      if (mesh.calc_edge_length(e) <= max_length) continue;
      if (mesh.n_vertices() >= max_vertices) {
        mesh = before;
        throw InvalidArgument(fmt::format(
            "refine: splitting the region's edges to {:.4g} would pass {} vertices; give a "
            "longer edge length or a smaller region",
            max_length, max_vertices));
      }
      const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
      const Vec3 mid =
          0.5 * (mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h)));
      mesh.split(e, mid);
      in.push_back(1);
      ++result.added;
    }
  }
  for (std::size_t v = 0; v < in.size(); ++v)
    if (in[v]) result.region.push_back(static_cast<int>(v));
  return result;
}

} // namespace remora
