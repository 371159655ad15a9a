// Geometric measures against values known in closed form: edge lengths, feature edges, triangle
// areas and angles (right, obtuse, needles, degenerate), mixed and barycentric vertex areas summing
// to the surface area on jittered meshes, bounding boxes. The quality report: test_quality.cpp.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/primitives.h"
#include "support.h"

namespace remora {
namespace {

using testing::kPi;
using testing::symmetric_unit;

double sum(const std::array<double, 3>& values) {
  return values[0] + values[1] + values[2];
}

/// A uniform grid whose interior vertices are moved randomly in x, y (up to 35 % of a cell) and z.
Mesh jittered_grid(std::uint32_t seed) {
  const int n = 12;
  Mesh mesh = make_grid(n, n, 1.0, 1.0, GridSplit::Uniform);
  std::mt19937 rng(seed);
  const double h = 1.0 / n;
  for (const VertexHandle v : mesh.vertices()) {
    if (mesh.is_boundary(v)) continue;
    mesh.point(v) += Vec3(0.35 * h * symmetric_unit(rng), 0.35 * h * symmetric_unit(rng),
                          0.3 * h * symmetric_unit(rng));
  }
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// Measures

TEST(MeasuresEdges, MeanEdgeLength) {
  EXPECT_NEAR(mean_edge_length(make_equilateral_grid(5, 4, 0.3)), 0.3, 1e-15);
  // A unit cube of 2x2 quads per side: 48 sides of 0.5 along the cube's edges and faces, 24
  // diagonals of 0.5 * sqrt(2).
  EXPECT_NEAR(mean_edge_length(make_cube(2, 1.0)), (48 * 0.5 + 24 * 0.5 * std::sqrt(2.0)) / 72,
              1e-15);
  EXPECT_EQ(mean_edge_length(Mesh()), 0.0);
}

TEST(MeasuresEdges, LengthScaleIgnoresNeedles) {
  // Well shaped: the mean edge length, and the area-based length agrees within 15 % (the grid's
  // boundary vertices carry less area).
  Mesh grid = make_equilateral_grid(20, 20, 0.3);
  LengthScale scale = length_scale(grid);
  EXPECT_FALSE(scale.needles);
  EXPECT_NEAR(scale.length, 0.3, 1e-12);
  EXPECT_NEAR(scale.from_area, 0.3, 0.15 * 0.3);
  // Squeezed 8x across: needles whose long edges keep the mean edge length at 0.2 while the area
  // per vertex is an eighth; the area-based length √(2A / (√3 V)) = 0.3 / √8 takes over.
  for (auto v : grid.vertices()) {
    Vec3 p = grid.point(v);
    p[1] /= 8.0;
    grid.set_point(v, p);
  }
  scale = length_scale(grid);
  EXPECT_TRUE(scale.needles);
  EXPECT_NEAR(scale.mean_edge, mean_edge_length(grid), 1e-15);
  EXPECT_NEAR(scale.from_area,
              std::sqrt(2.0 * surface_area(grid) /
                        (std::sqrt(3.0) * static_cast<double>(grid.n_vertices()))),
              1e-12);
  EXPECT_NEAR(scale.from_area, 0.3 / std::sqrt(8.0), 0.15 * 0.3 / std::sqrt(8.0));
  EXPECT_EQ(scale.length, scale.from_area);
  EXPECT_EQ(length_scale(Mesh()).length, 0.0);
}

std::size_t count(const std::vector<char>& marks) {
  std::size_t n = 0;
  for (char c : marks) n += c != 0;
  return n;
}

TEST(MeasuresFeatures, TheCubesEdgesAreItsOnlyFeatures) {
  // Each of the 12 edges of the cube is 4 mesh edges whose faces meet at 90 degrees; every other
  // edge lies in a side (its normals differ by 0).
  const Mesh cube = make_cube(4, 1.0);
  for (double angle : {1.0, 45.0, 89.0}) {
    const std::vector<char> sharp = feature_edges(cube, angle);
    ASSERT_EQ(sharp.size(), cube.n_edges());
    EXPECT_EQ(count(sharp), 48u) << angle;
    for (auto e : cube.edges()) {
      if (!sharp[static_cast<std::size_t>(e.idx())]) continue;
      // Both ends on the same edge of the cube: two coordinates at +-1/2 shared.
      const HalfedgeHandle h = cube.halfedge_handle(e, 0);
      const Vec3 a = cube.point(cube.from_vertex_handle(h)),
                 b = cube.point(cube.to_vertex_handle(h));
      int shared = 0;
      for (int d = 0; d < 3; ++d) shared += std::abs(std::abs(a[d]) - 0.5) < 1e-12 && a[d] == b[d];
      EXPECT_EQ(shared, 2);
    }
  }
  EXPECT_EQ(count(feature_edges(cube, 91.0)), 0u);
  EXPECT_EQ(count(feature_edges(cube, 0.0)), 48u); // the sides are exactly flat
}

TEST(MeasuresFeatures, SmoothSurfacesZeroAreaFacesAndBoundariesHaveNone) {
  // Neighbouring faces of a 3-times subdivided icosphere differ by a few degrees.
  const Mesh sphere = make_icosphere(3);
  EXPECT_EQ(count(feature_edges(sphere, 20.0)), 0u);
  EXPECT_EQ(count(feature_edges(sphere, 0.0)), sphere.n_edges());
  // Two triangles folded at 90 degrees along their shared edge: that edge only (the four others
  // are boundary edges). Flattening one into a line (zero area) leaves no normal: no feature.
  Mesh fold;
  const VertexHandle a = fold.add_vertex(Vec3(0, 0, 0)), b = fold.add_vertex(Vec3(1, 0, 0));
  const VertexHandle c = fold.add_vertex(Vec3(0.5, 1, 0)), d = fold.add_vertex(Vec3(0.5, 0, 1));
  fold.add_face(a, b, c);
  fold.add_face(b, a, d);
  EXPECT_EQ(count(feature_edges(fold, 45.0)), 1u);
  EXPECT_EQ(count(feature_edges(fold, 91.0)), 0u);
  fold.set_point(d, Vec3(0.5, 0, 0));
  EXPECT_EQ(count(feature_edges(fold, 0.0)), 0u);
  EXPECT_THROW(feature_edges(fold, -1.0), InvalidArgument);
  EXPECT_THROW(feature_edges(fold, 180.0), InvalidArgument);
  EXPECT_THROW(feature_edges(fold, std::nan("")), InvalidArgument);
}

TEST(MeasuresTriangle, AreaOfHandComputedTriangles) {
  EXPECT_DOUBLE_EQ(triangle_area(Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 3, 0)), 6.0);
  // (b - a) x (c - a) = (3, 4, 0) x (0, 0, 5) = (20, -15, 0): |.| / 2 = 12.5.
  EXPECT_DOUBLE_EQ(triangle_area(Vec3(1, 2, 3), Vec3(4, 6, 3), Vec3(1, 2, 8)), 12.5);
  EXPECT_EQ(triangle_area(Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2)), 0.0);
}

TEST(MeasuresAngles, EquilateralRightAndAccurateForNeedles) {
  const auto equilateral =
      triangle_angles(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, std::sqrt(3.0) / 2, 0));
  for (const double theta : equilateral) EXPECT_NEAR(theta, kPi / 3, 1e-15);

