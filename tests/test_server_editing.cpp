// The server's editing contract beyond the round trip (tests/test_server.cpp): a new k under moved
// handles, transforms that would invert the patch, picking and brushes on the shape shown, the
// change counters that spare the page its downloads, the progress of a job, and the HTTP binding
// over loopback (405, 413 and every error with a JSON body).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "api.h"
#include "remora/geometry/geodesic.h"
#include "remora/geometry/raycast.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "server_support.h"
#include "session.h"
#include "shape.h"

// Last: it includes httplib.h, whose <resolv.h> `_res` macro breaks Eigen's headers if they follow.
#include "loopback.h" // NOLINT(llvm-include-order)

namespace remora::server {
namespace {

using nlohmann::json;
using namespace testing_server;

/// The library's geodesic brush as the server marches it.
std::vector<std::pair<int, double>> brush_ball(const Mesh& mesh, const SurfacePoint& at,
                                               double radius) {
  return FastMarching(mesh, {.coarse_ratio = kBrushCoarseRatio}).ball(mesh, at, radius);
}

TEST(ServerEditing, ANewKKeepsTheMoveWithoutABakeAndUndoComesBack) {
  Session s;
  const SphereRegion r = load_sphere_with_region(s, 2);
  const json ready = status_of(s);
  ASSERT_EQ(move(s, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.4}).status, 200);
  call(s, "POST", "/api/commit");
  const auto k2 = as<float>(call(s, "GET", "/api/mesh/positions"));
  const json moved = status_of(s);
  // Same support and handle, k = 1: solved again under the same transform, no bake.
  ASSERT_EQ(call(s, "POST", "/api/region",
                 json{{"support", r.support}, {"handles", {r.handle}}, {"k", 1}}.dump())
                .status,
            202);
  s.wait();
  const json k1_status = status_of(s);
  ASSERT_FALSE(k1_status.contains("error")) << k1_status;
  EXPECT_EQ(k1_status["transforms"], moved["transforms"]);
  EXPECT_EQ(k1_status["region"]["k"], 1);
  EXPECT_EQ(k1_status["base"]["preprocess_ms"], ready["base"]["preprocess_ms"]); // same base
  EXPECT_EQ(k1_status["mesh_id"], moved["mesh_id"]);
  EXPECT_NE(k1_status["positions_id"], moved["positions_id"]);
  EXPECT_NE(k1_status["region_id"], moved["region_id"]);
  const auto k1 = as<float>(call(s, "GET", "/api/mesh/positions"));
  double rise = 0, differ = 0;
  for (const int v : r.handle) {
    const auto i = 3 * static_cast<std::size_t>(v) + 2;
    rise += (k1[i] - r.rest[i]) / double(r.handle.size());
  }
  for (std::size_t i = 0; i < k1.size(); ++i)
    differ = std::max(differ, double(std::abs(k1[i] - k2[i])));
  EXPECT_NEAR(rise, 0.4, 0.02); // the handle is where the drag left it
  EXPECT_GT(differ, 1e-3);      // and the support bends as k = 1 bends it
  // Undo: k = 2 under the same move, exactly.
  EXPECT_TRUE(json::parse(call(s, "POST", "/api/undo").body)["changed"]);
  EXPECT_EQ(as<float>(call(s, "GET", "/api/mesh/positions")), k2);
  EXPECT_EQ(status_of(s)["region"]["k"], 2);
}

/// A bumpy sphere of about 10k vertices as OFF text: its set_region takes long enough for a
/// newer region to arrive while it runs.
std::string large_sphere_off() {
  Mesh m = make_icosphere(5, 1.0);
  std::ostringstream out;
  out.precision(17);
  out << "OFF\n" << m.n_vertices() << " " << m.n_faces() << " 0\n";
  for (const VertexHandle v : m.vertices()) {
    const Vec3 p = m.point(v) * (1.0 + 0.02 * std::sin(11 * m.point(v)[0]));
    out << p[0] << " " << p[1] << " " << p[2] << "\n";
  }
  for (const FaceHandle f : m.faces()) {
    out << 3;
    for (const VertexHandle v : m.fv_range(f)) out << " " << v.idx();
    out << "\n";
  }
  return out.str();
}

/// The vertices above height z, and those above z_handle, of positions (x, y, z Float32).
json cap_region(const std::vector<float>& p, double z, double z_handle) {
  std::vector<int> support, handle;
  for (std::size_t v = 0; v < p.size() / 3; ++v) {
    if (p[3 * v + 2] > z) support.push_back(static_cast<int>(v));
    if (p[3 * v + 2] > z_handle) handle.push_back(static_cast<int>(v));
  }
  return {{"support", support}, {"handles", {handle}}, {"k", 2}};
}

// Regions sent while a region job runs stop it: only the last is installed (one snapshot), and
// a stopped job never installs its region.
TEST(ServerEditing, ANewerRegionStopsTheRunningOneAndOnlyTheLastIsInstalled) {
  Session s;
  ASSERT_EQ(call(s, "POST", "/api/load", large_sphere_off(), {{"name", "ball.off"}}).status, 202);
  s.wait();
  const auto rest = as<float>(call(s, "GET", "/api/mesh/positions"));
  const std::vector<json> regions = {cap_region(rest, 0.0, 0.8), cap_region(rest, 0.3, 0.9),
                                     cap_region(rest, -0.2, 0.85), cap_region(rest, 0.5, 0.95)};
  for (const json& r : regions) ASSERT_EQ(call(s, "POST", "/api/region", r.dump()).status, 202);
  s.wait();
  const json status = status_of(s);
  ASSERT_FALSE(status.contains("error")) << status;
  EXPECT_EQ(json::parse(call(s, "GET", "/api/region").body)["support"], regions.back()["support"]);
  EXPECT_EQ(status["region"]["support"], regions.back()["support"].size());
  // One snapshot after the load's: undo goes straight back to no region.
  EXPECT_TRUE(json::parse(call(s, "POST", "/api/undo").body)["changed"]);
  EXPECT_TRUE(json::parse(call(s, "GET", "/api/region").body).is_null());
  EXPECT_FALSE(status_of(s)["undo"]);
}

// A region job stopped after its set_region, followed by one that fails: the session keeps the
// region it had, and its editor solves that region again (the same positions for the same move).
TEST(ServerEditing, AFailedRegionAfterAStoppedOneLeavesTheSessionsRegion) {
  Session s;
  ASSERT_EQ(call(s, "POST", "/api/load", large_sphere_off(), {{"name", "ball.off"}}).status, 202);
  s.wait();
  const auto rest = as<float>(call(s, "GET", "/api/mesh/positions"));
  const json first = cap_region(rest, 0.2, 0.9);
  ASSERT_EQ(call(s, "POST", "/api/region", first.dump()).status, 202);
  s.wait();
  const std::vector<double> lift = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.3};
  const auto moved = as<float>(move(s, lift));
  ASSERT_FALSE(moved.empty());
  ASSERT_EQ(move(s, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}).status, 200); // back to rest
  // Another region, then one whose handle lies outside its support (refused by set_region).
  ASSERT_EQ(call(s, "POST", "/api/region", cap_region(rest, -0.3, 0.7).dump()).status, 202);
  json bad = cap_region(rest, 0.6, 0.9);
  bad["handles"] = json::array({cap_region(rest, -0.9, -0.8)["handles"][0]});
  ASSERT_EQ(call(s, "POST", "/api/region", bad.dump()).status, 202);
  s.wait();
  const json status = status_of(s);
  ASSERT_TRUE(status.contains("error")) << status;
  EXPECT_NE(status["error"].get<std::string>().find("outside the support"), std::string::npos);
  EXPECT_EQ(json::parse(call(s, "GET", "/api/region").body)["support"], first["support"]);
  EXPECT_EQ(as<float>(move(s, lift)), moved);
}

