// A point on a triangle mesh: a face and barycentric coordinates. The correspondence between a
// mesh and its remesh (paper §4, "mutual parameterization") and the Phong detail encoding (§3)
// are made of these.
#pragma once

#include <array>

#include "remora/mesh/mesh.h"

namespace remora {

/// The three vertices of a triangle in the order barycentric coordinates refer to:
/// from(h), to(h), to(next(h)) with h = halfedge_handle(f).
inline std::array<VertexHandle, 3> face_vertices(const Mesh& mesh, FaceHandle f) {
  const HalfedgeHandle h = mesh.halfedge_handle(f);
  const HalfedgeHandle n = mesh.next_halfedge_handle(h);
  return {mesh.from_vertex_handle(h), mesh.to_vertex_handle(h), mesh.to_vertex_handle(n)};
}

/// face + barycentric coordinates w.r.t. face_vertices(face); the weights sum to 1 and are
/// >= 0 for a point inside the triangle.
struct SurfacePoint {
  FaceHandle face;
  std::array<double, 3> bary{1.0, 0.0, 0.0};
};

/// The point in space a surface point stands for.
inline Vec3 evaluate(const Mesh& mesh, const SurfacePoint& sp) {
  const auto v = face_vertices(mesh, sp.face);
  return mesh.point(v[0]) * sp.bary[0] + mesh.point(v[1]) * sp.bary[1] +
         mesh.point(v[2]) * sp.bary[2];
}

} // namespace remora
