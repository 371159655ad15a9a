#include <chrono>
#include <iostream>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "remora/geometry/quality.h"
#include "remora/mesh/io.h"
#include "report.h"

namespace remora::cli {

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Load a mesh with repair and report its quality figures");
  auto file = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("file", *file, "Mesh file (.obj .off .ply .stl)")->required();
  cmd->add_flag("--json", *json, "Print one JSON object instead of a table");
  cmd->callback([file, json] {
    const auto t0 = std::chrono::steady_clock::now();
    const LoadResult loaded = read_mesh(*file);
    const auto t1 = std::chrono::steady_clock::now();
    const MeshQuality quality = mesh_quality(loaded.mesh);
    spdlog::debug(
        "loaded and repaired in {:.1f} ms, quality figures in {:.1f} ms",
        std::chrono::duration<double, std::milli>(t1 - t0).count(),
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count());
    if (*json) {
      nlohmann::json j = to_json(quality);
      j["load"] = to_json(loaded.report);
      std::cout << j.dump(2) << "\n";
      return;
    }
    print_load_report(std::cout, loaded.report);
    print_quality(std::cout, quality);
  });
}

} // namespace remora::cli