// A new region after a move bakes the edited shape locally (only around the move), and undo and
// redo through several such bakes give back every state's positions bit for bit.
TEST(ServerEditing, UndoAndRedoThroughLocalBakesAreExact) {
  Session s;
  ASSERT_EQ(call(s, "POST", "/api/load", sphere_off(5), {{"name", "fine.off"}}).status, 202);
  s.wait();
  const auto rest = as<float>(call(s, "GET", "/api/mesh/positions"));
  std::vector<int> support, handle;
  for (std::size_t v = 0; v < rest.size() / 3; ++v) {
    if (rest[3 * v + 2] > 0.85) support.push_back(static_cast<int>(v));
    if (rest[3 * v + 2] > 0.97) handle.push_back(static_cast<int>(v));
  }
  // The positions of every state of the history: the load, then per round the region (the shape
  // as baked) and the move.
  std::vector<std::vector<float>> steps{rest};
  for (int i = 0; i < 3; ++i) {
    const json region = {{"support", support}, {"handles", {handle}}, {"k", 2}};
    ASSERT_EQ(call(s, "POST", "/api/region", region.dump()).status, 202);
    s.wait();
    const json status = status_of(s);
    ASSERT_FALSE(status.contains("error")) << status;
    if (i > 0) {
      EXPECT_TRUE(status["base"]["bake"]["local"].get<bool>()) << status["base"];
    }
    steps.push_back(as<float>(call(s, "GET", "/api/mesh/positions")));
    const double lift = i % 2 == 0 ? 0.1 : -0.05;
    ASSERT_EQ(move(s, {1, 0, 0, 0, 0, 1, 0, 0.05 * i, 0, 0, 1, lift}).status, 200);
    call(s, "POST", "/api/commit");
    steps.push_back(as<float>(call(s, "GET", "/api/mesh/positions")));
  }
  for (std::size_t k = steps.size() - 1; k-- > 0;) {
    ASSERT_TRUE(json::parse(call(s, "POST", "/api/undo").body)["changed"]);
    EXPECT_EQ(as<float>(call(s, "GET", "/api/mesh/positions")), steps[k]) << "undo to step " << k;
  }
  for (std::size_t k = 1; k < steps.size(); ++k) {
    ASSERT_TRUE(json::parse(call(s, "POST", "/api/redo").body)["changed"]);
    EXPECT_EQ(as<float>(call(s, "GET", "/api/mesh/positions")), steps[k]) << "redo to step " << k;
  }
}

