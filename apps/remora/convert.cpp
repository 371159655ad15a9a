#include <iostream>

#include <spdlog/spdlog.h>

#include "commands.h"
#include "remora/common/timer.h"
#include "remora/mesh/io.h"
#include "report.h"

namespace remora::cli {

void add_convert_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("convert", "Load a mesh with repair, report, write it out");
  auto in = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto ascii = std::make_shared<bool>(false);
  cmd->add_option("input", *in, "Input mesh (.obj .off .ply .stl)")->required();
  cmd->add_option("-o,--output", *out, "Output mesh; the format follows the extension")->required();
  cmd->add_flag("--ascii", *ascii, "Write PLY and STL as text instead of binary");
  cmd->callback([in, out, ascii] {
    format_from_path(*out); // fail on an unknown extension before the (maybe long) load
    const auto t0 = Clock::now();
    const LoadResult loaded = read_mesh(*in);
    spdlog::debug("loaded and repaired in {:.1f} ms", ms_since(t0));
    print_load_report(std::cout, loaded.report);
    WriteOptions options;
    options.binary = !*ascii;
    write_mesh(*out, loaded.mesh, options);
    std::cout << "wrote " << *out << " (" << loaded.mesh.n_vertices() << " vertices, "
              << loaded.mesh.n_faces() << " faces)\n";
  });
}

} // namespace remora::cli
