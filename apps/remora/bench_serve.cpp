// `remora bench serve`: the browser editor's latency (docs/benchmarks.md): the time from
// sending a transform request to having the moved positions, and of a status poll, over loopback
// HTTP against an in-process `remora serve` bound as the command binds it (apps/server/http.h),
// with a client that talks as the page's browser does: one kept-alive connection, TCP_NODELAY,
// for a geodesic support of a given number of input vertices.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "api.h"
#include "commands.h"
#include "http.h"
#include "remora/common/error.h"
#include "remora/common/json.h"
#include "remora/common/timer.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/io.h"
#include "session.h"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers if they follow.
#include <httplib.h> // NOLINT(llvm-include-order)

namespace remora::cli {

namespace {

struct BenchServeArgs {
  std::string mesh = std::string(REMORA_REPO_DATA) + "/bunny.ply";
  int support = 15000, requests = 200;
  double brush = 0.125; ///< the brush radius of the timed picks, in bounding-sphere radii
  bool json = false;
};

/// The body of a successful answer; throws Error naming `what` otherwise.
std::string ok(const httplib::Result& r, const char* what) {
  if (!r || r->status >= 300)
    throw Error(fmt::format("bench serve: {} failed: {}", what,
                            r ? r->body : httplib::to_string(r.error())));
  return r->body;
}

/// An in-process `remora serve` API on a free loopback port and a client for it. The listener
/// stops and is joined however the benchmark ends.
class Loopback {
public:
  Loopback() {
    server::bind_http(http_, session_, limits_, "");
    const int port = http_.bind_to_any_port("127.0.0.1");
    if (port < 0) throw IoError("127.0.0.1", "bench serve: cannot listen on any port");
    listener_ = std::thread([this] { http_.listen_after_bind(); });
    // As a browser's: one kept-alive connection, TCP_NODELAY on the client's side.
    client_ = std::make_unique<httplib::Client>("127.0.0.1", port);
    client_->set_keep_alive(true);
    client_->set_tcp_nodelay(true);
    client_->set_read_timeout(600, 0);
  }
  ~Loopback() {
    http_.stop();
    listener_.join();
  }
  Loopback(const Loopback&) = delete;
  Loopback& operator=(const Loopback&) = delete;

  httplib::Client& client() { return *client_; }

  /// Polls the status until the session is not busy; throws the job's error.
  nlohmann::json wait_ready() {
    for (;;) {
      const auto s = nlohmann::json::parse(ok(client_->Get("/api/status"), "status"));
      if (s["state"] != "busy") {
        if (s.contains("error")) throw Error("bench serve: " + s["error"].get<std::string>());
        return s;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

private:
  server::Session session_;
  const server::ApiLimits limits_;
  httplib::Server http_;
  std::thread listener_;
  std::unique_ptr<httplib::Client> client_;
};

/// Uploads the mesh and sets the region: a geodesic disc of `support` vertices around the vertex
/// nearest the centroid, the handle its innermost 3 %. Returns the status.
nlohmann::json load_with_region(Loopback& server, const std::string& path, int support) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path, "cannot open the file");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const std::string name = std::filesystem::path(path).filename().string();
  ok(server.client().Post(("/api/load?name=" + name).c_str(), bytes.str(),
                          "application/octet-stream"),
     "load");
  server.wait_ready();
  const Mesh mesh = read_mesh(path).mesh;
  const std::vector<int> disc =
      geodesic_order(mesh, central_vertex(mesh), static_cast<std::size_t>(support));
  const std::vector<int> handle(disc.begin(),
                                disc.begin() + static_cast<long>(disc.size() * 3 / 100 + 1));
  ok(server.client().Post("/api/region",
                          nlohmann::json{{"support", disc}, {"handles", {handle}}}.dump(),
                          "application/json"),
     "region");
  return server.wait_ready();
}

/// Times `count` picks (POST /api/pick, geodesic brush of `radius`) of the rays that look at the
/// vertex nearest the centroid along its normal, nudged sideways a little each time. Returns the
/// round trips and the brush size of the last one.
std::pair<std::vector<double>, std::size_t> time_picks(Loopback& server, const Mesh& mesh,
                                                       double radius, int count) {
  const VertexHandle seed = central_vertex(mesh);
  Vec3 normal(0, 0, 0);
  for (const FaceHandle f : mesh.vf_range(seed)) normal += mesh.calc_face_normal(f);
  normal.normalize();
  const Vec3 at = mesh.point(seed);
  double extent = 0;
  for (const VertexHandle v : mesh.vertices())
    extent = std::max(extent, (mesh.point(v) - at).norm());
  std::vector<double> trips;
  std::size_t brush = 0;
  for (int i = 0; i < count; ++i) {
    const Vec3 origin = at + normal * extent + Vec3(1e-4 * extent * (i % 5), 0, 0);
    const Vec3 d = -normal;
    const nlohmann::json body = {{"origin", {origin[0], origin[1], origin[2]}},
                                 {"direction", {d[0], d[1], d[2]}},
                                 {"radius", radius}};
    const auto t0 = Clock::now();
    brush = ok(server.client().Post("/api/pick", body.dump(), "application/json"), "pick").size() /
            sizeof(std::uint32_t);
    trips.push_back(ms_since(t0));
  }
  return {trips, brush};
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * double(v.size())))];
}

