// Topology: components, boundary loops, Euler characteristic and genus on meshes whose values are
// known in closed form (spheres, a torus, a torus with a hole, an annulus, disjoint unions), and
// on meshes holding deleted elements before garbage collection.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "remora/mesh/primitives.h"
#include "remora/mesh/topology.h"

namespace remora {
namespace {

/// An (m x n) quad torus, each quad split into two triangles: V = m n, E = 3 m n, F = 2 m n.
Mesh make_torus(int m, int n, double major_radius, double minor_radius) {
  Mesh mesh;
  for (int i = 0; i < m; ++i) {
    const double theta = 2.0 * std::numbers::pi * i / m;
    for (int j = 0; j < n; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / n;
      const double r = major_radius + minor_radius * std::cos(phi);
      mesh.add_vertex(Vec3(r * std::cos(theta), r * std::sin(theta), minor_radius * std::sin(phi)));
    }
  }
  const auto v = [m, n](int i, int j) { return VertexHandle((i % m) * n + j % n); };
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) {
      EXPECT_TRUE(mesh.add_face(v(i, j), v(i + 1, j), v(i + 1, j + 1)).is_valid());
      EXPECT_TRUE(mesh.add_face(v(i, j), v(i + 1, j + 1), v(i, j + 1)).is_valid());
    }
  }
  return mesh;
}

/// Appends a translated copy of `source` to `target`.
void append(Mesh& target, const Mesh& source, const Vec3& offset) {
  const int base = static_cast<int>(target.n_vertices());
  for (const VertexHandle v : source.vertices()) target.add_vertex(source.point(v) + offset);
  for (const FaceHandle f : source.faces()) {
    std::vector<VertexHandle> corners;
    for (const VertexHandle v : source.fv_range(f)) corners.emplace_back(base + v.idx());
    ASSERT_TRUE(target.add_face(corners).is_valid());
  }
}

void expect_topology(const ComponentTopology& c, int euler, int boundary_loops, int genus) {
  EXPECT_EQ(c.euler, c.vertices - c.edges + c.faces);
  EXPECT_EQ(c.euler, euler);
  EXPECT_EQ(c.boundary_loops, boundary_loops);
  EXPECT_EQ(c.genus, genus);
  EXPECT_EQ(c.closed, boundary_loops == 0 && c.faces > 0);
}

/// Shoelace area of the polygon through the loop's vertices (projected to z = 0).
double signed_area_xy(const Mesh& mesh, const std::vector<HalfedgeHandle>& loop) {
  double area = 0.0;
  for (const HalfedgeHandle h : loop) {
    const Vec3& p = mesh.point(mesh.from_vertex_handle(h));
    const Vec3& q = mesh.point(mesh.to_vertex_handle(h));
    area += 0.5 * (p[0] * q[1] - q[0] * p[1]);
  }
  return area;
}

TEST(TopologySphere, IcosphereAndCubeHaveEulerTwoGenusZero) {
  for (int s = 0; s <= 3; ++s) {
    const Mesh mesh = make_icosphere(s);
    const auto topology = component_topology(mesh);
    ASSERT_EQ(topology.size(), 1u);
    expect_topology(topology[0], 2, 0, 0);
    EXPECT_EQ(topology[0].vertices, static_cast<int>(mesh.n_vertices()));
    EXPECT_EQ(topology[0].faces, static_cast<int>(mesh.n_faces()));
    EXPECT_TRUE(boundary_loops(mesh).empty());
  }
  for (int n = 1; n <= 4; ++n) {
    const auto topology = component_topology(make_cube(n, 1.0));
    ASSERT_EQ(topology.size(), 1u);
    expect_topology(topology[0], 2, 0, 0);
    EXPECT_EQ(topology[0].vertices, 6 * n * n + 2);
  }
}

TEST(TopologyTorus, ClosedTorusHasGenusOne) {
  const Mesh mesh = make_torus(12, 7, 2.0, 0.5);
  const auto topology = component_topology(mesh);
  ASSERT_EQ(topology.size(), 1u);
  EXPECT_EQ(topology[0].vertices, 12 * 7);
  EXPECT_EQ(topology[0].edges, 3 * 12 * 7);
  EXPECT_EQ(topology[0].faces, 2 * 12 * 7);
  expect_topology(topology[0], 0, 0, 1);
}

