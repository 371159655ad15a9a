// Longest-edge bisection of a region (mesh/refine.h): every edge inside the region ends at most
// as long as asked, the surface does not change (area, every new vertex on the old surface), the
// old vertices and the faces outside stay, the mesh stays a valid closed one; an editor on the
// refined support no longer reports it as too coarse.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/primitives.h"
#include "remora/mesh/refine.h"
#include "remora/multires/editor.h"
#include "support.h"

namespace remora {
namespace {

double area(const Mesh& m) {
  double a = 0.0;
  for (const FaceHandle f : m.faces()) a += m.calc_face_area(f);
  return a;
}

TEST(Refine, SplitsTheRegionsEdgesAndLeavesTheSurfaceAndTheRest) {
  Mesh cube = make_cube(1, 1.0);
  const Mesh before = cube;
  std::vector<int> top; // the upper face's corners
  for (const VertexHandle v : cube.vertices())
    if (cube.point(v)[2] > 0.0) top.push_back(v.idx());
  ASSERT_EQ(top.size(), 4u);
  const RefineResult r = refine_region(cube, top, 0.3, 1000);
  EXPECT_GT(r.added, 0u);
  EXPECT_EQ(cube.n_vertices(), before.n_vertices() + r.added);
  EXPECT_EQ(r.region.size(), top.size() + r.added);
  for (const EdgeHandle e : cube.edges()) {
    const HalfedgeHandle h = cube.halfedge_handle(e, 0);
    const bool inside = cube.point(cube.from_vertex_handle(h))[2] > 0.0 &&
                        cube.point(cube.to_vertex_handle(h))[2] > 0.0;
    if (inside) {
      EXPECT_LE(cube.calc_edge_length(e), 0.3 + 1e-12);
    }
  }
  for (const VertexHandle v : before.vertices()) EXPECT_EQ(cube.point(v), before.point(v));
  for (std::size_t v = before.n_vertices(); v < cube.n_vertices(); ++v) // on the top face
    EXPECT_EQ(cube.point(VertexHandle(static_cast<int>(v)))[2], 0.5);
  EXPECT_NEAR(area(cube), 6.0, 1e-12);
  testing::expect_valid_halfedge_mesh(cube);
  EXPECT_EQ(static_cast<int>(cube.n_vertices()) - static_cast<int>(cube.n_edges()) +
                static_cast<int>(cube.n_faces()),
            2);
  // The bottom face (no edge inside the region) keeps its two triangles.
  int bottom = 0;
  for (const FaceHandle f : cube.faces()) {
    bool low = true;
    for (const VertexHandle v : cube.fv_range(f)) low = low && cube.point(v)[2] < 0.0;
    bottom += low ? 1 : 0;
  }
  EXPECT_EQ(bottom, 2);
}

TEST(Refine, RefusesBadInputAndLeavesTheMeshWhenTooManyVerticesWouldCome) {
  Mesh cube = make_cube(1, 1.0);
  const Mesh before = cube;
  EXPECT_THROW(refine_region(cube, {0, 99}, 0.3, 1000), InvalidArgument);
  EXPECT_THROW(refine_region(cube, {0, 1}, 0.0, 1000), InvalidArgument);
  std::vector<int> all;
  for (const VertexHandle v : cube.vertices()) all.push_back(v.idx());
  try {
    refine_region(cube, all, 0.01, 100);
    ADD_FAILURE() << "no exception";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("would pass 100 vertices"), std::string::npos) << e.what();
  }
  EXPECT_EQ(cube.n_vertices(), before.n_vertices());
  EXPECT_EQ(cube.n_faces(), before.n_faces());
}

// A support reported as too coarse for a fine base is not, once refined to the base's length.
TEST(Refine, TheRefinedSupportIsNoLongerTooCoarse) {
  Mesh mesh = make_icosphere(3, 1.0);
  const auto support = select_sphere(mesh, Vec3(0, 0, 1), 0.8);
  const auto handle = select_sphere(mesh, Vec3(0, 0, 1), 0.2);
  EditorOptions o;
  o.remesh_options.target_length = mean_edge_length(mesh) / 6.0;
  Editor coarse(mesh, o);
  coarse.set_region(support, {handle});
  EXPECT_FALSE(coarse.report().coarse_support.empty());
  const RefineResult r = refine_region(mesh, support, o.remesh_options.target_length, 1000000);
  Editor refined(mesh, o);
  refined.set_region(r.region, {handle});
  EXPECT_LE(refined.report().support_edge_ratio, 1.0 + 1e-9);
  EXPECT_TRUE(refined.report().coarse_support.empty());
}

} // namespace
} // namespace remora
