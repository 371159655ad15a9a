// The limits Remora's apps apply (docs/limits.md): the triangles a reader accepts (refused where
// the reader first learns of them, before it allocates for them), the default that follows from
// the machine's memory, the handles and region lists the server takes, and how deep EDIT.json's
// unions nest. Each is refused with a message that names it.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "remora/common/error.h"
#include "remora/common/memory.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/edit_request.h"
#include "remora/multires/editor.h"
#include "remora/multires/limits.h"
#include "server_support.h"
#include "session.h"

namespace remora {
namespace {

/// The message of the IoError reading `bytes` throws, or "" when it loads.
std::string refusal(const std::string& bytes, MeshFormat format, std::uint64_t max_triangles) {
  ReadLimits limits;
  limits.max_triangles = max_triangles;
  try {
    read_mesh_from_memory(bytes, format, "m", {}, limits);
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

TEST(Limits, EveryReaderRefusesAFileOverTheTriangleLimitWhereItLearnsOfIt) {
  const Mesh mesh = make_icosphere(2, 1.0); // 162 vertices, 320 faces
  ASSERT_EQ(mesh.n_faces(), 320u);
  struct Case {
    MeshFormat format;
    bool binary;
    std::string where; // where the refusal is placed in the file
  };
  const std::string triangles = ": over the limit of 100 triangles";
  const std::vector<Case> cases = {
      {MeshFormat::Ply, true, "line 8: the header declares 320 faces" + triangles},
      {MeshFormat::Ply, false, "line 8: the header declares 320 faces" + triangles},
      {MeshFormat::Off, false, "line 2: the header declares 320 faces" + triangles},
      {MeshFormat::Stl, true, "byte 80: the binary STL header declares 320 triangles" + triangles},
      // An STL's vertices come first: facet 101's first vertex is the 301st, over 3 per triangle.
      {MeshFormat::Stl, false, "line 704: more vertices: over the limit of 300 vertices"},
      {MeshFormat::Obj, false, "line 263: the faces make more triangles" + triangles}, // face 101
  };
  for (const Case& c : cases) {
    WriteOptions w;
    w.binary = c.binary;
    const std::string bytes = write_mesh_to_memory(mesh, c.format, "m", w);
    const std::string over = refusal(bytes, c.format, 100);
    EXPECT_NE(over.find(c.where), std::string::npos) << over;
    EXPECT_NE(over.find("--max-triangles"), std::string::npos) << over;
    EXPECT_EQ(refusal(bytes, c.format, 320), "") << c.where;
    EXPECT_NE(refusal(bytes, c.format, 319), "") << c.where;
    EXPECT_EQ(refusal(bytes, c.format, 0), "") << c.where; // 0: no limit
  }
}

TEST(Limits, PolygonsAndStripsCountTheTrianglesTheyMake) {
  // One convex polygon of 200 corners: 198 triangles. (Strings are built by appending: GCC 12
  // gives a false -Wrestrict on `"literal" + std::string`.)
  std::string obj, off = "OFF\n200 1 0\n";
  std::string face = "f", off_face = "200";
  for (int i = 0; i < 200; ++i) {
    const double a = 2 * M_PI * i / 200;
    std::string p = std::to_string(std::cos(a));
    p += ' ';
    p += std::to_string(std::sin(a));
    p += " 0\n";
    obj += "v ";
    obj += p;
    off += p;
    (face += ' ') += std::to_string(i + 1);
    (off_face += ' ') += std::to_string(i);
  }
  obj += face + "\n";
  off += off_face + "\n";
  EXPECT_NE(refusal(obj, MeshFormat::Obj, 197).find("line 201: the faces make more triangles"),
            std::string::npos);
  EXPECT_EQ(refusal(obj, MeshFormat::Obj, 198), "");
  // OFF declares one face: the header passes, the polygon's triangles do not.
  EXPECT_NE(refusal(off, MeshFormat::Off, 197).find("the faces make 198 triangles"),
            std::string::npos);
  // A tristrip of 12 indices: 10 triangles in one record.
  std::string strips = "ply\nformat ascii 1.0\nelement vertex 12\nproperty float x\nproperty "
                       "float y\nproperty float z\nelement tristrips 1\nproperty list int int "
                       "vertex_indices\nend_header\n";
  for (int i = 0; i < 12; ++i)
    strips += std::to_string(i / 2) + " " + std::to_string(i % 2) + " " +
              std::to_string(0.1 * i * (i % 2)) + "\n";
  strips += "12 0 1 2 3 4 5 6 7 8 9 10 11\n";
  EXPECT_NE(refusal(strips, MeshFormat::Ply, 9).find("the faces make 10 triangles"),
            std::string::npos);
  EXPECT_EQ(refusal(strips, MeshFormat::Ply, 10), "");
}

TEST(Limits, VertexRecordsAreCappedAtThreePerTriangle) {
  // A header that declares 301 vertices for a limit of 100 triangles.
  std::string off = "OFF\n301 1 0\n";
  for (int i = 0; i < 301; ++i) off += std::to_string(i) + " " + std::to_string(i % 7) + " 0\n";
  off += "3 0 1 2\n";
  EXPECT_NE(refusal(off, MeshFormat::Off, 100)
                .find("declares 301 vertices: over the limit of "
                      "300 vertices"),
            std::string::npos);
  EXPECT_EQ(refusal(off, MeshFormat::Off, 101), "");
  // Without a header: at the 301st `v` line.
  std::string obj;
  for (int i = 0; i < 301; ++i)
    (obj += "v ") += std::to_string(i) + " " + std::to_string(i % 7) + " 0\n";
  obj += "f 1 2 3\n";
  EXPECT_NE(refusal(obj, MeshFormat::Obj, 100).find("line 301: more vertices"), std::string::npos);
}

TEST(Limits, TheTriangleLimitFollowsTheMachinesMemory) {
  const std::uint64_t gb24 = 24ull << 30;
  EXPECT_EQ(editor_triangle_limit(gb24, 1),
            static_cast<std::uint64_t>(kMemoryShare * double(gb24)) / kMeshBytesPerTriangle);
  EXPECT_EQ(editor_triangle_limit(gb24, 4), editor_triangle_limit(gb24, 1) / 4);
  EXPECT_EQ(editor_triangle_limit(0, 1), 0u);    // unknown: no limit
  EXPECT_EQ(editor_triangle_limit(1000, 1), 1u); // never below one triangle
  EXPECT_GT(physical_memory_bytes(), 0u);
}

TEST(Limits, ARegionOverItsMemoryIsRefusedBeforeTheFactorization) {
  EXPECT_EQ(region_bytes(1000, 2, 1), 1000 * kRegionBytesPerFreeVertex[1]);
  EXPECT_EQ(region_bytes(1000, 3, 3), 1000 * (kRegionBytesPerFreeVertex[2] + 2 * 64));
  const Mesh sphere = make_icosphere(3, 1.0);
  std::vector<int> cap, top, all, pole;
  for (const VertexHandle v : sphere.vertices()) {
    all.push_back(v.idx());
    if (sphere.point(v)[2] > 0.5) cap.push_back(v.idx());
    if (sphere.point(v)[2] > 0.95) top.push_back(v.idx());
    if (sphere.point(v)[2] < -0.95) pole.push_back(v.idx());
  }
  EditorOptions options;
  // Room for the preprocessing and the cap's region, not for all of it.
  options.memory_bytes =
      kEditorBytesPerTriangle * sphere.n_faces() + region_bytes(cap.size() * 2, 2, 1);
  Editor editor(sphere, options);
  editor.set_region(cap, {top});
  const std::size_t cap_movable = editor.movable_vertices().size();
  try {
    editor.set_region(all, {top, pole});
    ADD_FAILURE() << "a region over the limit was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("free base vertices: at k = 2 with 2 handles"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(editor.movable_vertices().size(), cap_movable); // the cap's region stays
}

// The regions an editor keeps for an undo give way to a new region that has no room beside them:
// with room for one region, setting the first again after a second solves it again (the same
// doubles); without a limit it is reused as it was.
TEST(Limits, RegionsKeptForAnUndoGiveWayToANewOne) {
  const Mesh sphere = make_icosphere(3, 1.0);
  std::vector<int> north, top, south, pole;
  for (const VertexHandle v : sphere.vertices()) {
    const double z = sphere.point(v)[2];
    if (z > 0.5) north.push_back(v.idx());
    if (z > 0.95) top.push_back(v.idx());
    if (z < -0.5) south.push_back(v.idx());
    if (z < -0.95) pole.push_back(v.idx());
  }
  const Transform lift = translation({0.0, 0.0, 0.1});
  Editor unlimited(sphere);
  unlimited.set_region(north, {top});
  const std::uint64_t north_bytes = region_bytes(unlimited.report().free_base_vertices, 2, 1);
  unlimited.set_region(south, {pole});
  const std::uint64_t south_bytes = region_bytes(unlimited.report().free_base_vertices, 2, 1);
  unlimited.set_region(north, {top});
  EXPECT_TRUE(unlimited.report().region_reused);
  unlimited.set_transform(0, lift);

  EditorOptions options;
  options.memory_bytes = kEditorBytesPerTriangle * sphere.n_faces() +
                         std::max(north_bytes, south_bytes) +
                         std::min(north_bytes, south_bytes) / 2;
  Editor limited(sphere, options);
  limited.set_region(north, {top});
  limited.set_region(south, {pole});
  limited.set_region(north, {top});
  EXPECT_FALSE(limited.report().region_reused);
  limited.set_transform(0, lift);
  EXPECT_EQ(limited.positions(), unlimited.positions());
}

TEST(Limits, UnionsNestAtMost32Deep) {
  // {"union": [{"union": [ ... [0] ... ]}]}, `depth` unions deep.
  const auto nested = [](int depth) {
    std::string s;
    for (int i = 0; i < depth; ++i) s += R"({"union": [)";
    s += "[0]";
    for (int i = 0; i < depth; ++i) s += "]}";
    return nlohmann::json::parse(s);
  };
  EXPECT_EQ(parse_region(nested(32)).kind, RegionSpec::Kind::Union);
  for (const int depth : {33, 100000}) {
    try {
      parse_region(nested(depth));
      ADD_FAILURE() << depth;
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("unions nested more than 32 deep"), std::string::npos)
          << e.what();
    }
  }
}

} // namespace

namespace server {
namespace {

using namespace testing_server;
using nlohmann::json;

TEST(Limits, TheServerRefusesAMeshOverItsLimitAndRegionsOverTheirs) {
  SessionOptions small;
  small.read.max_triangles = 1000; // sphere_off() has 1,280
  Session refusing(small);
  ASSERT_EQ(call(refusing, "POST", "/api/load", sphere_off(), {{"name", "s.off"}}).status, 202);
  refusing.wait();
  const json st = json::parse(call(refusing, "GET", "/api/status").body);
  EXPECT_EQ(st["state"], "empty");
  EXPECT_NE(st.value("error", "").find("over the limit of 1000 triangles"), std::string::npos)
      << st;

  SessionOptions two;
  two.max_handles = 2;
  Session s(two);
  const SphereRegion r = load_sphere_with_region(s);
  const auto region = [&](std::vector<std::vector<int>> handles, std::vector<int> support) {
    return call(s, "POST", "/api/region", json{{"support", support}, {"handles", handles}}.dump());
  };
  const std::vector<int> a{r.handle[0]}, b{r.handle[1]}, c{r.handle[2]};
  expect_error(region({a, b, c}, r.support), 400, "3 handles: at most 2 are accepted");
  std::vector<int> doubled = r.support;
  doubled.insert(doubled.end(), r.support.begin(), r.support.end());
  doubled.insert(doubled.end(), r.support.begin(), r.support.end());
  doubled.resize(r.rest.size() / 3 + 1, r.support[0]);
  expect_error(region({a}, doubled), 400, "more ids than the mesh has vertices (642)");
  EXPECT_EQ(region({a, b}, r.support).status, 202);
  s.wait();
  // The default: kMaxHandles.
  EXPECT_EQ(SessionOptions{}.max_handles, kMaxHandles);
  // A region over the editor's memory: the job fails with the message, the session goes on.
  SessionOptions tight;
  tight.editor.memory_bytes = 1000;
  Session t(tight);
  ASSERT_EQ(call(t, "POST", "/api/load", sphere_off(), {{"name", "s.off"}}).status, 202);
  t.wait();
  ASSERT_EQ(
      call(t, "POST", "/api/region", json{{"support", r.support}, {"handles", {r.handle}}}.dump())
          .status,
      202);
  t.wait();
  const json failed = json::parse(call(t, "GET", "/api/status").body);
  EXPECT_EQ(failed["state"], "ready");
  EXPECT_NE(failed.value("error", "").find("free base vertices"), std::string::npos) << failed;
}

} // namespace
} // namespace server
} // namespace remora
