// Step 3 of the soup repair: polygons with more than three corners become triangles.
#include <cmath>
#include <limits>
#include <numeric>

#include "remora/mesh/repair_detail.h"

namespace remora::repair_detail {

void triangulate_polygon(const std::vector<Vec3>& pts, const std::vector<std::uint32_t>& poly,
                         std::vector<Tri>& out) {
  const std::size_t n = poly.size();
  if (n == 3) {
    out.push_back({poly[0], poly[1], poly[2]});
    return;
  }
  Vec3 normal(0, 0, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& a = pts[poly[i]];
    const Vec3& b = pts[poly[(i + 1) % n]];
    normal[0] += (a[1] - b[1]) * (a[2] + b[2]);
    normal[1] += (a[2] - b[2]) * (a[0] + b[0]);
    normal[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  // Drop the dominant axis of the normal; the 2D polygon then has the sign of that component.
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(normal[k]) > std::abs(normal[axis])) axis = k;
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double sign = normal[axis] >= 0 ? 1.0 : -1.0;
  std::vector<std::array<double, 2>> p2(n);
  for (std::size_t i = 0; i < n; ++i) p2[i] = {pts[poly[i]][u], sign * pts[poly[i]][v]};

  auto cross = [&](std::size_t a, std::size_t b, std::size_t c) {
    return (p2[b][0] - p2[a][0]) * (p2[c][1] - p2[a][1]) -
           (p2[b][1] - p2[a][1]) * (p2[c][0] - p2[a][0]);
  };
  std::vector<std::size_t> ring(n);
  std::iota(ring.begin(), ring.end(), std::size_t{0});
  while (ring.size() > 3) {
    const std::size_t m = ring.size();
    std::size_t best = m; // index in ring of the ear to clip
    double best_fallback = -std::numeric_limits<double>::infinity();
    std::size_t fallback = 0;
    for (std::size_t i = 0; i < m && best == m; ++i) {
      const std::size_t a = ring[(i + m - 1) % m], b = ring[i], c = ring[(i + 1) % m];
      const double turn = cross(a, b, c);
      if (turn > best_fallback) {
        best_fallback = turn;
        fallback = i;
      }
      if (turn <= 0) continue; // reflex or flat corner
      bool empty = true;
      for (std::size_t j = 0; j < m && empty; ++j) {
        const std::size_t q = ring[j];
        if (q == a || q == b || q == c) continue;
        if (cross(a, b, q) >= 0 && cross(b, c, q) >= 0 && cross(c, a, q) >= 0) empty = false;
      }
      if (empty) best = i;
    }
    if (best == m) best = fallback;
    const std::size_t a = ring[(best + m - 1) % m], b = ring[best], c = ring[(best + 1) % m];
    out.push_back({poly[a], poly[b], poly[c]});
    ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(best));
  }
  out.push_back({poly[ring[0]], poly[ring[1]], poly[ring[2]]});
}

} // namespace remora::repair_detail
