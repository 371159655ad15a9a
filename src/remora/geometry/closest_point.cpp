#include "remora/geometry/closest_point.h"

#include <algorithm>
#include <array>
#include <limits>

namespace remora {
namespace {

// Doubled area over the longest squared edge (about the smallest angle, in radians): below
// kDegenerate the triangle is a segment to round-off (the computed normal is noise); below kThin
// the face candidate's error (of order |p - point| (1e-16 / ratio)^2) may exceed the edges' error
// (of order height^2 / |p - point|), so both are compared.
constexpr double kDegenerate = 1e-15;
constexpr double kThin = 1e-8;

TriangleClosest at_corner(const Vec3& p, const Vec3& corner, int index) {
  TriangleClosest result;
  result.point = corner;
  result.bary = {0.0, 0.0, 0.0};
  result.bary[static_cast<std::size_t>(index)] = 1.0;
  result.distance2 = (p - corner).sqrnorm();
  return result;
}

// The closest of the edges ab, bc, ca that `use` selects (by default all three).
TriangleClosest on_edges(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                         std::array<bool, 3> use = {true, true, true}) {
  TriangleClosest result;
  result.distance2 = std::numeric_limits<double>::infinity();
  if (use[0]) {
    const SegmentClosest ab = closest_point_on_segment(p, a, b);
    result = {ab.point, {1.0 - ab.t, ab.t, 0.0}, ab.distance2};
  }
  if (use[1]) {
    const SegmentClosest bc = closest_point_on_segment(p, b, c);
    if (bc.distance2 < result.distance2) result = {bc.point, {0.0, 1.0 - bc.t, bc.t}, bc.distance2};
  }
  if (use[2]) {
    const SegmentClosest ca = closest_point_on_segment(p, c, a);
    if (ca.distance2 < result.distance2) result = {ca.point, {ca.t, 0.0, 1.0 - ca.t}, ca.distance2};
  }
  return result;
}

} // namespace

SegmentClosest closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double length2 = ab.sqrnorm();
  double t = 0.0;
  if (length2 > 0.0) t = std::clamp(((p - a) | ab) / length2, 0.0, 1.0);
  // This form is exact at both ends (a + t ab need not give b at t = 1).
  const Vec3 point = a * (1.0 - t) + b * t;
  return {point, t, (p - point).sqrnorm()};
}

TriangleClosest closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                          const Vec3& c) {
  const Vec3 ab = b - a;
  const Vec3 bc = c - b;
  const Vec3 ca = a - c;
  const Vec3 ap = p - a;
  const Vec3 bp = p - b;
  const Vec3 cp = p - c;
  // Vertex regions: if p lies behind a corner along both of its edges, the corner is the closest
  // point of every triangle, degenerate or not; so these tests need no care.
  if ((ab | ap) <= 0.0 && (ca | ap) >= 0.0) return at_corner(p, a, 0);
  if ((bc | bp) <= 0.0 && (ab | bp) >= 0.0) return at_corner(p, b, 1);
  if ((ca | cp) <= 0.0 && (bc | cp) >= 0.0) return at_corner(p, c, 2);

  // The cross product of the two edges at the corner opposite the longest edge is the most
  // accurate normal; all three pairs are (b - a) x (c - a) in exact arithmetic.
  const double l_ab = ab.sqrnorm();
  const double l_bc = bc.sqrnorm();
  const double l_ca = ca.sqrnorm();
  Vec3 n;
  double longest = 0.0;
  if (l_ab >= l_bc && l_ab >= l_ca) {
    n = bc % ca;
    longest = l_ab;
  } else if (l_bc >= l_ca) {
    n = ab % (-ca);
    longest = l_bc;
  } else {
    n = bc % (-ab);
    longest = l_ca;
  }
  const double twice_area = n.norm();
  if (!(twice_area > kDegenerate * longest)) return on_edges(p, a, b, c);

  // Signed sub-areas of the projection of p against n (moving p along n leaves them unchanged).
  const double u = n | (bc % bp);
  const double v = n | (ca % cp);
  const double w = n | (ab % ap);
  const double sum = u + v + w;
  if (u >= 0.0 && v >= 0.0 && w >= 0.0 && sum > 0.0) {
    TriangleClosest face;
    face.bary = {u / sum, v / sum, w / sum};
    face.point = a * face.bary[0] + b * face.bary[1] + c * face.bary[2];
    face.distance2 = (p - face.point).sqrnorm();
    if (twice_area >= kThin * longest) return face;
    const TriangleClosest edges = on_edges(p, a, b, c);
    return edges.distance2 < face.distance2 ? edges : face;
  }
  // Outside: the closest point of a convex polygon lies on an edge whose line separates p from
  // it, i.e. one with a negative sub-area (u is opposite bc, v opposite ca, w opposite ab). Only
  // a well-shaped triangle's signs are trusted for this.
  const bool any = w < 0.0 || u < 0.0 || v < 0.0; // false only for a non-finite p
  if (any && twice_area >= kThin * longest)
    return on_edges(p, a, b, c, {w < 0.0, u < 0.0, v < 0.0});
  return on_edges(p, a, b, c);
}

bool plane_barycentrics(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                        std::array<double, 3>& bary) {
  const Vec3 ab = b - a, ac = c - a;
  const Vec3 n = OpenMesh::cross(ab, ac);
  const double nn = OpenMesh::dot(n, n);
  const double scale = ab.sqrnorm() + ac.sqrnorm();
  if (!(nn > 1e-24 * scale * scale)) return false;
  const Vec3 ap = p - a;
  // Signed sub-areas against the normal: the weight of b is the area of (a, p, c), of c (a, b, p).
  const double wb = OpenMesh::dot(OpenMesh::cross(ap, ac), n) / nn;
  const double wc = OpenMesh::dot(OpenMesh::cross(ab, ap), n) / nn;
  bary = {1.0 - wb - wc, wb, wc};
  return true;
}

} // namespace remora