// The region's kernel (GET /api/region/kernel): sections that add up to the body as its header
// says, `corrected` for the nonlinear energies that iterate. A move answered with "none" is a 204
// without positions that moves the server's shape all the same, when it is read. Base offsets
// follow the positions in an answer, one row per basis row of the kernel; blended motions have
// none.
TEST(ServerEditing, TheKernelIsServedAMoveCanGoUnansweredAndNonlinearAnswersBaseOffsets) {
  Session s;
  ASSERT_EQ(call(s, "POST", "/api/load", sphere_off(), {{"name", "sphere.off"}}).status, 202);
  s.wait();
  expect_error(call(s, "GET", "/api/region/kernel"), 409, "no region");
  const SphereRegion r = load_sphere_with_region(s);
  const HttpResponse kernel = call(s, "GET", "/api/region/kernel");
  ASSERT_EQ(kernel.status, 200) << kernel.body;
  const auto words = as<std::uint32_t>(kernel);
  ASSERT_GE(words.size(), 16u);
  const std::uint32_t handles = words[1], local = words[2], rows = words[3], columns = words[4],
                      handle_vertices = words[5], faces = words[6], normal_vertices = words[7],
                      ring = words[8], records = words[9], residuals = words[10],
                      offsets = words[11];
  EXPECT_EQ(words[0], 1u);
  EXPECT_EQ(handles, 1u);
  EXPECT_EQ(columns, 7u);
  EXPECT_EQ(records, r.support.size()); // one detail per movable vertex
  EXPECT_EQ(offsets, 0u);
  EXPECT_GT(rows, 0u);
  const std::size_t expected = 16 + 6 * local + rows + rows * columns + handles + 1 +
                               handle_vertices + 3 * faces + normal_vertices + normal_vertices + 1 +
                               ring + records * 7 + 3 * residuals;
  EXPECT_EQ(words.size(), expected);
  // A move without an answer, then the same move answered: the same positions.
  const std::vector<double> lift = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.3};
  const HttpResponse quiet =
      call(s, "POST", "/api/transform",
           nlohmann::json{{"handle", 0}, {"matrix", lift}, {"answer", "none"}}.dump());
  EXPECT_EQ(quiet.status, 204);
  EXPECT_TRUE(quiet.body.empty());
  EXPECT_EQ(status_of(s)["transforms"][0][11], 0.3);
  // Its frame is computed when the shape is read: a pick from above meets the lifted cap (the
  // sphere's top is at z = 1 at rest), and the positions are those of the answered move.
  const HttpResponse top =
      call(s, "POST", "/api/pick", R"({"origin": [0, 0, 5], "direction": [0, 0, -1]})");
  ASSERT_EQ(top.status, 200) << top.body;
  std::istringstream hit(top.headers.at("X-Hit-Point"));
  double hx = 0, hy = 0, hz = 0;
  hit >> hx >> hy >> hz;
  EXPECT_NEAR(hz, 1.3, 0.05);
  const std::vector<float> lifted = as<float>(call(s, "GET", "/api/mesh/positions"));
  const std::vector<float> answered = as<float>(move(s, lift));
  ASSERT_EQ(answered.size(), 3 * r.support.size());
  for (std::size_t i = 0; i < r.support.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_EQ(lifted[3 * std::size_t(r.support[i]) + c], answered[3 * i + c]);
  expect_error(call(s, "POST", "/api/transform",
                    nlohmann::json{{"handle", 0}, {"matrix", lift}, {"answer", "all"}}.dump()),
               400, "answer");
  // Method nonlinear (rotated-laplacian): the same kernel, corrected by the base offsets that
  // its frames answer after the positions.
  const nlohmann::json region = {
      {"support", r.support}, {"handles", {r.handle}}, {"method", "nonlinear"}};
  ASSERT_EQ(call(s, "POST", "/api/region", region.dump()).status, 202);
  s.wait();
  const HttpResponse corrected = call(s, "GET", "/api/region/kernel");
  ASSERT_EQ(corrected.status, 200) << corrected.body;
  EXPECT_EQ(as<std::uint32_t>(corrected)[13], 1u);
  EXPECT_EQ(words[13], 0u);
  const auto answer = [&](const char* path, nlohmann::json body, const char* what) {
    body["answer"] = what;
    return call(s, "POST", path, body.dump());
  };
  const HttpResponse moved =
      answer("/api/transform", {{"handle", 0}, {"matrix", lift}}, "base-offsets");
  ASSERT_EQ(moved.status, 200) << moved.body;
  EXPECT_EQ(moved.headers.at("X-Base-Offset-Rows"), std::to_string(rows));
  EXPECT_EQ(as<float>(moved).size(), 3 * std::size_t(rows));
  const HttpResponse both =
      answer("/api/relax", {{"budget_ms", 10000}}, "positions-and-base-offsets");
  ASSERT_EQ(both.status, 200) << both.body;
  EXPECT_EQ(both.headers.at("X-Converged"), "1");
  const std::vector<float> both_floats = as<float>(both);
  ASSERT_EQ(both_floats.size(), 3 * (r.support.size() + rows));
  const std::vector<float> positions = as<float>(call(s, "GET", "/api/mesh/positions"));
  for (std::size_t i = 0; i < r.support.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_EQ(positions[3 * std::size_t(r.support[i]) + c], both_floats[3 * i + c]);
  const std::vector<float> base_offsets = as<float>(answer("/api/relax", {}, "base-offsets"));
  EXPECT_TRUE(std::equal(base_offsets.begin(), base_offsets.end(), both_floats.end() - 3 * rows));
  float largest = 0.0f;
  for (const float d : base_offsets) largest = std::max(largest, std::abs(d));
  EXPECT_GT(largest, 1e-4f); // nonlinear is not linear
  expect_error(answer("/api/relax", {}, "none"), 400, "answer");
  // The energy blended-motions (no iteration): its own kernel, and no base offsets.
  const nlohmann::json blended = {{"support", r.support},
                                  {"handles", {r.handle}},
                                  {"method", "nonlinear"},
                                  {"energy", "blended-motions"}};
  ASSERT_EQ(call(s, "POST", "/api/region", blended.dump()).status, 202);
  s.wait();
  const HttpResponse blended_kernel = call(s, "GET", "/api/region/kernel");
  ASSERT_EQ(blended_kernel.status, 200) << blended_kernel.body;
  EXPECT_EQ(as<std::uint32_t>(blended_kernel)[12], 1u);
  EXPECT_EQ(as<std::uint32_t>(blended_kernel)[13], 0u);
  EXPECT_EQ(words[12], 0u);
  const nlohmann::json before = status_of(s)["transforms"];
  expect_error(
      answer("/api/transform",
             {{"handle", 0}, {"matrix", std::vector<double>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.1}}},
             "base-offsets"),
      400, "blended-motions");
  EXPECT_EQ(status_of(s)["transforms"], before); // refused before the move
}

