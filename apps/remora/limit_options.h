// The --max-triangles and --max-handles options of the commands that build editors (edit,
// remesh, serve): their defaults follow from this machine's memory (multires/limits.h,
// docs/limits.md).
#pragma once

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "remora/common/memory.h"
#include "remora/multires/limits.h"

namespace remora::cli {

/// --max-triangles into `max`, by default what `editors` editors alive at once fit in.
inline void add_max_triangles_option(CLI::App* cmd, std::uint64_t& max, int editors) {
  const std::uint64_t memory = physical_memory_bytes();
  max = editor_triangle_limit(memory, editors);
  const std::string why =
      memory == 0 ? std::string("the machine's memory is unknown")
                  : fmt::format("{:.0f} % of this machine's {:.1f} GB at {:.1f} kB per triangle{}",
                                100 * kMemoryShare, double(memory) / 1e9,
                                double(kMeshBytesPerTriangle) / 1000,
                                editors > 1 ? fmt::format(" for {} editors", editors) : "");
  cmd->add_option("--max-triangles", max,
                  fmt::format("Largest mesh accepted, in triangles; a larger file is refused "
                              "as it is read, before the mesh is built (default {}: {}; 0 = no "
                              "limit)",
                              max, why));
}

/// --max-handles into `max` (default kMaxHandles).
inline void add_max_handles_option(CLI::App* cmd, int& max) {
  max = kMaxHandles;
  cmd->add_option("--max-handles", max,
                  fmt::format("Most handles an edit may have (default {})", kMaxHandles))
      ->check(CLI::PositiveNumber);
}

} // namespace remora::cli
