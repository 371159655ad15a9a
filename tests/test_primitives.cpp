// Procedural meshes: element counts from the closed formulas, positions, orientation, areas and
// volumes against their exact values, determinism, and argument checking.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/primitives.h"
#include "remora/mesh/topology.h"
#include "support.h"

namespace remora {
namespace {

using testing::kPi;

using testing::signed_volume;

std::array<Vec3, 3> corners(const Mesh& mesh, FaceHandle f) {
  std::array<Vec3, 3> p;
  int i = 0;
  for (const VertexHandle v : mesh.fv_range(f)) p[static_cast<std::size_t>(i++)] = mesh.point(v);
  return p;
}

/// (b - a) x (c - a): the face's area-weighted normal (twice the area).
Vec3 area_normal(const Mesh& mesh, FaceHandle f) {
  const std::array<Vec3, 3> p = corners(mesh, f);
  return (p[1] - p[0]) % (p[2] - p[0]);
}

Vec3 centroid(const Mesh& mesh, FaceHandle f) {
  const std::array<Vec3, 3> p = corners(mesh, f);
  return (p[0] + p[1] + p[2]) / 3.0;
}

/// Signed volume enclosed by a closed, outward-oriented mesh (divergence theorem).

void expect_flat_and_up(const Mesh& mesh) {
  for (const VertexHandle v : mesh.vertices()) EXPECT_EQ(mesh.point(v)[2], 0.0);
  for (const FaceHandle f : mesh.faces()) EXPECT_GT(area_normal(mesh, f)[2], 0.0);
}

std::size_t boundary_halfedges(const Mesh& mesh) {
  std::size_t n = 0;
  for (const HalfedgeHandle h : mesh.halfedges()) n += mesh.is_boundary(h) ? 1 : 0;
  return n;
}

/// Area of the regular n-gon inscribed in a circle of radius r.
double polygon_area(int n, double r) {
  return 0.5 * n * r * r * std::sin(2.0 * kPi / n);
}

TEST(PrimitivesGrid, CountsPositionsOrientationAndArea) {
  for (const GridSplit split : {GridSplit::Uniform, GridSplit::Alternating}) {
    const int nx = 5;
    const int ny = 3;
    const double width = 2.5;
    const double height = 1.5;
    const Mesh mesh = make_grid(nx, ny, width, height, split);
    ASSERT_EQ(mesh.n_vertices(), static_cast<std::size_t>((nx + 1) * (ny + 1)));
    ASSERT_EQ(mesh.n_faces(), static_cast<std::size_t>(2 * nx * ny));
    for (int j = 0; j <= ny; ++j) {
      for (int i = 0; i <= nx; ++i) {
        const Vec3& p = mesh.point(VertexHandle(j * (nx + 1) + i));
        EXPECT_DOUBLE_EQ(p[0], width * i / nx);
        EXPECT_DOUBLE_EQ(p[1], height * j / ny);
      }
    }
    expect_flat_and_up(mesh);
    EXPECT_NEAR(surface_area(mesh), width * height, 1e-12);
    EXPECT_EQ(boundary_halfedges(mesh), static_cast<std::size_t>(2 * (nx + ny)));
    EXPECT_EQ(boundary_loops(mesh).size(), 1u);
  }
}

TEST(PrimitivesGrid, InteriorValencesFollowTheSplit) {
  const int nx = 6;
  const int ny = 4;
  const Mesh uniform = make_grid(nx, ny, 1.0, 1.0, GridSplit::Uniform);
  const Mesh alternating = make_grid(nx, ny, 1.0, 1.0, GridSplit::Alternating);
  for (int j = 1; j < ny; ++j) {
    for (int i = 1; i < nx; ++i) {
      const VertexHandle v(j * (nx + 1) + i);
      ASSERT_FALSE(uniform.is_boundary(v));
      EXPECT_EQ(uniform.valence(v), 6u);
      EXPECT_EQ(alternating.valence(v), (i + j) % 2 == 0 ? 8u : 4u);
    }
  }
}

TEST(PrimitivesEquilateralGrid, EveryEdgeHasTheGivenLengthAndInteriorValenceIsSix) {
  const int nx = 7;
  const int ny = 5;
  const double edge = 0.3;
  const Mesh mesh = make_equilateral_grid(nx, ny, edge);
  ASSERT_EQ(mesh.n_vertices(), static_cast<std::size_t>((nx + 1) * (ny + 1)));
  ASSERT_EQ(mesh.n_faces(), static_cast<std::size_t>(2 * nx * ny));
  expect_flat_and_up(mesh);
  for (const EdgeHandle e : mesh.edges()) EXPECT_NEAR(mesh.calc_edge_length(e), edge, 1e-15);
  // Each face is equilateral, so the area is F (sqrt(3)/4) edge^2.
  EXPECT_NEAR(surface_area(mesh), 2 * nx * ny * std::sqrt(3.0) / 4.0 * edge * edge, 1e-13);
  std::size_t interior = 0;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const VertexHandle v(j * (nx + 1) + i);
      const bool expect_interior = 0 < i && i < nx && 0 < j && j < ny;
      EXPECT_EQ(!mesh.is_boundary(v), expect_interior) << "vertex (" << i << ", " << j << ")";
      if (expect_interior) {
        EXPECT_EQ(mesh.valence(v), 6u);
        ++interior;
      }
    }
  }
  EXPECT_EQ(interior, static_cast<std::size_t>((nx - 1) * (ny - 1)));
  EXPECT_EQ(boundary_loops(mesh).size(), 1u);
}

