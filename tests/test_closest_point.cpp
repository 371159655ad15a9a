// Closest points on segments and triangles against hand-computed answers, an independent textbook
// implementation and dense sampling (also for needles and degenerate triangles), and the plane
// projection's barycentrics. The walks on meshes: test_locate.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "remora/geometry/closest_point.h"
#include "remora/geometry/measures.h"
#include "support.h"

namespace remora {
namespace {

using testing::random_offset;
using testing::random_vector;
using testing::unit;

/// The smallest distance from p to the points of a 200 x 200 barycentric grid on the triangle.
double sampled_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const int n = 200;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const double u = static_cast<double>(i) / n;
      const double v = static_cast<double>(j) / n;
      const Vec3 s = a * (1.0 - u - v) + b * u + c * v;
      best = std::min(best, (p - s).sqrnorm());
    }
  }
  return std::sqrt(best);
}

double longest_edge(const Vec3& a, const Vec3& b, const Vec3& c) {
  return std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
}

/// The textbook form of Ericson's Voronoi-region method (Real-Time Collision Detection, §5.1.5),
/// written independently as a reference for well-shaped triangles.
Vec3 ericson_reference(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 ap = p - a;
  const double d1 = ab | ap;
  const double d2 = ac | ap;
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab | bp;
  const double d4 = ac | bp;
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab | cp;
  const double d6 = ac | cp;
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double denominator = va + vb + vc;
  return a + ab * (vb / denominator) + ac * (vc / denominator);
}

/// The invariants every result must satisfy: finite, bary >= 0 summing to 1 and reproducing the
/// point, distance2 = |p - point|^2.
void expect_valid(const TriangleClosest& r, const Vec3& p, const Vec3& a, const Vec3& b,
                  const Vec3& c) {
  const double scale = std::max({longest_edge(a, b, c), (p - a).norm(), 1e-300});
  for (const double w : r.bary) {
    EXPECT_TRUE(std::isfinite(w));
    EXPECT_GE(w, 0.0);
  }
  EXPECT_NEAR(r.bary[0] + r.bary[1] + r.bary[2], 1.0, 1e-15);
  EXPECT_TRUE(std::isfinite(r.distance2));
  const Vec3 from_bary = a * r.bary[0] + b * r.bary[1] + c * r.bary[2];
  EXPECT_LE((from_bary - r.point).norm(), 1e-15 * scale);
  EXPECT_NEAR(r.distance2, (p - r.point).sqrnorm(), 1e-15 * scale * scale);
}

