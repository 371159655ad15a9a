#include "remora/geometry/geodesic.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"

namespace remora {

namespace {

void check_radius(double radius) {
  if (!(radius >= 0.0) || !std::isfinite(radius))
    throw InvalidArgument(
        fmt::format("geodesic ball: the radius {} must be finite and >= 0", radius));
}

std::vector<std::array<int, 3>> face_corners(const Mesh& mesh) {
  std::vector<std::array<int, 3>> triangles;
  triangles.reserve(mesh.n_faces());
  for (const FaceHandle f : mesh.faces()) {
    const auto c = face_vertices(mesh, f);
    triangles.push_back({c[0].idx(), c[1].idx(), c[2].idx()});
  }
  return triangles;
}

/// The diagonal of the bounding box of the faces' corners with finite coordinates (0: none).
double corner_diagonal(const Mesh& mesh, const std::vector<std::array<int, 3>>& faces) {
  Vec3 low(std::numeric_limits<double>::infinity()), high(-std::numeric_limits<double>::infinity());
  for (const auto& f : faces)
    for (const int v : f) {
      const Vec3& p = mesh.points()[static_cast<std::size_t>(v)];
      if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))
        low.minimize(p), high.maximize(p);
    }
  return low[0] <= high[0] ? (high - low).norm() : 0.0;
}

} // namespace

FastMarching::FastMarching(const Mesh& mesh, const FastMarchingOptions& options)
    : faces_(mesh.n_faces()), options_(options) {
  if (!(options.coarse_ratio == 0.0 || options.coarse_ratio >= 1.0) ||
      !std::isfinite(options.coarse_ratio))
    throw InvalidArgument(fmt::format(
        "geodesic ball: coarse_ratio {} must be 0 (no coarse levels) or a finite number >= 1",
        options.coarse_ratio));
  auto corners = face_corners(mesh);
  marcher_ = Marcher(march_rings(mesh.n_vertices(), corners));
  if (options.coarse_ratio > 0.0) {
    mean_edge_ = mean_edge_length(mesh);
    // The last level's cells span the whole mesh (one cluster per component); larger balls use it.
    diagonal_ = corner_diagonal(mesh, corners);
    if (mean_edge_ > 0.0 && std::isfinite(mean_edge_) && diagonal_ > 0.0 &&
        std::isfinite(diagonal_))
      top_level_ = std::max(1, static_cast<int>(std::ceil(std::log2(diagonal_ / mean_edge_))));
    corners_ = std::make_shared<const std::vector<std::array<int, 3>>>(std::move(corners));
  }
}

FastMarching::~FastMarching() = default;
FastMarching::FastMarching(FastMarching&&) noexcept = default;
FastMarching& FastMarching::operator=(FastMarching&&) noexcept = default;

double FastMarching::last_cell() const {
  return last_level_ > 0 ? levels_[static_cast<std::size_t>(last_level_ - 1)]->cell() : 0.0;
}

void FastMarching::check_mesh(const Mesh& mesh) const {
  if (mesh.n_vertices() != marcher_.size() || mesh.n_faces() != faces_)
    throw InvalidArgument(fmt::format(
        "geodesic ball: the mesh has {} vertices and {} faces; the marcher was built for {} and {}",
        mesh.n_vertices(), mesh.n_faces(), marcher_.size(), faces_));
}

int FastMarching::level_for(double radius) const {
  const double reach = options_.coarse_ratio * mean_edge_; // the largest radius of level 0
  if (top_level_ == 0 || radius <= reach) return 0;
  const double k = std::ceil(std::log2(radius / reach)); // in double: the ratio may be huge
  return k >= top_level_ ? top_level_ : std::max(1, static_cast<int>(k));
}

std::vector<std::pair<int, double>>
FastMarching::fine(const Mesh& mesh, const std::vector<std::pair<int, double>>& seeds,
                   double radius) {
  last_level_ = 0;
  std::vector<std::pair<int, double>> out;
  for (const Accepted& a : marcher_.march(mesh.points(), seeds, radius, 0.0))
    if (a.fresh) out.emplace_back(a.vertex, a.distance);
  return out;
}

void FastMarching::start_stroke() {
  marcher_.start_stroke();
  for (const auto& level : levels_)
    if (level) level->start_stroke();
  stroke_radius_ = -1.0;
}

CoarseLevel& FastMarching::level(const Mesh& mesh, int k) {
  if (levels_.size() < static_cast<std::size_t>(k)) levels_.resize(static_cast<std::size_t>(k));
  auto& level = levels_[static_cast<std::size_t>(k - 1)];
  if (!level)
    level = std::make_unique<CoarseLevel>(mesh, corners_, mean_edge_ * std::ldexp(1.0, k));
  return *level;
}