TEST(PrimitivesDisc, CountsRingsAreaAndOneBoundaryLoop) {
  for (const auto& [rings, segments] : std::vector<std::pair<int, int>>{{1, 3}, {4, 6}, {7, 5}}) {
    const double radius = 1.7;
    const Mesh mesh = make_disc(rings, segments, radius);
    ASSERT_EQ(mesh.n_vertices(), static_cast<std::size_t>(1 + segments * rings * (rings + 1) / 2));
    ASSERT_EQ(mesh.n_faces(), static_cast<std::size_t>(segments * rings * rings));
    expect_flat_and_up(mesh);
    EXPECT_EQ(mesh.point(VertexHandle(0)), Vec3(0.0, 0.0, 0.0));
    EXPECT_EQ(mesh.valence(VertexHandle(0)), static_cast<unsigned>(segments));
    // Ring k has k * segments vertices at radius k * radius / rings.
    int index = 1;
    for (int k = 1; k <= rings; ++k) {
      for (int m = 0; m < k * segments; ++m, ++index) {
        EXPECT_NEAR(mesh.point(VertexHandle(index)).norm(), radius * k / rings, 1e-14);
      }
    }
    // The triangles tile the outer ring's polygon exactly.
    EXPECT_NEAR(surface_area(mesh), polygon_area(rings * segments, radius), 1e-12);
    const auto loops = boundary_loops(mesh);
    ASSERT_EQ(loops.size(), 1u);
    EXPECT_EQ(loops[0].size(), static_cast<std::size_t>(rings * segments));
  }
}

TEST(PrimitivesAnnulus, CountsAreaAndTwoBoundaryLoops) {
  const int rings = 3;
  const int segments = 16;
  const double inner = 0.5;
  const double outer = 2.0;
  const Mesh mesh = make_annulus(rings, segments, inner, outer);
  ASSERT_EQ(mesh.n_vertices(), static_cast<std::size_t>((rings + 1) * segments));
  ASSERT_EQ(mesh.n_faces(), static_cast<std::size_t>(2 * rings * segments));
  expect_flat_and_up(mesh);
  for (int k = 0; k <= rings; ++k) {
    for (int s = 0; s < segments; ++s) {
      EXPECT_NEAR(mesh.point(VertexHandle(k * segments + s)).norm(),
                  inner + (outer - inner) * k / rings, 1e-14);
    }
  }
  EXPECT_NEAR(surface_area(mesh), polygon_area(segments, outer) - polygon_area(segments, inner),
              1e-12);
  const auto loops = boundary_loops(mesh);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_EQ(loops[0].size(), static_cast<std::size_t>(segments));
  EXPECT_EQ(loops[1].size(), static_cast<std::size_t>(segments));
}

