#include "remora/geometry/measures.h"
#include "remora/geometry/per_face.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "remora/common/error.h"

namespace remora {
namespace {

std::array<Vec3, 3> face_points(const Mesh& mesh, FaceHandle f) {
  const HalfedgeHandle h0 = mesh.halfedge_handle(f);
  const HalfedgeHandle h1 = mesh.next_halfedge_handle(h0);
  const HalfedgeHandle h2 = mesh.next_halfedge_handle(h1);
  return {mesh.point(mesh.to_vertex_handle(h0)), mesh.point(mesh.to_vertex_handle(h1)),
          mesh.point(mesh.to_vertex_handle(h2))};
}

// to(h), to(next(h)), to(next(next(h))): the order of face_points() (surface_point.h's
// face_vertices() starts one corner earlier; these figures keep their own order, bit for bit).
std::array<VertexHandle, 3> halfedge_cycle_vertices(const Mesh& mesh, FaceHandle f) {
  const HalfedgeHandle h0 = mesh.halfedge_handle(f);
  const HalfedgeHandle h1 = mesh.next_halfedge_handle(h0);
  const HalfedgeHandle h2 = mesh.next_halfedge_handle(h1);
  return {mesh.to_vertex_handle(h0), mesh.to_vertex_handle(h1), mesh.to_vertex_handle(h2)};
}

double max_abs_component(const Vec3& v) {
  return std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
}

double corner_angle(const Vec3& u, const Vec3& v) {
  return std::atan2((u % v).norm(), u | v);
}

} // namespace

double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * ((b - a) % (c - a)).norm();
}

double face_area(const Mesh& mesh, FaceHandle f) {
  const std::array<Vec3, 3> p = face_points(mesh, f);
  return triangle_area(p[0], p[1], p[2]);
}

double surface_area(const Mesh& mesh) {
  double sum = 0.0;
  for (const FaceHandle f : mesh.faces()) sum += face_area(mesh, f);
  return sum;
}

std::array<double, 3> triangle_angles(const Vec3& a, const Vec3& b, const Vec3& c) {
  constexpr double pi = std::numbers::pi;
  Vec3 ab = b - a;
  Vec3 ac = c - a;
  Vec3 bc = c - b;
  const double largest =
      std::max({max_abs_component(ab), max_abs_component(ac), max_abs_component(bc)});
  if (largest == 0.0) return {0.0, 0.0, pi};
  // Scaling by a power of two is exact and brings the largest component into [0.5, 1), so squared
  // lengths, cross and dot products neither underflow nor overflow: the result is scale-invariant.
  int exponent = 0;
  std::frexp(largest, &exponent);
  const double scale = std::ldexp(1.0, -exponent);
  ab *= scale;
  ac *= scale;
  bc *= scale;
  // An edge whose squared length underflows is zero-length relative to the triangle. At most one
  // can be: the largest component bounds some edge's squared length from below by 1/4.
  if (ab.sqrnorm() == 0.0) return {pi / 2, pi / 2, 0.0};
  if (bc.sqrnorm() == 0.0) return {0.0, pi / 2, pi / 2};
  if (ac.sqrnorm() == 0.0) return {pi / 2, 0.0, pi / 2};
  return {corner_angle(ab, ac), corner_angle(-ab, bc), corner_angle(ac, bc)};
}

std::array<double, 3> triangle_mixed_areas(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e0 = c - b; // opposite a
  const Vec3 e1 = a - c; // opposite b
  const Vec3 e2 = b - a; // opposite c
  const double twice_area = (e2 % (c - a)).norm();
  if (!(twice_area > 0.0)) return {0.0, 0.0, 0.0};
  const double area = 0.5 * twice_area;
  // Corner dot products: cot of the corner's angle is d / twice_area, and d < 0 means obtuse.
  const double d0 = -(e1 | e2);
  const double d1 = -(e2 | e0);
  const double d2 = -(e0 | e1);
  if (d0 < 0.0) return {area / 2, area / 4, area / 4};
  if (d1 < 0.0) return {area / 4, area / 2, area / 4};
  if (d2 < 0.0) return {area / 4, area / 4, area / 2};
  const double l0 = e0.sqrnorm();
  const double l1 = e1.sqrnorm();
  const double l2 = e2.sqrnorm();
  const double denominator = 8.0 * twice_area;
  const auto part = [area, denominator](double value) {
    return std::clamp(value / denominator, 0.0, area);
  };
  return {part(l1 * d1 + l2 * d2), part(l2 * d2 + l0 * d0), part(l1 * d1 + l0 * d0)};
}