TEST(ServerEditing, MirrorsCollapsesAndNumbersOutOfRangeAreRefused) {
  Session s;
  load_sphere_with_region(s);
  expect_error(move(s, {-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, -1, 0}), 400, "mirrors");
  expect_error(move(s, {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}), 400, "mirrors");
  expect_error(move(s, {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}), 400, "collapses");
  expect_error(move(s, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1e-9, 0}), 400, "collapses");
  expect_error(call(s, "POST", "/api/transform",
                    R"({"handle": 0, "matrix": [1e400,0,0,0,0,1,0,0,0,0,1,0]})"),
               400, "not valid JSON");
  // Refusals leave the shape as it was; a positive scale is an edit.
  EXPECT_EQ(status_of(s)["transforms"][0], json({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}));
  EXPECT_EQ(move(s, {0.5, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0}).status, 200);
}

/// The brush of a pick response as sorted ids, and its hit face.
std::vector<std::uint32_t> brush_of(const HttpResponse& r) {
  auto ids = as<std::uint32_t>(r);
  std::sort(ids.begin(), ids.end());
  return ids;
}

TEST(ServerEditing, PicksAndBrushesAreTheLibrarysOnTheShapeShown) {
  Session s;
  expect_error(call(s, "POST", "/api/pick", R"({"origin": [0,0,3], "direction": [0,0,-1]})"), 409,
               "no mesh");
  load_sphere_with_region(s);
  const auto pick = [&](const Vec3& o, const Vec3& d, double radius, const char* brush) {
    return call(s, "POST", "/api/pick",
                json{{"origin", {o[0], o[1], o[2]}},
                     {"direction", {d[0], d[1], d[2]}},
                     {"radius", radius},
                     {"brush", brush}}
                    .dump());
  };
  // The library on the same mesh, the same ray and radius.
  Mesh mesh = read_mesh_from_memory(sphere_off(), MeshFormat::Off, "sphere.off").mesh;
  const Vec3 origin(0.1, 0.2, 3), down(0, 0, -1);
  for (const double radius : {0.0, 0.1, 0.5}) {
    const HttpResponse got = pick(origin, down, radius, "geodesic");
    ASSERT_EQ(got.status, 200) << got.body;
    const RayHit hit = RayCaster(mesh).first_hit(origin, down, 0.0, 1e300);
    ASSERT_TRUE(hit.face.is_valid());
    EXPECT_EQ(got.headers.at("X-Hit-Face"), std::to_string(hit.face.idx()));
    std::vector<std::uint32_t> expected;
    for (const auto& [v, d] : brush_ball(mesh, SurfacePoint{hit.face, hit.bary}, radius))
      expected.push_back(static_cast<std::uint32_t>(v));
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(brush_of(got), expected) << "radius " << radius;
  }
  // A miss, and bad requests.
  const HttpResponse miss = pick(Vec3(5, 5, 5), Vec3(1, 0, 0), 0.3, "geodesic");
  EXPECT_EQ(miss.headers.at("X-Hit-Face"), "-1");
  EXPECT_TRUE(miss.body.empty());
  expect_error(pick(origin, Vec3(0, 0, 0), 0.1, "geodesic"), 400, "direction");
  expect_error(pick(origin, down, -1, "geodesic"), 400, "radius");
  expect_error(pick(origin, down, 0.1, "lasso"), 400, "unknown brush 'lasso'");
  expect_error(call(s, "POST", "/api/pick", R"({"origin": [0,0,"x"], "direction": [0,0,-1]})"), 400,
               "origin[2]");
  // After a lift the handle is higher: the ray meets the lifted top, and the brush is the
  // library's on the moved mesh.
  ASSERT_EQ(move(s, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5}).status, 200);
  const Vec3 above(0.0, 0.0, 3);
  const HttpResponse lifted = pick(above, down, 0.2, "geodesic");
  const auto moved = as<float>(call(s, "GET", "/api/mesh/positions"));
  for (const VertexHandle v : mesh.vertices()) {
    const auto i = 3 * static_cast<std::size_t>(v.idx());
    mesh.set_point(v, Vec3(moved[i], moved[i + 1], moved[i + 2]));
  }
  const RayHit hit = RayCaster(mesh).first_hit(above, down, 0.0, 1e300);
  ASSERT_TRUE(hit.face.is_valid());
  EXPECT_EQ(lifted.headers.at("X-Hit-Face"), std::to_string(hit.face.idx()));
  EXPECT_GT(evaluate(mesh, SurfacePoint{hit.face, hit.bary})[2], 1.3);
  std::vector<std::uint32_t> expected;
  for (const auto& [v, d] : brush_ball(mesh, SurfacePoint{hit.face, hit.bary}, 0.2))
    expected.push_back(static_cast<std::uint32_t>(v));
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(brush_of(lifted), expected);
  // The sphere brush: the straight-line ball around the hit point.
  const HttpResponse sphere = pick(above, down, 0.2, "sphere");
  const Vec3 at = evaluate(mesh, SurfacePoint{hit.face, hit.bary});
  std::vector<std::uint32_t> within;
  for (const VertexHandle v : mesh.vertices())
    if ((mesh.point(v) - at).norm() <= 0.2) within.push_back(static_cast<std::uint32_t>(v.idx()));
  EXPECT_EQ(brush_of(sphere), within);
}

