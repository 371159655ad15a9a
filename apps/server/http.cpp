#include "http.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "remora/common/json.h"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers if they follow.
#include <httplib.h> // NOLINT(llvm-include-order)

namespace remora::server {

namespace {

/// The message of an error httplib answered without reaching a handler.
std::string transport_error(const httplib::Request& req, int status, const ApiLimits& limits) {
  switch (status) {
  case 413:
    if (req.get_header_value("Content-Type") == "application/x-www-form-urlencoded")
      return "the body was sent as a form (application/x-www-form-urlencoded, curl's default for "
             "-d); send files as application/octet-stream (curl: --data-binary @file -H "
             "'Content-Type: application/octet-stream')";
    return fmt::format("the request body is larger than the upload limit of {} bytes (remora "
                       "serve --max-upload-mb)",
                       limits.max_upload_bytes);
  case 414:
    return "the request's URI is too long";
  case 404:
    return fmt::format("no endpoint {} (see docs/server.md)", req.path);
  default:
    return fmt::format("the request could not be read (HTTP {})", status);
  }
}

} // namespace

void bind_http(httplib::Server& http, Session& session, const ApiLimits& limits,
               std::string web_root) {
  http.set_tcp_nodelay(true);
  // A page sends thousands of small requests on a few kept-alive connections; httplib closes one
  // after 5 requests by default, and the browser then opens another (or retries a request sent
  // on one being closed): 20-30 ms lost each time.
  http.set_keep_alive_max_count(100000);
  http.set_payload_max_length(limits.max_upload_bytes + 1);
  auto adapt = [&session, &limits, root = std::move(web_root)](const httplib::Request& req,
                                                               httplib::Response& res) {
    HttpRequest q{req.method, req.path, {}, req.body};
    for (const auto& [key, value] : req.params) q.query[key] = value;
    HttpResponse r;
    if (req.path.rfind("/api/", 0) == 0)
      r = handle_api(session, q, limits);
    else if (req.method != "GET")
      r = {405, "application/json", R"({"error": "only GET serves files"})", {{"Allow", "GET"}}};
    else if (root.empty())
      r = {404, "application/json", R"({"error": "no page is served here"})", {}};
    else
      r = serve_static(root, req.path);
    res.status = r.status;
    for (const auto& [key, value] : r.headers) res.set_header(key, value);
    res.set_header("Cache-Control", "no-store");
    // Cross-origin isolation, so that the page may share memory with a worker (its frames on
    // both cores: web/kernel.js); everything it loads comes from here.
    res.set_header("Cross-Origin-Opener-Policy", "same-origin");
    res.set_header("Cross-Origin-Embedder-Policy", "require-corp");
    res.set_content(r.body, r.content_type.c_str());
  };
  http.Get(".*", adapt);
  http.Post(".*", adapt);
  http.Put(".*", adapt);
  http.Patch(".*", adapt);
  http.Delete(".*", adapt);
  http.Options(".*", adapt);
  // Called for every answer of 400 and above: ours already have a body.
  http.set_error_handler([&limits](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    res.set_content(dump_json({{"error", transport_error(req, res.status, limits)}}),
                    "application/json");
  });
}

} // namespace remora::server