  const auto right = triangle_angles(Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 3, 0));
  EXPECT_EQ(right[0], kPi / 2);
  EXPECT_DOUBLE_EQ(right[1], std::atan2(3.0, 4.0));
  EXPECT_DOUBLE_EQ(right[2], std::atan2(4.0, 3.0));

  // A 1e-10 radian corner keeps full relative accuracy (acos of a dot product would not).
  const auto needle = triangle_angles(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1e-10, 0));
  EXPECT_DOUBLE_EQ(needle[0], std::atan2(1e-10, 1.0));
  EXPECT_NEAR(sum(needle), kPi, 1e-15);

  // A corner 2e-12 short of 180 degrees.
  const auto flat = triangle_angles(Vec3(0, 0, 0), Vec3(1, 1e-12, 0), Vec3(2, 0, 0));
  EXPECT_DOUBLE_EQ(flat[0], std::atan2(1e-12, 1.0));
  EXPECT_NEAR(flat[1], kPi - 2e-12, 1e-15);
  EXPECT_NEAR(sum(flat), kPi, 1e-15);
}

TEST(MeasuresAngles, ScaleInvariantEvenWhereProductsUnderflowOrOverflow) {
  const Vec3 a(0.1, 0.2, 0.3);
  const Vec3 b(1.3, -0.4, 0.9);
  const Vec3 c(-0.7, 1.1, 0.2);
  const auto reference = triangle_angles(a, b, c);
  for (const int exponent : {-1000, -600, -200, 200, 600, 1000}) {
    const double s = std::ldexp(1.0, exponent);
    const auto scaled = triangle_angles(a * s, b * s, c * s);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(scaled[i], reference[i]) << "2^" << exponent;
  }
}

