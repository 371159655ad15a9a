// build_mesh(): direct half-edge construction from oriented manifold triangles.
#include <sstream>

#include <OpenMesh/Tools/Utils/MeshCheckerT.hh>
#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/mesh/build.h"
#include "remora/mesh/primitives.h"
#include "remora/mesh/surface_point.h"
#include "remora/mesh/topology.h"
#include "support.h"

namespace remora {
namespace {

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

void triangles_of(const Mesh& m, std::vector<Vec3>& points, Triangles& tris) {
  for (auto v : m.vertices()) points.push_back(m.point(v));
  for (auto f : m.faces()) {
    const auto v = face_vertices(m, f);
    tris.push_back({static_cast<std::uint32_t>(v[0].idx()), static_cast<std::uint32_t>(v[1].idx()),
                    static_cast<std::uint32_t>(v[2].idx())});
  }
}

TEST(BuildMesh, RebuildsClosedAndOpenMeshesExactly) {
  for (const Mesh& original : {make_icosphere(2), make_annulus(4, 24, 0.5, 1.0), make_cube(3, 1)}) {
    std::vector<Vec3> points;
    Triangles tris;
    triangles_of(original, points, tris);
    const Mesh m = build_mesh(points, tris);
    testing::expect_valid_halfedge_mesh(m);
    EXPECT_EQ(m.n_vertices(), original.n_vertices());
    EXPECT_EQ(m.n_faces(), original.n_faces());
    EXPECT_EQ(m.n_edges(), original.n_edges());
    EXPECT_EQ(boundary_loops(m).size(), boundary_loops(original).size());
    for (std::size_t f = 0; f < tris.size(); ++f) {
      const auto v = face_vertices(m, FaceHandle(static_cast<int>(f)));
      EXPECT_EQ(v[0].idx(), static_cast<int>(tris[f][0]));
      EXPECT_EQ(v[1].idx(), static_cast<int>(tris[f][1]));
      EXPECT_EQ(v[2].idx(), static_cast<int>(tris[f][2]));
    }
  }
}

TEST(BuildMesh, RejectsWhatIsNotAnOrientedManifold) {
  const std::vector<Vec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  EXPECT_THROW(build_mesh(p, Triangles{{0, 1, 9}}), InvalidArgument);            // out of range
  EXPECT_THROW(build_mesh(p, Triangles{{0, 1, 1}}), InvalidArgument);            // repeated vertex
  EXPECT_THROW(build_mesh(p, Triangles{{0, 1, 2}, {0, 1, 3}}), InvalidArgument); // same direction
  EXPECT_THROW(build_mesh(p, Triangles{{0, 1, 2}, {1, 0, 3}, {0, 1, 5}}), InvalidArgument);
  EXPECT_THROW(build_mesh(p, Triangles{{0, 1, 2}, {0, 4, 5}}), InvalidArgument); // bow tie
  EXPECT_NO_THROW(build_mesh(p, Triangles{{0, 1, 2}, {1, 3, 2}}));
}

} // namespace
} // namespace remora