void run_bench_serve(const BenchServeArgs& a) {
  Loopback server;
  const nlohmann::json status = load_with_region(server, a.mesh, a.support);
  // The small answers the page waits for (status polls, commits): on a kept-alive connection
  // these meet the server's Nagle delay when it is on.
  std::vector<double> status_trips;
  for (int i = 0; i < std::min(a.requests, 100); ++i) {
    const auto t0 = Clock::now();
    ok(server.client().Get("/api/status"), "status");
    status_trips.push_back(ms_since(t0));
  }
  std::vector<double> round_trips, frames;
  std::size_t floats = 0;
  for (int i = 0; i < a.requests; ++i) {
    const double s = 0.02 * std::sin(0.1 * i);
    const nlohmann::json body = {{"handle", 0}, {"matrix", {1, 0, 0, s, 0, 1, 0, s, 0, 0, 1, 0}}};
    const auto t0 = Clock::now();
    const auto r = server.client().Post("/api/transform", body.dump(), "application/json");
    const std::string positions = ok(r, "transform");
    round_trips.push_back(ms_since(t0));
    frames.push_back(std::stod(r->get_header_value("X-Frame-Ms")));
    floats = positions.size() / sizeof(float);
  }
  const Mesh mesh = read_mesh(a.mesh).mesh;
  double bound = 0;
  const VertexHandle centre = central_vertex(mesh);
  for (const VertexHandle v : mesh.vertices())
    bound = std::max(bound, (mesh.point(v) - mesh.point(centre)).norm());
  const auto [picks, brush] = time_picks(server, mesh, a.brush * bound, 50);
  const nlohmann::json result = {{"mesh", a.mesh},
                                 {"support", status["region"]["support"]},
                                 {"free_base_vertices", status["region"]["free_base_vertices"]},
                                 {"movable_floats", floats},
                                 {"round_trip_ms_median", quantile(round_trips, 0.5)},
                                 {"round_trip_ms_p95", quantile(round_trips, 0.95)},
                                 {"round_trip_ms_max", quantile(round_trips, 1.0)},
                                 {"frame_ms_median", quantile(frames, 0.5)},
                                 {"status_round_trip_ms_median", quantile(status_trips, 0.5)},
                                 {"pick_round_trip_ms_median", quantile(picks, 0.5)},
                                 {"brush_vertices", brush},
                                 {"requests", a.requests}};
  if (a.json) {
    std::cout << dump_json(result, 2) << "\n";
    return;
  }
  std::cout << fmt::format(
      "{}: support {} vertices ({} free on the base), {} positions per answer ({:.0f} KB)\n"
      "transform request -> positions received: median {:.2f} ms, p95 {:.2f} ms, max {:.2f} ms "
      "over {} requests (server frame {:.2f} ms); GET /api/status: median {:.2f} ms\n"
      "pick with a geodesic brush of {} vertices: median {:.2f} ms\n",
      a.mesh, result["support"].get<std::size_t>(), result["free_base_vertices"].get<std::size_t>(),
      floats / 3, double(floats * 4) / 1024, quantile(round_trips, 0.5),
      quantile(round_trips, 0.95), quantile(round_trips, 1.0), a.requests, quantile(frames, 0.5),
      quantile(status_trips, 0.5), brush, quantile(picks, 0.5));
}

} // namespace

void add_bench_serve_command(CLI::App& bench) {
  auto* cmd = bench.add_subcommand(
      "serve", "The browser editor's latency: transform request to positions, on loopback");
  auto a = std::make_shared<BenchServeArgs>();
  cmd->add_option("mesh", a->mesh, "Mesh (default: the bundled bunny)");
  cmd->add_option("--support", a->support, "Input vertices in the support (default 15000)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--requests", a->requests, "Transform requests to time (default 200)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--brush", a->brush,
                  "Radius of the timed picks' brush, in bounding radii (default 0.125)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] { run_bench_serve(*a); });
}

} // namespace remora::cli
