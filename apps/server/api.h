// The HTTP API of `remora serve`, as plain functions from a request to a response so that every
// handler is tested without sockets (tests/test_server.cpp); serve_cmd.cpp binds them to
// cpp-httplib. docs/server.md lists the endpoints.
//
// Mesh data travels as binary, little-endian: Float32 x, y, z per vertex, Uint32 vertex triples
// per face, Uint32 ids. Everything else is JSON. A bad request gets a 4xx with {"error": "..."}:
// 400 malformed (JSON shape, ids, numbers), 404 unknown path, 405 wrong method (with an Allow
// header naming the methods the path takes), 409 busy or not ready, 413 too large, 422 a solver
// that failed on the request's region. Never a 5xx for anything a client sends.
#pragma once

#include <cstddef>
#include <map>
#include <string>

#include "session.h"

namespace remora::server {

struct HttpRequest {
  std::string method; ///< "GET", "POST"
  std::string path;   ///< e.g. "/api/status"
  std::map<std::string, std::string> query;
  std::string body;
};

struct HttpResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::map<std::string, std::string> headers;
};

struct ApiLimits {
  std::size_t max_upload_bytes = std::size_t(256) << 20; ///< POST /api/load
  std::size_t max_json_bytes = std::size_t(64) << 20;    ///< every JSON body
};

/// Handles a request under /api/. Never throws.
HttpResponse handle_api(Session& session, const HttpRequest& request, const ApiLimits& limits = {});

/// Serves a file of `root` for a GET of `path` ("/" is index.html); 404 for anything missing or
/// outside root (no "..", no absolute paths). Never throws.
HttpResponse serve_static(const std::string& root, const std::string& path);

} // namespace remora::server
