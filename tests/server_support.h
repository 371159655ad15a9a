// Helpers of the server's tests: a mesh to upload and calls of the API without sockets.
#pragma once

#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "api.h"
#include "remora/mesh/primitives.h"
#include "session.h"

namespace remora::server::testing_server {

/// A bumpy sphere as OFF text, made in memory (tests run in parallel: no shared temporary file).
inline std::string sphere_off(int subdivisions = 3) {
  Mesh m = make_icosphere(subdivisions, 1.0);
  std::ostringstream s;
  s.precision(17);
  s << "OFF\n" << m.n_vertices() << " " << m.n_faces() << " 0\n";
  for (const VertexHandle v : m.vertices()) {
    const Vec3 p =
        m.point(v) * (1.0 + 0.03 * std::sin(9 * m.point(v)[0]) * std::sin(9 * m.point(v)[1]));
    s << p[0] << " " << p[1] << " " << p[2] << "\n";
  }
  for (const FaceHandle f : m.faces()) {
    s << 3;
    for (const VertexHandle v : m.fv_range(f)) s << " " << v.idx();
    s << "\n";
  }
  return s.str();
}

inline HttpResponse call(Session& s, const std::string& method, const std::string& path,
                         const std::string& body = "",
                         std::map<std::string, std::string> query = {}) {
  return handle_api(s, HttpRequest{method, path, std::move(query), body});
}

template <class T>
std::vector<T> as(const HttpResponse& r) {
  std::vector<T> out(r.body.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), r.body.data(), out.size() * sizeof(T));
  return out;
}

inline void expect_error(const HttpResponse& r, int status, const std::string& part) {
  EXPECT_EQ(r.status, status) << r.body;
  const nlohmann::json j = nlohmann::json::parse(r.body, nullptr, false);
  ASSERT_TRUE(j.is_object() && j.contains("error")) << r.body;
  EXPECT_NE(j["error"].get<std::string>().find(part), std::string::npos) << r.body;
}

/// The rest positions of sphere_off() and a region on it: the cap above z = 0.2, the handle above
/// z = 0.9.
struct SphereRegion {
  std::vector<float> rest;
  std::vector<int> support, handle;
};

/// Loads sphere_off() into `s` and sets SphereRegion's region with `k`; fails the test on error.
inline SphereRegion load_sphere_with_region(Session& s, int k = 2) {
  SphereRegion r;
  EXPECT_EQ(call(s, "POST", "/api/load", sphere_off(), {{"name", "sphere.off"}}).status, 202);
  s.wait();
  r.rest = as<float>(call(s, "GET", "/api/mesh/positions"));
  for (std::size_t v = 0; v < r.rest.size() / 3; ++v) {
    if (r.rest[3 * v + 2] > 0.2) r.support.push_back(static_cast<int>(v));
    if (r.rest[3 * v + 2] > 0.9) r.handle.push_back(static_cast<int>(v));
  }
  const nlohmann::json region = {{"support", r.support}, {"handles", {r.handle}}, {"k", k}};
  EXPECT_EQ(call(s, "POST", "/api/region", region.dump()).status, 202);
  s.wait();
  const nlohmann::json status = nlohmann::json::parse(call(s, "GET", "/api/status").body);
  EXPECT_FALSE(status.contains("error")) << status;
  return r;
}

/// GET /api/status, parsed.
inline nlohmann::json status_of(Session& s) {
  return nlohmann::json::parse(call(s, "GET", "/api/status").body);
}

/// POST /api/transform of handle 0 with the rows of [M | t], answered as `answer` asks (the
/// server's default without one); the response.
inline HttpResponse move(Session& s, const std::vector<double>& rows,
                         const char* answer = nullptr) {
  nlohmann::json body{{"handle", 0}, {"matrix", rows}};
  if (answer) body["answer"] = answer;
  return call(s, "POST", "/api/transform", body.dump());
}

} // namespace remora::server::testing_server
