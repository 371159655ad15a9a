#include "remora/geometry/raycast.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <functional>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/mesh/surface_point.h"

namespace remora {

namespace {

constexpr std::int32_t kLeafSize = 4;
constexpr int kMaxDepth = 64;                 // median splits: depth <= log2(faces) + 1
constexpr std::int32_t kSplitFaces = 1 << 16; // below, one thread builds the tree

float down(double x) {
  const auto f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity())
                                    : f;
}

float up(double x) {
  const auto f = static_cast<float>(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

// Throws InvalidArgument unless origin and direction are finite, direction is not zero and
// t_min <= t_max.
void check_ray(const Vec3& origin, const Vec3& direction, double t_min, double t_max) {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(origin[k]) || !std::isfinite(direction[k]))
      throw InvalidArgument("ray caster: the ray's origin and direction must be finite");
  if (!(direction.sqrnorm() > 0.0))
    throw InvalidArgument("ray caster: the ray's direction is zero");
  if (!(t_min <= t_max))
    throw InvalidArgument(
        fmt::format("ray caster: t_min {} must not exceed t_max {}", t_min, t_max));
}

// origin + t direction, with the reciprocal of the direction (+-inf on an axis-parallel ray).
struct Ray {
  Ray(const Vec3& o, const Vec3& d) : origin(o), direction(d) {
    for (int k = 0; k < 3; ++k) inv[k] = 1.0 / direction[k];
  }

  /// Does the ray meet the box [lo, hi] within (t_min, t_max]?
  bool meets(const float lo[3], const float hi[3], double t_min, double t_max) const {
    double enter = t_min, leave = t_max;
    for (int k = 0; k < 3; ++k) {
      if (direction[k] == 0.0) {
        if (origin[k] < lo[k] || origin[k] > hi[k]) return false;
        continue;
      }
      double t0 = (lo[k] - origin[k]) * inv[k], t1 = (hi[k] - origin[k]) * inv[k];
      if (t0 > t1) std::swap(t0, t1);
      enter = std::max(enter, t0);
      leave = std::min(leave, t1);
      if (enter > leave) return false;
    }
    return true;
  }

  const Vec3& origin;
  const Vec3& direction;
  double inv[3];
};

// The axis along which the direction has its largest magnitude (the first of equal ones).
int dominant_axis(const Vec3& direction) {
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(direction[k]) > std::abs(direction[axis])) axis = k;
  return axis;
}

// Where a ray meets a triangle: origin + t direction = (1 - u - v) a + u b + v c.
struct TriangleHit {
  double t, u, v;
};

// Möller–Trumbore: false when the ray is parallel to the plane of (a, b, c) or misses the
// triangle by more than a relative 1e-12 on the barycentrics; any t is returned.
bool meet_triangle(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c, TriangleHit& out) {
  constexpr double kBaryTolerance = 1e-12;
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 p = OpenMesh::cross(ray.direction, ac);
  const double det = OpenMesh::dot(ab, p);
  if (det == 0.0) return false;
  const double inv_det = 1.0 / det;
  const Vec3 s = ray.origin - a;
  const double u = OpenMesh::dot(s, p) * inv_det;
  if (u < -kBaryTolerance || u > 1.0 + kBaryTolerance) return false;
  const Vec3 q = OpenMesh::cross(s, ab);
  const double v = OpenMesh::dot(ray.direction, q) * inv_det;
  if (v < -kBaryTolerance || u + v > 1.0 + kBaryTolerance) return false;
  out = {OpenMesh::dot(ac, q) * inv_det, u, v};
  return true;
}

} // namespace

