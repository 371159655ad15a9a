#include "api.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "remora/common/json.h"

namespace remora::server {

namespace {

using nlohmann::json;

HttpResponse json_response(int status, const json& body) {
  HttpResponse r;
  r.status = status;
  r.body = dump_json(body);
  return r;
}

HttpResponse error_response(int status, const std::string& message) {
  return json_response(status, {{"error", message}});
}

template <class T>
HttpResponse binary_response(const std::vector<T>& data) {
  HttpResponse r;
  r.content_type = "application/octet-stream";
  r.body.resize(data.size() * sizeof(T));
  if (!data.empty()) std::memcpy(r.body.data(), data.data(), r.body.size());
  return r;
}

/// A 400 with a message: a request the client can fix.
class BadRequest : public Error {
public:
  using Error::Error;
};

/// A 405: the path exists but does not take the request's method; `allowed` is what it takes
/// (the response's Allow header).
class MethodNotAllowed : public Error {
public:
  MethodNotAllowed(const HttpRequest& request, std::string allowed)
      : Error(fmt::format("{} does not take {}; use {}", request.path, request.method, allowed)),
        allowed_(std::move(allowed)) {}
  const std::string& allowed() const { return allowed_; }

private:
  std::string allowed_;
};

json parse_json(const HttpRequest& request, const ApiLimits& limits) {
  if (request.body.size() > limits.max_json_bytes)
    throw BadRequest(fmt::format("the JSON body has {} bytes; the limit is {}", request.body.size(),
                                 limits.max_json_bytes));
  try {
    return json::parse(request.body);
  } catch (const json::exception& e) { // a syntax error, or a number out of range (1e400)
    throw BadRequest(fmt::format("the body is not valid JSON: {}", e.what()));
  }
}

/// A list of vertex ids: an array of ids, or {"ranges": [[first, count], ...]} for the ids first,
/// first + 1, ..., first + count - 1 of each range in turn. Ranges expand to at most `vertices`
/// ids per list (the mesh's vertex count: more can only repeat ids) and `budget` ids over the
/// whole request (what arrays in a body of the JSON limit's size could hold), which each list
/// read decreases.
std::vector<int> ids(const json& j, const std::string& path, std::size_t vertices,
                     std::size_t& budget) {
  constexpr long long kMaxId = 2147483647LL;
  std::vector<int> out;
  if (j.is_object()) {
    if (j.size() != 1 || !j.contains("ranges") || !j.at("ranges").is_array())
      throw BadRequest(path + ": expected an array of vertex ids or {\"ranges\": [[first, count], "
                              "...]}");
    if (vertices == 0) throw Busy("no mesh is loaded yet: load one first");
    const json& ranges = j.at("ranges");
    std::vector<std::pair<long long, long long>> runs; // first, count
    std::size_t total = 0;
    for (std::size_t i = 0; i < ranges.size(); ++i) {
      const json& r = ranges[i];
      const bool well_formed =
          r.is_array() && r.size() == 2 && r[0].is_number_integer() && r[1].is_number_integer();
      const long long first = well_formed ? r[0].get<long long>() : -1;
      const long long count = well_formed ? r[1].get<long long>() : 0;
      if (first < 0 || count < 1 || first > kMaxId - count + 1)
        throw BadRequest(fmt::format("{}.ranges[{}]: expected [first, count], first >= 0, count "
                                     ">= 1, first + count - 1 a vertex id",
                                     path, i));
      total += static_cast<std::size_t>(count);
      if (total > vertices)
        throw BadRequest(fmt::format("{}: the ranges list more ids than the mesh has vertices "
                                     "({})",
                                     path, vertices));
      if (total > budget)
        throw BadRequest(fmt::format("{}: the ranges list more ids than a request can carry ({})",
                                     path, budget));
      runs.emplace_back(first, count);
    }
    out.reserve(total);
    for (const auto& [first, count] : runs)
      for (long long v = first; v < first + count; ++v) out.push_back(static_cast<int>(v));
    budget -= total;
    return out;
  }
  if (!j.is_array())
    throw BadRequest(path + ": expected an array of vertex ids or {\"ranges\": [[first, count], "
                            "...]}");
  out.reserve(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) {
    if (!j[i].is_number_integer() || j[i].get<long long>() < 0 || j[i].get<long long>() > kMaxId)
      throw BadRequest(fmt::format("{}[{}]: expected a vertex id (an integer >= 0)", path, i));
    out.push_back(j[i].get<int>());
  }
  budget -= std::min(budget, out.size());
  return out;
}

void only_keys(const json& j, std::initializer_list<const char*> keys) {
  if (!j.is_object()) throw BadRequest("expected a JSON object");
  for (const auto& item : j.items()) {
    bool known = false;
    for (const char* k : keys) known = known || item.key() == k;
    if (!known) throw BadRequest(fmt::format("unknown key '{}'", item.key()));
  }
}

HttpResponse region(Session& session, const HttpRequest& request, const ApiLimits& limits) {
  const json j = parse_json(request, limits);
  only_keys(j, {"support", "handles", "k", "method", "energy"});
  if (!j.contains("support") || !j.contains("handles"))
    throw BadRequest("expected {\"support\": [ids], \"handles\": [[ids], ...], \"k\": 1|2|3, "
                     "\"method\": \"linear\"|\"nonlinear\", \"energy\": name}");
  std::size_t budget = limits.max_json_bytes / 2; // "0," per id in an array
  const std::size_t vertices = session.vertex_count();
  std::vector<int> support = ids(j.at("support"), "support", vertices, budget);
  const json& hs = j.at("handles");
  if (!hs.is_array()) throw BadRequest("handles: expected an array of lists of vertex ids");
  std::vector<std::vector<int>> handles;
  for (std::size_t i = 0; i < hs.size(); ++i)
    handles.push_back(ids(hs[i], fmt::format("handles[{}]", i), vertices, budget));
  int k = 2;
  if (j.contains("k")) {
    if (!j.at("k").is_number_integer()) throw BadRequest("k: expected 1, 2 or 3");
    k = j.at("k").get<int>();
  }
  EditMethod method = EditMethod::Linear;
  if (j.contains("method")) {
    if (!j.at("method").is_string())
      throw BadRequest("method: expected \"linear\" or \"nonlinear\"");
    method = parse_edit_method(j.at("method").get<std::string>());
  }
  std::optional<NonlinearEnergy> energy;
  if (j.contains("energy")) {
    if (!j.at("energy").is_string())
      throw BadRequest("energy: expected \"rotated-laplacian\", \"propagated\", "
                       "\"blended-motions\" or \"arap\"");
    energy = parse_nonlinear_energy(j.at("energy").get<std::string>());
  }
  if (support.empty()) throw BadRequest("the support is empty: paint at least one vertex");
  if (handles.empty()) throw BadRequest("no handle: paint a handle inside the support");
  session.start_region(std::move(support), std::move(handles), k, method, energy);
  return json_response(202, session.status());
}

/// A frame's answer as Float32: the positions, then the base's row offsets, each when `answer`
/// asks for them; its figures in headers: X-Frame-Ms (the server's time), X-Converged (1, or 0
/// while method nonlinear still iterates), X-Iterations, and when offsets are asked for
/// X-Base-Offset-Rows (their rows, 3 floats each, at the end of the body).
HttpResponse frame_response(const Frame& f, FrameAnswer answer) {
  HttpResponse r = binary_response(f.positions);
  if (!f.base_offsets.empty())
    r.body.append(reinterpret_cast<const char*>(f.base_offsets.data()),
                  f.base_offsets.size() * sizeof(float));
  r.headers["X-Frame-Ms"] = fmt::format("{:.3f}", f.ms);
  r.headers["X-Converged"] = std::to_string(f.converged ? 1 : 0);
  r.headers["X-Iterations"] = std::to_string(f.iterations);
  if (answer == FrameAnswer::BaseOffsets || answer == FrameAnswer::PositionsAndBaseOffsets)
    r.headers["X-Base-Offset-Rows"] = std::to_string(f.base_offsets.size() / 3);
  return r;
}

/// The "answer" of a transform or relax request (default "positions").
FrameAnswer frame_answer(const json& j) {
  if (!j.contains("answer")) return FrameAnswer::Positions;
  const json& a = j.at("answer");
  if (a.is_string()) {
    if (a == "positions") return FrameAnswer::Positions;
    if (a == "none") return FrameAnswer::None;
    if (a == "base-offsets") return FrameAnswer::BaseOffsets;
    if (a == "positions-and-base-offsets") return FrameAnswer::PositionsAndBaseOffsets;
  }
  throw BadRequest("answer: expected \"positions\" (the default), \"none\", \"base-offsets\" "
                   "or \"positions-and-base-offsets\"");
}

HttpResponse transform(Session& session, const HttpRequest& request, const ApiLimits& limits) {
  const json j = parse_json(request, limits);
  only_keys(j, {"handle", "matrix", "answer", "relax"});
  const FrameAnswer answer = frame_answer(j);
  if (j.contains("relax") && !j.at("relax").is_boolean())
    throw BadRequest("relax: expected true (go on iterating after the answer) or false");
  const bool then_relax = j.value("relax", false);
  if (!j.contains("handle") || !j.at("handle").is_number_integer())
    throw BadRequest("handle: expected a handle index");
  const json& m = j.contains("matrix") ? j.at("matrix") : json();
  if (!m.is_array() || m.size() != 12)
    throw BadRequest("matrix: expected 12 numbers, the rows of the 3x4 affine map [M | t]");
  Transform t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      const json& x = m[static_cast<std::size_t>(4 * r + c)];
      if (!x.is_number() || !std::isfinite(x.get<double>()))
        throw BadRequest(fmt::format("matrix[{}]: expected a finite number", 4 * r + c));
      t(r, c) = x.get<double>();
    }
  HttpResponse r = frame_response(
      session.set_transform(j.at("handle").get<int>(), t, answer, then_relax), answer);
  if (answer == FrameAnswer::None) {
    r.status = 204;
    r.body.clear();
  }
  return r;
}

/// The region's frame (FrameExport) in one buffer of 4-byte little-endian words: a header of 16
/// Uint32 (version 1, handles, local vertices, basis rows, basis columns, handle vertices, faces,
/// normal vertices, ring length, records, residuals, offsets 0 or 1, blended motions 0 or 1,
/// corrected by the base offsets 0 or 1, 0...), then rest, free_local, basis, handle_begin, handle_local, faces, normal_vertices, ring_begin,
/// ring, record_face, record_slot, record_bary, record_offset, record_residual, residuals,
/// offsets (docs/server.md).
HttpResponse kernel_response(const FrameExport& f) {
  const auto count = [](const auto& v) { return static_cast<std::uint32_t>(v.size()); };
  const std::uint32_t columns = 3 + 4 * static_cast<std::uint32_t>(f.handles);
  const std::uint32_t header[16] = {1,
                                    static_cast<std::uint32_t>(f.handles),
                                    count(f.rest) / 6,
                                    count(f.free_local),
                                    columns,
                                    count(f.handle_local),
                                    count(f.faces) / 3,
                                    count(f.normal_vertices),
                                    count(f.ring),
                                    count(f.record_face),
                                    count(f.residuals) / 3,
                                    f.offsets.empty() ? 0u : 1u,
                                    f.blended ? 1u : 0u,
                                    f.corrected ? 1u : 0u};
  HttpResponse r;
  r.content_type = "application/octet-stream";
  const auto append = [&r](const void* data, std::size_t bytes) {
    if (bytes > 0) r.body.append(static_cast<const char*>(data), bytes);
  };
  const auto section = [&append](const auto& v) { append(v.data(), v.size() * sizeof(v[0])); };
  append(header, sizeof header);
  section(f.rest);
  section(f.free_local);
  section(f.basis);
  section(f.handle_begin);
  section(f.handle_local);
  section(f.faces);
  section(f.normal_vertices);
  section(f.ring_begin);
  section(f.ring);
  section(f.record_face);
  section(f.record_slot);
  section(f.record_bary);
  section(f.record_offset);
  section(f.record_residual);
  section(f.residuals);
  section(f.offsets);
  return r;
}

/// POST /api/relax {"budget_ms": B, "answer": A}: method nonlinear goes on iterating under the
/// live transforms for at most B milliseconds (default 50); A as for a transform, but "none".
HttpResponse relax(Session& session, const HttpRequest& request, const ApiLimits& limits) {
  double budget = 50.0;
  FrameAnswer answer = FrameAnswer::Positions;
  if (!request.body.empty()) {
    const json j = parse_json(request, limits);
    only_keys(j, {"budget_ms", "answer"});
    if (j.contains("budget_ms")) {
      const json& b = j.at("budget_ms");
      if (!b.is_number() || !(b.get<double>() > 0.0) || !(b.get<double>() <= 10000.0))
        throw BadRequest("budget_ms: expected milliseconds above 0, at most 10000");
      budget = b.get<double>();
    }
    answer = frame_answer(j);
    if (answer == FrameAnswer::None)
      throw BadRequest("answer: a relax step answers \"positions\", \"base-offsets\" or "
                       "\"positions-and-base-offsets\"");
  }
  return frame_response(session.relax(budget, answer), answer);
}

/// A 3-vector of finite numbers at `key`.
Vec3 vec3(const json& j, const char* key) {
  const json& v = j.contains(key) ? j.at(key) : json();
  if (!v.is_array() || v.size() != 3)
    throw BadRequest(fmt::format("{}: expected 3 numbers [x, y, z]", key));
  Vec3 out;
  for (std::size_t c = 0; c < 3; ++c) {
    if (!v[c].is_number() || !std::isfinite(v[c].get<double>()))
      throw BadRequest(fmt::format("{}[{}]: expected a finite number", key, c));
    out[static_cast<int>(c)] = v[c].get<double>();
  }
  return out;
}

HttpResponse pick(Session& session, const HttpRequest& request, const ApiLimits& limits) {
  const json j = parse_json(request, limits);
  only_keys(j, {"origin", "direction", "radius", "brush", "stroke"});
  const Vec3 origin = vec3(j, "origin"), direction = vec3(j, "direction");
  if (!(direction.sqrnorm() > 0.0)) throw BadRequest("direction: must not be zero");
  double radius = 0.0;
  if (j.contains("radius")) {
    if (!j.at("radius").is_number() || !(j.at("radius").get<double>() >= 0.0) ||
        !std::isfinite(j.at("radius").get<double>()))
      throw BadRequest("radius: expected a finite number >= 0");
    radius = j.at("radius").get<double>();
  }
  Brush brush = Brush::Geodesic;
  if (j.contains("brush")) {
    if (!j.at("brush").is_string()) throw BadRequest("brush: expected \"geodesic\" or \"sphere\"");
    brush = parse_brush(j.at("brush").get<std::string>());
  }
  std::int64_t stroke = -1;
  if (j.contains("stroke")) {
    const json& s = j.at("stroke");
    if (!s.is_number_integer() || s.get<std::int64_t>() < 0 ||
        s.get<std::int64_t>() > (std::int64_t{1} << 53))
      throw BadRequest("stroke: expected an integer from 0 to 2^53");
    stroke = s.get<std::int64_t>();
  }
  const Pick p = session.pick(origin, direction, radius, brush, stroke);
  HttpResponse r = binary_response(p.brush);
  r.headers["X-Hit-Face"] = std::to_string(p.face);
  r.headers["X-Hit-Vertex"] = std::to_string(p.vertex);
  r.headers["X-Hit-Point"] =
      fmt::format("{:.9g} {:.9g} {:.9g}", p.point[0], p.point[1], p.point[2]);
  return r;
}

/// The download's file name: the loaded file's stem, "_edited" and the format's extension.
std::string export_name(const std::string& loaded, const std::string& format) {
  std::string stem = std::filesystem::path(loaded).stem().string();
  // Only characters that need no quoting in a header.
  for (char& c : stem)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  return (stem.empty() ? std::string("mesh") : stem) + "_edited." + format;
}

HttpResponse dispatch(Session& session, const HttpRequest& q, const ApiLimits& limits) {
  const std::string& p = q.path;
  const bool get = q.method == "GET";
  // `method` or a 405 that names `allowed` (the methods the path takes).
  auto need = [&](const std::string& method, const std::string& allowed) {
    if (q.method != method) throw MethodNotAllowed(q, allowed);
  };
  auto get_only = [&] { need("GET", "GET"); };
  auto post_only = [&] { need("POST", "POST"); };
  if (p == "/api/status") {
    get_only();
    // ?wait=MS: a long poll, answered when the job ends or after MS milliseconds.
    if (const auto w = q.query.find("wait"); w != q.query.end()) {
      int ms = -1;
      const auto [end, error] =
          std::from_chars(w->second.data(), w->second.data() + w->second.size(), ms);
      if (error != std::errc() || end != w->second.data() + w->second.size() || ms < 0 ||
          ms > 10000)
        throw BadRequest("wait: expected milliseconds from 0 to 10000");
      session.wait_for(std::chrono::milliseconds(ms));
    }
    return json_response(200, session.status());
  }
  if (p == "/api/load") {
    post_only();
    const auto name = q.query.find("name");
    if (name == q.query.end() || name->second.empty())
      throw BadRequest("give the file name as ?name=mesh.ply (its extension names the format)");
    if (q.body.empty()) throw BadRequest("the upload is empty");
    if (q.body.size() > limits.max_upload_bytes)
      return error_response(413, fmt::format("the upload has {} bytes; the limit is {}",
                                             q.body.size(), limits.max_upload_bytes));
    session.start_load(q.body, name->second);
    return json_response(202, session.status());
  }
  if (p == "/api/mesh/positions") return get_only(), binary_response(session.positions());
  if (p == "/api/mesh/indices") return get_only(), binary_response(session.indices());
  if (p == "/api/movable") return get_only(), binary_response(session.movable_vertices());
  if (p == "/api/base/positions") return get_only(), binary_response(session.base_positions());
  if (p == "/api/base/indices") return get_only(), binary_response(session.base_indices());
  if (p == "/api/base/areas") return get_only(), binary_response(session.base_areas());
  if (p == "/api/region" && get) return json_response(200, session.region());
  if (p == "/api/region/kernel") return get_only(), kernel_response(session.frame_export());
  if (p == "/api/region") return need("POST", "GET, POST"), region(session, q, limits);
  if (p == "/api/transform") return post_only(), transform(session, q, limits);
  if (p == "/api/relax") return post_only(), relax(session, q, limits);
  if (p == "/api/pick") return post_only(), pick(session, q, limits);
  if (p == "/api/commit")
    return post_only(), session.commit(), json_response(200, session.status());
  if (p == "/api/undo" || p == "/api/redo") {
    post_only();
    const bool done = p == "/api/undo" ? session.undo() : session.redo();
    json s = session.status();
    s["changed"] = done;
    return json_response(200, s);
  }
  if (p == "/api/export") {
    get_only();
    const auto f = q.query.find("format");
    const std::string format = f == q.query.end() ? "ply" : f->second;
    HttpResponse r;
    r.content_type = "application/octet-stream";
    r.body = session.export_mesh(format);
    r.headers["Content-Disposition"] =
        fmt::format("attachment; filename=\"{}\"", export_name(session.name(), format));
    return r;
  }
  return error_response(404, fmt::format("no endpoint {} (see docs/server.md)", p));
}

} // namespace

