// The server's threads (apps/server/session.h, http.h): requests from many threads while jobs
// run, as `make test-tsan` runs them under ThreadSanitizer (every other build runs them as plain
// tests). A gate in the editor's progress callback holds a job at a known phase, so that what a
// busy session answers is checked deterministically: 409 for what would change it, the shape
// shown for picks, a status whose progress only moves forward; and after the job, the history
// is what it was.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <arpa/inet.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "api.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "server_support.h"
#include "session.h"

// Last: it includes httplib.h, whose <resolv.h> `_res` macro breaks Eigen's headers if they follow.
#include "loopback.h" // NOLINT(llvm-include-order)

namespace remora::server {
namespace {

using nlohmann::json;
using namespace testing_server;

/// Holds the worker in the session's progress callback at the first phase named `phase` after
/// arm(), until release().
class Gate {
public:
  explicit Gate(std::string phase) : phase_(std::move(phase)) {}
  SessionOptions options() {
    SessionOptions o;
    o.editor.progress = [this](std::string_view p, int, int) {
      std::unique_lock lock(mutex_);
      if (!armed_ || p != phase_) return;
      armed_ = false;
      reached_ = true;
      changed_.notify_all();
      changed_.wait(lock, [&] { return open_; });
    };
    return o;
  }
  void arm() {
    std::lock_guard lock(mutex_);
    armed_ = true;
    reached_ = open_ = false;
  }
  void wait_reached() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return reached_; });
  }
  void release() {
    std::lock_guard lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }

private:
  std::string phase_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool armed_ = false, reached_ = false, open_ = false;
};

/// A mesh whose preprocessing lasts long enough to meet requests: an icosphere of 5,120 faces.
std::string bigger_sphere_ply() {
  return write_mesh_to_memory(make_icosphere(4, 1.0), MeshFormat::Ply, "big.ply");
}

const std::string kPick = R"({"origin": [0.1, 0.2, 3], "direction": [0, 0, -1], "radius": 0.3})";

/// Long polls of the status until the session is not busy; the progress of one job only moves
/// forward and stays in [0, 1]. Returns the number of broken promises.
int poll_until_idle(Session& s) {
  int broken = 0;
  double last = 0.0;
  for (;;) {
    const HttpResponse r = call(s, "GET", "/api/status", "", {{"wait", "20"}});
    const json j = json::parse(r.body, nullptr, false);
    if (r.status != 200 || !j.is_object()) return broken + 1;
    if (j["state"] != "busy") return broken;
    const double f = j["progress"]["fraction"];
    broken += f < last || f > 1.0 ? 1 : 0;
    last = f;
  }
}

TEST(ServerThreads, ALoadBeingPreparedAnswersEveryRequestAtOnce) {
  Gate gate("remesh: remesh");
  Session s(gate.options());
  gate.arm();
  ASSERT_EQ(call(s, "POST", "/api/load", bigger_sphere_ply(), {{"name", "big.ply"}}).status, 202);
  gate.wait_reached();
  // Held in the middle of the preprocessing: everything but the status and picks is a 409, and
  // picks are 409 too (nothing was loaded before).
  std::atomic<int> wrong{0};
  std::vector<std::thread> clients;
  for (int t = 0; t < 4; ++t)
    clients.emplace_back([&] {
      for (int i = 0; i < 10; ++i) {
        wrong += call(s, "GET", "/api/mesh/positions").status != 409;
        wrong += call(s, "GET", "/api/export").status != 409;
        wrong += call(s, "POST", "/api/undo").status != 409;
        wrong +=
            call(s, "POST", "/api/region", R"({"support": [0], "handles": [[0]]})").status != 409;
        wrong += call(s, "POST", "/api/load", "x", {{"name", "again.off"}}).status != 409;
        wrong += call(s, "POST", "/api/pick", kPick).status != 409;
        wrong += status_of(s)["state"] != "busy";
      }
    });
  for (auto& c : clients) c.join();
  EXPECT_EQ(wrong.load(), 0);
  // Released: polls from several threads follow the job to its end.
  std::vector<std::thread> pollers;
  std::atomic<int> broken{0};
  for (int t = 0; t < 3; ++t) pollers.emplace_back([&] { broken += poll_until_idle(s); });
  gate.release();
  for (auto& p : pollers) p.join();
  EXPECT_EQ(broken.load(), 0);
  const json ready = status_of(s);
  ASSERT_EQ(ready["state"], "ready") << ready;
  EXPECT_EQ(ready["mesh"]["vertices"], 2562);
}