RayCaster::RayCaster(const Mesh& mesh) {
  points_.resize(mesh.n_vertices());
  for (const VertexHandle v : mesh.vertices())
    points_[static_cast<std::size_t>(v.idx())] = mesh.point(v);
  std::vector<Vec3> centroids;
  faces_.reserve(mesh.n_faces());
  centroids.reserve(mesh.n_faces());
  for (const FaceHandle f : mesh.faces()) {
    const auto fv = face_vertices(mesh, f);
    const Vec3 a = mesh.point(fv[0]), b = mesh.point(fv[1]), c = mesh.point(fv[2]);
    for (const Vec3& p : {a, b, c})
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
        throw InvalidArgument(fmt::format(
            "ray caster: face {} has a corner that is not finite; repair the mesh first", f.idx()));
    const Vec3 ab = b - a, ac = c - a;
    // Zero-area faces are never met (a ray in their plane would meet them anywhere).
    const double longest2 = std::max({ab.sqrnorm(), ac.sqrnorm(), (c - b).sqrnorm()});
    if (!(OpenMesh::cross(ab, ac).sqrnorm() > 1e-30 * longest2 * longest2)) continue;
    faces_.push_back({{fv[0].idx(), fv[1].idx(), fv[2].idx()}, f.idx()});
    centroids.push_back((a + b + c) / 3.0);
  }
  if (faces_.empty()) return;
  std::vector<std::int32_t> order(faces_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::int32_t>(i);
  nodes_.reserve(2 * faces_.size() / kLeafSize + 1);
  build(nodes_, order, centroids, 0, static_cast<std::int32_t>(order.size()), true);
  std::vector<Face> sorted;
  sorted.reserve(faces_.size());
  for (const std::int32_t i : order) sorted.push_back(faces_[static_cast<std::size_t>(i)]);
  faces_ = std::move(sorted);
}

namespace {

/// The point of vertex `v` of `mesh`; throws InvalidArgument when it is not finite.
const Vec3& finite_point(const Mesh& mesh, int v) {
  const Vec3& p = mesh.point(VertexHandle(v));
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    throw InvalidArgument(
        fmt::format("ray caster: vertex {} is not finite; repair the mesh first", v));
  return p;
}

} // namespace

void RayCaster::refit_node(std::size_t i) {
  Node& n = nodes_[i];
  if (n.count == 0) {
    const Node& l = nodes_[i + 1];
    const Node& r = nodes_[static_cast<std::size_t>(n.first)];
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = std::min(l.lo[k], r.lo[k]);
      n.hi[k] = std::max(l.hi[k], r.hi[k]);
    }
    return;
  }
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::numeric_limits<double>::infinity();
    hi[k] = -std::numeric_limits<double>::infinity();
  }
  for (std::int32_t f = n.first; f < n.first + n.count; ++f)
    for (const std::int32_t v : faces_[static_cast<std::size_t>(f)].v)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], points_[static_cast<std::size_t>(v)][k]);
        hi[k] = std::max(hi[k], points_[static_cast<std::size_t>(v)][k]);
      }
  for (int k = 0; k < 3; ++k) {
    n.lo[k] = down(lo[k]);
    n.hi[k] = up(hi[k]);
  }
}

void RayCaster::refit(const Mesh& mesh) {
  if (mesh.n_vertices() != points_.size())
    throw InvalidArgument(fmt::format("ray caster: refit with {} vertices; the tree has {}",
                                      mesh.n_vertices(), points_.size()));
  for (std::size_t v = 0; v < points_.size(); ++v)
    points_[v] = finite_point(mesh, static_cast<int>(v));
  // Children come after their parent: from the last node back, every child is done first.
  for (std::size_t i = nodes_.size(); i-- > 0;) refit_node(i);
}

void RayCaster::index_for_partial_refit() {
  parent_.assign(nodes_.size(), -1);
  slot_leaf_.assign(faces_.size(), -1);
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const Node& n = nodes_[i];
    if (n.count == 0) {
      parent_[i + 1] = static_cast<std::int32_t>(i);
      parent_[static_cast<std::size_t>(n.first)] = static_cast<std::int32_t>(i);
    } else {
      for (std::int32_t f = n.first; f < n.first + n.count; ++f)
        slot_leaf_[static_cast<std::size_t>(f)] = static_cast<std::int32_t>(i);
    }
  }
  vertex_slots_begin_.assign(points_.size() + 1, 0);
  for (const Face& f : faces_)
    for (const std::int32_t v : f.v) ++vertex_slots_begin_[static_cast<std::size_t>(v) + 1];
  for (std::size_t v = 0; v < points_.size(); ++v)
    vertex_slots_begin_[v + 1] += vertex_slots_begin_[v];
  vertex_slots_.resize(static_cast<std::size_t>(vertex_slots_begin_.back()));
  std::vector<std::int32_t> fill(vertex_slots_begin_.begin(), vertex_slots_begin_.end() - 1);
  for (std::size_t slot = 0; slot < faces_.size(); ++slot)
    for (const std::int32_t v : faces_[slot].v)
      vertex_slots_[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] =
          static_cast<std::int32_t>(slot);
}

void RayCaster::refit(const Mesh& mesh, const std::vector<int>& moved) {
  if (mesh.n_vertices() != points_.size())
    throw InvalidArgument(fmt::format("ray caster: refit with {} vertices; the tree has {}",
                                      mesh.n_vertices(), points_.size()));
  if (parent_.size() != nodes_.size()) index_for_partial_refit();
  std::vector<std::int32_t> dirty;
  std::vector<char> marked(nodes_.size(), 0);
  for (const int v : moved) {
    if (v < 0 || static_cast<std::size_t>(v) >= points_.size())
      throw InvalidArgument(fmt::format("ray caster: moved vertex {} is out of range", v));
    points_[static_cast<std::size_t>(v)] = finite_point(mesh, v);
    for (std::int32_t s = vertex_slots_begin_[static_cast<std::size_t>(v)];
         s < vertex_slots_begin_[static_cast<std::size_t>(v) + 1]; ++s)
      for (std::int32_t node =
               slot_leaf_[static_cast<std::size_t>(vertex_slots_[static_cast<std::size_t>(s)])];
           node >= 0 && !marked[static_cast<std::size_t>(node)];
           node = parent_[static_cast<std::size_t>(node)]) {
        marked[static_cast<std::size_t>(node)] = 1;
        dirty.push_back(node);
      }
  }
  // Children have larger indices than their parents: the largest first.
  std::sort(dirty.begin(), dirty.end(), std::greater<>());
  for (const std::int32_t i : dirty) refit_node(static_cast<std::size_t>(i));
}

