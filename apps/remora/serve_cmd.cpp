// `remora serve`: the browser editor. Binds the API of apps/server/api.h and the page's files to
// cpp-httplib, on loopback unless told otherwise, and prints the URL.
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <fmt/format.h>

#include "api.h"
#include "commands.h"
#include "http.h"
#include "limit_options.h"
#include "remora/common/error.h"
#include "session.h"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers if they follow.
#include <httplib.h> // NOLINT(llvm-include-order)

namespace remora::cli {

namespace {

httplib::Server* running = nullptr;

void stop_on_signal(int) {
  if (running) running->stop();
}

} // namespace

void add_serve_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("serve", "The editor in the browser: serves the page and its API");
  struct Args {
    std::string mesh, host = "127.0.0.1", web_root = REMORA_WEB_ROOT, energy;
    int port = 8080, threads = 0, max_handles = kMaxHandles, history_editors = 3;
    double max_upload_mb = 256, frame_budget_ms = 6.0;
    std::uint64_t max_triangles = 0;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("mesh", a->mesh, "Mesh to load at start (.obj .off .ply .stl)");
  cmd->add_option("--host", a->host, "Address to bind (default 127.0.0.1: this machine only)");
  cmd->add_option("--port", a->port, "Port (default 8080; 0 picks a free one)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--web-root", a->web_root, "Folder of the page's files (default: the build's)");
  cmd->add_option("--max-upload-mb", a->max_upload_mb, "Largest mesh upload in MB (default 256)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--threads", a->threads, "Editor threads (default: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--frame-budget", a->frame_budget_ms,
                  "Method nonlinear: milliseconds of iterations per handle move (default 6)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--energy", a->energy,
                  "Method nonlinear: rotated-laplacian (default), propagated, blended-motions or "
                  "arap (docs/nonlinear.md)")
      ->check(CLI::IsMember(nonlinear_energy_names()));
  cmd->add_option("--history-editors", a->history_editors,
                  "Editors (one per bake) the undo history keeps alive (default 3); fewer raise "
                  "the default --max-triangles")
      ->check(CLI::PositiveNumber);
  // The history keeps its editors alive and a bake builds one more.
  add_max_triangles_option(cmd, a->max_triangles, a->history_editors + 1);
  add_max_handles_option(cmd, a->max_handles);
  cmd->callback([a, cmd] {
    // The default of --max-triangles for the --history-editors given.
    if (cmd->count("--max-triangles") == 0)
      a->max_triangles = editor_triangle_limit(physical_memory_bytes(), a->history_editors + 1);
    if (!std::filesystem::exists(std::filesystem::path(a->web_root) / "index.html"))
      throw InvalidArgument(fmt::format(
          "the page's files are not in {0} (index.html missing): build them with `make build` "
          "(into the build folder's web/) or `scripts/build_web.sh {0}`, or give --web-root",
          a->web_root));
    server::SessionOptions options;
    options.threads = a->threads;
    options.max_editors = static_cast<std::size_t>(a->history_editors);
    options.editor.memory_bytes =
        editor_memory_share(physical_memory_bytes(), a->history_editors + 1);
    options.read.max_triangles = a->max_triangles;
    options.max_handles = a->max_handles;
    options.frame_budget_ms = a->frame_budget_ms;
    if (!a->energy.empty()) options.editor.nonlinear.energy = parse_nonlinear_energy(a->energy);
    server::Session session(options);
    server::ApiLimits limits;
    limits.max_upload_bytes = static_cast<std::size_t>(a->max_upload_mb * 1024 * 1024);
    if (!a->mesh.empty()) {
      std::ifstream in(a->mesh, std::ios::binary);
      if (!in) throw IoError(a->mesh, "cannot open the file");
      std::ostringstream bytes;
      bytes << in.rdbuf();
      session.start_load(bytes.str(), std::filesystem::path(a->mesh).filename().string());
    }
    httplib::Server http;
    server::bind_http(http, session, limits, a->web_root);
    int port = a->port;
    if (port == 0) {
      port = http.bind_to_any_port(a->host.c_str());
    } else if (!http.bind_to_port(a->host.c_str(), port)) {
      throw IoError(fmt::format("{}:{}", a->host, port),
                    "cannot listen there (in use? try --port 0 for a free port)");
    }
    if (port < 0) throw IoError(a->host, "cannot listen on any port");
    std::cout << fmt::format("remora: editing at http://{}:{}/  (Ctrl+C stops)", a->host, port)
              << std::endl;
    running = &http;
    std::signal(SIGINT, stop_on_signal);
    std::signal(SIGTERM, stop_on_signal);
    http.listen_after_bind();
    running = nullptr;
    session.wait();
  });
}

} // namespace remora::cli