TEST(PrimitivesIcosphere, CountsOnTheSphereOutwardAndValences) {
  const double radius = 2.5;
  for (int s = 0; s <= 4; ++s) {
    const Mesh mesh = make_icosphere(s, radius);
    const std::size_t power = std::size_t{1} << (2 * s); // 4^s
    ASSERT_EQ(mesh.n_vertices(), 10 * power + 2);
    ASSERT_EQ(mesh.n_faces(), 20 * power);
    ASSERT_EQ(mesh.n_edges(), 30 * power);
    std::size_t valence5 = 0;
    for (const VertexHandle v : mesh.vertices()) {
      EXPECT_NEAR(mesh.point(v).norm(), radius, 1e-14 * radius);
      const unsigned valence = mesh.valence(v);
      EXPECT_TRUE(valence == 5 || valence == 6);
      valence5 += valence == 5 ? 1 : 0;
    }
    EXPECT_EQ(valence5, 12u);
    for (const FaceHandle f : mesh.faces()) {
      EXPECT_GT(area_normal(mesh, f) | centroid(mesh, f), 0.0);
    }
    EXPECT_EQ(boundary_halfedges(mesh), 0u);
    // The inscribed polyhedron's volume is below the ball's and converges to it.
    EXPECT_GT(signed_volume(mesh), 0.0);
    EXPECT_LT(signed_volume(mesh), 4.0 / 3.0 * kPi * radius * radius * radius);
  }
  const double ball = 4.0 / 3.0 * kPi;
  EXPECT_LT(ball - signed_volume(make_icosphere(4)), ball - signed_volume(make_icosphere(3)));
}

TEST(PrimitivesCube, CountsSurfaceAreaVolumeAndOrientation) {
  const double size = 3.0;
  for (int n = 1; n <= 5; ++n) {
    const Mesh mesh = make_cube(n, size);
    ASSERT_EQ(mesh.n_vertices(), static_cast<std::size_t>(6 * n * n + 2));
    ASSERT_EQ(mesh.n_faces(), static_cast<std::size_t>(12 * n * n));
    for (const VertexHandle v : mesh.vertices()) {
      const Vec3& p = mesh.point(v);
      EXPECT_EQ(std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}), size / 2);
    }
    const double h = size / n;
    for (const FaceHandle f : mesh.faces()) {
      EXPECT_NEAR(face_area(mesh, f), h * h / 2, 1e-14);
      EXPECT_GT(area_normal(mesh, f) | centroid(mesh, f), 0.0);
    }
    EXPECT_NEAR(surface_area(mesh), 6 * size * size, 1e-12);
    EXPECT_NEAR(signed_volume(mesh), size * size * size, 1e-12);
    EXPECT_EQ(boundary_halfedges(mesh), 0u);
  }
}

TEST(PrimitivesTorus, CountsOnTheTubeOutwardGenusOneAndVolume) {
  const double big = 2.0, small = 0.5;
  double previous_gap = std::numeric_limits<double>::infinity();
  for (const int k : {8, 16, 32}) {
    const Mesh mesh = make_torus(2 * k, k, big, small);
    ASSERT_EQ(mesh.n_vertices(), static_cast<std::size_t>(2 * k * k));
    ASSERT_EQ(mesh.n_faces(), static_cast<std::size_t>(4 * k * k));
    // Euler characteristic 0, closed: genus 1.
    const auto chi = static_cast<long>(mesh.n_vertices()) - static_cast<long>(mesh.n_edges()) +
                     static_cast<long>(mesh.n_faces());
    EXPECT_EQ(chi, 0);
    EXPECT_EQ(boundary_halfedges(mesh), 0u);
    // Every vertex lies on the tube: at distance r from the centre circle.
    for (const VertexHandle v : mesh.vertices()) {
      const Vec3& p = mesh.point(v);
      EXPECT_NEAR(std::hypot(std::hypot(p[0], p[1]) - big, p[2]), small, 1e-14);
    }
    // Outward: each face's normal points away from the tube's centre circle.
    for (const FaceHandle f : mesh.faces()) {
      const Vec3 c = centroid(mesh, f);
      const double rho = std::hypot(c[0], c[1]);
      const Vec3 axis(c[0] * big / rho, c[1] * big / rho, 0.0);
      EXPECT_GT(area_normal(mesh, f) | (c - axis), 0.0);
    }
    // The inscribed polyhedron's volume approaches 2 pi^2 R r^2 from below.
    const double gap = 2 * kPi * kPi * big * small * small - signed_volume(mesh);
    EXPECT_GT(gap, 0.0);
    EXPECT_LT(gap, previous_gap);
    previous_gap = gap;
  }
  EXPECT_LT(previous_gap, 0.01 * 2 * kPi * kPi * big * small * small);
}

