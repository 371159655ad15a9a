#include <iostream>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "remora/common/json.h"
#include "remora/common/timer.h"
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
    const auto t0 = Clock::now();
    const LoadResult loaded = read_mesh(*file);
    const double load_ms = ms_since(t0);
    const auto t1 = Clock::now();
    const MeshQuality quality = mesh_quality(loaded.mesh);
    spdlog::debug("loaded and repaired in {:.1f} ms, quality figures in {:.1f} ms", load_ms,
                  ms_since(t1));
    if (*json) {
      nlohmann::json j = to_json(quality);
      j["load"] = to_json(loaded.report);
      std::cout << dump_json(j, 2) << "\n";
      return;
    }
    print_load_report(std::cout, loaded.report);
    print_quality(std::cout, quality);
  });
}

} // namespace remora::cli