TEST(MeasuresAngles, DegenerateTrianglesFollowTheDocumentedConvention) {
  const Vec3 p(1, 2, 3);
  const Vec3 q(4, 0, -1);
  // Collinear, distinct points: the middle corner is pi, exactly.
  const auto collinear = triangle_angles(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0));
  EXPECT_EQ(collinear[0], 0.0);
  EXPECT_EQ(collinear[1], kPi);
  EXPECT_EQ(collinear[2], 0.0);
  // One zero-length edge: its ends get pi/2, the opposite corner 0.
  EXPECT_EQ(triangle_angles(p, p, q), (std::array<double, 3>{kPi / 2, kPi / 2, 0.0}));
  EXPECT_EQ(triangle_angles(q, p, p), (std::array<double, 3>{0.0, kPi / 2, kPi / 2}));
  EXPECT_EQ(triangle_angles(p, q, p), (std::array<double, 3>{kPi / 2, 0.0, kPi / 2}));
  // All three points coincide.
  EXPECT_EQ(triangle_angles(p, p, p), (std::array<double, 3>{0.0, 0.0, kPi}));
  // An edge 1e-200 times the others is zero-length relative to the triangle.
  const auto tiny = triangle_angles(Vec3(0, 0, 0), Vec3(1e-200, 0, 0), Vec3(1, 1, 0));
  EXPECT_EQ(tiny, (std::array<double, 3>{kPi / 2, kPi / 2, 0.0}));
}

TEST(MeasuresMixedArea, RightTriangleHandComputed) {
  // Legs 4 (PQ) and 3 (PR), right angle at P, area 6. cot Q = 4/3, cot R = 3/4, cot P = 0:
  //   P: (|PR|^2 cot Q + |PQ|^2 cot R) / 8 = (9 * 4/3 + 16 * 3/4) / 8 = 3
  //   Q: (|QP|^2 cot R + |QR|^2 cot P) / 8 = (16 * 3/4 + 0) / 8 = 1.5
  //   R: (|RP|^2 cot Q + |RQ|^2 cot P) / 8 = (9 * 4/3 + 0) / 8 = 1.5
  const auto parts = triangle_mixed_areas(Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 3, 0));
  EXPECT_DOUBLE_EQ(parts[0], 3.0);
  EXPECT_DOUBLE_EQ(parts[1], 1.5);
  EXPECT_DOUBLE_EQ(parts[2], 1.5);
}