TEST(ServerThreads, UndoDuringABakeIsRefusedPicksSeeTheShapeShownAndTheHistoryHolds) {
  Gate gate("base surface");
  Session s(gate.options());
  const SphereRegion r = load_sphere_with_region(s);
  ASSERT_EQ(move(s, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.3}).status, 200);
  ASSERT_EQ(call(s, "POST", "/api/commit").status, 200);
  const auto moved = as<float>(call(s, "GET", "/api/mesh/positions"));
  const HttpResponse picked = call(s, "POST", "/api/pick", kPick);
  ASSERT_EQ(picked.status, 200);
  // A new region after the move bakes: held while the new editor builds its base surface.
  gate.arm();
  std::vector<int> smaller(r.support.begin() + 1, r.support.end());
  ASSERT_EQ(
      call(s, "POST", "/api/region", json{{"support", smaller}, {"handles", {r.handle}}}.dump())
          .status,
      202);
  gate.wait_reached();
  std::atomic<int> wrong{0};
  std::vector<std::thread> clients;
  for (int t = 0; t < 4; ++t)
    clients.emplace_back([&] {
      for (int i = 0; i < 10; ++i) {
        wrong += call(s, "POST", "/api/undo").status != 409;
        wrong += call(s, "POST", "/api/redo").status != 409;
        wrong += call(s, "POST", "/api/commit").status != 409;
        wrong += move(s, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.1}).status != 409;
        wrong += call(s, "GET", "/api/export", "", {{"format", "obj"}}).status != 409;
        const HttpResponse p = call(s, "POST", "/api/pick", kPick);
        wrong += p.status != 200 || p.body != picked.body ||
                 p.headers.at("X-Hit-Face") != picked.headers.at("X-Hit-Face");
        const json st = status_of(s);
        wrong += st["state"] != "busy" || st["progress"]["job"] != "region";
      }
    });
  for (auto& c : clients) c.join();
  EXPECT_EQ(wrong.load(), 0);
  std::vector<std::thread> pollers;
  std::atomic<int> broken{0};
  for (int t = 0; t < 2; ++t) pollers.emplace_back([&] { broken += poll_until_idle(s); });
  gate.release();
  for (auto& p : pollers) p.join();
  EXPECT_EQ(broken.load(), 0);
  const json baked = status_of(s);
  ASSERT_FALSE(baked.contains("error")) << baked;
  // Undo goes back through the bake to the moved shape, bit for bit.
  EXPECT_TRUE(json::parse(call(s, "POST", "/api/undo").body)["changed"]);
  EXPECT_EQ(as<float>(call(s, "GET", "/api/mesh/positions")), moved);
}

TEST(ServerThreads, ARegionJobLetsPicksAndPollsThroughAndRefusesDrags) {
  Gate gate("set_region");
  Session s(gate.options());
  const SphereRegion r = load_sphere_with_region(s);
  const HttpResponse picked = call(s, "POST", "/api/pick", kPick);
  gate.arm();
  ASSERT_EQ(call(s, "POST", "/api/region",
                 json{{"support", r.support}, {"handles", {r.handle}}, {"k", 3}}.dump())
                .status,
            202);
  gate.wait_reached();
  std::atomic<int> wrong{0};
  std::vector<std::thread> clients;
  for (int t = 0; t < 4; ++t)
    clients.emplace_back([&] {
      for (int i = 0; i < 10; ++i) {
        const HttpResponse p = call(s, "POST", "/api/pick", kPick);
        wrong += p.status != 200 || p.body != picked.body;
        wrong += move(s, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.1}).status != 409;
        wrong += call(s, "GET", "/api/region").status != 409;
      }
    });
  for (auto& c : clients) c.join();
  EXPECT_EQ(wrong.load(), 0);
  gate.release();
  EXPECT_EQ(poll_until_idle(s), 0);
  EXPECT_EQ(status_of(s)["region"]["k"], 3);
}

