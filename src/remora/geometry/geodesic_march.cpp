#include "remora/geometry/geodesic_march.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>

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

} // namespace

MarchRings march_rings(std::size_t n, const std::vector<std::array<int, 3>>& triangles,
                       const std::vector<std::array<int, 2>>& lone_edges) {
  MarchRings rings;
  rings.begin.assign(n + 1, 0);
  for (const auto& t : triangles)
    for (const int c : t) ++rings.begin[static_cast<std::size_t>(c) + 1];
  for (const auto& e : lone_edges)
    for (const int c : e) ++rings.begin[static_cast<std::size_t>(c) + 1];
  for (std::size_t v = 0; v < n; ++v) rings.begin[v + 1] += rings.begin[v];
  rings.ring.resize(rings.begin.back());
  std::vector<std::uint32_t> fill(rings.begin.begin(), rings.begin.end() - 1);
  for (const auto& t : triangles)
    for (std::size_t k = 0; k < 3; ++k)
      rings.ring[fill[static_cast<std::size_t>(t[k])]++] = {t[(k + 1) % 3], t[(k + 2) % 3]};
  for (const auto& e : lone_edges) {
    rings.ring[fill[static_cast<std::size_t>(e[0])]++] = {e[1], e[1]};
    rings.ring[fill[static_cast<std::size_t>(e[1])]++] = {e[0], e[0]};
  }
  return rings;
}

Marcher::Marcher(MarchRings rings)
    : rings_(std::move(rings)), distance_(rings_.begin.size() - 1, kInf),
      state_(distance_.size(), kFar), nearest_(distance_.size(), kInf) {}

void Marcher::start_stroke() {
  for (const int v : stroke_touched_) nearest_[static_cast<std::size_t>(v)] = kInf;
  stroke_touched_.clear();
  slack_ = 0.0;
}

std::vector<Accepted> Marcher::march(const Vec3* points,
                                     const std::vector<std::pair<int, double>>& seeds,
                                     double radius, double extra_slack) {
  for (const int v : touched_) {
    distance_[static_cast<std::size_t>(v)] = kInf;
    state_[static_cast<std::size_t>(v)] = kFar;
  }
  touched_.clear();
  const bool first = stroke_touched_.empty(); // the whole ball: measure the slack on it
  const double slack = first ? kInf : slack_ + extra_slack;
  double edge_sum = 0.0;
  std::size_t edges = 0;
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> front;
  auto offer = [&](int v, double d) {
    const auto i = static_cast<std::size_t>(v);
    // Beyond the radius it is never accepted; where an earlier source of the stroke is nearer
    // by more than the slack, no vertex beyond it is new.
    if (!(d < distance_[i]) || d > radius || !(d < nearest_[i] + slack)) return;
    if (state_[i] == kFar) {
      touched_.push_back(v); // first: a throw leaves nothing that the next march does not reset
      state_[i] = kTrial;
    }
    front.push({d, v});
    distance_[i] = d;
  };
  for (const auto& [v, d] : seeds) offer(v, d);
  std::vector<Accepted> out;
  const auto& begin = rings_.begin;
  const auto& ring = rings_.ring;
  while (!front.empty()) {
    const auto [d, v] = front.top();
    front.pop();
    const auto i = static_cast<std::size_t>(v);
    if (state_[i] == kAccepted || d > distance_[i]) continue; // a stale entry
    const bool fresh = nearest_[i] == kInf;
    if (fresh) stroke_touched_.push_back(v);
    out.push_back({v, d, fresh});
    state_[i] = kAccepted;
    nearest_[i] = std::min(nearest_[i], d);
    const Vec3& pv = points[i];
    for (std::uint32_t r = begin[i]; r < begin[i + 1]; ++r) {
      const auto p = static_cast<std::size_t>(ring[r][0]);
      const auto q = static_cast<std::size_t>(ring[r][1]);
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
      if (!q_done && q != p)
        offer(static_cast<int>(q),
              p_done ? std::min(d + vq, through_triangle(vp, vq, (points[q] - points[p]).norm(), d,
                                                         distance_[p]))
                     : d + vq);
    }
  }
  if (first && edges > 0) slack_ = 2.0 * edge_sum / static_cast<double>(edges);
  return out;
}

} // namespace remora