TEST(ServerEditing, ACoarseBrushFollowsTheShapeThroughADragAndAWholeChange) {
  // Coarse levels from 2 mean edge lengths, so that a unit sphere's brushes use them.
  Mesh mesh = make_icosphere(4, 1.0);
  Shape shape(mesh, 2.0);
  FastMarching library(mesh, {.coarse_ratio = 2.0}); // clustered at the same rest positions
  const Vec3 above(0.05, 0.1, 3), down(0, 0, -1);
  const auto expect_library_brush = [&](const char* when) {
    const Pick got = shape.pick(above, down, 0.9, Brush::Geodesic);
    const RayHit hit = RayCaster(mesh).first_hit(above, down, 0.0, 1e300);
    ASSERT_EQ(got.face, hit.face.idx()) << when;
    std::vector<std::uint32_t> expected;
    for (const auto& [v, d] : library.ball(mesh, SurfacePoint{hit.face, hit.bary}, 0.9))
      expected.push_back(static_cast<std::uint32_t>(v));
    std::sort(expected.begin(), expected.end());
    EXPECT_GE(library.last_level(), 1) << when;
    EXPECT_EQ(got.brush, expected) << when;
  };
  expect_library_brush("at rest");
  // A drag moves the cap: the shape reads again only the clusters around it, the library all.
  std::vector<int> cap;
  Eigen::MatrixXd positions(mesh.n_vertices(), 3);
  for (const VertexHandle v : mesh.vertices()) {
    Vec3 p = mesh.point(v);
    if (p[2] > 0.3) {
      cap.push_back(v.idx());
      p = Vec3(p[0] * 1.3, p[1] * 0.8, p[2] + 0.4 * (p[2] - 0.3));
      mesh.set_point(v, p);
    }
    positions.row(v.idx()) << p[0], p[1], p[2];
  }
  shape.set_positions(cap, positions);
  library.positions_changed();
  expect_library_brush("after a drag");
  // Every vertex moved (an undo, a bake).
  for (const VertexHandle v : mesh.vertices()) {
    const Vec3 p = mesh.point(v) * 1.1;
    mesh.set_point(v, p);
    positions.row(v.idx()) << p[0], p[1], p[2];
  }
  shape.set_positions(positions);
  library.positions_changed();
  expect_library_brush("after a whole change");
}