bool same_bits(const Mesh& a, const Mesh& b) {
  if (a.n_vertices() != b.n_vertices() || a.n_faces() != b.n_faces()) return false;
  for (const VertexHandle v : a.vertices()) {
    if (std::memcmp(a.point(v).data(), b.point(v).data(), 3 * sizeof(double)) != 0) return false;
  }
  for (const FaceHandle f : a.faces()) {
    auto va = a.cfv_iter(f);
    auto vb = b.cfv_iter(f);
    for (int i = 0; i < 3; ++i, ++va, ++vb) {
      if (*va != *vb) return false;
    }
  }
  return true;
}

TEST(PrimitivesDeterminism, TheSameArgumentsGiveTheSameMeshBitForBit) {
  EXPECT_TRUE(same_bits(make_grid(4, 3, 1.0, 2.0), make_grid(4, 3, 1.0, 2.0)));
  EXPECT_TRUE(same_bits(make_equilateral_grid(4, 3, 0.1), make_equilateral_grid(4, 3, 0.1)));
  EXPECT_TRUE(same_bits(make_disc(5, 6, 1.0), make_disc(5, 6, 1.0)));
  EXPECT_TRUE(same_bits(make_annulus(2, 9, 0.3, 1.0), make_annulus(2, 9, 0.3, 1.0)));
  EXPECT_TRUE(same_bits(make_icosphere(3, 1.5), make_icosphere(3, 1.5)));
  EXPECT_TRUE(same_bits(make_cube(3, 2.0), make_cube(3, 2.0)));
  EXPECT_TRUE(same_bits(make_torus(9, 5, 2.0, 0.5), make_torus(9, 5, 2.0, 0.5)));
}

TEST(PrimitivesArguments, InvalidArgumentsThrow) {
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(make_grid(0, 1, 1.0, 1.0), InvalidArgument);
  EXPECT_THROW(make_grid(1, -2, 1.0, 1.0), InvalidArgument);
  EXPECT_THROW(make_grid(1, 1, 0.0, 1.0), InvalidArgument);
  EXPECT_THROW(make_grid(1, 1, 1.0, nan), InvalidArgument);
  EXPECT_THROW(make_grid(100000, 100000, 1.0, 1.0), InvalidArgument);
  EXPECT_THROW(make_equilateral_grid(1, 0, 1.0), InvalidArgument);
  EXPECT_THROW(make_equilateral_grid(1, 1, -1.0), InvalidArgument);
  EXPECT_THROW(make_disc(0, 6, 1.0), InvalidArgument);
  EXPECT_THROW(make_disc(1, 2, 1.0), InvalidArgument);
  EXPECT_THROW(make_disc(1, 6, inf), InvalidArgument);
  EXPECT_THROW(make_annulus(1, 8, 1.0, 1.0), InvalidArgument);
  EXPECT_THROW(make_annulus(1, 8, 2.0, 1.0), InvalidArgument);
  EXPECT_THROW(make_annulus(1, 8, 0.0, 1.0), InvalidArgument);
  EXPECT_THROW(make_icosphere(-1), InvalidArgument);
  EXPECT_THROW(make_icosphere(13), InvalidArgument);
  EXPECT_THROW(make_icosphere(1, 0.0), InvalidArgument);
  EXPECT_THROW(make_cube(0, 1.0), InvalidArgument);
  EXPECT_THROW(make_cube(2, nan), InvalidArgument);
  EXPECT_THROW(make_torus(2, 8, 2.0, 0.5), InvalidArgument);
  EXPECT_THROW(make_torus(8, 2, 2.0, 0.5), InvalidArgument);
  EXPECT_THROW(make_torus(8, 8, 1.0, 1.0), InvalidArgument);
  EXPECT_THROW(make_torus(8, 8, 2.0, 0.0), InvalidArgument);
  EXPECT_THROW(make_torus(8, 8, inf, 0.5), InvalidArgument);
}

} // namespace
} // namespace remora