TEST(ServerThreads, ConcurrentDragsEndOnOneOfTheirTransforms) {
  Session s;
  load_sphere_with_region(s);
  std::vector<std::vector<double>> matrices;
  for (int t = 0; t < 6; ++t) matrices.push_back({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.05 * (t + 1)});
  std::atomic<int> wrong{0};
  std::vector<std::thread> clients;
  for (int t = 0; t < 6; ++t)
    clients.emplace_back([&, t] {
      for (int i = 0; i < 20; ++i) {
        wrong += move(s, matrices[static_cast<std::size_t>(t)]).status != 200;
        wrong += call(s, "GET", (i % 2) ? "/api/mesh/positions" : "/api/status").status != 200;
        if (i % 5 == 4) wrong += call(s, "POST", "/api/commit").status != 200;
      }
    });
  for (auto& c : clients) c.join();
  EXPECT_EQ(wrong.load(), 0);
  // The live transform is one client's, and the positions are that transform's, exactly.
  const json live = status_of(s)["transforms"][0];
  const auto last = std::find_if(matrices.begin(), matrices.end(),
                                 [&](const std::vector<double>& m) { return json(m) == live; });
  ASSERT_NE(last, matrices.end()) << live;
  const auto shown = as<float>(call(s, "GET", "/api/mesh/positions"));
  ASSERT_EQ(move(s, *last).status, 200);
  EXPECT_EQ(as<float>(call(s, "GET", "/api/mesh/positions")), shown);
}

/// The sphere of load_sphere_with_region() with its region set again under method nonlinear.
void set_nonlinear_region(Session& s) {
  const SphereRegion r = load_sphere_with_region(s);
  ASSERT_EQ(
      call(s, "POST", "/api/region",
           json{{"support", r.support}, {"handles", {r.handle}}, {"method", "nonlinear"}}.dump())
          .status,
      202);
  s.wait();
}

/// The handle turned by `a` about z and lifted by 0.3, answered as `answer` asks.
HttpResponse turn(Session& s, double a, const char* answer) {
  const double c = std::cos(a), n = std::sin(a);
  return move(s, {c, -n, 0, 0, n, c, 0, 0, 0, 0, 1, 0.3}, answer);
}

// A relax step with a long budget gives way to a request that waits for the session: it ends
// after the iteration under way, and the next step goes on to convergence. Three clients poll
// the status while a step runs; a step can still end first (a small region converges in a few
// milliseconds, and a loaded machine may not run the clients meanwhile), so the edit is tried
// again, under new transforms, until one step has given way.
TEST(ServerThreads, ARelaxStepGivesWayToARequestThatWaits) {
  Session s;
  set_nonlinear_region(s);
  int gave_way = 0;
  for (int attempt = 0; attempt < 40 && gave_way == 0; ++attempt) {
    ASSERT_EQ(turn(s, 1.0 + 0.01 * attempt, "none").status, 204);
    std::atomic<bool> done{false};
    std::atomic<int> wrong{0}, polling{0};
    std::vector<std::thread> pollers;
    for (int t = 0; t < 3; ++t)
      pollers.emplace_back([&] {
        wrong += call(s, "GET", "/api/status").status != 200;
        ++polling;
        while (!done) wrong += call(s, "GET", "/api/status").status != 200;
      });
    while (polling < 3) std::this_thread::yield();
    const HttpResponse first = call(s, "POST", "/api/relax", R"({"budget_ms": 10000})");
    done = true;
    for (auto& p : pollers) p.join();
    EXPECT_EQ(wrong.load(), 0);
    ASSERT_EQ(first.status, 200) << first.body;
    if (first.headers.at("X-Converged") == "1") continue; // ended before a client waited
    ++gave_way;
    const HttpResponse rest = call(s, "POST", "/api/relax", R"({"budget_ms": 10000})");
    ASSERT_EQ(rest.status, 200) << rest.body;
    EXPECT_EQ(rest.headers.at("X-Converged"), "1");
  }
  EXPECT_EQ(gave_way, 1); // without the interrupt every step runs to convergence
}

