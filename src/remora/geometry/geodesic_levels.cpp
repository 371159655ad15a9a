#include "remora/geometry/geodesic_levels.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numeric>
#include <tuple>

#include "remora/common/error.h"
#include "remora/mesh/surface_point.h"

namespace remora {

namespace {

/// Union-find over vertex indices, with path halving.
int find(std::vector<int>& parent, int v) {
  while (parent[static_cast<std::size_t>(v)] != v) {
    auto& p = parent[static_cast<std::size_t>(v)];
    p = parent[static_cast<std::size_t>(p)];
    v = p;
  }
  return v;
}

std::array<int, 2> sorted(int a, int b) {
  return a < b ? std::array{a, b} : std::array{b, a};
}

template <class T>
void sort_unique(std::vector<T>& items) {
  std::sort(items.begin(), items.end());
  items.erase(std::unique(items.begin(), items.end()), items.end());
}

/// A CSR list of items per group: group g's are items[begin[g] .. begin[g + 1]).
struct Groups {
  std::vector<std::uint32_t> begin;
  std::vector<int> items;
};

/// Groups (item, group) pairs, items in increasing order within a group.
Groups group(std::size_t groups, const std::vector<std::pair<int, int>>& pairs) {
  Groups out;
  out.begin.assign(groups + 1, 0);
  for (const auto& [item, g] : pairs) ++out.begin[static_cast<std::size_t>(g) + 1];
  for (std::size_t g = 0; g < groups; ++g) out.begin[g + 1] += out.begin[g];
  out.items.resize(pairs.size());
  std::vector<std::uint32_t> fill(out.begin.begin(), out.begin.end() - 1);
  for (const auto& [item, g] : pairs) out.items[fill[static_cast<std::size_t>(g)]++] = item;
  return out;
}

/// Every vertex's cluster (numbered from 0), and the number of clusters: the vertices of one
/// cell that the edges inside it connect.
std::pair<std::vector<int>, int>
cluster_vertices(const Mesh& mesh, const std::vector<std::array<int, 3>>& faces, double cell) {
  const std::size_t n = mesh.n_vertices();
  const Vec3* p = mesh.points();
  const auto finite = [&](std::size_t v) {
    return std::isfinite(p[v][0]) && std::isfinite(p[v][1]) && std::isfinite(p[v][2]);
  };
  // The cells of the faces' corners with finite coordinates, from their bounding box's corner;
  // any other vertex is a cluster of its own.
  std::vector<char> placed(n, 0);
  Vec3 low(std::numeric_limits<double>::infinity());
  for (const auto& f : faces)
    for (const int v : f)
      if (finite(static_cast<std::size_t>(v)))
        placed[static_cast<std::size_t>(v)] = 1, low.minimize(p[v]);
  std::vector<std::array<std::int64_t, 3>> cell_of(n);
  for (std::size_t v = 0; v < n; ++v)
    for (std::size_t k = 0; k < 3 && placed[v]; ++k) // at most 2^62 cells: no overflow
      cell_of[v][k] = static_cast<std::int64_t>(std::min(
          std::floor((p[v][static_cast<int>(k)] - low[static_cast<int>(k)]) / cell), 0x1p62));
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& f : faces)
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      if (!placed[static_cast<std::size_t>(a)] || !placed[static_cast<std::size_t>(b)] ||
          cell_of[static_cast<std::size_t>(a)] != cell_of[static_cast<std::size_t>(b)])
        continue;
      const int ra = find(parent, a), rb = find(parent, b);
      if (ra != rb) parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
    }
  // A set's root is its smallest vertex, so it is numbered before the others.
  std::vector<int> cluster_of(n, -1);
  int clusters = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const int root = find(parent, static_cast<int>(v));
    cluster_of[v] =
        root == static_cast<int>(v) ? clusters++ : cluster_of[static_cast<std::size_t>(root)];
  }
  return {std::move(cluster_of), clusters};
}

