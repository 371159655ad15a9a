#include "shape.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/surface_point.h"

namespace remora::server {

Brush parse_brush(const std::string& name) {
  if (name == "geodesic") return Brush::Geodesic;
  if (name == "sphere") return Brush::Sphere;
  throw InvalidArgument(fmt::format("unknown brush '{}': use geodesic or sphere", name));
}

// The caster and the brush's coarse levels are built here, on the load's worker, not on the
// first pick (half a second and a few tenths on a million triangles). The levels are those of
// every brush up to half the diagonal of the faces' bounding box, which the page's largest (its
// bounding sphere's radius) does not exceed.
Shape::Shape(const Mesh& mesh, double coarse_ratio)
    : mesh_(mesh), caster_(mesh_), marching_(mesh_, {.coarse_ratio = coarse_ratio}) {
  marching_.prepare(mesh_, 0.5 * marching_.faces_diagonal());
}

void Shape::set_positions(const Eigen::MatrixXd& positions) {
  for (const VertexHandle v : mesh_.vertices())
    mesh_.set_point(v, Vec3(positions(v.idx(), 0), positions(v.idx(), 1), positions(v.idx(), 2)));
  stale_ = true;
}

void Shape::set_positions(const std::vector<int>& ids, const Eigen::MatrixXd& positions) {
  if (moved_flag_.size() != mesh_.n_vertices()) moved_flag_.assign(mesh_.n_vertices(), 0);
  for (const int i : ids) {
    mesh_.set_point(VertexHandle(i), Vec3(positions(i, 0), positions(i, 1), positions(i, 2)));
    if (!moved_flag_[static_cast<std::size_t>(i)]) {
      moved_flag_[static_cast<std::size_t>(i)] = 1;
      moved_.push_back(i);
    }
  }
}

void Shape::start_stroke(std::int64_t stroke, Brush brush, double radius) {
  marching_.start_stroke();
  for (const std::uint32_t v : answered_list_) answered_[v] = 0;
  answered_list_.clear();
  stroke_ = stroke;
  stroke_brush_ = brush;
  stroke_radius_ = radius;
}

Pick Shape::pick(const Vec3& origin, const Vec3& direction, double radius, Brush brush,
                 std::int64_t stroke) {
  if (!(radius >= 0.0) || !std::isfinite(radius))
    throw InvalidArgument(fmt::format("radius: {} must be finite and >= 0", radius));
  // A stroke goes on only on the same shape, with the same brush.
  if (stroke < 0 || stroke != stroke_ || brush != stroke_brush_ || radius != stroke_radius_ ||
      stale_ || !moved_.empty())
    start_stroke(stroke, brush, radius);
  if (stale_) {
    caster_.refit(mesh_);
    marching_.positions_changed();
  } else if (!moved_.empty()) {
    caster_.refit(mesh_, moved_); // a drag moved only its region
    marching_.positions_changed(mesh_, moved_);
  }
  stale_ = false;
  for (const int i : moved_) moved_flag_[static_cast<std::size_t>(i)] = 0;
  moved_.clear();
  const RayHit hit =
      caster_.first_hit(origin, direction, 0.0, std::numeric_limits<double>::infinity());
  Pick out;
  if (!hit.face.is_valid()) return out;
  const SurfacePoint at{hit.face, hit.bary};
  out.face = hit.face.idx();
  out.point = evaluate(mesh_, at);
  const auto corners = face_vertices(mesh_, hit.face);
  double nearest = std::numeric_limits<double>::infinity();
  for (const VertexHandle c : corners) {
    const double d = (mesh_.point(c) - out.point).sqrnorm();
    if (d < nearest) {
      nearest = d;
      out.vertex = c.idx();
    }
  }
  if (radius <= 0.0) return out;
  if (brush == Brush::Sphere) {
    if (answered_.size() != mesh_.n_vertices()) answered_.assign(mesh_.n_vertices(), 0);
    for (const int v : select_sphere(mesh_, out.point, radius)) {
      const auto u = static_cast<std::uint32_t>(v);
      if (answered_[u]) continue;
      out.brush.push_back(u);
      if (stroke >= 0) answered_[u] = 1, answered_list_.push_back(u);
    }
    return out;
  }
  for (const auto& [v, d] : marching_.stroke_ball(mesh_, at, radius))
    out.brush.push_back(static_cast<std::uint32_t>(v));
  std::sort(out.brush.begin(), out.brush.end());
  return out;
}

} // namespace remora::server
