#include "remora/geometry/geodesic.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>

#include <fmt/format.h>

#include "remora/common/error.h"

namespace remora {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::uint8_t kFar = 0, kTrial = 1, kAccepted = 2;

/// The distance at c of triangle (a, b, c), given by its edge lengths ab, ac, bc, from the
/// distances da at a and db at b: the triangle unfolded into the plane, a virtual source on the
/// far side of ab at distances da and db, and the straight line from it to c if that line crosses
/// ab; otherwise the shorter edge path.
double through_triangle(double ab, double ac, double bc, double da, double db) {
  const double edge_path = std::min(da + ac, db + bc);
  if (!(ab > 0.0)) return edge_path;
  // a at the origin, b on the positive x axis, c above it.
  const double cx = (ac * ac - bc * bc + ab * ab) / (2.0 * ab);
  const double cy2 = ac * ac - cx * cx;
  if (!(cy2 > 0.0)) return edge_path;
  const double cy = std::sqrt(cy2);
  const double sx = (da * da - db * db + ab * ab) / (2.0 * ab);
  const double sy2 = da * da - sx * sx;
  if (sy2 < 0.0) return edge_path; // da, db and ab violate the triangle inequality
  const double sy = -std::sqrt(sy2);
  const double t = -sy / (cy - sy); // where the line from s to c meets the x axis
  const double x = sx + t * (cx - sx);
  if (x < 0.0 || x > ab) return edge_path;
  const double dx = cx - sx, dy = cy - sy; // magnitudes of the mesh's size: no overflow
  return std::min(edge_path, std::sqrt(dx * dx + dy * dy));
}

void check_radius(double radius) {
  if (!(radius >= 0.0) || !std::isfinite(radius))
    throw InvalidArgument(
        fmt::format("geodesic ball: the radius {} must be finite and >= 0", radius));
}

} // namespace

FastMarching::FastMarching(const Mesh& mesh)
    : faces_(mesh.n_faces()), ring_begin_(mesh.n_vertices() + 1, 0),
      distance_(mesh.n_vertices(), kInf), state_(mesh.n_vertices(), kFar),
      nearest_(mesh.n_vertices(), kInf) {
  for (const FaceHandle f : mesh.faces())
    for (const VertexHandle v : face_vertices(mesh, f)) ++ring_begin_[v.idx() + 1];
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v) ring_begin_[v + 1] += ring_begin_[v];
  ring_.resize(ring_begin_.back());
  std::vector<std::uint32_t> fill(ring_begin_.begin(), ring_begin_.end() - 1);
  for (const FaceHandle f : mesh.faces()) {
    const auto c = face_vertices(mesh, f);
    for (std::size_t k = 0; k < 3; ++k)
      ring_[fill[static_cast<std::size_t>(c[k].idx())]++] = {c[(k + 1) % 3].idx(),
                                                             c[(k + 2) % 3].idx()};
  }
}