/// The clusters' rings. Two clusters are adjacent where an edge joins them; every triangle of
/// that graph (three clusters pairwise adjacent) is a coarse triangle: where four clusters meet,
/// both diagonals of their quadrilateral, so the front has updates in more directions than the
/// fine triangles alone give. An edge on no triangle stays a lone edge.
MarchRings cluster_rings(const std::vector<std::array<int, 3>>& faces,
                         const std::vector<int>& cluster_of, int clusters) {
  std::vector<std::array<int, 2>> edges;
  for (const auto& f : faces)
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = cluster_of[static_cast<std::size_t>(f[k])];
      const int b = cluster_of[static_cast<std::size_t>(f[(k + 1) % 3])];
      if (a != b) edges.push_back(sorted(a, b));
    }
  sort_unique(edges);
  // edges is sorted: cluster a's larger neighbours are edges[first[a] .. first[a + 1]), in order.
  std::vector<std::uint32_t> first(static_cast<std::size_t>(clusters) + 1, 0);
  for (const auto& e : edges) ++first[static_cast<std::size_t>(e[0]) + 1];
  for (std::size_t c = 0; c < static_cast<std::size_t>(clusters); ++c) first[c + 1] += first[c];
  std::vector<std::array<int, 3>> triangles;
  std::vector<char> on_triangle(edges.size(), 0);
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto [a, b] = edges[e];
    std::size_t i = first[static_cast<std::size_t>(a)], j = first[static_cast<std::size_t>(b)];
    const std::size_t i_end = first[static_cast<std::size_t>(a) + 1],
                      j_end = first[static_cast<std::size_t>(b) + 1];
    while (i < i_end && j < j_end) { // each c > b adjacent to both a and b
      if (edges[i][1] <= b || edges[i][1] < edges[j][1]) {
        ++i;
      } else if (edges[j][1] < edges[i][1]) {
        ++j;
      } else {
        triangles.push_back({a, b, edges[i][1]});
        on_triangle[e] = on_triangle[i] = on_triangle[j] = 1;
        ++i, ++j;
      }
    }
  }
  std::vector<std::array<int, 2>> lone;
  for (std::size_t e = 0; e < edges.size(); ++e)
    if (!on_triangle[e]) lone.push_back(edges[e]);
  return march_rings(static_cast<std::size_t>(clusters), triangles, lone);
}

} // namespace

CoarseLevel::CoarseLevel(const Mesh& mesh,
                         std::shared_ptr<const std::vector<std::array<int, 3>>> faces, double cell)
    : cell_(cell), faces_(std::move(faces)), reported_(mesh.n_vertices(), 0) {
  if (!(cell > 0.0) || !std::isfinite(cell))
    throw InvalidArgument("geodesic levels: the cell size must be finite and > 0");
  const auto& fine = *faces_;
  int clusters = 0;
  std::tie(cluster_of_, clusters) = cluster_vertices(mesh, fine, cell);
  const auto n = static_cast<std::size_t>(clusters);
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(cluster_of_.size());
  for (std::size_t v = 0; v < cluster_of_.size(); ++v)
    pairs.emplace_back(static_cast<int>(v), cluster_of_[v]);
  Groups members = group(n, pairs);
  member_begin_ = std::move(members.begin);
  members_ = std::move(members.items);
  pairs.clear();
  for (std::size_t f = 0; f < fine.size(); ++f) {
    std::array<int, 3> c{};
    for (std::size_t k = 0; k < 3; ++k) c[k] = cluster_of_[static_cast<std::size_t>(fine[f][k])];
    pairs.emplace_back(static_cast<int>(f), c[0]);
    if (c[1] != c[0]) pairs.emplace_back(static_cast<int>(f), c[1]);
    if (c[2] != c[0] && c[2] != c[1]) pairs.emplace_back(static_cast<int>(f), c[2]);
  }
  Groups around = group(n, pairs);
  face_begin_ = std::move(around.begin);
  cluster_faces_ = std::move(around.items);
  marcher_ = Marcher(cluster_rings(fine, cluster_of_, clusters));
  points_.resize(n);
  normals_.resize(n);
  deviations_.resize(n);
  dirty_flag_.assign(n, 0);
  unreported_.resize(n);
  for (std::size_t c = 0; c < n; ++c) unreported_[c] = member_begin_[c + 1] - member_begin_[c];
  positions_changed(); // read at the first stroke
}

void CoarseLevel::positions_changed() {
  all_dirty_ = true;
}

void CoarseLevel::positions_changed(const std::vector<int>& vertices) {
  if (all_dirty_) return;
  for (const int v : vertices) {
    const auto c = static_cast<std::size_t>(cluster_of_[static_cast<std::size_t>(v)]);
    if (!dirty_flag_[c]) dirty_flag_[c] = 1, dirty_.push_back(static_cast<int>(c));
  }
}