// Appends to `nodes` the subtree over order[begin, end) (indices into faces_ and centroids):
// leaves take their bounds from their faces, inner nodes the union of their children's, so every
// face is read once. With `split`, a large range builds its two halves on two threads.
void RayCaster::build(std::vector<Node>& nodes, std::vector<std::int32_t>& order,
                      const std::vector<Vec3>& centroids, std::int32_t begin, std::int32_t end,
                      bool split) const {
  const auto self = nodes.size();
  nodes.push_back({});
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::numeric_limits<double>::infinity();
    hi[k] = -std::numeric_limits<double>::infinity();
  }
  for (std::int32_t i = begin; i < end; ++i) {
    const Vec3& c = centroids[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], c[k]);
      hi[k] = std::max(hi[k], c[k]);
    }
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  if (end - begin <= kLeafSize || !(hi[axis] > lo[axis])) {
    Node& node = nodes[self];
    node.first = begin;
    node.count = end - begin;
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::numeric_limits<double>::infinity();
      hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (std::int32_t i = begin; i < end; ++i)
      for (const std::int32_t v :
           faces_[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])].v) {
        const Vec3& p = points_[static_cast<std::size_t>(v)];
        for (int k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], p[k]);
          hi[k] = std::max(hi[k], p[k]);
        }
      }
    for (int k = 0; k < 3; ++k) {
      node.lo[k] = down(lo[k]);
      node.hi[k] = up(hi[k]);
    }
    return;
  }
  // Median split by centroid along the widest axis of the centroids.
  const std::int32_t mid = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&](std::int32_t x, std::int32_t y) {
                     return centroids[static_cast<std::size_t>(x)][axis] <
                            centroids[static_cast<std::size_t>(y)][axis];
                   });
  std::size_t right = 0;
  if (split && end - begin > kSplitFaces) {
    // The halves' subtrees in two arrays (their right-child indices local), then spliced.
    std::vector<Node> halves[2];
#pragma omp parallel for num_threads(2)
    for (int h = 0; h < 2; ++h)
      build(halves[h], order, centroids, h == 0 ? begin : mid, h == 0 ? mid : end, false);
    right = self + 1 + halves[0].size();
    for (int h = 0; h < 2; ++h) {
      const auto offset = static_cast<std::int32_t>(h == 0 ? self + 1 : right);
      for (Node n : halves[h]) {
        if (n.count == 0) n.first += offset;
        nodes.push_back(n);
      }
    }
  } else {
    build(nodes, order, centroids, begin, mid, false);
    right = nodes.size();
    build(nodes, order, centroids, mid, end, false);
  }
  Node& inner = nodes[self]; // nodes may have grown
  const Node& l = nodes[self + 1];
  const Node& r = nodes[right];
  inner.first = static_cast<std::int32_t>(right);
  inner.count = 0;
  for (int k = 0; k < 3; ++k) {
    inner.lo[k] = std::min(l.lo[k], r.lo[k]);
    inner.hi[k] = std::max(l.hi[k], r.hi[k]);
  }
}

RayHit RayCaster::first_hit(const Vec3& origin, const Vec3& direction, double t_min, double t_max,
                            VertexHandle skip) const {
  check_ray(origin, direction, t_min, t_max);
  RayHit hit;
  if (nodes_.empty()) return hit;
  const Ray ray(origin, direction);
  const int axis = dominant_axis(direction);
  const int skipped = skip.is_valid() ? skip.idx() : -1;
  double best = t_max;

  std::int32_t stack[kMaxDepth];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[static_cast<std::size_t>(stack[--top])];
    if (!ray.meets(n.lo, n.hi, t_min, best)) continue;
    if (n.count == 0) {
      // Visit the child nearer along the ray first (pushed last).
      const auto left = static_cast<std::int32_t>(&n - nodes_.data()) + 1, right = n.first;
      const Node& l = nodes_[static_cast<std::size_t>(left)];
      const Node& r = nodes_[static_cast<std::size_t>(right)];
      const bool left_first =
          (direction[axis] >= 0) == (l.lo[axis] + l.hi[axis] <= r.lo[axis] + r.hi[axis]);
      assert(top + 2 <= kMaxDepth); // each level holds at most one pending sibling
      stack[top++] = left_first ? right : left;
      stack[top++] = left_first ? left : right;
      continue;
    }
    for (std::int32_t i = n.first; i < n.first + n.count; ++i) {
      const Face& f = faces_[static_cast<std::size_t>(i)];
      if (f.v[0] == skipped || f.v[1] == skipped || f.v[2] == skipped) continue;
      TriangleHit met{};
      if (!meet_triangle(ray, points_[static_cast<std::size_t>(f.v[0])],
                         points_[static_cast<std::size_t>(f.v[1])],
                         points_[static_cast<std::size_t>(f.v[2])], met))
        continue;
      if (!(met.t > t_min) || !(met.t <= best)) continue;
      best = met.t;
      hit.t = met.t;
      hit.face = FaceHandle(f.face);
      hit.bary = {1.0 - met.u - met.v, met.u, met.v};
    }
  }
  return hit;
}

} // namespace remora