// The faces' parts are computed in parallel, then added up in face order: the same sums as one
// sequential loop, whatever the number of threads.
Eigen::VectorXd vertex_areas_barycentric(const Mesh& mesh) {
  const std::vector<double> thirds =
      per_face<double>(mesh, [&](FaceHandle f) { return face_area(mesh, f) / 3.0; });
  Eigen::VectorXd areas = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh.n_vertices()));
  for (const FaceHandle f : mesh.faces())
    for (const VertexHandle v : halfedge_cycle_vertices(mesh, f))
      areas[v.idx()] += thirds[static_cast<std::size_t>(f.idx())];
  return areas;
}

Eigen::VectorXd vertex_areas_mixed(const Mesh& mesh) {
  const auto parts = per_face<std::array<double, 3>>(mesh, [&](FaceHandle f) {
    const std::array<VertexHandle, 3> v = halfedge_cycle_vertices(mesh, f);
    return triangle_mixed_areas(mesh.point(v[0]), mesh.point(v[1]), mesh.point(v[2]));
  });
  Eigen::VectorXd areas = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh.n_vertices()));
  for (const FaceHandle f : mesh.faces()) {
    const std::array<VertexHandle, 3> v = halfedge_cycle_vertices(mesh, f);
    for (int i = 0; i < 3; ++i)
      areas[v[i].idx()] += parts[static_cast<std::size_t>(f.idx())][static_cast<std::size_t>(i)];
  }
  return areas;
}

double vertex_area_mixed(const Mesh& mesh, VertexHandle v) {
  thread_local std::vector<FaceHandle> faces;
  faces.clear();
  for (const FaceHandle f : mesh.vf_range(v)) faces.push_back(f);
  std::sort(faces.begin(), faces.end(),
            [](FaceHandle x, FaceHandle y) { return x.idx() < y.idx(); });
  double area = 0.0;
  for (const FaceHandle f : faces) {
    const std::array<VertexHandle, 3> c = halfedge_cycle_vertices(mesh, f);
    const std::array<double, 3> parts =
        triangle_mixed_areas(mesh.point(c[0]), mesh.point(c[1]), mesh.point(c[2]));
    for (std::size_t i = 0; i < 3; ++i)
      if (c[i] == v) area += parts[i];
  }
  return area;
}

BoundingBox bounding_box(const Mesh& mesh) {
  BoundingBox box;
  bool first = true;
  for (const VertexHandle v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    if (first) {
      box.min = p;
      box.max = p;
      first = false;
    } else {
      box.min.minimize(p);
      box.max.maximize(p);
    }
  }
  return box;
}

double bounding_box_diagonal(const Mesh& mesh) {
  return bounding_box(mesh).diagonal();
}

bool is_zero_area(double area, double bbox_diagonal) {
  return area <= kZeroAreaRelative * bbox_diagonal * bbox_diagonal;
}

double mean_edge_length(const Mesh& mesh) {
  double sum = 0.0;
  std::size_t n = 0;
  for (auto e : mesh.edges()) {
    sum += mesh.calc_edge_length(e);
    ++n;
  }
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

std::vector<char> feature_edges(const Mesh& mesh, double angle_deg) {
  if (!(angle_deg >= 0.0 && angle_deg < 180.0))
    throw InvalidArgument("feature_edges: the angle must be in [0, 180) degrees (got " +
                          std::to_string(angle_deg) + ")");
  const double cos_limit = std::cos(angle_deg * std::numbers::pi / 180.0);
  std::vector<char> sharp(mesh.n_edges(), 0);
  auto normal = [&mesh](FaceHandle f) {
    const auto p = face_points(mesh, f);
    return OpenMesh::cross(p[1] - p[0], p[2] - p[0]);
  };
  for (auto e : mesh.edges()) {
    if (mesh.is_boundary(e)) continue;
    const Vec3 n0 = normal(mesh.face_handle(mesh.halfedge_handle(e, 0)));
    const Vec3 n1 = normal(mesh.face_handle(mesh.halfedge_handle(e, 1)));
    const double lengths = n0.norm() * n1.norm();
    if (!(lengths > 0)) continue;
    sharp[static_cast<std::size_t>(e.idx())] = OpenMesh::dot(n0, n1) < cos_limit * lengths;
  }
  return sharp;
}

LengthScale length_scale(const Mesh& mesh) {
  LengthScale scale;
  scale.mean_edge = mean_edge_length(mesh);
  scale.length = scale.mean_edge;
  std::size_t used = 0;
  for (auto v : mesh.vertices())
    if (!mesh.is_isolated(v)) ++used;
  const double area = surface_area(mesh);
  if (used == 0 || !(area > 0.0)) return scale;
  scale.from_area = std::sqrt(2.0 * area / (std::sqrt(3.0) * static_cast<double>(used)));
  if (scale.from_area < 0.75 * scale.mean_edge) {
    scale.length = scale.from_area;
    scale.needles = true;
  }
  return scale;
}

} // namespace remora
