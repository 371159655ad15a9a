// The `remora` command line tool: parses, calls the library, prints. Every remora::Error becomes
// one line on stderr and exit code 1; a usage error exits with 2, anything unexpected with 3.
#include <cstdio>
#include <iostream>
#include <new>

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "remora/common/error.h"
#include "remora/common/memory.h"

int main(int argc, char** argv) {
  remora::keep_freed_memory(); // a one-shot process: page faults cost more than a kept heap
  CLI::App app{"Remora: detail-preserving multiresolution editing of triangle meshes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("remora ") + REMORA_VERSION);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Print debug output");

  remora::cli::add_info_command(app);
  remora::cli::add_convert_command(app);
  remora::cli::add_remesh_command(app);
  remora::cli::add_edit_command(app);
  remora::cli::add_serve_command(app);
  remora::cli::add_bench_command(app);

  // Logs go to stderr so that stdout carries only the command's output (e.g. --json).
  spdlog::set_default_logger(spdlog::stderr_color_mt("remora"));
  app.parse_complete_callback(
      [&] { spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info); });

  // The subcommands run as CLI11 callbacks, inside parse().
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version end here with 0; every usage error is exit code 2.
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const remora::Error& e) {
    std::cerr << "remora: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "remora: error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "remora: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