void FastMarching::prepare(const Mesh& mesh, double radius) {
  check_radius(radius);
  check_mesh(mesh);
  for (int k = 1; k <= level_for(radius); ++k) level(mesh, k);
}

void FastMarching::positions_changed(const Mesh& mesh, const std::vector<int>& vertices) {
  check_mesh(mesh);
  for (const int v : vertices)
    if (v < 0 || static_cast<std::size_t>(v) >= mesh.n_vertices())
      throw InvalidArgument(fmt::format("geodesic ball: vertex {} is not a vertex of the mesh", v));
  if (std::none_of(levels_.begin(), levels_.end(),
                   [](const auto& level) { return level && !level->reads_all(); }))
    return;
  // The moved vertices and their neighbours (a face's normal changes with any of its corners),
  // once for every level.
  near_moved_.assign(mesh.n_vertices(), 0);
  std::vector<int> near;
  const auto add = [&](int v) {
    if (!near_moved_[static_cast<std::size_t>(v)])
      near_moved_[static_cast<std::size_t>(v)] = 1, near.push_back(v);
  };
  for (const int v : vertices) {
    add(v);
    for (const VertexHandle w : mesh.vv_range(VertexHandle(v))) add(w.idx());
  }
  for (const auto& level : levels_)
    if (level) level->positions_changed(near);
}

void FastMarching::positions_changed() {
  for (const auto& level : levels_)
    if (level) level->positions_changed();
}

std::vector<std::pair<int, double>>
FastMarching::stroke_ball(const Mesh& mesh, const SurfacePoint& source, double radius) {
  check_radius(radius);
  check_mesh(mesh);
  const FaceHandle f = source.face;
  if (!f.is_valid() || f.idx() >= static_cast<int>(mesh.n_faces()) || mesh.status(f).deleted())
    throw InvalidArgument(
        fmt::format("geodesic ball: face {} is not a face of the mesh (it has {} faces)", f.idx(),
                    mesh.n_faces()));
  for (const double b : source.bary)
    if (!std::isfinite(b))
      throw InvalidArgument("geodesic ball: the source's barycentric coordinates are not finite");
  if (radius != stroke_radius_) start_stroke();
  stroke_radius_ = radius;
  const Vec3 point = evaluate(mesh, source);
  const auto corners = face_vertices(mesh, f);
  const int k = level_for(radius);
  if (k == 0) {
    std::vector<std::pair<int, double>> seeds;
    for (const VertexHandle v : corners)
      seeds.emplace_back(v.idx(), (mesh.point(v) - point).norm());
    return fine(mesh, seeds, radius);
  }
  auto& coarse = level(mesh, k);
  last_level_ = k;
  return coarse.stroke_ball(mesh, point, {corners[0].idx(), corners[1].idx(), corners[2].idx()},
                            radius);
}

std::vector<std::pair<int, double>> FastMarching::ball(const Mesh& mesh, const SurfacePoint& source,
                                                       double radius) {
  start_stroke();
  auto out = stroke_ball(mesh, source, radius);
  stroke_radius_ = -1.0; // the next stroke_ball() starts a stroke
  return out;
}

std::vector<std::pair<int, double>> FastMarching::ball(const Mesh& mesh, VertexHandle source,
                                                       double radius) {
  check_radius(radius);
  check_mesh(mesh);
  if (!source.is_valid() || source.idx() >= static_cast<int>(mesh.n_vertices()) ||
      mesh.status(source).deleted())
    throw InvalidArgument(
        fmt::format("geodesic ball: vertex {} is not a vertex of the mesh (it has {} vertices)",
                    source.idx(), mesh.n_vertices()));
  if (level_for(radius) > 0) // the same ball from a face at the vertex
    for (const FaceHandle f : mesh.vf_range(source)) {
      const auto corners = face_vertices(mesh, f);
      std::array<double, 3> bary{};
      for (std::size_t k = 0; k < 3; ++k) bary[k] = corners[k] == source ? 1.0 : 0.0;
      return ball(mesh, SurfacePoint{f, bary}, radius);
    }
  start_stroke();
  auto out = fine(mesh, {{source.idx(), 0.0}}, radius);
  stroke_radius_ = -1.0;
  return out;
}

std::vector<std::pair<int, double>> geodesic_ball(const Mesh& mesh, const SurfacePoint& source,
                                                  double radius) {
  return FastMarching(mesh).ball(mesh, source, radius);
}

std::vector<std::pair<int, double>> geodesic_ball(const Mesh& mesh, VertexHandle source,
                                                  double radius) {
  return FastMarching(mesh).ball(mesh, source, radius);
}

} // namespace remora
