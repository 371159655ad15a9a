// Exact closest points on a segment and on a triangle in 3D: the building block of the local
// surface search (locate.h) that projects remeshed vertices back onto the input (paper §4).
// Inputs must be finite, with coordinate differences whose squares neither overflow nor underflow
// (roughly 1e-150 < |x| < 1e150); for such inputs no result is NaN or Inf. Thread-safe (pure).
#pragma once

#include <array>

#include "remora/mesh/mesh.h"

namespace remora {

/// The closest point on the segment [a, b]: point = (1 - t) a + t b with t in [0, 1] (exactly a
/// at t = 0, exactly b at t = 1), distance2 = |p - point|^2. A zero-length segment gives t = 0.
struct SegmentClosest {
  Vec3 point{0.0, 0.0, 0.0};
  double t = 0.0;
  double distance2 = 0.0;
};

SegmentClosest closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b);

/// The closest point on the (closed, filled) triangle (a, b, c): point = bary[0] a + bary[1] b +
/// bary[2] c with every bary >= 0 and their sum 1 to round-off; distance2 = |p - point|^2.
struct TriangleClosest {
  Vec3 point{0.0, 0.0, 0.0};
  std::array<double, 3> bary{1.0, 0.0, 0.0};
  double distance2 = 0.0;
};

/// Ericson, "Real-Time Collision Detection", §5.1.5: the vertex regions are decided by his dot
/// product tests; otherwise, if the orthogonal projection of p onto the triangle's plane lies in
/// the triangle, it is the answer, else the nearest of the closest points on the three edges.
/// The face region is tested with the normal of the two shortest edges and signed sub-areas, which
/// stays well defined for needles where Ericson's Gram-determinant form cancels catastrophically.
/// Degenerate triangles (doubled area <= 1e-15 (longest edge)^2: collinear or coincident corners)
/// skip the face region: the answer is the nearest point over the three edges taken as segments,
/// with the matching bary (0 on the unused corner). Thin triangles (doubled area below 1e-8
/// (longest edge)^2, where the computed normal carries a relative error of ~1e-16 / (that ratio))
/// also compare the face candidate with the edges and keep the nearer, so the distance stays
/// accurate to about 1e-16 |p - point| even for needles.
TriangleClosest closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                          const Vec3& c);

/// Barycentric coordinates (summing to 1) of the orthogonal projection of p onto the plane of
/// (a, b, c): all >= 0 when it falls in the triangle, the most negative one names the edge it
/// falls beyond (the edge opposite that corner). A few dot products, for walks that step across
/// edges; false (bary untouched) for a triangle whose doubled area is <= 1e-12 (sum of its two
/// edges from a, squared).
bool plane_barycentrics(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                        std::array<double, 3>& bary);

} // namespace remora