/// Exact distance never worse than any sample (to round-off), and no better than the nearest
/// sample can be off (the samples are within one grid cell, longest / 200, of every point).
void expect_matches_sampling(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const TriangleClosest r = closest_point_on_triangle(p, a, b, c);
  expect_valid(r, p, a, b, c);
  const double exact = std::sqrt(r.distance2);
  const double sampled = sampled_distance(p, a, b, c);
  EXPECT_LE(exact, sampled + 1e-12);
  EXPECT_GE(exact, sampled - longest_edge(a, b, c) / 200.0 - 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Closest point on a segment and on a triangle

TEST(ClosestPointSegment, ProjectsAndClampsExactly) {
  const Vec3 a(1, 2, 3);
  const Vec3 b(5, 2, 3);
  const SegmentClosest inside = closest_point_on_segment(Vec3(2, 7, 3), a, b);
  EXPECT_EQ(inside.t, 0.25);
  EXPECT_EQ(inside.point, Vec3(2, 2, 3));
  EXPECT_EQ(inside.distance2, 25.0);
  const SegmentClosest before = closest_point_on_segment(Vec3(-4, 0, 0), a, b);
  EXPECT_EQ(before.t, 0.0);
  EXPECT_EQ(before.point, a);
  const SegmentClosest after = closest_point_on_segment(Vec3(9, 1, 1), a, b);
  EXPECT_EQ(after.t, 1.0);
  EXPECT_EQ(after.point, b);
  const SegmentClosest zero = closest_point_on_segment(Vec3(0, 0, 0), a, a);
  EXPECT_EQ(zero.t, 0.0);
  EXPECT_EQ(zero.point, a);
  EXPECT_EQ(zero.distance2, 14.0);
}

TEST(ClosestPointTriangle, HandComputedRegions) {
  const Vec3 a(0, 0, 0);
  const Vec3 b(2, 0, 0);
  const Vec3 c(0, 2, 0);
  const TriangleClosest face = closest_point_on_triangle(Vec3(0.5, 0.5, 3), a, b, c);
  EXPECT_NEAR((face.point - Vec3(0.5, 0.5, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(face.bary[0], 0.5, 1e-15);
  EXPECT_NEAR(face.bary[1], 0.25, 1e-15);
  EXPECT_NEAR(face.bary[2], 0.25, 1e-15);
  EXPECT_NEAR(face.distance2, 9.0, 1e-14);

  const TriangleClosest corner = closest_point_on_triangle(Vec3(-1, -1, 1), a, b, c);
  EXPECT_EQ(corner.point, a);
  EXPECT_EQ(corner.bary, (std::array<double, 3>{1, 0, 0}));
  EXPECT_EQ(corner.distance2, 3.0);
  EXPECT_EQ(closest_point_on_triangle(Vec3(3, -1, 0), a, b, c).bary,
            (std::array<double, 3>{0, 1, 0}));
  EXPECT_EQ(closest_point_on_triangle(Vec3(-1, 5, 2), a, b, c).bary,
            (std::array<double, 3>{0, 0, 1}));

  const TriangleClosest ab = closest_point_on_triangle(Vec3(1, -1, 0), a, b, c);
  EXPECT_EQ(ab.point, Vec3(1, 0, 0));
  EXPECT_EQ(ab.bary, (std::array<double, 3>{0.5, 0.5, 0}));
  const TriangleClosest bc = closest_point_on_triangle(Vec3(2, 2, -1), a, b, c);
  EXPECT_EQ(bc.point, Vec3(1, 1, 0));
  EXPECT_EQ(bc.bary, (std::array<double, 3>{0, 0.5, 0.5}));
  EXPECT_EQ(bc.distance2, 3.0);
  const TriangleClosest ca = closest_point_on_triangle(Vec3(-3, 1.5, 0), a, b, c);
  EXPECT_EQ(ca.point, Vec3(0, 1.5, 0));
  EXPECT_EQ(ca.bary, (std::array<double, 3>{0.25, 0, 0.75}));
}

TEST(ClosestPointTriangle, AgreesWithTheTextbookMethodOnRandomTriangles) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec3 a = random_vector(rng, 1.0);
    const Vec3 b = random_vector(rng, 1.0);
    const Vec3 c = random_vector(rng, 1.0);
    const Vec3 p = random_vector(rng, 2.0);
    // Well-shaped enough for the textbook form to be accurate.
    if (triangle_area(a, b, c) < 0.05 * longest_edge(a, b, c) * longest_edge(a, b, c)) continue;
    const TriangleClosest r = closest_point_on_triangle(p, a, b, c);
    expect_valid(r, p, a, b, c);
    EXPECT_LE((r.point - ericson_reference(p, a, b, c)).norm(), 1e-13) << trial;
  }
}

TEST(ClosestPointTriangle, NeverFartherThanDenseSamplingOnRandomTriangles) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 12; ++trial) {
    const Vec3 a = random_vector(rng, 1.0);
    const Vec3 b = random_vector(rng, 1.0);
    const Vec3 c = random_vector(rng, 1.0);
    for (int k = 0; k < 4; ++k) {
      SCOPED_TRACE(::testing::Message() << "trial " << trial << " point " << k);
      expect_matches_sampling(random_vector(rng, 1.5), a, b, c);
    }
  }
}

TEST(ClosestPointTriangle, PointsOnTheTriangleAreTheirOwnClosestPoint) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3 a = random_vector(rng, 1.0);
    const Vec3 b = random_vector(rng, 1.0);
    const Vec3 c = random_vector(rng, 1.0);
    const double u = unit(rng);
    const double v = (1.0 - u) * unit(rng);
    const Vec3 p = a * (1.0 - u - v) + b * u + c * v;
    const TriangleClosest r = closest_point_on_triangle(p, a, b, c);
    EXPECT_LE(std::sqrt(r.distance2), 1e-14) << trial;
  }
}