TEST(ServerEditing, APicksStrokeAnswersOnlyWhatItsEarlierPicksDidNot) {
  Session s;
  load_sphere_with_region(s);
  const auto pick = [&](double x, const char* brush, int stroke) {
    json body{
        {"origin", {x, 0.1, 3}}, {"direction", {0, 0, -1}}, {"radius", 0.3}, {"brush", brush}};
    if (stroke >= 0) body["stroke"] = stroke;
    const HttpResponse r = call(s, "POST", "/api/pick", body.dump());
    EXPECT_EQ(r.status, 200) << r.body;
    return brush_of(r);
  };
  for (const char* brush : {"geodesic", "sphere"}) {
    // Along a path: each answer of the stroke is new, and together they are the union of the
    // whole brushes.
    std::vector<std::uint32_t> stroke, whole;
    for (int i = 0; i < 8; ++i)
      for (const std::uint32_t v : pick(-0.4 + 0.1 * i, brush, -1)) whole.push_back(v);
    for (int i = 0; i < 8; ++i)
      for (const std::uint32_t v : pick(-0.4 + 0.1 * i, brush, 7)) stroke.push_back(v);
    std::sort(whole.begin(), whole.end());
    whole.erase(std::unique(whole.begin(), whole.end()), whole.end());
    const std::size_t answered = stroke.size();
    std::sort(stroke.begin(), stroke.end());
    EXPECT_EQ(std::unique(stroke.begin(), stroke.end()) - stroke.begin(),
              static_cast<std::ptrdiff_t>(answered))
        << brush << ": a vertex answered twice";
    EXPECT_EQ(stroke, whole) << brush;
  }
  // The same point again: nothing new in the stroke; a new stroke, a pick outside a stroke or a
  // move of the shape starts over.
  const auto first = pick(0.0, "geodesic", 8);
  EXPECT_FALSE(first.empty());
  EXPECT_TRUE(pick(0.0, "geodesic", 8).empty());
  EXPECT_EQ(pick(0.0, "geodesic", 9), first);
  pick(0.0, "geodesic", -1);
  EXPECT_EQ(pick(0.0, "geodesic", 9), first);
  ASSERT_EQ(move(s, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.01}).status, 200);
  EXPECT_FALSE(pick(0.0, "geodesic", 9).empty());
  for (const char* bad : {"-1", "1.5", "\"x\"", "1e300"})
    expect_error(
        call(s, "POST", "/api/pick",
             std::string(R"({"origin": [0,0,3], "direction": [0,0,-1], "stroke": )") + bad + "}"),
        400, "stroke");
}

