// The API of `remora serve` (apps/server/api.h), driven as functions: no sockets. Every bad
// request is a 4xx with a JSON error; the editing round trip (load, region, transform, commit,
// undo, redo, export) keeps its promises.
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "api.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "server_support.h"
#include "session.h"

namespace remora::server {
namespace {

using nlohmann::json;
using testing_server::as;
using testing_server::call;
using testing_server::expect_error;
using testing_server::load_sphere_with_region;
using testing_server::sphere_off;
using testing_server::SphereRegion;

TEST(Server, EmptySessionAnswersStatusAndRefusesTheRest) {
  Session s;
  const HttpResponse status = call(s, "GET", "/api/status");
  EXPECT_EQ(status.status, 200);
  EXPECT_EQ(json::parse(status.body)["state"], "empty");
  expect_error(call(s, "GET", "/api/mesh/positions"), 409, "no mesh");
  expect_error(
      call(s, "POST", "/api/transform", R"({"handle": 0, "matrix": [1,0,0,0,0,1,0,0,0,0,1,0]})"),
      409, "no mesh");
  expect_error(call(s, "GET", "/api/nowhere"), 404, "no endpoint");
  // A wrong method is a 405 with a JSON body and the methods the path takes in Allow.
  const HttpResponse post_status = call(s, "POST", "/api/status");
  expect_error(post_status, 405, "/api/status does not take POST; use GET");
  EXPECT_EQ(post_status.headers.count("Allow") ? post_status.headers.at("Allow") : "", "GET");
  const HttpResponse put_region = call(s, "PUT", "/api/region");
  expect_error(put_region, 405, "does not take PUT");
  EXPECT_EQ(put_region.headers.count("Allow") ? put_region.headers.at("Allow") : "", "GET, POST");
  const HttpResponse get_transform = call(s, "GET", "/api/transform");
  expect_error(get_transform, 405, "does not take GET");
  EXPECT_EQ(get_transform.headers.count("Allow") ? get_transform.headers.at("Allow") : "", "POST");
  expect_error(call(s, "POST", "/api/load", "", {{"name", "a.ply"}}), 400, "empty");
  expect_error(call(s, "POST", "/api/load", "x"), 400, "?name=");
  expect_error(call(s, "POST", "/api/load", "x", {{"name", "a.doc"}}), 400, "extension");
  ApiLimits small;
  small.max_upload_bytes = 10;
  EXPECT_EQ(
      handle_api(s, {"POST", "/api/load", {{"name", "a.off"}}, std::string(11, 'x')}, small).status,
      413);
}

TEST(Server, ABrokenUploadEndsInAnErrorTheStatusNames) {
  Session s;
  EXPECT_EQ(call(s, "POST", "/api/load", "OFF\n3 1 0\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n",
                 {{"name", "bad.off"}})
                .status,
            202);
  s.wait();
  const json status = json::parse(call(s, "GET", "/api/status").body);
  EXPECT_EQ(status["state"], "empty");
  ASSERT_TRUE(status.contains("error"));
  EXPECT_NE(status["error"].get<std::string>().find("bad.off"), std::string::npos) << status;
}

TEST(Server, EditRoundTripWithUndoAndRedo) {
  Session s;
  ASSERT_EQ(call(s, "POST", "/api/load", sphere_off(), {{"name", "sphere.off"}}).status, 202);
  s.wait();
  ASSERT_EQ(json::parse(call(s, "GET", "/api/status").body)["state"], "ready");
  const auto indices = as<std::uint32_t>(call(s, "GET", "/api/mesh/indices"));
  const auto before = as<float>(call(s, "GET", "/api/mesh/positions"));
  ASSERT_EQ(indices.size() % 3, 0u);
  const std::size_t n = before.size() / 3;
  ASSERT_EQ(n, 642u);
  // The region: vertices by height.
  std::vector<int> support, handle;
  for (std::size_t v = 0; v < n; ++v) {
    if (before[3 * v + 2] > 0.2) support.push_back(static_cast<int>(v));
    if (before[3 * v + 2] > 0.9) handle.push_back(static_cast<int>(v));
  }
  // Bad regions first.
  expect_error(call(s, "POST", "/api/region", R"({"support": [1, 2)"), 400, "not valid JSON");
  expect_error(call(s, "POST", "/api/region", R"({"support": [1], "handles": [[1]], "colour": 3})"),
               400, "unknown key 'colour'");
  expect_error(call(s, "POST", "/api/region", R"({"support": [1, -4], "handles": [[1]]})"), 400,
               "support[1]");
  expect_error(call(s, "POST", "/api/region", R"({"support": [1, 99999], "handles": [[1]]})"), 400,
               "out of range");
  expect_error(call(s, "POST", "/api/region", R"({"support": [1], "handles": [[1]], "k": 7})"), 400,
               "k = 7");
  expect_error(call(s, "POST", "/api/region", R"({"support": [], "handles": [[1]]})"), 400,
               "empty");
  expect_error(
      call(s, "POST", "/api/transform", R"({"handle": 0, "matrix": [1,0,0,0,0,1,0,0,0,0,1,0]})"),
      409, "no region");
  // A handle outside the support: accepted by the API, refused by the editor on the worker.
  ASSERT_EQ(call(s, "POST", "/api/region", json{{"support", {0, 1}}, {"handles", {handle}}}.dump())
                .status,
            202);
  s.wait();
  EXPECT_NE(json::parse(call(s, "GET", "/api/status").body)
                .value("error", "")
                .find("outside the support"),
            std::string::npos);
  // The real region.
  ASSERT_EQ(call(s, "POST", "/api/region",
                 json{{"support", support}, {"handles", {handle}}, {"k", 2}}.dump())
                .status,
            202);
  s.wait();
  const json ready = json::parse(call(s, "GET", "/api/status").body);
  ASSERT_FALSE(ready.contains("error")) << ready;
  EXPECT_EQ(ready["region"]["support"], support.size());
  const auto movable = as<std::uint32_t>(call(s, "GET", "/api/movable"));
  EXPECT_EQ(movable.size(), support.size());
  EXPECT_EQ(json::parse(call(s, "GET", "/api/region").body)["handles"][0].size(), handle.size());
  // Transforms: bad ones, then a lift by 0.5.
  expect_error(call(s, "POST", "/api/transform", R"({"handle": 0, "matrix": [1,0,0]})"), 400,
               "12 numbers");
  expect_error(
      call(s, "POST", "/api/transform", R"({"handle": 3, "matrix": [1,0,0,0,0,1,0,0,0,0,1,0]})"),
      400, "handle 3");
  expect_error(
      call(s, "POST", "/api/transform", R"({"handle": 0, "matrix": [1,0,0,0,0,1,0,0,0,0,1,"x"]})"),
      400, "matrix[11]");
  expect_error(call(s, "POST", "/api/transform",
                    R"({"handle": 0, "matrix": [1,0,0,0,0,1,0,0,0,0,1,0], "relax": 1})"),
               400, "relax: expected true");
  const HttpResponse moved =
      call(s, "POST", "/api/transform", R"({"handle": 0, "matrix": [1,0,0,0,0,1,0,0,0,0,1,0.5]})");
  ASSERT_EQ(moved.status, 200) << moved.body;
  EXPECT_EQ(moved.content_type, "application/octet-stream");
  EXPECT_TRUE(moved.headers.count("X-Frame-Ms"));
  const auto moved_positions = as<float>(moved);
  ASSERT_EQ(moved_positions.size(), 3 * movable.size());
  EXPECT_EQ(call(s, "POST", "/api/commit").status, 200);
  const auto after = as<float>(call(s, "GET", "/api/mesh/positions"));
  for (std::size_t i = 0; i < movable.size(); ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(after[3 * movable[i] + static_cast<std::size_t>(c)],
                moved_positions[3 * i + static_cast<std::size_t>(c)]);
  // The handle rose by 0.5; nothing outside the support moved.
  double rise = 0;
  for (const int v : handle)
    rise +=
        (after[3 * static_cast<std::size_t>(v) + 2] - before[3 * static_cast<std::size_t>(v) + 2]) /
        double(handle.size());
  EXPECT_NEAR(rise, 0.5, 0.02);
  std::vector<char> in_support(n, 0);
  for (const int v : support) in_support[static_cast<std::size_t>(v)] = 1;
  for (std::size_t v = 0; v < n; ++v) {
    if (in_support[v]) continue;
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(after[3 * v + static_cast<std::size_t>(c)],
                before[3 * v + static_cast<std::size_t>(c)]);
    }
  }
  // Undo twice: the region's identity state, then the bare mesh, exactly; redo comes back.
  EXPECT_TRUE(json::parse(call(s, "POST", "/api/undo").body)["changed"]);
  const auto undone = as<float>(call(s, "GET", "/api/mesh/positions"));
  std::size_t differ = 0;
  for (std::size_t i = 0; i < before.size(); ++i)
    differ += std::abs(undone[i] - before[i]) > 1e-6f ? 1 : 0;
  EXPECT_EQ(differ, 0u);
  EXPECT_TRUE(json::parse(call(s, "POST", "/api/redo").body)["changed"]);
  EXPECT_EQ(as<float>(call(s, "GET", "/api/mesh/positions")), after);
  EXPECT_FALSE(json::parse(call(s, "POST", "/api/redo").body)["changed"]);
  // Base views and exports.
  const auto base_indices = as<std::uint32_t>(call(s, "GET", "/api/base/indices"));
  const auto base_areas = as<float>(call(s, "GET", "/api/base/areas"));
  EXPECT_EQ(as<float>(call(s, "GET", "/api/base/positions")).size(), 3 * base_areas.size());
  EXPECT_GT(base_indices.size(), 0u);
  for (const std::string format : {"obj", "ply", "stl"}) {
    const HttpResponse r = call(s, "GET", "/api/export", "", {{"format", format}});
    EXPECT_EQ(r.status, 200);
    const SoupFile soup = read_soup_from_memory(r.body, format_from_path("x." + format), "export");
    EXPECT_EQ(soup.soup.num_polygons(), indices.size() / 3) << format;
  }
  expect_error(call(s, "GET", "/api/export", "", {{"format", "doc"}}), 400,
               "unknown export format");
  // A new region after a move bakes the result into a new base: the moved shape stays.
  std::vector<int> smaller;
  for (const int v : support)
    if (before[3 * static_cast<std::size_t>(v) + 2] > 0.3) smaller.push_back(v);
  ASSERT_EQ(call(s, "POST", "/api/region",
                 json{{"support", smaller}, {"handles", {handle}}, {"k", 1}}.dump())
                .status,
            202);
  s.wait();
  EXPECT_EQ(as<float>(call(s, "GET", "/api/mesh/positions")).size(), after.size());
  const auto baked = as<float>(call(s, "GET", "/api/mesh/positions"));
  double baked_rise = 0;
  for (const int v : handle)
    baked_rise +=
        (baked[3 * static_cast<std::size_t>(v) + 2] - before[3 * static_cast<std::size_t>(v) + 2]) /
        double(handle.size());
  EXPECT_NEAR(baked_rise, 0.5, 0.02);
}

/// `ids` as ranges of consecutive ids: {"ranges": [[first, count], ...]}.
json as_ranges(const std::vector<int>& ids) {
  json ranges = json::array();
  for (std::size_t i = 0; i < ids.size();) {
    std::size_t j = i + 1;
    while (j < ids.size() && ids[j] == ids[j - 1] + 1) ++j;
    ranges.push_back({ids[i], j - i});
    i = j;
  }
  return {{"ranges", ranges}};
}

TEST(Server, ARegionSentAsRangesIsTheRegionOfTheIdsTheyList) {
  Session s;
  // Ranges need a mesh to bound them.
  expect_error(
      call(s, "POST", "/api/region", R"({"support": {"ranges": [[0, 9]]}, "handles": [[0]]})"), 409,
      "no mesh");
  const SphereRegion sphere = load_sphere_with_region(s);
  const json ranges = as_ranges(sphere.support), handle_ranges = as_ranges(sphere.handle);
  ASSERT_GT(ranges["ranges"].size(), 1u); // several ranges, some longer than one id
  ASSERT_LT(ranges["ranges"].size(), sphere.support.size());
  // The support as ranges, the handle as ids, then both as ranges: the server lists the same ids.
  for (const json& handle : {json(sphere.handle), handle_ranges}) {
    ASSERT_EQ(
        call(s, "POST", "/api/region", json{{"support", ranges}, {"handles", {handle}}}.dump())
            .status,
        202);
    s.wait();
    const json status = json::parse(call(s, "GET", "/api/status").body);
    ASSERT_FALSE(status.contains("error")) << status;
    const json region = json::parse(call(s, "GET", "/api/region").body);
    EXPECT_EQ(region["support"].get<std::vector<int>>(), sphere.support);
    EXPECT_EQ(region["handles"][0].get<std::vector<int>>(), sphere.handle);
  }
  // Bad ranges are 400s that name the list or the range; the region stays.
  const auto refused = [&](const std::string& support_json, const std::string& handle_json,
                           const std::string& part, const ApiLimits& limits = {}) {
    const std::string body =
        R"({"support": )" + support_json + R"(, "handles": [)" + handle_json + "]}";
    expect_error(handle_api(s, HttpRequest{"POST", "/api/region", {}, body}, limits), 400, part);
  };
  refused(R"({"ranges": [[0, 0]]})", "[0]", "support.ranges[0]");
  refused(R"({"ranges": [[1, 2], [-1, 2]]})", "[0]", "support.ranges[1]");
  refused(R"({"ranges": [[0]]})", "[0]", "support.ranges[0]");
  refused(R"({"ranges": [[2147483647, 2]]})", "[0]", "support.ranges[0]");
  refused(R"({"ranges": [[0, 1.5]]})", "[0]", "support.ranges[0]");
  refused(R"({"ranges": [[0, 2]], "more": 1})", "[0]", "support: expected");
  refused(R"({"ids": [1]})", "[0]", "support: expected");
  // At most the mesh's vertex count per list, before anything is expanded.
  refused(R"({"ranges": [[0, 1000000000]]})", "[0]",
          "support: the ranges list more ids than the "
          "mesh has vertices (642)");
  refused(R"({"ranges": [[0, 600], [0, 43]]})", "[0]", "than the mesh has vertices (642)");
  refused("[0]", R"({"ranges": [[0, 643]]})", "handles[0]: the ranges list more ids than the mesh");
  // At most what the request's JSON limit could carry, over all its lists.
  ApiLimits small;
  small.max_json_bytes = 200; // 100 ids
  refused(R"({"ranges": [[0, 60], [100, 60]]})", "[0]",
          "support: the ranges list more ids than a "
          "request can carry (100)",
          small);
  refused("[1,2,3,4,5,6,7,8,9,10]", R"({"ranges": [[0, 95]]})",
          "handles[0]: the ranges list more ids than a request can carry (90)", small);
  // A range's last id within int: the session's check of the ids.
  refused(R"({"ranges": [[2147483647, 1]]})", "[0]", "out of range");
  EXPECT_EQ(json::parse(call(s, "GET", "/api/region").body)["support"].get<std::vector<int>>(),
            sphere.support);
}

// The status gives set_region's steps, each within the whole; a region taken again from the
// recent ones (no work) gives none, and a linear region after a nonlinear one no nonlinear step.
TEST(Server, TheStatusGivesSetRegionsStepsOfTheRegionSet) {
  Session s;
  const SphereRegion sphere = load_sphere_with_region(s);
  const auto parts = [&] { return json::parse(call(s, "GET", "/api/status").body)["region"]; };
  const json first = parts();
  double steps = 0.0;
  for (const char* step : {"map", "assemble", "factor", "solve", "encode", "finish"}) {
    ASSERT_TRUE(first["set_region_parts_ms"].contains(step)) << first;
    steps += first["set_region_parts_ms"][step].get<double>();
  }
  EXPECT_LE(steps, first["set_region_ms"].get<double>());
  const auto region = [&](const std::vector<int>& support, const char* method) {
    ASSERT_EQ(
        call(s, "POST", "/api/region",
             json{{"support", support}, {"handles", {sphere.handle}}, {"method", method}}.dump())
            .status,
        202);
    s.wait();
  };
  std::vector<int> smaller(sphere.support.begin() + 1, sphere.support.end());
  region(smaller, "nonlinear");
  EXPECT_TRUE(parts()["set_region_parts_ms"].contains("nonlinear setup")) << parts();
  std::vector<int> smallest(sphere.support.begin() + 2, sphere.support.end());
  region(smallest, "linear");
  EXPECT_FALSE(parts()["set_region_parts_ms"].contains("nonlinear setup")) << parts();
  region(sphere.support, "linear"); // the first region, kept for an undo: taken again
  EXPECT_TRUE(parts()["set_region_parts_ms"].empty()) << parts();
}

// The export is the mesh I/O layer's memory writer on the current result, byte for byte, and
// needs no file: it works without a usable temporary folder.
TEST(Server, ExportIsTheMemoryWriterAndNeedsNoTemporaryFolder) {
  Session s;
  const std::string off = sphere_off();
  ASSERT_EQ(call(s, "POST", "/api/load", off, {{"name", "sphere.off"}}).status, 202);
  s.wait();
  const Mesh loaded = read_mesh_from_memory(off, MeshFormat::Off, "sphere.off").mesh;
  const char* old_tmpdir = std::getenv("TMPDIR");
  const std::string saved = old_tmpdir ? old_tmpdir : "";
  ::setenv("TMPDIR", "/nonexistent/remora-no-temporary-folder", 1);
  for (const std::string format : {"obj", "ply", "stl"}) {
    const HttpResponse r = call(s, "GET", "/api/export", "", {{"format", format}});
    EXPECT_EQ(r.status, 200) << format << ": " << r.body;
    const std::string name = "edited." + format;
    EXPECT_EQ(r.body, write_mesh_to_memory(loaded, format_from_path(name), name)) << format;
  }
  if (old_tmpdir)
    ::setenv("TMPDIR", saved.c_str(), 1);
  else
    ::unsetenv("TMPDIR");
}

TEST(Server, BusyWhileWorkingAndSafeUnderConcurrentRequests) {
  Session s;
  const std::string off = sphere_off();
  ASSERT_EQ(call(s, "POST", "/api/load", off, {{"name", "sphere.off"}}).status, 202);
  // A second load while the first runs is refused (or the first is already done).
  const HttpResponse second = call(s, "POST", "/api/load", off, {{"name", "sphere.off"}});
  EXPECT_TRUE(second.status == 409 || second.status == 202) << second.body;
  s.wait();
  // Many threads at once: statuses, positions and transforms interleave without harm.
  const auto p = as<float>(call(s, "GET", "/api/mesh/positions"));
  std::vector<int> support, handle;
  for (std::size_t v = 0; v < p.size() / 3; ++v) {
    if (p[3 * v] > 0.0) support.push_back(static_cast<int>(v));
    if (p[3 * v] > 0.9) handle.push_back(static_cast<int>(v));
  }
  ASSERT_EQ(call(s, "POST", "/api/region", json{{"support", support}, {"handles", {handle}}}.dump())
                .status,
            202);
  s.wait();
  ASSERT_FALSE(json::parse(call(s, "GET", "/api/status").body).contains("error"));
  std::vector<std::thread> threads;
  std::atomic<int> bad{0};
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 20; ++i) {
        const HttpResponse r =
            (t % 2)
                ? call(s, "GET", (i % 2) ? "/api/status" : "/api/mesh/positions")
                : call(s, "POST", "/api/transform",
                       json{{"handle", 0}, {"matrix", {1, 0, 0, 0.01 * i, 0, 1, 0, 0, 0, 0, 1, 0}}}
                           .dump());
        if (r.status != 200) ++bad;
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(bad.load(), 0);
}

TEST(Server, TheHistoryKeepsFewEditorsAlive) {
  SessionOptions options;
  options.max_editors = 1;
  Session s(options);
  ASSERT_EQ(call(s, "POST", "/api/load", sphere_off(), {{"name", "sphere.off"}}).status, 202);
  s.wait();
  const auto p = as<float>(call(s, "GET", "/api/mesh/positions"));
  std::vector<int> support, handle;
  for (std::size_t v = 0; v < p.size() / 3; ++v) {
    if (p[3 * v + 1] > 0.0) support.push_back(static_cast<int>(v));
    if (p[3 * v + 1] > 0.9) handle.push_back(static_cast<int>(v));
  }
  const std::string region = json{{"support", support}, {"handles", {handle}}}.dump();
  ASSERT_EQ(call(s, "POST", "/api/region", region).status, 202);
  s.wait();
  ASSERT_EQ(
      call(s, "POST", "/api/transform", R"({"handle": 0, "matrix": [1,0,0,0,0,1,0,0.3,0,0,1,0]})")
          .status,
      200);
  call(s, "POST", "/api/commit");
  EXPECT_TRUE(json::parse(call(s, "GET", "/api/status").body)["undo"]);
  // A new region after the move bakes a new editor; with room for one, the old history goes.
  ASSERT_EQ(call(s, "POST", "/api/region", region).status, 202);
  s.wait();
  EXPECT_FALSE(json::parse(call(s, "GET", "/api/status").body)["undo"]);
  EXPECT_FALSE(json::parse(call(s, "POST", "/api/undo").body)["changed"]);
}

// Bytes that are not UTF-8 (in a path, a JSON key, a file name a client sent) come back in the
// JSON answers as U+FFFD: the answers parse, and nothing is a 500.
TEST(Server, BytesThatAreNotUtf8ComeBackReplacedInJson) {
  Session s;
  const auto parses = [](const HttpResponse& r) { return json::accept(r.body); };
  const HttpResponse path = call(s, "GET", "/api/\xff\xfe");
  EXPECT_EQ(path.status, 404);
  EXPECT_TRUE(parses(path)) << path.body;
  const HttpResponse key = call(s, "POST", "/api/region", "{\"\xff\": 1}");
  EXPECT_EQ(key.status, 400);
  EXPECT_TRUE(parses(key)) << key.body;
  // A broken upload named in Latin-1: the status names it, replaced, and parses.
  const std::string latin1 = "\xe9t\xe9.off";
  ASSERT_EQ(call(s, "POST", "/api/load", "OFF\n3 1 0\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n",
                 {{"name", latin1}})
                .status,
            202);
  s.wait();
  HttpResponse st = call(s, "GET", "/api/status");
  ASSERT_EQ(st.status, 200) << st.body;
  EXPECT_NE(json::parse(st.body).value("error", "").find("\xef\xbf\xbd"), std::string::npos);
  // The same name on a good mesh: every later status carries it.
  ASSERT_EQ(call(s, "POST", "/api/load", sphere_off(), {{"name", latin1}}).status, 202);
  s.wait();
  st = call(s, "GET", "/api/status");
  ASSERT_EQ(st.status, 200) << st.body;
  EXPECT_EQ(json::parse(st.body)["state"], "ready");
  EXPECT_NE(json::parse(st.body)["mesh"]["name"].get<std::string>().find("t\xef\xbf\xbd.off"),
            std::string::npos);
}

TEST(Server, StaticFilesStayInsideTheRoot) {
  const auto root = std::filesystem::temp_directory_path() / "remora_web_root_test";
  std::filesystem::create_directories(root / "three");
  std::ofstream(root / "index.html") << "<html></html>";
  std::ofstream(root / "three" / "a.js") << "export {};";
  EXPECT_EQ(serve_static(root.string(), "/").status, 200);
  EXPECT_EQ(serve_static(root.string(), "/").content_type, "text/html; charset=utf-8");
  EXPECT_EQ(serve_static(root.string(), "/three/a.js").content_type,
            "text/javascript; charset=utf-8");
  EXPECT_EQ(serve_static(root.string(), "/../etc/passwd").status, 404);
  EXPECT_EQ(serve_static(root.string(), "/three/../../x").status, 404);
  EXPECT_EQ(serve_static(root.string(), "//etc/passwd").status, 404);
  EXPECT_EQ(serve_static(root.string(), "/missing.js").status, 404);
  std::filesystem::remove_all(root);
}

} // namespace
} // namespace remora::server
