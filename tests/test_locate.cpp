// The local walks on meshes against brute-force searches over all faces or the whole boundary
// loop, and along feature lines. Closest points on single triangles: test_closest_point.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "remora/common/error.h"
#include "remora/geometry/closest_point.h"
#include "remora/geometry/locate.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/primitives.h"
#include "remora/mesh/surface_point.h"
#include "support.h"

namespace remora {
namespace {

using testing::random_offset;
using testing::random_vector;
using testing::symmetric_unit;
using testing::unit;

// ---------------------------------------------------------------------------------------------
// Walking to the closest point on a mesh

struct Closest {
  FaceHandle face;
  Vec3 point{0.0, 0.0, 0.0};
  double distance = 0.0;
};

/// The global answer: every live face.
Closest brute_force(const Mesh& mesh, const Vec3& q) {
  Closest best;
  best.distance = std::numeric_limits<double>::infinity();
  for (const FaceHandle f : mesh.faces()) {
    const auto v = face_vertices(mesh, f);
    const TriangleClosest r =
        closest_point_on_triangle(q, mesh.point(v[0]), mesh.point(v[1]), mesh.point(v[2]));
    if (std::sqrt(r.distance2) < best.distance) best = {f, r.point, std::sqrt(r.distance2)};
  }
  return best;
}

/// A random live face exactly `rings` edge-adjacency steps from f (or the farthest found).
FaceHandle face_rings_away(const Mesh& mesh, FaceHandle f, int rings, std::mt19937& rng) {
  std::vector<int> distance(mesh.n_faces(), -1);
  std::vector<FaceHandle> frontier{f};
  distance[f.idx()] = 0;
  for (int r = 0; r < rings; ++r) {
    std::vector<FaceHandle> next;
    for (const FaceHandle g : frontier) {
      for (const FaceHandle h : mesh.ff_range(g)) {
        if (distance[h.idx()] >= 0) continue;
        distance[h.idx()] = r + 1;
        next.push_back(h);
      }
    }
    if (next.empty()) break;
    frontier = next;
  }
  return frontier[rng() % frontier.size()];
}

/// A random point on a random live face.
Vec3 random_surface_point(const Mesh& mesh, std::mt19937& rng, FaceHandle& face) {
  do {
    face = FaceHandle(static_cast<int>(rng() % mesh.n_faces()));
  } while (mesh.status(face).deleted());
  const double u = unit(rng);
  const double v = (1.0 - u) * unit(rng);
  return evaluate(mesh, SurfacePoint{face, {1.0 - u - v, u, v}});
}

/// Queries within `reach` edge lengths of the surface, each started `rings` face rings away from
/// the face it was generated on: the walk finds the brute-force point and distance.
void expect_walk_matches_brute_force(const Mesh& mesh, std::uint32_t seed, int queries,
                                     double reach, int rings) {
  std::mt19937 rng(seed);
  const double h = mean_edge_length(mesh);
  for (int k = 0; k < queries; ++k) {
    FaceHandle origin;
    const Vec3 q = random_surface_point(mesh, rng, origin) + random_offset(rng, reach * h);
    const FaceHandle start = face_rings_away(mesh, origin, rings, rng);
    const SurfacePoint sp = walk_to_closest(mesh, q, start);
    ASSERT_TRUE(sp.face.is_valid());
    EXPECT_FALSE(mesh.status(sp.face).deleted());
    for (const double w : sp.bary) {
      EXPECT_TRUE(std::isfinite(w));
      EXPECT_GE(w, 0.0);
    }
    const Vec3 found = evaluate(mesh, sp);
    const Closest expected = brute_force(mesh, q);
    EXPECT_NEAR((q - found).norm(), expected.distance, 1e-12 * h) << "query " << k;
    EXPECT_LE((found - expected.point).norm(), 1e-6 * h) << "query " << k;
  }
}

/// A grid with every interior vertex moved randomly by up to 30 % of a cell in x, y and z.
Mesh jittered_grid(int n, std::uint32_t seed) {
  Mesh mesh = make_grid(n, n, 1.0, 1.0, GridSplit::Uniform);
  std::mt19937 rng(seed);
  const double h = 1.0 / n;
  for (const VertexHandle v : mesh.vertices()) {
    if (mesh.is_boundary(v)) continue;
    mesh.point(v) += random_vector(rng, 0.3 * h);
  }
  return mesh;
}

TEST(LocateWalk, IcosphereMatchesBruteForce) {
  const Mesh mesh = make_icosphere(4);
  expect_walk_matches_brute_force(mesh, 29, 300, 1.0, 3);
}

TEST(LocateWalk, JitteredGridMatchesBruteForce) {
  const Mesh mesh = jittered_grid(24, 31);
  expect_walk_matches_brute_force(mesh, 37, 300, 1.0, 3);
}

/// Columns pair up 1e-9 apart and so do rows: half of the faces are needles 1e-9 high, a quarter
/// are right triangles 1e-9 across; z = bump (x, y).
Mesh needle_grid(const std::function<double(double, double)>& bump) {
  constexpr int n = 18;
  Mesh mesh = make_grid(n, n, 1.0, 1.0, GridSplit::Alternating);
  const auto squeeze = [](double s) {
    const int i = static_cast<int>(std::lround(s * n));
    return (i / 2) * 2.0 / n + (i % 2 == 1 ? 1e-9 : 0.0);
  };
  for (const VertexHandle v : mesh.vertices()) {
    Vec3& p = mesh.point(v);
    p[0] = squeeze(p[0]);
    p[1] = squeeze(p[1]);
    p[2] = bump(p[0], p[1]);
  }
  return mesh;
}

TEST(LocateWalk, FlatNeedleGridMatchesBruteForce) {
  // Reaching the answer means crossing needle strips; the distance must not be spoiled by them.
  const Mesh mesh = needle_grid([](double, double) { return 0.0; });
  expect_walk_matches_brute_force(mesh, 41, 300, 1.0, 3);
}

TEST(LocateWalk, BumpedNeedleGridEndsInALocalMinimum) {
  // Bent, the surface has creases along the needle strips. Above a concave one the distance has a
  // local minimum on each side, and the faces on the two sides share no vertex (the strip is in
  // between), so a walk may stop on the farther side (rarely, and only here: not without the
  // needles or without the bump): then the result is still a local minimum over its
  // neighbourhood, and only slightly farther than the global one.
  const Mesh mesh =
      needle_grid([](double x, double y) { return 0.1 * std::sin(3.0 * x) * std::cos(2.0 * y); });
  std::mt19937 rng(41);
  const double h = 1.0 / 18;
  int global = 0;
  for (int k = 0; k < 300; ++k) {
    FaceHandle origin;
    const Vec3 q = random_surface_point(mesh, rng, origin) + random_offset(rng, h);
    const FaceHandle start = face_rings_away(mesh, origin, 3, rng);
    const SurfacePoint sp = walk_to_closest(mesh, q, start);
    for (const double w : sp.bary) EXPECT_TRUE(std::isfinite(w) && w >= 0.0);
    const double found = (q - evaluate(mesh, sp)).norm();
    const Closest expected = brute_force(mesh, q);
    EXPECT_GE(found, expected.distance - 1e-15) << "query " << k;
    EXPECT_LE(found, expected.distance + 1e-2 * h) << "query " << k;
    if (found <= expected.distance + 1e-12) ++global;
    // No face sharing a vertex with the result is closer.
    for (const VertexHandle v : face_vertices(mesh, sp.face)) {
      for (const FaceHandle g : mesh.vf_range(v)) {
        const auto c = face_vertices(mesh, g);
        const double d2 =
            closest_point_on_triangle(q, mesh.point(c[0]), mesh.point(c[1]), mesh.point(c[2]))
                .distance2;
        EXPECT_GE(d2, found * found * (1.0 - 1e-11)) << "query " << k;
      }
    }
  }
  EXPECT_GE(global, 290);
}

TEST(LocateWalk, SkipsDeletedFaces) {
  Mesh mesh = make_icosphere(3);
  std::vector<FaceHandle> deleted;
  for (const FaceHandle f : mesh.faces()) {
    if (f.idx() % 7 == 3) deleted.push_back(f);
  }
  for (const FaceHandle f : deleted) mesh.delete_face(f, false);
  ASSERT_TRUE(mesh.status(deleted.front()).deleted());
  expect_walk_matches_brute_force(mesh, 43, 200, 1.0, 3);

  // Queries right above the holes: the answer is on their rims.
  std::mt19937 rng(47);
  const double h = mean_edge_length(mesh);
  for (const FaceHandle f : deleted) {
    const Vec3 q = evaluate(mesh, SurfacePoint{f, {1.0 / 3, 1.0 / 3, 1.0 / 3}}) * 1.02;
    FaceHandle start;
    do {
      start = face_rings_away(mesh, f, 3, rng);
    } while (mesh.status(start).deleted());
    const SurfacePoint sp = walk_to_closest(mesh, q, start);
    EXPECT_FALSE(mesh.status(sp.face).deleted());
    EXPECT_NEAR((q - evaluate(mesh, sp)).norm(), brute_force(mesh, q).distance, 1e-12 * h);
  }
  EXPECT_THROW(walk_to_closest(mesh, Vec3(0, 0, 1), deleted.front()), InvalidArgument);
}

TEST(LocateWalk, PointsOnTheStartFaceStayThere) {
  const Mesh mesh = make_icosphere(3);
  std::mt19937 rng(53);
  for (int k = 0; k < 200; ++k) {
    FaceHandle face;
    const Vec3 q = random_surface_point(mesh, rng, face);
    const SurfacePoint sp = walk_to_closest(mesh, q, face);
    EXPECT_EQ(sp.face, face);
    EXPECT_LE((evaluate(mesh, sp) - q).norm(), 1e-15);
  }
}

TEST(LocateWalk, MaxStepsBoundsTheWalk) {
  const Mesh mesh = make_icosphere(4);
  std::mt19937 rng(59);
  FaceHandle origin;
  const Vec3 q = random_surface_point(mesh, rng, origin);
  const FaceHandle start = face_rings_away(mesh, origin, 8, rng);
  const SurfacePoint none = walk_to_closest(mesh, q, start, 0);
  EXPECT_EQ(none.face, start);
  const SurfacePoint one = walk_to_closest(mesh, q, start, 1);
  EXPECT_NE(one.face, start);
  EXPECT_LT((evaluate(mesh, one) - q).norm(), (evaluate(mesh, none) - q).norm());
  const SurfacePoint all = walk_to_closest(mesh, q, start);
  EXPECT_LE((evaluate(mesh, all) - q).norm(), 1e-15);
}

TEST(LocateWalk, RejectsUnusableArguments) {
  const Mesh mesh = make_icosphere(1);
  const Vec3 q(0, 0, 1);
  EXPECT_THROW(walk_to_closest(mesh, q, FaceHandle()), InvalidArgument);
  EXPECT_THROW(walk_to_closest(mesh, q, FaceHandle(static_cast<int>(mesh.n_faces()))),
               InvalidArgument);
  EXPECT_THROW(walk_to_closest(mesh, Vec3(0, std::nan(""), 0), FaceHandle(0)), InvalidArgument);
  EXPECT_THROW(walk_to_closest(mesh, Vec3(0, 0, HUGE_VAL), FaceHandle(0)), InvalidArgument);
  EXPECT_THROW(walk_to_closest(mesh, q, FaceHandle(0), -1), InvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// Walking along a boundary loop

/// The boundary halfedges of the loop through h, in order.
std::vector<HalfedgeHandle> boundary_loop(const Mesh& mesh, HalfedgeHandle h) {
  std::vector<HalfedgeHandle> loop;
  HalfedgeHandle g = h;
  do {
    loop.push_back(g);
    g = mesh.next_halfedge_handle(g);
  } while (g != h);
  return loop;
}

/// The boundary loop whose vertices lie at distance `radius` from the origin.
std::vector<HalfedgeHandle> loop_at_radius(const Mesh& mesh, double radius) {
  for (const HalfedgeHandle h : mesh.halfedges()) {
    if (mesh.is_boundary(h) &&
        std::abs(mesh.point(mesh.to_vertex_handle(h)).norm() - radius) < 1e-12) {
      return boundary_loop(mesh, h);
    }
  }
  return {};
}

/// Queries around the circle of `radius` (the loop's), from random starts on the loop.
void expect_boundary_walk_matches(const Mesh& mesh, const std::vector<HalfedgeHandle>& loop,
                                  double radius, std::uint32_t seed) {
  ASSERT_FALSE(loop.empty());
  std::mt19937 rng(seed);
  for (int k = 0; k < 300; ++k) {
    const double angle = 2.0 * std::numbers::pi * unit(rng);
    const double r = radius * (1.0 + 0.4 * symmetric_unit(rng));
    const Vec3 q(r * std::cos(angle), r * std::sin(angle), 0.2 * radius * symmetric_unit(rng));
    const HalfedgeHandle start = loop[rng() % loop.size()];
    const BoundaryPoint bp = walk_to_closest_on_boundary(mesh, q, start);

    ASSERT_TRUE(mesh.is_boundary(bp.halfedge));
    EXPECT_NE(std::find(loop.begin(), loop.end(), bp.halfedge), loop.end());
    EXPECT_EQ(bp.point.face, mesh.face_handle(mesh.opposite_halfedge_handle(bp.halfedge)));
    EXPECT_GE(bp.t, 0.0);
    EXPECT_LE(bp.t, 1.0);
    const auto corners = face_vertices(mesh, bp.point.face);
    const VertexHandle from = mesh.from_vertex_handle(bp.halfedge);
    const VertexHandle to = mesh.to_vertex_handle(bp.halfedge);
    for (std::size_t i = 0; i < 3; ++i) {
      if (corners[i] == from) {
        EXPECT_EQ(bp.point.bary[i], 1.0 - bp.t);
      } else if (corners[i] == to) {
        EXPECT_EQ(bp.point.bary[i], bp.t);
      } else {
        EXPECT_EQ(bp.point.bary[i], 0.0); // exactly
      }
    }
    const Vec3 found = evaluate(mesh, bp.point);
    const Vec3 along = mesh.point(from) * (1.0 - bp.t) + mesh.point(to) * bp.t;
    EXPECT_LE((found - along).norm(), 1e-15);

    double expected = std::numeric_limits<double>::infinity();
    Vec3 expected_point(0, 0, 0);
    for (const HalfedgeHandle h : loop) {
      const SegmentClosest s = closest_point_on_segment(q, mesh.point(mesh.from_vertex_handle(h)),
                                                        mesh.point(mesh.to_vertex_handle(h)));
      if (std::sqrt(s.distance2) < expected) {
        expected = std::sqrt(s.distance2);
        expected_point = s.point;
      }
    }
    EXPECT_NEAR((q - found).norm(), expected, 1e-12) << "query " << k;
    EXPECT_LE((found - expected_point).norm(), 1e-9) << "query " << k;
  }
}

TEST(LocateBoundary, DiscMatchesBruteForceOverTheLoop) {
  const Mesh mesh = make_disc(8, 6, 1.0);
  const auto loop = loop_at_radius(mesh, 1.0);
  EXPECT_EQ(loop.size(), 48u);
  expect_boundary_walk_matches(mesh, loop, 1.0, 61);
}

TEST(LocateBoundary, AnnulusStaysOnTheStartLoop) {
  const Mesh mesh = make_annulus(3, 40, 0.5, 1.5);
  const auto inner = loop_at_radius(mesh, 0.5);
  const auto outer = loop_at_radius(mesh, 1.5);
  EXPECT_EQ(inner.size(), 40u);
  EXPECT_EQ(outer.size(), 40u);
  expect_boundary_walk_matches(mesh, inner, 0.5, 67);
  expect_boundary_walk_matches(mesh, outer, 1.5, 71);
}

TEST(LocateBoundary, RejectsUnusableHalfedges) {
  const Mesh mesh = make_disc(2, 6, 1.0);
  HalfedgeHandle interior;
  HalfedgeHandle boundary;
  for (const HalfedgeHandle h : mesh.halfedges()) {
    if (mesh.is_boundary(h)) boundary = h;
    if (!mesh.is_boundary(mesh.edge_handle(h))) interior = h;
  }
  const Vec3 q(2, 0, 0);
  EXPECT_NO_THROW(walk_to_closest_on_boundary(mesh, q, boundary));
  EXPECT_THROW(walk_to_closest_on_boundary(mesh, q, interior), InvalidArgument);
  // The face side of a boundary edge is not a boundary halfedge either.
  EXPECT_THROW(walk_to_closest_on_boundary(mesh, q, mesh.opposite_halfedge_handle(boundary)),
               InvalidArgument);
  EXPECT_THROW(walk_to_closest_on_boundary(mesh, q, HalfedgeHandle()), InvalidArgument);
  EXPECT_THROW(walk_to_closest_on_boundary(mesh, Vec3(0, 0, std::nan("")), boundary),
               InvalidArgument);
  EXPECT_THROW(walk_to_closest_on_boundary(mesh, q, boundary, -2), InvalidArgument);
}

// The curve walk with the boundary as its curve is the boundary walk.
TEST(LocateCurve, OnTheBoundaryItIsTheBoundaryWalk) {
  const Mesh mesh = make_annulus(3, 40, 0.5, 1.5);
  std::vector<char> boundary(mesh.n_edges(), 0);
  for (auto e : mesh.edges()) boundary[static_cast<std::size_t>(e.idx())] = mesh.is_boundary(e);
  std::mt19937 rng(73);
  for (const double radius : {0.5, 1.5}) {
    const auto loop = loop_at_radius(mesh, radius);
    for (int k = 0; k < 200; ++k) {
      const double angle = 2.0 * std::numbers::pi * unit(rng);
      const double r = radius * (1.0 + 0.4 * symmetric_unit(rng));
      const Vec3 q(r * std::cos(angle), r * std::sin(angle), 0.2 * symmetric_unit(rng));
      const HalfedgeHandle start = loop[rng() % loop.size()];
      const BoundaryPoint expected = walk_to_closest_on_boundary(mesh, q, start);
      const BoundaryPoint found = walk_to_closest_on_curve(mesh, q, start, boundary);
      EXPECT_EQ(found.halfedge, expected.halfedge);
      EXPECT_EQ(found.point.face, expected.point.face);
      EXPECT_EQ(found.point.bary, expected.point.bary);
    }
  }
}

// On the cube's feature lines: the walk follows the line it starts on and stops where three
// lines meet (a corner), whatever the query.
TEST(LocateCurve, FollowsAFeatureLineAndStopsAtItsCorners) {
  const Mesh cube = make_cube(6, 1.0);
  const std::vector<char> lines = feature_edges(cube, 45.0);
  // The line x = y = 1/2, along z, and one of its halfedges to start from.
  auto on_line = [&](VertexHandle v) {
    const Vec3 p = cube.point(v);
    return p[0] == 0.5 && p[1] == 0.5;
  };
  std::vector<HalfedgeHandle> starts;
  for (auto h : cube.halfedges())
    if (lines[static_cast<std::size_t>(h.idx() / 2)] && on_line(cube.from_vertex_handle(h)) &&
        on_line(cube.to_vertex_handle(h)))
      starts.push_back(h);
  ASSERT_EQ(starts.size(), 12u); // 6 edges, both halfedges
  std::mt19937 rng(79);
  for (int k = 0; k < 300; ++k) {
    const double z = 0.8 * symmetric_unit(rng); // past the corners at +-1/2 too
    const Vec3 q(0.5 + 0.3 * symmetric_unit(rng), 0.5 + 0.3 * symmetric_unit(rng), z);
    const HalfedgeHandle start = starts[rng() % starts.size()];
    const BoundaryPoint bp = walk_to_closest_on_curve(cube, q, start, lines);
    ASSERT_TRUE(on_line(cube.from_vertex_handle(bp.halfedge)) &&
                on_line(cube.to_vertex_handle(bp.halfedge)));
    EXPECT_EQ(bp.point.face, cube.face_handle(bp.halfedge));
    const Vec3 found = evaluate(cube, bp.point);
    EXPECT_LE((found - Vec3(0.5, 0.5, std::clamp(z, -0.5, 0.5))).norm(), 1e-12) << "query " << k;
  }
  // A boundary halfedge of the curve puts its point on the face across it.
  const Mesh disc = make_disc(2, 6, 1.0);
  std::vector<char> rim(disc.n_edges(), 0);
  HalfedgeHandle boundary;
  for (auto h : disc.halfedges())
    if (disc.is_boundary(h)) {
      rim[static_cast<std::size_t>(h.idx() / 2)] = 1;
      boundary = h;
    }
  const BoundaryPoint bp = walk_to_closest_on_curve(disc, Vec3(2, 0, 0), boundary, rim);
  EXPECT_TRUE(disc.is_boundary(bp.halfedge));
  EXPECT_EQ(bp.point.face, disc.face_handle(disc.opposite_halfedge_handle(bp.halfedge)));
}

TEST(LocateCurve, RejectsUnusableArguments) {
  const Mesh cube = make_cube(2, 1.0);
  const std::vector<char> lines = feature_edges(cube, 45.0);
  HalfedgeHandle marked, unmarked;
  for (auto h : cube.halfedges())
    (lines[static_cast<std::size_t>(h.idx() / 2)] ? marked : unmarked) = h;
  const Vec3 q(1, 1, 1);
  EXPECT_NO_THROW(walk_to_closest_on_curve(cube, q, marked, lines));
  EXPECT_THROW(walk_to_closest_on_curve(cube, q, unmarked, lines), InvalidArgument);
  EXPECT_THROW(walk_to_closest_on_curve(cube, q, HalfedgeHandle(), lines), InvalidArgument);
  EXPECT_THROW(walk_to_closest_on_curve(cube, q, marked, std::vector<char>(3, 1)), InvalidArgument);
  EXPECT_THROW(walk_to_closest_on_curve(cube, Vec3(0, std::nan(""), 0), marked, lines),
               InvalidArgument);
  EXPECT_THROW(walk_to_closest_on_curve(cube, q, marked, lines, -1), InvalidArgument);
}

} // namespace
} // namespace remora