// After a relax step that ends unconverged the session iterates on by itself, between requests:
// the status turns converged with no further step, and the next step answers that shape.
// A move meanwhile is answered (it waits for one iteration at most) and stops it: the iteration
// under the move's transform stays where the move's frame left it until the next relax step.
TEST(ServerThreads, AnUnconvergedRelaxStepLeavesTheSessionIterating) {
  Session s;
  set_nonlinear_region(s);
  const auto converged = [&] { return status_of(s)["nonlinear"]["converged"].get<bool>(); };
  ASSERT_EQ(turn(s, 1.2, "none").status, 204);
  const HttpResponse step = call(s, "POST", "/api/relax", R"({"budget_ms": 0.001})");
  ASSERT_EQ(step.status, 200) << step.body;
  ASSERT_EQ(step.headers.at("X-Iterations"), "1"); // one iteration always runs
  ASSERT_EQ(step.headers.at("X-Converged"), "0");
  const auto t0 = std::chrono::steady_clock::now();
  while (!converged() && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(converged()); // no request iterated meanwhile: the status polls do not
  const HttpResponse done = call(s, "POST", "/api/relax", R"({"budget_ms": 10000})");
  EXPECT_EQ(done.headers.at("X-Converged"), "1");
  const HttpResponse again = call(s, "POST", "/api/relax", R"({"budget_ms": 10000})");
  EXPECT_EQ(as<float>(again), as<float>(done)); // nothing was left to iterate

  // A move during the relaxer's iterations: answered, and the relaxer stops.
  ASSERT_EQ(turn(s, 0.4, "none").status, 204);
  ASSERT_EQ(call(s, "POST", "/api/relax", R"({"budget_ms": 0.001})").headers.at("X-Converged"),
            "0");
  const HttpResponse moved = turn(s, 0.5, "positions");
  ASSERT_EQ(moved.status, 200) << moved.body;
  if (moved.headers.at("X-Converged") == "0") {
    const auto status = status_of(s);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const auto later = status_of(s);
    EXPECT_EQ(later["nonlinear"]["iterations"], status["nonlinear"]["iterations"]);
    EXPECT_FALSE(later["nonlinear"]["converged"].get<bool>());
  }
}

// A drag's last move with "relax": true leaves the session iterating after its answer, as an
// unconverged relax step does: the status turns converged with no relax step; without it nothing
// iterates until one comes. (The moves answer nothing here: a frame of this small region could
// converge within the move's own budget.)
TEST(ServerThreads, ADragsLastMoveCanLeaveTheSessionIterating) {
  Session s;
  set_nonlinear_region(s);
  const auto nonlinear = [&] { return status_of(s)["nonlinear"]; };
  const auto last_move = [&](double a, bool relax) {
    const double c = std::cos(a), n = std::sin(a);
    const json body{{"handle", 0},
                    {"matrix", {c, -n, 0, 0, n, c, 0, 0, 0, 0, 1, 0.3}},
                    {"answer", "none"},
                    {"relax", relax}};
    return call(s, "POST", "/api/transform", body.dump());
  };
  ASSERT_EQ(last_move(1.0, false).status, 204);
  const int iterations = nonlinear()["iterations"].get<int>();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(nonlinear()["iterations"], iterations); // nothing iterates without a relax step
  EXPECT_FALSE(nonlinear()["converged"].get<bool>());

  ASSERT_EQ(last_move(1.3, true).status, 204);
  const auto t0 = std::chrono::steady_clock::now();
  while (!nonlinear()["converged"].get<bool>() &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(nonlinear()["converged"].get<bool>());
}

/// The support of SphereRegion's sphere above z = `z`, its handle above z = 0.9.
json region_above(const SphereRegion& r, double z) {
  std::vector<int> support;
  for (std::size_t v = 0; v < r.rest.size() / 3; ++v)
    if (r.rest[3 * v + 2] > z) support.push_back(static_cast<int>(v));
  return {{"support", support}, {"handles", {r.handle}}, {"method", "nonlinear"}};
}

// Method nonlinear: a new region is shown before its nonlinear state is built on the worker.
// Meanwhile moves answer the linear frame, not converged, and a relax step waits for the state
// at most its budget, or until a move; once it is there a relax step converges; a new region
// stops a build and follows it.
TEST(ServerThreads, ANonlinearRegionIsShownWhileItsNonlinearStateIsBuilt) {
  Gate gate("nonlinear state");
  Session s(gate.options());
  const SphereRegion r = load_sphere_with_region(s); // linear: nothing built apart
  const std::vector<double> turn{1, 0, 0, 0, 0, 0, -1, 0.2, 0, 1, 0, 0.5};
  gate.arm();
  ASSERT_EQ(call(s, "POST", "/api/region", region_above(r, 0.0).dump()).status, 202);
  gate.wait_reached(); // the worker builds the state
  json st = status_of(s);
  EXPECT_EQ(st["state"], "ready");
  EXPECT_EQ(st["region"]["method"], "nonlinear");
  EXPECT_TRUE(st["nonlinear"]["preparing"].get<bool>());
  const HttpResponse moved = move(s, turn);
  ASSERT_EQ(moved.status, 200) << moved.body;
  EXPECT_EQ(moved.headers.at("X-Converged"), "0");
  const HttpResponse waited = call(s, "POST", "/api/relax", R"({"budget_ms": 30})");
  ASSERT_EQ(waited.status, 200) << waited.body;
  EXPECT_EQ(waited.headers.at("X-Converged"), "0");
  EXPECT_EQ(waited.body, moved.body); // still the linear frame
  // A step with a long budget waiting for the state ends when a move comes (the page sends a
  // grab of the handle during a step at once): moves until it has answered, within 5 s.
  std::atomic<bool> answered{false};
  HttpResponse long_step;
  std::thread stepper([&] {
    long_step = call(s, "POST", "/api/relax", R"({"budget_ms": 10000})");
    answered = true;
  });
  int moves = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (!answered && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5)) {
    moves += move(s, turn).status == 200;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const bool gave_way = answered;
  gate.release();
  stepper.join();
  EXPECT_TRUE(gave_way) << moves << " moves did not end the step";
  ASSERT_EQ(long_step.status, 200) << long_step.body;
  if (gave_way) {
    EXPECT_EQ(long_step.headers.at("X-Converged"), "0");
  }
  const HttpResponse relaxed = call(s, "POST", "/api/relax", R"({"budget_ms": 10000})");
  ASSERT_EQ(relaxed.status, 200) << relaxed.body;
  EXPECT_EQ(relaxed.headers.at("X-Converged"), "1");
  EXPECT_NE(relaxed.body, moved.body); // the nonlinear shape
  st = status_of(s);
  EXPECT_FALSE(st["nonlinear"]["preparing"].get<bool>());
  EXPECT_GT(st["nonlinear"]["iterations"].get<int>(), 0);

  // A new region while a build runs: the build stops and the region follows.
  gate.arm();
  ASSERT_EQ(call(s, "POST", "/api/region", region_above(r, 0.1).dump()).status, 202);
  gate.wait_reached();
  const json last = region_above(r, -0.2);
  ASSERT_EQ(call(s, "POST", "/api/region", last.dump()).status, 202);
  EXPECT_EQ(status_of(s)["state"], "busy");
  gate.release();
  s.wait();
  st = status_of(s);
  EXPECT_FALSE(st.contains("error")) << st;
  EXPECT_EQ(st["region"]["support"], last["support"].size());
  ASSERT_EQ(move(s, turn).status, 200);
  const HttpResponse end = call(s, "POST", "/api/relax", R"({"budget_ms": 10000})");
  ASSERT_EQ(end.status, 200) << end.body;
  EXPECT_EQ(end.headers.at("X-Converged"), "1");
}

/// Connects to the loopback port, sends `bytes`, reads at most `keep` bytes of the answer and
/// hangs up (with a reset when `reset`).
void send_and_hang_up(int port, const std::string& bytes, std::size_t keep, bool reset) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  EXPECT_EQ(::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL),
            static_cast<ssize_t>(bytes.size()));
  std::string got(keep, '\0');
  if (keep > 0) {
    EXPECT_GE(::recv(fd, got.data(), keep, 0), 0);
  }
  if (reset) {
    const linger hard{1, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_LINGER, &hard, sizeof hard);
  }
  ::close(fd);
}