TEST(ServerEditing, TheCountersChangeOnlyWithWhatTheyCount) {
  Session s;
  const json empty = status_of(s);
  const SphereRegion r = load_sphere_with_region(s);
  const json loaded = status_of(s);
  EXPECT_NE(loaded["mesh_id"], empty["mesh_id"]);
  // A frame of a drag and its commit: the page has those positions already.
  ASSERT_EQ(move(s, {1, 0, 0, 0.1, 0, 1, 0, 0, 0, 0, 1, 0}).status, 200);
  call(s, "POST", "/api/commit");
  const json dragged = status_of(s);
  for (const char* id : {"mesh_id", "positions_id", "region_id"})
    EXPECT_EQ(dragged[id], loaded[id]) << id;
  // Undo of the drag: positions, not the region.
  call(s, "POST", "/api/undo");
  const json undone = status_of(s);
  EXPECT_NE(undone["positions_id"], dragged["positions_id"]);
  EXPECT_EQ(undone["region_id"], dragged["region_id"]);
  EXPECT_EQ(undone["mesh_id"], dragged["mesh_id"]);
  // A new region after a move (a bake): the region, not the faces nor the positions shown.
  call(s, "POST", "/api/redo");
  const json redone = status_of(s);
  std::vector<int> smaller(r.support.begin() + 1, r.support.end());
  if (std::find(r.handle.begin(), r.handle.end(), r.support.front()) != r.handle.end())
    smaller = r.support;
  ASSERT_EQ(
      call(s, "POST", "/api/region", json{{"support", smaller}, {"handles", {r.handle}}}.dump())
          .status,
      202);
  s.wait();
  const json baked = status_of(s);
  ASSERT_FALSE(baked.contains("error")) << baked;
  EXPECT_NE(baked["region_id"], redone["region_id"]);
  EXPECT_EQ(baked["positions_id"], redone["positions_id"]);
  EXPECT_EQ(baked["mesh_id"], redone["mesh_id"]);
}

