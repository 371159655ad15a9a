// libFuzzer harness of the server's request -> response handlers (apps/server/api.h): a script of
// up to 12 requests (inputs.h: any method, path, query and body) against a session that has just
// loaded a small mesh. Every job is waited for after its request, so a run is deterministic.
// Every answer must be one the API documents: 2xx, or 400/404/405/409/413/422 with a JSON
// {"error": "..."} body (a 405 with Allow), JSON where it says JSON, finite positions; never a
// 500 (an exception the handlers did not expect).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "api.h"
#include "inputs.h"
#include "session.h"

namespace {

using namespace remora::server;

[[noreturn]] void fail(const std::string& what, const HttpRequest& q, const HttpResponse& r) {
  std::fprintf(stderr, "remora fuzz check failed: %s\n  request: %s %s\n  answer: %d %s\n",
               what.c_str(), q.method.c_str(), q.path.c_str(), r.status,
               r.body.substr(0, 400).c_str());
  std::abort();
}

bool is_json(const std::string& content_type) {
  return content_type.rfind("application/json", 0) == 0;
}

/// Float32 triples that must be finite: positions and base positions.
bool float_paths(const std::string& path) {
  return path == "/api/transform" || path == "/api/mesh/positions" ||
         path == "/api/base/positions" || path == "/api/base/areas";
}

void check_answer(const HttpRequest& q, const HttpResponse& r) {
  switch (r.status) {
  case 200:
  case 202:
    if (is_json(r.content_type) && !nlohmann::json::accept(r.body))
      fail("a 2xx JSON answer that is not JSON", q, r);
    if (float_paths(q.path)) {
      if (r.body.size() % sizeof(float) != 0) fail("a float array of odd length", q, r);
      for (std::size_t i = 0; i < r.body.size(); i += sizeof(float)) {
        float x;
        std::memcpy(&x, r.body.data() + i, sizeof x);
        if (!std::isfinite(x)) fail("a non-finite position or area", q, r);
      }
    }
    return;
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

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string fixture = remora::fuzz::server_fixture_off();
  const auto requests =
      remora::fuzz::parse_requests(std::string_view(reinterpret_cast<const char*>(data), size), 12);
  if (requests.empty()) return 0;
  SessionOptions options;
  options.threads = 1;
  Session session(options);
  session.start_load(fixture, "sphere.off");
  session.wait();
  ApiLimits limits;
  limits.max_upload_bytes = 1 << 16;
  limits.max_json_bytes = 1 << 16;
  for (const auto& r : requests) {
    const HttpRequest q{r.method, r.path, r.query, r.body};
    // The session is idle here, so a long poll of the status answers at once.
    check_answer(q, handle_api(session, q, limits));
    session.wait();
  }
  return 0;
}