HttpResponse handle_api(Session& session, const HttpRequest& request, const ApiLimits& limits) {
  try {
    return dispatch(session, request, limits);
  } catch (const MethodNotAllowed& e) {
    HttpResponse r = error_response(405, e.what());
    r.headers["Allow"] = e.allowed();
    return r;
  } catch (const BadRequest& e) {
    return error_response(400, e.what());
  } catch (const Busy& e) {
    return error_response(409, e.what());
  } catch (const InvalidArgument& e) {
    return error_response(400, e.what());
  } catch (const IoError& e) {
    return error_response(400, e.what());
  } catch (const NumericalError& e) {
    return error_response(422, e.what());
  } catch (const std::bad_alloc&) {
    return error_response(413, "out of memory: the request is too large for this machine");
  } catch (const std::exception& e) {
    return error_response(500, fmt::format("internal error: {}", e.what()));
  }
}

HttpResponse serve_static(const std::string& root, const std::string& path) {
  namespace fs = std::filesystem;
  const std::string rel = path == "/" || path.empty() ? "index.html" : path.substr(1);
  if (rel.find("..") != std::string::npos || rel.find('\\') != std::string::npos ||
      (!rel.empty() && rel[0] == '/'))
    return error_response(404, "not found");
  const fs::path file = fs::path(root) / rel;
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return error_response(404, "not found: " + path);
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  HttpResponse r;
  r.body = bytes.str();
  const std::string ext = file.extension().string();
  r.content_type = ext == ".html"   ? "text/html; charset=utf-8"
                   : ext == ".js"   ? "text/javascript; charset=utf-8"
                   : ext == ".mjs"  ? "text/javascript; charset=utf-8"
                   : ext == ".css"  ? "text/css; charset=utf-8"
                   : ext == ".png"  ? "image/png"
                   : ext == ".wasm" ? "application/wasm"
                                    : "application/octet-stream";
  return r;
}

} // namespace remora::server