TEST(MeasuresMixedArea, EquilateralTriangleSplitsIntoThirds) {
  const Vec3 a(0, 0, 0);
  const Vec3 b(2, 0, 0);
  const Vec3 c(1, std::sqrt(3.0), 0);
  const double area = triangle_area(a, b, c);
  for (const double part : triangle_mixed_areas(a, b, c)) EXPECT_NEAR(part, area / 3, 1e-15);
}

TEST(MeasuresMixedArea, ObtuseTriangleHandComputed) {
  // P (0,0), Q (4,0), R (2,0.5): area 1; the angle at R is obtuse ((-2,-0.5).(2,-0.5) < 0), so R
  // gets area/2 and P, Q get area/4, in whichever position R is passed.
  const Vec3 p(0, 0, 0);
  const Vec3 q(4, 0, 0);
  const Vec3 r(2, 0.5, 0);
  EXPECT_EQ(triangle_mixed_areas(p, q, r), (std::array<double, 3>{0.25, 0.25, 0.5}));
  EXPECT_EQ(triangle_mixed_areas(r, p, q), (std::array<double, 3>{0.5, 0.25, 0.25}));
  EXPECT_EQ(triangle_mixed_areas(q, r, p), (std::array<double, 3>{0.25, 0.5, 0.25}));
}

TEST(MeasuresMixedArea, NeedlesStayFiniteAndSumToTheArea) {
  // Non-obtuse needle: apex angle 2e-9, two angles just below 90 degrees, so the Voronoi formula
  // applies with cot(apex) = 5e8.
  const Vec3 a(0, 0, 0);
  const Vec3 b(1, -1e-9, 0);
  const Vec3 c(1, 1e-9, 0);
  const double area = triangle_area(a, b, c);
  const auto parts = triangle_mixed_areas(a, b, c);
  for (const double part : parts) {
    EXPECT_TRUE(std::isfinite(part));
    EXPECT_GE(part, 0.0);
    EXPECT_LE(part, area);
  }
  EXPECT_NEAR(sum(parts), area, 1e-15 * area);
}

TEST(MeasuresMixedArea, ZeroAreaTrianglesContributeNothing) {
  const Vec3 p(1, 2, 3);
  const std::array<double, 3> zero{0.0, 0.0, 0.0};
  EXPECT_EQ(triangle_mixed_areas(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)), zero);
  EXPECT_EQ(triangle_mixed_areas(p, p, Vec3(0, 0, 0)), zero);
  EXPECT_EQ(triangle_mixed_areas(p, p, p), zero);
}

TEST(MeasuresVertexAreas, SingleTriangleMeshMatchesTheTriangleRule) {
  Mesh mesh;
  const VertexHandle a = mesh.add_vertex(Vec3(0, 0, 0));
  const VertexHandle b = mesh.add_vertex(Vec3(4, 0, 0));
  const VertexHandle c = mesh.add_vertex(Vec3(0, 3, 0));
  mesh.add_face(a, b, c);
  const Eigen::VectorXd mixed = vertex_areas_mixed(mesh);
  EXPECT_DOUBLE_EQ(mixed[a.idx()], 3.0);
  EXPECT_DOUBLE_EQ(mixed[b.idx()], 1.5);
  EXPECT_DOUBLE_EQ(mixed[c.idx()], 1.5);
  const Eigen::VectorXd barycentric = vertex_areas_barycentric(mesh);
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(barycentric[i], 2.0);
}