/// Triangles of zero or nearly zero area, in random orientations: a needle of height 1e-9 with the
/// apex over the middle and one at an end, collinear corners in both orders, two coincident
/// corners (each pair) and three.
std::vector<std::array<Vec3, 3>> degenerate_triangles(std::mt19937& rng) {
  std::vector<std::array<Vec3, 3>> flat = {
      {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1e-9, 0)},
      {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1e-9, 0)},
      {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2.5, 0, 0)},
      {Vec3(0, 0, 0), Vec3(2.5, 0, 0), Vec3(1, 0, 0)},
      {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(1, 0.3, 0)},
      {Vec3(1, 0.3, 0), Vec3(0, 0, 0), Vec3(0, 0, 0)},
      {Vec3(0, 0, 0), Vec3(1, 0.3, 0), Vec3(0, 0, 0)},
      {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 0, 0)},
  };
  std::vector<std::array<Vec3, 3>> result;
  for (const auto& t : flat) {
    // As given, then rotated about a random axis and moved off the origin.
    result.push_back(t);
    const Vec3 k = random_offset(rng, 1.0).normalized();
    const double angle = 3.0 * unit(rng);
    const Vec3 shift = random_vector(rng, 1.0);
    std::array<Vec3, 3> moved;
    for (std::size_t i = 0; i < 3; ++i) {
      const Vec3& p = t[i];
      moved[i] = p * std::cos(angle) + (k % p) * std::sin(angle) +
                 k * ((k | p) * (1.0 - std::cos(angle))) + shift;
    }
    result.push_back(moved);
  }
  return result;
}

TEST(ClosestPointTriangle, DegenerateTrianglesMatchDenseSampling) {
  std::mt19937 rng(13);
  const auto triangles = degenerate_triangles(rng);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& [a, b, c] = triangles[t];
    const Vec3 centre = (a + b + c) / 3.0;
    for (int k = 0; k < 6; ++k) {
      SCOPED_TRACE(::testing::Message() << "triangle " << t << " point " << k);
      // Half the points close to the triangle, where the needle's width matters.
      const double reach = k % 2 == 0 ? 1.5 : 1e-8;
      expect_matches_sampling(centre + random_vector(rng, reach), a, b, c);
    }
  }
}

TEST(ClosestPointTriangle, DegenerateTrianglesAreTheirEdges) {
  std::mt19937 rng(17);
  const auto triangles = degenerate_triangles(rng);
  for (std::size_t t = 2; t < triangles.size(); ++t) { // the zero-area ones
    const auto& [a, b, c] = triangles[t];
    for (int k = 0; k < 50; ++k) {
      const Vec3 p = (a + b + c) / 3.0 + random_vector(rng, 2.0);
      const TriangleClosest r = closest_point_on_triangle(p, a, b, c);
      expect_valid(r, p, a, b, c);
      const double edges = std::min({closest_point_on_segment(p, a, b).distance2,
                                     closest_point_on_segment(p, b, c).distance2,
                                     closest_point_on_segment(p, c, a).distance2});
      EXPECT_NEAR(r.distance2, edges, 1e-15 * (1.0 + edges)) << t << " " << k;
      EXPECT_TRUE(r.bary[0] == 0.0 || r.bary[1] == 0.0 || r.bary[2] == 0.0);
    }
  }
  // Three coincident corners: the corner itself.
  const Vec3 q(0.3, -0.2, 0.9);
  const TriangleClosest point = closest_point_on_triangle(Vec3(1, 2, 3), q, q, q);
  EXPECT_EQ(point.point, q);
  EXPECT_EQ(point.bary, (std::array<double, 3>{1, 0, 0}));
}