TEST(ServerEditing, AJobsProgressRunsForwardToTheEnd) {
  Session s;
  // Large enough that the polls see several phases (81,920 faces; under the sanitizers, where a
  // 20,480-face sphere takes as long, that one).
  const Mesh big = make_icosphere(std::getenv("REMORA_SANITIZED") ? 5 : 6, 1.0);
  const std::string bytes = write_mesh_to_memory(big, MeshFormat::Ply, "big.ply");
  ASSERT_EQ(call(s, "POST", "/api/load", bytes, {{"name", "big.ply"}}).status, 202);
  std::vector<double> seen;
  for (;;) {
    const json st = status_of(s);
    if (st["state"] != "busy") break;
    const double f = st["progress"]["fraction"];
    seen.push_back(f);
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_GT(seen.size(), 2u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GT(seen.back(), 0.5);
}

TEST(ServerEditing, ALongPollOfTheStatusAnswersWhenTheJobEnds) {
  Session s;
  expect_error(call(s, "GET", "/api/status", "", {{"wait", "soon"}}), 400, "wait");
  expect_error(call(s, "GET", "/api/status", "", {{"wait", "20000"}}), 400, "wait");
  ASSERT_EQ(call(s, "POST", "/api/load", sphere_off(), {{"name", "sphere.off"}}).status, 202);
  // One poll of up to 10 s answers once the job has ended: ready, not busy.
  EXPECT_EQ(json::parse(call(s, "GET", "/api/status", "", {{"wait", "10000"}}).body)["state"],
            "ready");
  // Idle: no wait at all.
  EXPECT_EQ(json::parse(call(s, "GET", "/api/status", "", {{"wait", "0"}}).body)["state"], "ready");
}

TEST(ServerEditing, OverHttpEveryErrorIsJsonAndWrongMethodsAre405) {
  Session s;
  ApiLimits limits;
  limits.max_upload_bytes = 1000;
  Loopback server(s, limits);
  httplib::Client c = server.client();
  c.set_keep_alive(true);
  EXPECT_EQ(c.Get("/api/status")->status, 200);
  const auto del = c.Delete("/api/status");
  expect_json_error(del, 405, "does not take DELETE");
  EXPECT_EQ(del->get_header_value("Allow"), "GET");
  expect_json_error(c.Put("/api/region", "{}", "application/json"), 405, "does not take PUT");
  expect_json_error(c.Patch("/api/transform", "{}", "application/json"), 405,
                    "does not take PATCH");
  expect_json_error(c.Delete("/index.html"), 405, "only GET");
  expect_json_error(c.Get("/index.html"), 404, "no page");
  // Larger than the upload limit: httplib answers by itself, with our JSON.
  expect_json_error(
      c.Post("/api/load?name=a.ply", std::string(5000, 'x'), "application/octet-stream"), 413,
      "upload limit of 1000 bytes");
  expect_json_error(
      c.Post("/api/load?name=a.ply", std::string(5000, 'x'), "application/x-www-form-urlencoded"),
      413, "application/octet-stream");
  expect_json_error(
      c.Post("/api/transform", R"({"handle": 0, "matrix": [1e400]})", "application/json"), 400,
      "number overflow");
}

} // namespace
} // namespace remora::server