TEST(ServerThreads, ManyClientsOverHttpAndClientsThatHangUpMidAnswer) {
  Session s;
  const SphereRegion r = load_sphere_with_region(s);
  Loopback server(s);
  std::atomic<int> wrong{0};
  std::vector<std::thread> clients;
  for (int t = 0; t < 3; ++t)
    clients.emplace_back([&, t] {
      httplib::Client c = server.client();
      c.set_keep_alive(true);
      for (int i = 0; i < 15; ++i) {
        const std::string lift =
            json{{"handle", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.02 * (t + i)}}}
                .dump();
        const auto moved = c.Post("/api/transform", lift, "application/json");
        wrong += !moved || (moved->status != 200 && moved->status != 409);
        const auto st = c.Get("/api/status?wait=5");
        wrong += !st || st->status != 200;
        const auto picked = c.Post("/api/pick", kPick, "application/json");
        wrong += !picked || (picked->status != 200 && picked->status != 409);
      }
    });
  // Hang-ups: after a few bytes of a large answer (with a reset), in the middle of a request
  // line, and before a promised body.
  clients.emplace_back([&] {
    for (int i = 0; i < 10; ++i) {
      send_and_hang_up(server.port(), "GET /api/mesh/positions HTTP/1.1\r\nHost: x\r\n\r\n", 10,
                       i % 2 == 0);
      send_and_hang_up(server.port(), "GET /api/sta", 0, false);
      send_and_hang_up(server.port(),
                       "POST /api/load?name=a.off HTTP/1.1\r\nHost: x\r\nContent-Length: 100000\r\n"
                       "Content-Type: application/octet-stream\r\n\r\nOFF\n",
                       0, i % 2 == 1);
    }
  });
  // An upload of the same mesh while the others drag: they meet 409s until it is loaded.
  clients.emplace_back([&] {
    httplib::Client c = server.client();
    const auto loaded =
        c.Post("/api/load?name=sphere.off", sphere_off(), "application/octet-stream");
    wrong += !loaded || loaded->status != 202;
  });
  for (auto& c : clients) c.join();
  EXPECT_EQ(wrong.load(), 0);
  EXPECT_EQ(poll_until_idle(s), 0);
  // The server still answers, and the session is the upload's: the same mesh, no region.
  httplib::Client c = server.client();
  const auto st = c.Get("/api/status");
  ASSERT_TRUE(st);
  const json j = json::parse(st->body);
  EXPECT_EQ(j["state"], "ready");
  EXPECT_EQ(j["mesh"]["vertices"], r.rest.size() / 3);
  EXPECT_FALSE(j.contains("region")) << j;
}

TEST(ServerThreads, ASessionDestroyedWhileItsJobRunsWaitsForIt) {
  for (const bool region_job : {false, true}) {
    Gate gate(region_job ? "set_region" : "remesh: remesh");
    auto s = std::make_unique<Session>(gate.options());
    if (region_job) {
      const SphereRegion r = load_sphere_with_region(*s);
      gate.arm();
      ASSERT_EQ(call(*s, "POST", "/api/region",
                     json{{"support", r.support}, {"handles", {r.handle}}, {"k", 1}}.dump())
                    .status,
                202);
    } else {
      gate.arm();
      ASSERT_EQ(call(*s, "POST", "/api/load", sphere_off(), {{"name", "sphere.off"}}).status, 202);
    }
    gate.wait_reached();
    std::thread release([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      gate.release();
    });
    s.reset(); // joins the worker, which the release lets finish
    release.join();
  }
}

} // namespace
} // namespace remora::server
