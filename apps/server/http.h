// The API (api.h) and the page's files bound to a cpp-httplib server, as `remora serve` runs it
// and `remora bench serve` measures it: every method of every path is routed (so a wrong method
// gets a 405 naming the right ones, not httplib's bare 404), TCP_NODELAY is on (without it every
// small answer on a kept-alive connection waits about 40 ms for the client's delayed ACK), a
// connection stays alive for many requests (not httplib's default of 5), the
// request body is capped at the upload limit, and whatever httplib answers by itself (413 too
// large, 400 malformed, 414 URI too long) carries a JSON {"error": "..."} body like every other
// error.
#pragma once

#include <string>

#include "api.h"
#include "session.h"

namespace httplib {
class Server;
} // namespace httplib

namespace remora::server {

/// Routes `http` to `session`. `web_root`: the folder of the page's files served for GETs outside
/// /api/ (empty: none, every such path is a 404). `session` and `limits` must outlive `http`.
void bind_http(httplib::Server& http, Session& session, const ApiLimits& limits,
               std::string web_root);

} // namespace remora::server
