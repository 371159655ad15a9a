// The subcommands of the `remora` tool. Each registers itself on the app with a callback that
// does the work; callbacks throw remora::Error on failure (main() reports it).
#pragma once

#include <CLI/CLI.hpp>

namespace remora::cli {

void add_info_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_remesh_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_edit_command(CLI::App& app);
void add_serve_command(CLI::App& app);
/// `remora bench edit`, a subcommand of `remora bench`.
void add_bench_edit_command(CLI::App& bench);
/// `remora bench serve`, a subcommand of `remora bench`.
void add_bench_serve_command(CLI::App& bench);
/// `remora bench pipeline`, a subcommand of `remora bench`.
void add_bench_pipeline_command(CLI::App& bench);
/// `remora bench bake`, a subcommand of `remora bench`.
void add_bench_bake_command(CLI::App& bench);

} // namespace remora::cli