TEST(MeasuresVertexAreas, MixedAndBarycentricSumToTheSurfaceArea) {
  std::vector<std::pair<std::string, Mesh>> meshes;
  meshes.emplace_back("icosphere", make_icosphere(3, 1.3));
  meshes.emplace_back("cube", make_cube(4, 2.0));
  meshes.emplace_back("annulus", make_annulus(3, 17, 0.4, 1.0));
  meshes.emplace_back("disc", make_disc(5, 6, 1.0));
  for (const std::uint32_t seed : {1u, 2u, 3u}) {
    meshes.emplace_back("jittered grid " + std::to_string(seed), jittered_grid(seed));
  }
  for (const auto& [name, mesh] : meshes) {
    const double area = surface_area(mesh);
    const Eigen::VectorXd mixed = vertex_areas_mixed(mesh);
    const Eigen::VectorXd barycentric = vertex_areas_barycentric(mesh);
    ASSERT_EQ(mixed.size(), static_cast<Eigen::Index>(mesh.n_vertices()));
    EXPECT_NEAR(mixed.sum(), area, 1e-13 * area) << name;
    EXPECT_NEAR(barycentric.sum(), area, 1e-13 * area) << name;
    EXPECT_GT(mixed.minCoeff(), 0.0) << name;
  }
  // The jittered grids exercise the obtuse rule.
  const Mesh jittered = jittered_grid(1);
  int obtuse = 0;
  for (const FaceHandle f : jittered.faces()) {
    auto v = jittered.cfv_iter(f);
    const Vec3 a = jittered.point(*v);
    const Vec3 b = jittered.point(*++v);
    const Vec3 c = jittered.point(*++v);
    for (const double theta : triangle_angles(a, b, c)) obtuse += theta > kPi / 2 ? 1 : 0;
  }
  EXPECT_GT(obtuse, 20);
}

TEST(MeasuresVertexAreas, DeletedElementsContributeNothing) {
  Mesh mesh = make_grid(1, 1, 1.0, 1.0, GridSplit::Uniform);
  mesh.delete_face(FaceHandle(1), true); // removes vertex 2, now isolated
  const Eigen::VectorXd mixed = vertex_areas_mixed(mesh);
  const Eigen::VectorXd barycentric = vertex_areas_barycentric(mesh);
  ASSERT_EQ(mixed.size(), 4);
  EXPECT_EQ(mixed[2], 0.0);
  EXPECT_EQ(barycentric[2], 0.0);
  EXPECT_DOUBLE_EQ(mixed.sum(), 0.5);
  EXPECT_DOUBLE_EQ(barycentric.sum(), 0.5);
  EXPECT_DOUBLE_EQ(surface_area(mesh), 0.5);
}

TEST(MeasuresBoundingBox, CubeEmptyAndDeletedVertices) {
  const BoundingBox cube = bounding_box(make_cube(3, 2.0));
  EXPECT_EQ(cube.min, Vec3(-1, -1, -1));
  EXPECT_EQ(cube.max, Vec3(1, 1, 1));
  EXPECT_DOUBLE_EQ(bounding_box_diagonal(make_cube(3, 2.0)), 2.0 * std::sqrt(3.0));

  const BoundingBox empty = bounding_box(Mesh());
  EXPECT_EQ(empty.min, Vec3(0, 0, 0));
  EXPECT_EQ(empty.max, Vec3(0, 0, 0));
  EXPECT_EQ(empty.diagonal(), 0.0);

  Mesh grid = make_grid(2, 2, 1.0, 1.0);
  grid.point(VertexHandle(0)) = Vec3(-100, -100, -100);
  grid.delete_vertex(VertexHandle(0));
  const BoundingBox box = bounding_box(grid);
  EXPECT_EQ(box.min, Vec3(0, 0, 0));
  EXPECT_EQ(box.max, Vec3(1, 1, 0));
}

TEST(MeasuresZeroArea, ThresholdIsRelativeToTheSquaredDiagonal) {
  EXPECT_TRUE(is_zero_area(0.0, 0.0));
  EXPECT_TRUE(is_zero_area(0.0, 5.0));
  EXPECT_TRUE(is_zero_area(1e-12 * 16.0, 4.0)); // on the threshold (exact for a power of two)
  EXPECT_TRUE(is_zero_area(0.999e-12 * 25.0, 5.0));
  EXPECT_FALSE(is_zero_area(1.001e-12 * 25.0, 5.0));
  EXPECT_FALSE(is_zero_area(1e-20, 0.0));
}

} // namespace
} // namespace remora
