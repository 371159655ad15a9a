// Geodesic distance by fast marching (geometry/geodesic.h): against the analytic distances of a
// plane and a sphere, against edge paths (which give diamonds), and its contract.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/geometry/geodesic.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "support.h"

namespace remora {
namespace {

/// The largest |d - exact| / exact over the ball's vertices farther than `from` from the source.
template <class Exact>
double worst_relative_error(const std::vector<std::pair<int, double>>& ball, double from,
                            Exact exact) {
  double worst = 0.0;
  for (const auto& [v, d] : ball) {
    const double e = exact(v);
    if (e > from) worst = std::max(worst, std::abs(d - e) / e);
  }
  return worst;
}

TEST(Geodesic, IsTheStraightDistanceOnAPlaneAndNotTheEdgePath) {
  // A 60 x 60 square grid of right triangles: the edge paths along the diagonals that the split
  // does not follow are sqrt(2) times too long.
  const Mesh grid = make_grid(60, 60, 1.0, 1.0);
  const VertexHandle centre(30 * 61 + 30);
  const Vec3 c = grid.point(centre);
  const double r = 0.4;
  const auto ball = geodesic_ball(grid, centre, r);
  const auto euclid = [&](int v) { return (grid.point(VertexHandle(v)) - c).norm(); };
  EXPECT_LT(worst_relative_error(ball, 3.0 / 60, euclid), 0.02);
  // In increasing order of distance, none beyond the radius.
  for (std::size_t i = 1; i < ball.size(); ++i) EXPECT_LE(ball[i - 1].second, ball[i].second);
  EXPECT_LE(ball.back().second, r);
  // The ball is the disc: every vertex well inside it is in, every vertex in it is near it.
  const auto disc = select_geodesic_disc(grid, centre, r);
  const auto sphere_inner = select_sphere(grid, c, r * 0.97);
  EXPECT_TRUE(std::includes(disc.begin(), disc.end(), sphere_inner.begin(), sphere_inner.end()));
  for (const int v : disc) EXPECT_LE(euclid(v), r * 1.001);
  // Edge paths (geodesic_order) miss much of that disc: the diamond a brush must not paint.
  auto edge_ball = geodesic_order(grid, centre, grid.n_vertices(), r);
  std::sort(edge_ball.begin(), edge_ball.end());
  EXPECT_LT(static_cast<double>(edge_ball.size()), 0.95 * static_cast<double>(disc.size()));
  EXPECT_FALSE(
      std::includes(edge_ball.begin(), edge_ball.end(), sphere_inner.begin(), sphere_inner.end()));
}

TEST(Geodesic, ConvergesToTheGreatCircleDistanceOnASphere) {
  double previous = 1.0;
  for (const int s : {4, 5, 6}) {
    const Mesh sphere = make_icosphere(s, 1.0);
    const VertexHandle source(0);
    const Vec3 p = sphere.point(source);
    const auto arc = [&](int v) {
      const double cosine = OpenMesh::dot(sphere.point(VertexHandle(v)), p);
      return std::acos(std::clamp(cosine, -1.0, 1.0));
    };
    const auto ball = geodesic_ball(sphere, source, 1.5);
    const double error = worst_relative_error(ball, 0.2, arc);
    EXPECT_LT(error, 0.03) << "subdivisions " << s;
    EXPECT_LT(error, previous) << "subdivisions " << s;
    previous = error;
    // Never shorter than the chord (up to the march's small error).
    for (const auto& [v, d] : ball)
      EXPECT_GE(d, 0.99 * (sphere.point(VertexHandle(v)) - p).norm() - 1e-12);
  }
}

TEST(Geodesic, FromAPointInAFace) {
  const Mesh grid = make_grid(40, 40, 1.0, 1.0);
  // The first face of the quad whose lower left corner is (20, 20), at its centroid.
  const FaceHandle f(2 * (20 * 40 + 20));
  const SurfacePoint source{f, {1.0 / 3, 1.0 / 3, 1.0 / 3}};
  const Vec3 c = evaluate(grid, source);
  const auto ball = geodesic_ball(grid, source, 0.3);
  const auto euclid = [&](int v) { return (grid.point(VertexHandle(v)) - c).norm(); };
  // The face's corners are at their exact distance; the rest within the plane's error.
  for (const VertexHandle v : face_vertices(grid, f)) {
    const auto it = std::find_if(ball.begin(), ball.end(),
                                 [&](const auto& item) { return item.first == v.idx(); });
    ASSERT_NE(it, ball.end());
    EXPECT_DOUBLE_EQ(it->second, euclid(v.idx()));
  }
  EXPECT_LT(worst_relative_error(ball, 3.0 / 40, euclid), 0.02);
  // Radius 0: nothing, as a brush of radius 0 paints nothing.
  EXPECT_TRUE(geodesic_ball(grid, source, 0.0).empty());
}

TEST(Geodesic, OneMarcherGivesTheSameBallsAsFreshOnesAndFollowsMovedVertices) {
  Mesh sphere = make_icosphere(4, 1.0);
  FastMarching marching(sphere);
  for (const int v : {0, 17, 300, 17})
    EXPECT_EQ(marching.ball(sphere, VertexHandle(v), 0.7),
              geodesic_ball(sphere, VertexHandle(v), 0.7))
        << "source " << v;
  // Scaled by 2: every distance doubles.
  const auto before = marching.ball(sphere, VertexHandle(5), 0.5);
  for (const VertexHandle v : sphere.vertices()) sphere.set_point(v, 2.0 * sphere.point(v));
  const auto after = marching.ball(sphere, VertexHandle(5), 1.0);
  ASSERT_EQ(before.size(), after.size());
  for (std::size_t i = 0; i < before.size(); ++i)
    EXPECT_NEAR(after[i].second, 2.0 * before[i].second, 1e-12);
  EXPECT_THROW(marching.ball(make_icosphere(2, 1.0), VertexHandle(0), 1.0), InvalidArgument);
  // Two spheres in one mesh: a ball larger than either reaches one sphere only.
  Mesh two = make_icosphere(2, 1.0);
  const Mesh other = make_icosphere(2, 1.0);
  testing::append_component(two, other, Vec3(5, 0, 0));
  EXPECT_EQ(geodesic_ball(two, VertexHandle(0), 100.0).size(), other.n_vertices());
}

/// Sources along a path: from vertex `start`, `steps` times the neighbour farthest along +x.
std::vector<SurfacePoint> path_along_x(const Mesh& mesh, VertexHandle start, int steps) {
  std::vector<SurfacePoint> path;
  VertexHandle v = start;
  for (int i = 0; i < steps; ++i) {
    const FaceHandle f = *mesh.vf_range(v).begin();
    const auto corners = face_vertices(mesh, f);
    std::array<double, 3> bary{0, 0, 0};
    for (std::size_t k = 0; k < 3; ++k) bary[k] = corners[k] == v ? 1.0 : 0.0;
    path.push_back({f, bary});
    for (const VertexHandle w : mesh.vv_range(v))
      if (mesh.point(w)[0] > mesh.point(v)[0]) v = w;
  }
  return path;
}

/// A stroke along `path` reports what the union of the full balls holds, each vertex once, at no
/// less than its distance in the full ball of that source.
void expect_stroke_is_the_union_of_balls(const Mesh& mesh, const std::vector<SurfacePoint>& path,
                                         double radius, const FastMarchingOptions& options = {}) {
  FastMarching stroke(mesh, options), full(mesh, options);
  std::vector<int> reported, covered;
  std::vector<char> in_union(mesh.n_vertices(), 0);
  for (const SurfacePoint& at : path) {
    std::vector<double> exact(mesh.n_vertices(), -1.0);
    for (const auto& [v, d] : full.ball(mesh, at, radius)) {
      exact[static_cast<std::size_t>(v)] = d;
      if (!in_union[static_cast<std::size_t>(v)]) covered.push_back(v);
      in_union[static_cast<std::size_t>(v)] = 1;
    }
    for (const auto& [v, d] : stroke.stroke_ball(mesh, at, radius)) {
      reported.push_back(v);
      ASSERT_GE(exact[static_cast<std::size_t>(v)], 0.0) << "vertex " << v << " is not in the ball";
      EXPECT_GE(d, exact[static_cast<std::size_t>(v)] - 1e-12);
    }
    // Up to this source, the stroke reported exactly the union (each vertex once).
    auto a = reported, b = covered;
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    ASSERT_EQ(a, b);
  }
}

TEST(Geodesic, AStrokeReportsTheUnionOfItsBallsEachVertexOnce) {
  const Mesh grid = make_grid(80, 80, 1.0, 1.0);
  expect_stroke_is_the_union_of_balls(grid, path_along_x(grid, VertexHandle(40 * 81 + 10), 30),
                                      0.2);
  const Mesh sphere = make_icosphere(5, 1.0);
  expect_stroke_is_the_union_of_balls(sphere, path_along_x(sphere, VertexHandle(7), 25), 0.5);
  // A scan's irregular triangles, with a radius of a few edges and of many.
  const Mesh bunny = read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh;
  for (const double r : {0.01, 0.03})
    expect_stroke_is_the_union_of_balls(bunny, path_along_x(bunny, VertexHandle(1000), 30), r);
}

TEST(Geodesic, AStrokeStartsAgainWithAnotherRadiusOrOnRequest) {
  const Mesh grid = make_grid(40, 40, 1.0, 1.0);
  FastMarching marching(grid);
  const SurfacePoint at{FaceHandle(800), {0.2, 0.3, 0.5}};
  const std::size_t whole = marching.ball(grid, at, 0.2).size();
  EXPECT_EQ(marching.stroke_ball(grid, at, 0.2).size(), whole); // ball() ended the stroke
  EXPECT_TRUE(marching.stroke_ball(grid, at, 0.2).empty());     // nothing new where it was
  EXPECT_GT(marching.stroke_ball(grid, at, 0.3).size(), whole); // another radius: a new stroke
  marching.start_stroke();
  EXPECT_EQ(marching.stroke_ball(grid, at, 0.2).size(), whole);
  EXPECT_THROW(marching.stroke_ball(grid, at, -1.0), InvalidArgument);
  EXPECT_THROW(marching.stroke_ball(grid, SurfacePoint{FaceHandle(-1), {1, 0, 0}}, 0.2),
               InvalidArgument);
}

// ---- coarse levels for large balls -------------------------------------------------------------

/// The largest |d - exact| over the ball, and whether every vertex with exact <= inner is in it.
template <class Exact>
std::pair<double, bool> error_and_cover(const Mesh& mesh,
                                        const std::vector<std::pair<int, double>>& ball,
                                        double inner, Exact exact) {
  double worst = 0.0;
  std::vector<char> in(mesh.n_vertices(), 0);
  for (const auto& [v, d] : ball) {
    worst = std::max(worst, std::abs(d - exact(v)));
    in[static_cast<std::size_t>(v)] = 1;
  }
  bool covers = true;
  for (const VertexHandle v : mesh.vertices())
    if (exact(v.idx()) <= inner && !in[static_cast<std::size_t>(v.idx())]) covers = false;
  return {worst, covers};
}

TEST(Geodesic, ACoarseLevelKeepsALargeBallWithinTwoPercentOfItsRadius) {
  // A plane: the geodesic distance is the straight one.
  const Mesh grid = make_grid(240, 240, 1.0, 1.0);
  FastMarching coarse(grid, {.coarse_ratio = 16});
  const SurfacePoint at{FaceHandle(2 * (120 * 240 + 117)), {0.2, 0.5, 0.3}};
  const Vec3 c = evaluate(grid, at);
  for (const double r : {0.12, 0.3, 0.45}) {
    const auto ball = coarse.ball(grid, at, r);
    EXPECT_GE(coarse.last_level(), 1) << "radius " << r;
    EXPECT_GT(coarse.last_cell(), r / 16 * 0.99);
    EXPECT_LE(coarse.last_cell(), r / 8 * 1.01);
    const auto [error, covers] = error_and_cover(
        grid, ball, 0.98 * r, [&](int v) { return (grid.point(VertexHandle(v)) - c).norm(); });
    EXPECT_LT(error, 0.02 * r) << "radius " << r;
    EXPECT_TRUE(covers) << "radius " << r;
    for (std::size_t i = 1; i < ball.size(); ++i) ASSERT_LE(ball[i - 1].second, ball[i].second);
    // No coarse level below coarse_ratio mean edges: the fine ball, bit for bit.
    EXPECT_EQ(FastMarching(grid, {.coarse_ratio = 1e6}).ball(grid, at, r),
              geodesic_ball(grid, at, r));
  }
  // A sphere: the great-circle distance (cells of a tenth of its radius at most: a coarser level
  // cuts through its curvature).
  const Mesh sphere = make_icosphere(6, 1.0);
  FastMarching marching(sphere, {.coarse_ratio = 32});
  const Vec3 p = sphere.point(VertexHandle(3));
  for (const double r : {0.8, 1.5, 2.5}) {
    const auto ball = marching.ball(sphere, VertexHandle(3), r);
    EXPECT_GE(marching.last_level(), 1);
    const auto [error, covers] = error_and_cover(sphere, ball, 0.98 * r, [&](int v) {
      return std::acos(std::clamp(OpenMesh::dot(sphere.point(VertexHandle(v)), p), -1.0, 1.0));
    });
    EXPECT_LT(error, 0.02 * r) << "radius " << r;
    EXPECT_TRUE(covers) << "radius " << r;
  }
  // A radius beyond the whole sphere: all of it.
  EXPECT_EQ(marching.ball(sphere, VertexHandle(3), 100.0).size(), sphere.n_vertices());
  EXPECT_THROW(FastMarching(sphere, {.coarse_ratio = -1}), InvalidArgument);
}

TEST(Geodesic, ACoarseStrokeReportsTheUnionOfItsBallsEachVertexOnce) {
  const FastMarchingOptions levels{.coarse_ratio = 8};
  const Mesh grid = make_grid(160, 160, 1.0, 1.0);
  expect_stroke_is_the_union_of_balls(grid, path_along_x(grid, VertexHandle(80 * 161 + 30), 40),
                                      0.2, levels);
  const Mesh sphere = make_icosphere(5, 1.0);
  expect_stroke_is_the_union_of_balls(sphere, path_along_x(sphere, VertexHandle(7), 25), 0.7,
                                      levels);
  const Mesh bunny = read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh;
  for (const double r : {0.03, 0.06})
    expect_stroke_is_the_union_of_balls(bunny, path_along_x(bunny, VertexHandle(1000), 30), r,
                                        levels);
}

TEST(Geodesic, ACoarseStrokeOfLongStepsStillReportsTheUnion) {
  // Steps of several cells: the earlier sources' margin (twice the clusters' spread) matters.
  const FastMarchingOptions levels{.coarse_ratio = 8};
  const Mesh sphere = make_icosphere(5, 1.0);
  const auto dense = path_along_x(sphere, VertexHandle(7), 60);
  std::vector<SurfacePoint> sparse;
  for (std::size_t i = 0; i < dense.size(); i += 6) sparse.push_back(dense[i]);
  expect_stroke_is_the_union_of_balls(sphere, sparse, 0.6, levels);
  const Mesh bunny = read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh;
  const auto along = path_along_x(bunny, VertexHandle(1000), 80);
  std::vector<SurfacePoint> far;
  for (std::size_t i = 0; i < along.size(); i += 8) far.push_back(along[i]);
  expect_stroke_is_the_union_of_balls(bunny, far, 0.05, levels);
}

TEST(Geodesic, RandomCoarseStrokesOnAScanReportTheUnion) {
  // Seeded strokes from random vertices in random directions, with random radii and steps of 1
  // to 12 edges, on levels from 2 mean edge lengths: the slack's argument is not a proof.
  const Mesh bunny = read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> radius(0.003, 0.045);
  std::uniform_int_distribution<int> vertex(0, static_cast<int>(bunny.n_vertices()) - 1),
      step(1, 12);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 12; ++trial) {
    const double r = radius(rng);
    const int edges = step(rng);
    const Vec3 toward(normal(rng), normal(rng), normal(rng));
    std::vector<SurfacePoint> path;
    VertexHandle v(vertex(rng));
    for (int s = 0; s < 20; ++s) {
      const FaceHandle f = *bunny.vf_range(v).begin();
      const auto corners = face_vertices(bunny, f);
      std::array<double, 3> bary{};
      for (std::size_t k = 0; k < 3; ++k) bary[k] = corners[k] == v ? 1.0 : 0.0;
      path.push_back({f, bary});
      for (int e = 0; e < edges; ++e) {
        VertexHandle next = v;
        double ahead = -std::numeric_limits<double>::infinity();
        for (const VertexHandle w : bunny.vv_range(v))
          if (const double d = OpenMesh::dot(bunny.point(w) - bunny.point(v), toward); d > ahead)
            ahead = d, next = w;
        v = next;
      }
    }
    SCOPED_TRACE(::testing::Message()
                 << "trial " << trial << ", radius " << r << ", steps of " << edges);
    expect_stroke_is_the_union_of_balls(bunny, path, r, {.coarse_ratio = 2});
  }
}

TEST(Geodesic, ACoarseLevelToldOfSomeMovedVerticesEqualsOneToldOfAll) {
  // A bump pushed out of a sphere changes points, spreads and normals around it; the marcher
  // told only of the bump's vertices must read again every cluster that changed.
  Mesh sphere = make_icosphere(5, 1.0);
  FastMarching some(sphere, {.coarse_ratio = 4}), all(sphere, {.coarse_ratio = 4});
  const SurfacePoint at{*sphere.vf_range(VertexHandle(0)).begin(), {1.0 / 3, 1.0 / 3, 1.0 / 3}};
  EXPECT_EQ(some.ball(sphere, at, 0.8), all.ball(sphere, at, 0.8));
  std::vector<int> bump;
  for (const VertexHandle v : sphere.vertices()) {
    const Vec3 p = sphere.point(v);
    const double near = (p - sphere.point(VertexHandle(0))).norm();
    if (near < 0.35) {
      bump.push_back(v.idx());
      sphere.set_point(v, p * (1.0 + 0.3 * (0.35 - near)));
    }
  }
  some.positions_changed(sphere, bump);
  all.positions_changed();
  for (const double r : {0.3, 0.8, 1.6}) {
    const auto expected = all.ball(sphere, at, r);
    EXPECT_GE(all.last_level(), 1);
    EXPECT_EQ(some.ball(sphere, at, r), expected) << "radius " << r;
  }
}

TEST(Geodesic, CoarseLevelsTakeStrayVerticesComponentsAndHugeRadii) {
  // Two spheres, and vertices on no face: one far away, one not finite.
  Mesh mesh = make_icosphere(4, 1.0);
  const Mesh other = make_icosphere(4, 1.0);
  testing::append_component(mesh, other, Vec3(5, 0, 0));
  mesh.add_vertex(Vec3(1e300, 0, 0));
  mesh.add_vertex(Vec3(std::numeric_limits<double>::infinity(), 0, 0));
  FastMarching marching(mesh, {.coarse_ratio = 4});
  const SurfacePoint at{FaceHandle(0), {0.2, 0.3, 0.5}};
  const std::size_t sphere = other.n_vertices();
  for (const double r : {1.0, 10.0, 1e300}) {
    const auto ball = marching.ball(mesh, at, r);
    EXPECT_GE(marching.last_level(), 1);
    for (const auto& [v, d] : ball) {
      ASSERT_LT(static_cast<std::size_t>(v), sphere) << "the other sphere or a stray vertex";
      ASSERT_TRUE(std::isfinite(d));
    }
    if (r > 4) {
      EXPECT_EQ(ball.size(), sphere);
    }
  }
  EXPECT_NO_THROW(marching.prepare(mesh, 1e300));
  EXPECT_THROW(FastMarching(mesh, {.coarse_ratio = 0.5}), InvalidArgument);
  EXPECT_THROW(FastMarching(mesh, {.coarse_ratio = std::nan("")}), InvalidArgument);
}

TEST(Geodesic, ACoarseLevelFollowsMovedVerticesAtAStrokesStart) {
  Mesh grid = make_grid(120, 120, 1.0, 1.0);
  FastMarching marching(grid, {.coarse_ratio = 8});
  const SurfacePoint at{FaceHandle(2 * (60 * 120 + 60)), {0.3, 0.3, 0.4}};
  const double r = 0.3;
  const auto flat = marching.ball(grid, at, r);
  ASSERT_GE(marching.last_level(), 1);
  // Stretched by 1.5 along y: the ball follows the new distances, not the clusters' old points.
  for (const VertexHandle v : grid.vertices()) {
    const Vec3 q = grid.point(v);
    grid.set_point(v, Vec3(q[0], 1.5 * q[1], q[2]));
  }
  const Vec3 c = evaluate(grid, at);
  const auto straight = [&](int v) { return (grid.point(VertexHandle(v)) - c).norm(); };
  // Not told: the clusters keep their old points, and the ball misses much of the new one.
  EXPECT_FALSE(error_and_cover(grid, marching.ball(grid, at, r), 0.98 * r, straight).second);
  std::vector<int> all(grid.n_vertices());
  std::iota(all.begin(), all.end(), 0);
  marching.positions_changed(grid, all);
  const auto stretched = marching.ball(grid, at, r);
  const auto [error, covers] = error_and_cover(grid, stretched, 0.98 * r, straight);
  EXPECT_LT(error, 0.02 * r);
  EXPECT_TRUE(covers);
  EXPECT_LT(static_cast<double>(stretched.size()), 0.75 * static_cast<double>(flat.size()));
}

TEST(Geodesic, RefusesBadArguments) {
  const Mesh grid = make_grid(4, 4, 1.0, 1.0);
  EXPECT_THROW(geodesic_ball(grid, VertexHandle(100), 1.0), InvalidArgument);
  EXPECT_THROW(geodesic_ball(grid, VertexHandle(0), -1.0), InvalidArgument);
  EXPECT_THROW(geodesic_ball(grid, VertexHandle(0), std::nan("")), InvalidArgument);
  EXPECT_THROW(geodesic_ball(grid, SurfacePoint{FaceHandle(99), {1, 0, 0}}, 1.0), InvalidArgument);
  EXPECT_THROW(geodesic_ball(grid, SurfacePoint{FaceHandle(0), {std::nan(""), 0, 0}}, 1.0),
               InvalidArgument);
}

} // namespace
} // namespace remora