TEST(TopologyTorus, TorusWithAHoleKeepsGenusOne) {
  // Deleting one face (not garbage-collected) leaves one boundary loop: euler = -1, b = 1, g = 1.
  Mesh mesh = make_torus(9, 6, 2.0, 0.5);
  mesh.delete_face(FaceHandle(10), false);
  const auto topology = component_topology(mesh);
  ASSERT_EQ(topology.size(), 1u);
  EXPECT_EQ(topology[0].faces, 2 * 9 * 6 - 1);
  expect_topology(topology[0], -1, 1, 1);
  const auto loops = boundary_loops(mesh);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].size(), 3u);
}

TEST(TopologyBoundary, AnnulusHasTwoLoopsOuterClockwiseHoleCounterClockwise) {
  const int segments = 20;
  const Mesh mesh = make_annulus(3, segments, 0.5, 1.5);
  const auto topology = component_topology(mesh);
  ASSERT_EQ(topology.size(), 1u);
  expect_topology(topology[0], 0, 2, 0);

  const auto loops = boundary_loops(mesh);
  ASSERT_EQ(loops.size(), 2u);
  int outer = 0;
  int hole = 0;
  for (const auto& loop : loops) {
    ASSERT_EQ(loop.size(), static_cast<std::size_t>(segments));
    for (std::size_t k = 0; k < loop.size(); ++k) {
      EXPECT_TRUE(mesh.is_boundary(loop[k]));
      // Consecutive in next_halfedge order.
      EXPECT_EQ(mesh.next_halfedge_handle(loop[k]), loop[(k + 1) % loop.size()]);
    }
    // The mesh lies to the right: the outer loop is clockwise, the hole counter-clockwise.
    const double radius = mesh.point(mesh.to_vertex_handle(loop[0])).norm();
    if (radius > 1.0) {
      ++outer;
      EXPECT_LT(signed_area_xy(mesh, loop), 0.0);
    } else {
      ++hole;
      EXPECT_GT(signed_area_xy(mesh, loop), 0.0);
    }
  }
  EXPECT_EQ(outer, 1);
  EXPECT_EQ(hole, 1);
  // Loops are ordered by their smallest halfedge index and start there.
  EXPECT_LT(loops[0][0].idx(), loops[1][0].idx());
  for (const auto& loop : loops) {
    for (const HalfedgeHandle h : loop) EXPECT_LE(loop[0].idx(), h.idx());
  }
}

TEST(TopologyBoundary, DiscAndGridAreTopologicalDiscs) {
  expect_topology(component_topology(make_disc(4, 6, 1.0)).at(0), 1, 1, 0);
  expect_topology(component_topology(make_grid(3, 5, 1.0, 1.0)).at(0), 1, 1, 0);
  expect_topology(component_topology(make_equilateral_grid(4, 4, 1.0)).at(0), 1, 1, 0);
}

TEST(TopologyBoundary, DeletingAnInteriorFaceOpensASecondLoop) {
  Mesh mesh = make_grid(3, 3, 1.0, 1.0, GridSplit::Uniform);
  // Quad (1, 1) has only interior corners; its first triangle is face 2 (j 3 + i).
  mesh.delete_face(FaceHandle(2 * (1 * 3 + 1)), false);
  const auto loops = boundary_loops(mesh);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_EQ(loops[0].size() + loops[1].size(), 12u + 3u);
  const auto topology = component_topology(mesh);
  ASSERT_EQ(topology.size(), 1u);
  expect_topology(topology[0], 0, 2, 0);
}

TEST(TopologyComponents, TwoSpheresAreTwoComponents) {
  Mesh mesh = make_icosphere(2);
  const std::size_t first_vertices = mesh.n_vertices();
  const std::size_t first_faces = mesh.n_faces();
  append(mesh, make_icosphere(1), Vec3(5.0, 0.0, 0.0));
  const Components components = connected_components(mesh);
  ASSERT_EQ(components.count, 2);
  ASSERT_EQ(components.vertex_component.size(), mesh.n_vertices());
  ASSERT_EQ(components.face_component.size(), mesh.n_faces());
  for (const VertexHandle v : mesh.vertices()) {
    EXPECT_EQ(components.vertex_component[v.idx()],
              static_cast<std::size_t>(v.idx()) < first_vertices ? 0 : 1);
  }
  for (const FaceHandle f : mesh.faces()) {
    EXPECT_EQ(components.face_component[f.idx()],
              static_cast<std::size_t>(f.idx()) < first_faces ? 0 : 1);
    for (const VertexHandle v : mesh.fv_range(f)) {
      EXPECT_EQ(components.vertex_component[v.idx()], components.face_component[f.idx()]);
    }
  }
  const auto topology = component_topology(mesh);
  ASSERT_EQ(topology.size(), 2u);
  expect_topology(topology[0], 2, 0, 0);
  expect_topology(topology[1], 2, 0, 0);
  EXPECT_EQ(topology[0].vertices + topology[1].vertices, static_cast<int>(mesh.n_vertices()));
}

