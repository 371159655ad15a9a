// `remora serve`'s HTTP binding (apps/server/http.h) on a free loopback port, for the tests that
// talk to it over sockets.
#pragma once

#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "api.h"
#include "http.h"
#include "session.h"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers if they follow.
#include <httplib.h> // NOLINT(llvm-include-order)

namespace remora::server::testing_server {

/// bind_http() on a free loopback port, listening on its own thread until destroyed.
class Loopback {
public:
  explicit Loopback(Session& session, ApiLimits limits = {}) : limits_(limits) {
    bind_http(http_, session, limits_, "");
    port_ = http_.bind_to_any_port("127.0.0.1");
    listener_ = std::thread([this] { http_.listen_after_bind(); });
  }
  ~Loopback() {
    http_.stop();
    listener_.join();
  }
  Loopback(const Loopback&) = delete;
  Loopback& operator=(const Loopback&) = delete;
  httplib::Client client() const { return httplib::Client("127.0.0.1", port_); }
  int port() const { return port_; }

private:
  ApiLimits limits_;
  httplib::Server http_;
  int port_ = 0;
  std::thread listener_;
};

/// An answer of `status` whose JSON body's error contains `part`.
inline void expect_json_error(const httplib::Result& r, int status, const std::string& part) {
  ASSERT_TRUE(r) << httplib::to_string(r.error());
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/json");
  const nlohmann::json j = nlohmann::json::parse(r->body, nullptr, false);
  ASSERT_TRUE(j.is_object() && j.contains("error")) << r->body;
  EXPECT_NE(j["error"].get<std::string>().find(part), std::string::npos) << r->body;
}

} // namespace remora::server::testing_server