void CoarseLevel::read_cluster(const Vec3* p, std::size_t c) {
  Vec3 sum(0.0);
  for (std::uint32_t m = member_begin_[c]; m < member_begin_[c + 1]; ++m)
    sum += p[static_cast<std::size_t>(members_[m])];
  points_[c] = sum / static_cast<double>(member_begin_[c + 1] - member_begin_[c]);
  double deviation = 0.0;
  for (std::uint32_t m = member_begin_[c]; m < member_begin_[c + 1]; ++m)
    deviation = std::max(deviation, (p[static_cast<std::size_t>(members_[m])] - points_[c]).norm());
  deviations_[c] = deviation;
  // The normal: the sum of the area vectors of the faces with a corner in the cluster.
  Vec3 normal(0.0);
  for (std::uint32_t i = face_begin_[c]; i < face_begin_[c + 1]; ++i) {
    const auto& f = (*faces_)[static_cast<std::size_t>(cluster_faces_[i])];
    const Vec3& a = p[static_cast<std::size_t>(f[0])];
    normal += OpenMesh::cross(p[static_cast<std::size_t>(f[1])] - a,
                              p[static_cast<std::size_t>(f[2])] - a);
  }
  const double length = normal.norm();
  normals_[c] = length > 0.0 ? Vec3(normal / length) : Vec3(0.0);
}

void CoarseLevel::read_positions(const Mesh& mesh) {
  const Vec3* p = mesh.points();
  if (all_dirty_) {
    for (std::size_t c = 0; c < points_.size(); ++c) read_cluster(p, c);
  } else {
    for (const int c : dirty_) read_cluster(p, static_cast<std::size_t>(c));
  }
  for (const int c : dirty_) dirty_flag_[static_cast<std::size_t>(c)] = 0;
  dirty_.clear();
  all_dirty_ = false;
  deviation_ =
      deviations_.empty() ? 0.0 : *std::max_element(deviations_.begin(), deviations_.end());
}

void CoarseLevel::start_stroke() {
  marcher_.start_stroke();
  for (const int v : reported_list_) {
    reported_[static_cast<std::size_t>(v)] = 0;
    const auto c = static_cast<std::size_t>(cluster_of_[static_cast<std::size_t>(v)]);
    unreported_[c] = member_begin_[c + 1] - member_begin_[c];
  }
  reported_list_.clear();
  stroke_started_ = false;
}

std::vector<std::pair<int, double>> CoarseLevel::stroke_ball(const Mesh& mesh, const Vec3& source,
                                                             const std::array<int, 3>& corners,
                                                             double radius) {
  if (!stroke_started_ && (all_dirty_ || !dirty_.empty())) {
    read_positions(mesh);
    // The vertices moved so far that a cluster spreads over several cells (clustered at rest, a
    // cluster's points are within a cell's diagonal of its mean): cluster them again.
    if (deviation_ > 2.0 * cell_) {
      auto faces = faces_;
      *this = CoarseLevel(mesh, std::move(faces), cell_);
      read_positions(mesh);
    }
  }
  stroke_started_ = true;
  // The clusters of the face's corners and their neighbours start at their straight-line
  // distance: starting from the corners' clusters alone, the front would go through their mean
  // points, up to a cell out of the way.
  std::vector<std::pair<int, double>> seeds;
  const MarchRings& rings = marcher_.rings();
  const auto seed = [&](int c) {
    seeds.emplace_back(c, (points_[static_cast<std::size_t>(c)] - source).norm());
  };
  for (const int v : corners) {
    const auto c = static_cast<std::size_t>(cluster_of_[static_cast<std::size_t>(v)]);
    seed(static_cast<int>(c));
    for (std::uint32_t r = rings.begin[c]; r < rings.begin[c + 1]; ++r)
      for (const int n : rings.ring[r]) seed(n);
  }
  // A vertex is within deviation_ of its cluster's point, so its distance is within deviation_
  // of the cluster's: march that much farther, and let the stroke go on where an earlier source
  // is nearer by up to twice that (the two corrections of one vertex differ by at most that).
  const auto accepted =
      marcher_.march(points_.data(), seeds, radius + deviation_, 2.0 * deviation_);
  const Vec3* p = mesh.points();
  std::vector<std::pair<int, double>> out;
  for (const Accepted& a : accepted) {
    const auto c = static_cast<std::size_t>(a.vertex);
    if (unreported_[c] == 0) continue; // inside what the stroke painted: nothing new
    const Vec3 n = normals_[c];
    const auto in_plane = [&](const Vec3& x) { return (x - OpenMesh::dot(n, x) * n).norm(); };
    const double base = a.distance - in_plane(points_[c] - source);
    for (std::uint32_t m = member_begin_[c]; m < member_begin_[c + 1]; ++m) {
      const auto v = static_cast<std::size_t>(members_[m]);
      if (reported_[v]) continue;
      const double d = base + in_plane(p[v] - source);
      if (!(d <= radius)) continue;
      reported_list_.push_back(members_[m]); // first: start_stroke() resets what it lists
      out.emplace_back(members_[m], std::max(d, 0.0));
      reported_[v] = 1;
      --unreported_[c];
    }
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return a.second < b.second || (a.second == b.second && a.first < b.first);
  });
  return out;
}

} // namespace remora