TEST(ClosestPointTriangle, NeedlesKeepFullAccuracyAboveTheirFace) {
  // Needles 1e-4 to 1e-14 high in random orientations, p above a point `foot` of the long edge:
  // the distance is at most |p - foot| (the textbook form above is off by up to 0.4 here).
  std::mt19937 rng(19);
  for (int k = 0; k < 20000; ++k) {
    const Vec3 axis = random_offset(rng, 1.0).normalized();
    const Vec3 across = (axis % Vec3(0.3, 0.9, 0.1)).normalized();
    const Vec3 normal = axis % across;
    const double height = std::pow(10.0, -4.0 - 10.0 * unit(rng));
    const Vec3 a(0.1, 0.2, 0.3);
    const Vec3 b = a + axis;
    const Vec3 c = a + axis * unit(rng) + across * height;
    const Vec3 foot = a + axis * unit(rng);
    const Vec3 p = foot + normal * (0.5 + unit(rng));
    const TriangleClosest r = closest_point_on_triangle(p, a, b, c);
    expect_valid(r, p, a, b, c);
    EXPECT_LE(std::sqrt(r.distance2) - (p - foot).norm(), 1e-15) << k;
  }
}

TEST(ClosestPointTriangle, VertexOrderDoesNotMatter) {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 a = random_vector(rng, 1.0);
    const Vec3 b = random_vector(rng, 1.0);
    const Vec3 c = random_vector(rng, 1.0);
    const Vec3 p = random_vector(rng, 2.0);
    const TriangleClosest r = closest_point_on_triangle(p, a, b, c);
    const TriangleClosest rotated = closest_point_on_triangle(p, b, c, a);
    const TriangleClosest mirrored = closest_point_on_triangle(p, a, c, b);
    EXPECT_LE((r.point - rotated.point).norm(), 1e-14);
    EXPECT_LE((r.point - mirrored.point).norm(), 1e-14);
    EXPECT_NEAR(r.bary[0], rotated.bary[2], 1e-14);
    EXPECT_NEAR(r.bary[1], mirrored.bary[2], 1e-14);
  }
}

// The plane projection's barycentrics reproduce the foot of the perpendicular, agree with the
// closest point inside the triangle, and name the edge the foot falls beyond outside it.
TEST(PlaneBarycentrics, ReproduceTheFootOfThePerpendicular) {
  std::mt19937 rng(29);
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 a = random_vector(rng, 1.0), b = random_vector(rng, 1.0),
               c = random_vector(rng, 1.0), p = random_vector(rng, 2.0);
    std::array<double, 3> w{};
    ASSERT_TRUE(plane_barycentrics(p, a, b, c, w));
    EXPECT_NEAR(w[0] + w[1] + w[2], 1.0, 1e-12);
    const Vec3 foot = a * w[0] + b * w[1] + c * w[2];
    const Vec3 n = OpenMesh::cross(b - a, c - a).normalized();
    // p - foot is normal to the plane.
    EXPECT_LE((p - foot - n * OpenMesh::dot(p - foot, n)).norm(), 1e-9) << trial;
    const TriangleClosest r = closest_point_on_triangle(p, a, b, c);
    if (std::min({w[0], w[1], w[2]}) > 1e-9) {
      EXPECT_LE((r.point - foot).norm(), 1e-9) << trial;
    } else {
      EXPECT_GT(r.distance2, (p - foot).sqrnorm() - 1e-12) << trial;
    }
  }
  std::array<double, 3> w{};
  // Beyond the edge bc (opposite a): the weight of a is negative.
  ASSERT_TRUE(plane_barycentrics(Vec3(1, 1, 0.5), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), w));
  EXPECT_NEAR(w[0], -1.0, 1e-15);
  EXPECT_NEAR(w[1], 1.0, 1e-15);
  EXPECT_NEAR(w[2], 1.0, 1e-15);
  const std::array<double, 3> untouched{7, 8, 9};
  w = untouched;
  EXPECT_FALSE(plane_barycentrics(Vec3(1, 1, 1), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), w));
  EXPECT_FALSE(plane_barycentrics(Vec3(1, 1, 1), Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 0, 0), w));
  EXPECT_EQ(w, untouched);
}

} // namespace
} // namespace remora
