// run_server_script() of harness.h. A fresh session per script keeps a run reproducible: one
// carried over from input to input would make a finding depend on the inputs before it.
#include <cmath>
#include <cstring>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "api.h"
#include "harness.h"
#include "inputs.h"
#include "session.h"

namespace remora::fuzz {

namespace {

using server::HttpRequest;
using server::HttpResponse;

[[noreturn]] void fail(const std::string& what, const HttpRequest& q, const HttpResponse& r) {
  throw CheckFailed(what + "; request: " + q.method + " " + q.path +
                    "; answer: " + std::to_string(r.status) + " " + r.body.substr(0, 400));
}

bool is_json(const std::string& content_type) {
  return content_type.rfind("application/json", 0) == 0;
}

/// Float32 arrays that must be finite: positions (of a move, a relax step, the mesh), base
/// positions and areas.
bool float_paths(const std::string& path) {
  return path == "/api/transform" || path == "/api/relax" || path == "/api/mesh/positions" ||
         path == "/api/base/positions" || path == "/api/base/areas";
}

void check_success(const HttpRequest& q, const HttpResponse& r) {
  if (is_json(r.content_type) && !nlohmann::json::accept(r.body))
    fail("a 2xx JSON answer that is not JSON", q, r);
  if (!float_paths(q.path)) return;
  if (r.body.size() % sizeof(float) != 0) fail("a float array of odd length", q, r);
  for (std::size_t i = 0; i < r.body.size(); i += sizeof(float)) {
    float x;
    std::memcpy(&x, r.body.data() + i, sizeof x);
    if (!std::isfinite(x)) fail("a non-finite position or area", q, r);
  }
}

void check_answer(const HttpRequest& q, const HttpResponse& r) {
  switch (r.status) {
  case 200:
  case 202:
    return check_success(q, r);
  case 400:
  case 404:
  case 405:
  case 409:
  case 413:
  case 422: {
    if (!is_json(r.content_type)) fail("an error that is not JSON", q, r);
    const nlohmann::json j = nlohmann::json::parse(r.body, nullptr, false);
    if (!j.is_object() || !j.contains("error") || !j["error"].is_string() ||
        j["error"].get<std::string>().empty())
      fail("an error without its message", q, r);
    if (r.status == 405 && !r.headers.count("Allow")) fail("a 405 without Allow", q, r);
    return;
  }
  default:
    fail("an answer the API does not document (" + std::to_string(r.status) + ")", q, r);
  }
}

} // namespace

void run_server_script(std::string_view input) {
  static const std::string fixture = server_fixture_off();
  const auto requests = parse_requests(input, 12);
  if (requests.empty()) return;
  server::SessionOptions options;
  options.threads = 1;
  server::Session session(options);
  session.start_load(fixture, "sphere.off");
  session.wait();
  server::ApiLimits limits;
  limits.max_upload_bytes = 1 << 16;
  limits.max_json_bytes = 1 << 16;
  for (const auto& r : requests) {
    const HttpRequest q{r.method, r.path, r.query, r.body};
    // The session is idle here, so a long poll of the status answers at once.
    check_answer(q, server::handle_api(session, q, limits));
    session.wait();
  }
}

} // namespace remora::fuzz
