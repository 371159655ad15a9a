#include "remora/geometry/selection.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <utility>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/geometry/geodesic.h"

namespace remora {
namespace {

bool finite(const Vec3& p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

} // namespace

std::vector<int> select_sphere(const Mesh& mesh, const Vec3& center, double radius) {
  if (!finite(center)) throw InvalidArgument("select_sphere: the center is not finite");
  if (!(radius >= 0.0) || !std::isfinite(radius))
    throw InvalidArgument(
        fmt::format("select_sphere: the radius {} must be finite and >= 0", radius));
  std::vector<int> out;
  const double r2 = radius * radius;
  for (const VertexHandle v : mesh.vertices())
    if ((mesh.point(v) - center).sqrnorm() <= r2) out.push_back(v.idx());
  return out;
}

std::vector<int> select_box(const Mesh& mesh, const Vec3& min, const Vec3& max) {
  if (!finite(min) || !finite(max)) throw InvalidArgument("select_box: a corner is not finite");
  for (int c = 0; c < 3; ++c)
    if (min[c] > max[c])
      throw InvalidArgument(fmt::format(
          "select_box: min[{0}] = {1} exceeds max[{0}] = {2}; give the lower corner first", c,
          min[c], max[c]));
  std::vector<int> out;
  for (const VertexHandle v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    if (p[0] >= min[0] && p[1] >= min[1] && p[2] >= min[2] && p[0] <= max[0] && p[1] <= max[1] &&
        p[2] <= max[2])
      out.push_back(v.idx());
  }
  return out;
}

std::vector<int> geodesic_order(const Mesh& mesh, VertexHandle seed, std::size_t max_count,
                                double max_distance) {
  if (!seed.is_valid() || seed.idx() >= static_cast<int>(mesh.n_vertices()) ||
      mesh.status(seed).deleted())
    throw InvalidArgument(fmt::format("geodesic selection: vertex {} is not a vertex of the mesh "
                                      "(it has {} vertices)",
                                      seed.idx(), mesh.n_vertices()));
  std::vector<double> dist(mesh.n_vertices(), std::numeric_limits<double>::infinity());
  std::vector<char> done(mesh.n_vertices(), 0);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  dist[static_cast<std::size_t>(seed.idx())] = 0.0;
  queue.push({0.0, seed.idx()});
  std::vector<int> order;
  while (!queue.empty() && order.size() < max_count) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (done[static_cast<std::size_t>(i)]) continue;
    if (d > max_distance) break;
    done[static_cast<std::size_t>(i)] = 1;
    order.push_back(i);
    for (const HalfedgeHandle h : mesh.voh_range(VertexHandle(i))) {
      const auto w = static_cast<std::size_t>(mesh.to_vertex_handle(h).idx());
      const double nd = d + mesh.calc_edge_length(h);
      if (nd < dist[w]) {
        dist[w] = nd;
        queue.push({nd, static_cast<int>(w)});
      }
    }
  }
  return order;
}

VertexHandle nearest_vertex(const Mesh& mesh, const Vec3& point) {
  if (!finite(point)) throw InvalidArgument("nearest_vertex: the point is not finite");
  VertexHandle best;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (const VertexHandle v : mesh.vertices()) {
    const double d2 = (mesh.point(v) - point).sqrnorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = v;
    }
  }
  if (!best.is_valid()) throw InvalidArgument("nearest_vertex: the mesh has no vertices");
  return best;
}

VertexHandle central_vertex(const Mesh& mesh) {
  Vec3 centroid(0, 0, 0);
  std::size_t count = 0;
  for (const VertexHandle v : mesh.vertices()) {
    centroid += mesh.point(v);
    ++count;
  }
  if (count == 0) throw InvalidArgument("central_vertex: the mesh has no vertices");
  return nearest_vertex(mesh, centroid / double(count));
}

std::vector<int> select_geodesic_disc(const Mesh& mesh, VertexHandle seed, double radius) {
  std::vector<int> out;
  for (const auto& [v, d] : geodesic_ball(mesh, seed, radius)) out.push_back(v);
  std::sort(out.begin(), out.end());
  return out;
}

} // namespace remora
