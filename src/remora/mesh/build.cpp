#include "remora/mesh/build.h"

#include <algorithm>
#include <string>

#include "remora/common/error.h"

namespace remora {

Mesh build_mesh(const std::vector<Vec3>& points,
                const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  const std::size_t nt = triangles.size();
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = triangles[t];
    for (int k = 0; k < 3; ++k)
      if (tri[k] >= points.size())
        throw InvalidArgument("build_mesh: triangle " + std::to_string(t) + " uses vertex " +
                              std::to_string(tri[k]) + " of " + std::to_string(points.size()));
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0])
      throw InvalidArgument("build_mesh: triangle " + std::to_string(t) + " repeats a vertex");
  }
  // Sides (undirected edge key, 3*t + corner) sorted by edge: each group is one edge.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> sides(nt * 3);
  for (std::uint32_t t = 0; t < nt; ++t)
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      const std::uint64_t key = a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);
      sides[3 * t + k] = {key, 3 * t + k};
    }
  std::sort(sides.begin(), sides.end());

  Mesh mesh;
  mesh.reserve(points.size(), nt * 3 / 2 + 1, nt);
  for (const Vec3& p : points) mesh.new_vertex(p);
  std::vector<HalfedgeHandle> side_halfedge(nt * 3); // by 3*t + corner
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i + 1;
    while (j < sides.size() && sides[j].first == sides[i].first) ++j;
    const std::uint32_t s0 = sides[i].second;
    const auto& t0 = triangles[s0 / 3];
    const std::uint32_t a = t0[s0 % 3], b = t0[(s0 % 3 + 1) % 3];
    if (j - i > 2)
      throw InvalidArgument("build_mesh: an edge has more than two triangles (non-manifold)");
    const HalfedgeHandle h =
        mesh.new_edge(VertexHandle(static_cast<int>(a)), VertexHandle(static_cast<int>(b)));
    side_halfedge[s0] = h;
    if (j - i == 2) {
      const std::uint32_t s1 = sides[i + 1].second;
      if (triangles[s1 / 3][s1 % 3] != b)
        throw InvalidArgument("build_mesh: two triangles run an edge the same way "
                              "(inconsistent orientation)");
      side_halfedge[s1] = mesh.opposite_halfedge_handle(h);
    }
    i = j;
  }
  for (std::uint32_t t = 0; t < nt; ++t) {
    const FaceHandle fh = mesh.new_face();
    const HalfedgeHandle* hs = &side_halfedge[3 * t];
    for (int k = 0; k < 3; ++k) {
      mesh.set_face_handle(hs[k], fh);
      mesh.set_next_halfedge_handle(hs[k], hs[(k + 1) % 3]);
      mesh.set_halfedge_handle(VertexHandle(static_cast<int>(triangles[t][k])), hs[k]);
    }
    mesh.set_halfedge_handle(fh, hs[0]);
  }
  // Boundary halfedges: with one fan per vertex each vertex has at most one outgoing boundary
  // halfedge, which follows the incoming one around the hole. A boundary vertex's halfedge is its
  // outgoing boundary halfedge (OpenMesh's convention, which its boundary queries rely on).
  std::vector<HalfedgeHandle> boundary_out(mesh.n_vertices());
  for (auto h : mesh.halfedges())
    if (mesh.is_boundary(h)) {
      HalfedgeHandle& slot = boundary_out[mesh.from_vertex_handle(h).idx()];
      if (slot.is_valid())
        throw InvalidArgument("build_mesh: vertex " +
                              std::to_string(mesh.from_vertex_handle(h).idx()) +
                              " has more than one fan of triangles (non-manifold)");
      slot = h;
    }
  for (auto h : mesh.halfedges())
    if (mesh.is_boundary(h))
      mesh.set_next_halfedge_handle(h, boundary_out[mesh.to_vertex_handle(h).idx()]);
  for (auto v : mesh.vertices())
    if (boundary_out[v.idx()].is_valid()) mesh.set_halfedge_handle(v, boundary_out[v.idx()]);
  return mesh;
}

} // namespace remora
