#include "remora/geometry/thickness.h"

#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/geometry/raycast.h"
#include "remora/mesh/surface_point.h"

namespace remora {

Eigen::VectorXd vertex_half_widths(const Mesh& mesh, const HalfWidthOptions& options) {
  if (!(options.min_distance >= 0.0) || !std::isfinite(options.min_distance) ||
      !(options.max_distance > options.min_distance))
    throw InvalidArgument(fmt::format(
        "half widths: min_distance {} must be finite and >= 0, max_distance {} above it",
        options.min_distance, options.max_distance));
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const RayCaster caster(mesh);
  // Unit face normals; zero for faces without area.
  std::vector<Vec3> normals(mesh.n_faces(), Vec3(0, 0, 0));
  parallel_for(mesh.n_faces(), options.threads, [&](std::size_t i) {
    const FaceHandle f(static_cast<int>(i));
    if (mesh.status(f).deleted()) return;
    const auto fv = face_vertices(mesh, f);
    const Vec3 c = OpenMesh::cross(mesh.point(fv[1]) - mesh.point(fv[0]),
                                   mesh.point(fv[2]) - mesh.point(fv[0]));
    const double length = c.norm();
    if (length > 0.0) normals[i] = c / length;
  });
  Eigen::VectorXd half(static_cast<Eigen::Index>(mesh.n_vertices()));
  parallel_for(mesh.n_vertices(), options.threads, [&](std::size_t i) {
    const VertexHandle v(static_cast<int>(i));
    half[static_cast<Eigen::Index>(i)] = kInf;
    if (mesh.status(v).deleted() || mesh.is_isolated(v)) return;
    // Angle-weighted normal: the corner angle of each face at v.
    const Vec3 p = mesh.point(v);
    Vec3 n(0, 0, 0);
    for (const HalfedgeHandle h : mesh.voh_range(v)) {
      if (mesh.is_boundary(h)) continue;
      const Vec3 e1 = mesh.point(mesh.to_vertex_handle(h)) - p;
      const Vec3 e2 = mesh.point(mesh.from_vertex_handle(mesh.prev_halfedge_handle(h))) - p;
      const double angle = std::atan2(OpenMesh::cross(e1, e2).norm(), OpenMesh::dot(e1, e2));
      n += angle * normals[static_cast<std::size_t>(mesh.face_handle(h).idx())];
    }
    const double length = n.norm();
    if (!(length > 0.0)) return;
    n /= length;
    double nearest = kInf;
    for (const double side : {1.0, -1.0}) {
      const Vec3 d = side * n;
      const RayHit hit = caster.first_hit(p, d, options.min_distance, options.max_distance, v);
      if (!hit.face.is_valid()) continue;
      // Through air (+n) the face met must look back at the ray; through material, away.
      const double facing = OpenMesh::dot(normals[static_cast<std::size_t>(hit.face.idx())], d);
      if (side * facing < 0.0) nearest = std::min(nearest, hit.t);
    }
    half[static_cast<Eigen::Index>(i)] = 0.5 * nearest;
  });
  return half;
}

} // namespace remora