std::vector<std::pair<int, double>>
FastMarching::march(const Mesh& mesh, const std::vector<std::pair<int, double>>& seeds,
                    double radius) {
  if (mesh.n_vertices() != distance_.size() || mesh.n_faces() != faces_)
    throw InvalidArgument(fmt::format(
        "geodesic ball: the mesh has {} vertices and {} faces; the marcher was built for {} and {}",
        mesh.n_vertices(), mesh.n_faces(), distance_.size(), faces_));
  for (const int v : touched_) {
    distance_[static_cast<std::size_t>(v)] = kInf;
    state_[static_cast<std::size_t>(v)] = kFar;
  }
  touched_.clear();
  const bool first = stroke_touched_.empty(); // the whole ball: measure the slack on it
  double edge_sum = 0.0;
  std::size_t edges = 0;
  const Vec3* points = mesh.points();
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> front;
  auto offer = [&](int v, double d) {
    const auto i = static_cast<std::size_t>(v);
    // Beyond the radius it is never accepted; where an earlier source of the stroke is nearer
    // by more than the slack, no vertex beyond it is new.
    if (!(d < distance_[i]) || d > radius || !(d < nearest_[i] + slack_)) return;
    if (state_[i] == kFar) {
      state_[i] = kTrial;
      touched_.push_back(v);
    }
    distance_[i] = d;
    front.push({d, v});
  };
  for (const auto& [v, d] : seeds) offer(v, d);
  std::vector<std::pair<int, double>> out;
  while (!front.empty()) {
    const auto [d, v] = front.top();
    front.pop();
    const auto i = static_cast<std::size_t>(v);
    if (state_[i] == kAccepted || d > distance_[i]) continue; // a stale entry
    state_[i] = kAccepted;
    if (nearest_[i] == kInf) {
      out.emplace_back(v, d);
      stroke_touched_.push_back(v);
    }
    nearest_[i] = std::min(nearest_[i], d);
    const Vec3& pv = points[i];
    for (std::uint32_t r = ring_begin_[i]; r < ring_begin_[i + 1]; ++r) {
      const auto p = static_cast<std::size_t>(ring_[r][0]);
      const auto q = static_cast<std::size_t>(ring_[r][1]);
      const bool p_done = state_[p] == kAccepted, q_done = state_[q] == kAccepted;
      if (p_done && q_done) continue;
      const double vp = (points[p] - pv).norm(), vq = (points[q] - pv).norm();
      if (first) edge_sum += vp, ++edges;
      // Each corner not yet accepted: along the edge, or through the triangle from the other.
      if (!p_done)
        offer(static_cast<int>(p),
              q_done ? std::min(d + vp, through_triangle(vq, vp, (points[p] - points[q]).norm(), d,
                                                         distance_[q]))
                     : d + vp);
      if (!q_done)
        offer(static_cast<int>(q),
              p_done ? std::min(d + vq, through_triangle(vp, vq, (points[q] - points[p]).norm(), d,
                                                         distance_[p]))
                     : d + vq);
    }
  }
  if (first && edges > 0) slack_ = 2.0 * edge_sum / static_cast<double>(edges);
  return out;
}

std::vector<std::pair<int, double>> FastMarching::seeds_of(const Mesh& mesh,
                                                           const SurfacePoint& source) {
  const FaceHandle f = source.face;
  if (!f.is_valid() || f.idx() >= static_cast<int>(mesh.n_faces()) || mesh.status(f).deleted())
    throw InvalidArgument(
        fmt::format("geodesic ball: face {} is not a face of the mesh (it has {} faces)", f.idx(),
                    mesh.n_faces()));
  for (const double b : source.bary)
    if (!std::isfinite(b))
      throw InvalidArgument("geodesic ball: the source's barycentric coordinates are not finite");
  const Vec3 point = evaluate(mesh, source);
  std::vector<std::pair<int, double>> seeds;
  for (const VertexHandle v : face_vertices(mesh, f))
    seeds.emplace_back(v.idx(), (mesh.point(v) - point).norm());
  return seeds;
}

void FastMarching::start_stroke() {
  for (const int v : stroke_touched_) nearest_[static_cast<std::size_t>(v)] = kInf;
  stroke_touched_.clear();
  stroke_radius_ = -1.0;
  slack_ = 0.0;
}

std::vector<std::pair<int, double>>
FastMarching::stroke_ball(const Mesh& mesh, const SurfacePoint& source, double radius) {
  check_radius(radius);
  const auto seeds = seeds_of(mesh, source);
  if (radius != stroke_radius_) start_stroke();
  stroke_radius_ = radius;
  return march(mesh, seeds, radius);
}

std::vector<std::pair<int, double>> FastMarching::ball(const Mesh& mesh, const SurfacePoint& source,
                                                       double radius) {
  check_radius(radius);
  const auto seeds = seeds_of(mesh, source);
  start_stroke();
  return march(mesh, seeds, radius);
}

std::vector<std::pair<int, double>> FastMarching::ball(const Mesh& mesh, VertexHandle source,
                                                       double radius) {
  check_radius(radius);
  if (!source.is_valid() || source.idx() >= static_cast<int>(mesh.n_vertices()) ||
      mesh.status(source).deleted())
    throw InvalidArgument(
        fmt::format("geodesic ball: vertex {} is not a vertex of the mesh (it has {} vertices)",
                    source.idx(), mesh.n_vertices()));
  start_stroke();
  return march(mesh, {{source.idx(), 0.0}}, radius);
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
