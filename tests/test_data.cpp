// Acceptance on the real meshes of ../shared/data (see its MANIFEST.md): every face of the file is
// either loaded or dropped with a stated reason, and the known traps come out right. Skipped, with
// a message, when the folder is absent; the bundled bunny is always checked.
#include <filesystem>
#include <sstream>

#include <OpenMesh/Tools/Utils/MeshCheckerT.hh>
#include <gtest/gtest.h>

#include "remora/mesh/io.h"
#include "remora/mesh/topology.h"
#include "support.h"

namespace remora {
namespace {

using testing::expect_valid_halfedge_mesh;
using testing::signed_volume;

namespace fs = std::filesystem;

std::string shared_path(const std::string& rel) {
  if (const char* env = std::getenv("REMORA_DATA")) return std::string(env) + "/" + rel;
  return std::string(REMORA_SHARED_DATA) + "/" + rel;
}

struct CatalogueEntry {
  const char* path;
  std::size_t vertices;          // referenced vertices in the file (MANIFEST's V)
  std::size_t faces;             // faces in the file (MANIFEST's F)
  std::size_t boundary_loops;    // after repair (lato000: a pinch turns one loop into two;
                                 // featuretype: MANIFEST's 16 crack loops closed by the near weld)
  std::size_t components;        // in the file, through shared vertices (MANIFEST's comps)
  std::size_t components_loaded; // edge-connected, after pinch vertices are split
};

// From ../shared/data/MANIFEST.md.
const CatalogueEntry kCatalogue[] = {
    {"cad/conrod.stl", 3223, 6442, 0, 1, 1},
    {"cad/fandisk.obj", 6475, 12946, 0, 1, 1},
    {"cad/featuretype.STL", 2010, 3476, 0, 1, 1},
    {"cad/gears.stl", 9723, 19426, 0, 7, 7},
    {"genus/fertility.off", 4494, 9000, 0, 1, 1},
    {"heightfield/AcrossRiver.stl", 10464, 20520, 1, 1, 1},
    {"open/camelhead.off", 11381, 22704, 1, 1, 1},
    {"scans/bunny.ply", 34834, 69451, 5, 1, 1},
    {"scans/lucy.ply", 49987, 99970, 0, 1, 1},
    {"cad/blade.off", 8231, 16222, 2, 1, 1},
    {"open/lato000.ply", 44269, 86766, 19, 9, 10},
    {"scans/armadillo.obj", 43243, 86482, 0, 1, 1},
    {"scans/decimated-max.obj", 5272, 10540, 0, 1, 1},
    {"scans/igea.ply", 134345, 268686, 0, 1, 1},
};

// Names the mesh in test listings instead of dumping the struct's bytes.
void PrintTo(const CatalogueEntry& e, std::ostream* os) {
  *os << e.path;
}

class DataCatalogue : public ::testing::TestWithParam<CatalogueEntry> {};

TEST_P(DataCatalogue, EveryFaceIsLoadedOrDroppedWithAReason) {
  const CatalogueEntry& e = GetParam();
  const std::string path = shared_path(e.path);
  if (!fs::exists(path)) GTEST_SKIP() << path << " not present (../shared/data is optional)";
  const LoadResult r = read_mesh(path);
  const RepairReport& rep = r.report.repair;
  EXPECT_EQ(r.report.file.faces_in_file, rep.polygons_in);
  EXPECT_EQ(rep.triangles_in(), rep.faces_loaded + rep.faces_dropped());
  EXPECT_EQ(rep.faces_detached, 0u);
  EXPECT_EQ(rep.orientation_cuts, 0u);
  expect_valid_halfedge_mesh(r.mesh);

  // The file's referenced vertices, less those merged by welding, are all there (splitting
  // non-manifold vertices only adds copies).
  EXPECT_EQ(rep.vertices_in - rep.unreferenced_vertices, e.vertices + rep.welded_vertices)
      << "welded " << rep.welded_vertices;
  EXPECT_EQ(rep.components_in, e.components);
  EXPECT_EQ(rep.vertices_loaded + rep.near_welded_vertices + rep.orphaned_vertices,
            e.vertices + rep.vertices_added_by_split);
  EXPECT_EQ(connected_components(r.mesh).count, static_cast<int>(e.components_loaded));
  EXPECT_EQ(boundary_loops(r.mesh).size(), e.boundary_loops);
  // MANIFEST's F counts the faces loaded; for igea's tristrips the file also encodes the swap
  // triangles, which are dropped as repeated-vertex triangles.
  EXPECT_EQ(rep.polygons_in - rep.dropped_repeated_vertex, e.faces);
}

INSTANTIATE_TEST_SUITE_P(SharedData, DataCatalogue, ::testing::ValuesIn(kCatalogue),
                         [](const ::testing::TestParamInfo<CatalogueEntry>& param) {
                           std::string label = param.param.path;
                           for (char& c : label)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return label;
                         });

// MANIFEST: "16 crack loops between CAD patches". They are seams whose two sides differ by
// 2.7e-16 in z; the near weld (1e-10 of the diagonal) closes every one, and nothing else.
TEST(DataAcceptance, FeaturetypesCracksCloseUnderTheNearWeld) {
  const std::string path = shared_path("cad/featuretype.STL");
  if (!fs::exists(path)) GTEST_SKIP() << path << " not present";
  const LoadResult r = read_mesh(path);
  EXPECT_EQ(r.report.repair.near_welded_vertices, 288u);
  EXPECT_EQ(boundary_loops(r.mesh).size(), 0u);
  const auto topo = component_topology(r.mesh);
  ASSERT_EQ(topo.size(), 1u);
  EXPECT_TRUE(topo[0].closed);
  EXPECT_GT(signed_volume(r.mesh), 0.0);

  RepairOptions exact;
  exact.weld_tolerance = 0;
  EXPECT_EQ(boundary_loops(read_mesh(path, exact).mesh).size(), 16u);
}

TEST(DataAcceptance, ConrodBecomesOneClosedOutwardComponent) {
  const std::string path = shared_path("cad/conrod.stl");
  if (!fs::exists(path)) GTEST_SKIP() << path << " not present";
  const LoadResult r = read_mesh(path);
  EXPECT_EQ(connected_components(r.mesh).count, 1);
  for (auto h : r.mesh.halfedges()) ASSERT_FALSE(r.mesh.is_boundary(h));
  EXPECT_GT(signed_volume(r.mesh), 0.0);
  EXPECT_EQ(r.report.repair.dropped_flap, 6u); // three doubled flaps
  EXPECT_EQ(r.report.repair.dropped_duplicate, 0u);
  EXPECT_EQ(r.report.repair.nonmanifold_edges, 0u);
  EXPECT_GT(r.report.repair.flipped_faces, 0u);
  const auto topo = component_topology(r.mesh);
  ASSERT_EQ(topo.size(), 1u);
  EXPECT_TRUE(topo[0].closed);
}

TEST(DataAcceptance, IgeaTristripsYieldAllFaces) {
  const std::string path = shared_path("scans/igea.ply");
  if (!fs::exists(path)) GTEST_SKIP() << path << " not present";
  const LoadResult r = read_mesh(path);
  EXPECT_EQ(r.mesh.n_faces(), 268686u);
  EXPECT_EQ(r.report.repair.dropped_repeated_vertex,
            r.report.file.faces_in_file - 268686u); // the strips' swap triangles
}

TEST(DataAcceptance, BunnyReportsItsUnreferencedVertices) {
  for (const std::string& path :
       {std::string(REMORA_REPO_DATA) + "/bunny.ply", shared_path("scans/bunny.ply")}) {
    if (!fs::exists(path)) continue;
    const LoadResult r = read_mesh(path);
    EXPECT_EQ(r.report.repair.unreferenced_vertices, 1113u) << path;
    EXPECT_EQ(r.mesh.n_vertices(), 34834u) << path;
    EXPECT_EQ(r.mesh.n_faces(), 69451u) << path;
  }
}

TEST(DataAcceptance, Lato000ReportsItsPinchVerticesAndLoadsAllComponents) {
  const std::string path = shared_path("open/lato000.ply");
  if (!fs::exists(path)) GTEST_SKIP() << path << " not present";
  const LoadResult r = read_mesh(path);
  EXPECT_EQ(r.report.repair.split_vertices, 2u);
  EXPECT_EQ(r.report.repair.unreferenced_vertices, 192u);
  EXPECT_EQ(r.mesh.n_faces(), 86766u);
  EXPECT_EQ(r.report.repair.components_in, 9u);
  EXPECT_EQ(connected_components(r.mesh).count, 10);
  ASSERT_FALSE(r.report.file.skipped.empty());
  EXPECT_NE(r.report.file.skipped[0].find("camera"), std::string::npos);
}

} // namespace
} // namespace remora