TEST(TopologyComponents, SphereTorusAndAnnulusTogether) {
  Mesh mesh = make_icosphere(1);
  append(mesh, make_torus(8, 5, 2.0, 0.5), Vec3(10.0, 0.0, 0.0));
  append(mesh, make_annulus(2, 12, 1.0, 2.0), Vec3(-10.0, 0.0, 0.0));
  const auto topology = component_topology(mesh);
  ASSERT_EQ(topology.size(), 3u);
  expect_topology(topology[0], 2, 0, 0);
  expect_topology(topology[1], 0, 0, 1);
  expect_topology(topology[2], 0, 2, 0);
  EXPECT_EQ(boundary_loops(mesh).size(), 2u);
}

TEST(TopologyComponents, IsolatedVertexIsItsOwnComponent) {
  Mesh mesh;
  const VertexHandle a = mesh.add_vertex(Vec3(0, 0, 0));
  const VertexHandle b = mesh.add_vertex(Vec3(1, 0, 0));
  const VertexHandle lone = mesh.add_vertex(Vec3(5, 5, 5));
  const VertexHandle c = mesh.add_vertex(Vec3(0, 1, 0));
  mesh.add_face(a, b, c);
  const Components components = connected_components(mesh);
  ASSERT_EQ(components.count, 2);
  // Numbered in the order of their smallest vertex index.
  EXPECT_EQ(components.vertex_component[a.idx()], 0);
  EXPECT_EQ(components.vertex_component[c.idx()], 0);
  EXPECT_EQ(components.vertex_component[lone.idx()], 1);
  const auto topology = component_topology(mesh);
  ASSERT_EQ(topology.size(), 2u);
  expect_topology(topology[0], 1, 1, 0);
  EXPECT_EQ(topology[1].vertices, 1);
  EXPECT_EQ(topology[1].edges, 0);
  EXPECT_EQ(topology[1].faces, 0);
  EXPECT_EQ(topology[1].euler, 1);
  EXPECT_EQ(topology[1].genus, 0);
  EXPECT_FALSE(topology[1].closed);
}

TEST(TopologyDeleted, DeletedElementsAreSkippedAndMarked) {
  Mesh mesh = make_grid(1, 1, 1.0, 1.0, GridSplit::Uniform);
  // Face 1 is (v0, v3, v2); deleting it with its isolated vertex removes vertex 2 (0, 1).
  mesh.delete_face(FaceHandle(1), true);
  ASSERT_TRUE(mesh.status(VertexHandle(2)).deleted());
  ASSERT_EQ(mesh.n_vertices(), 4u); // not garbage-collected
  const Components components = connected_components(mesh);
  EXPECT_EQ(components.count, 1);
  EXPECT_EQ(components.vertex_component[2], -1);
  EXPECT_EQ(components.face_component[1], -1);
  EXPECT_EQ(components.face_component[0], 0);
  const auto loops = boundary_loops(mesh);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].size(), 3u);
  const auto topology = component_topology(mesh);
  ASSERT_EQ(topology.size(), 1u);
  EXPECT_EQ(topology[0].vertices, 3);
  EXPECT_EQ(topology[0].edges, 3);
  EXPECT_EQ(topology[0].faces, 1);
  expect_topology(topology[0], 1, 1, 0);
}

TEST(TopologyEmpty, EmptyMeshHasNothing) {
  const Mesh mesh;
  const Components components = connected_components(mesh);
  EXPECT_EQ(components.count, 0);
  EXPECT_TRUE(components.vertex_component.empty());
  EXPECT_TRUE(boundary_loops(mesh).empty());
  EXPECT_TRUE(component_topology(mesh).empty());
}

} // namespace
} // namespace remora
