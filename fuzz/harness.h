// The mesh readers' harness: one input through a reader, the repair and the half-edge build
// (read_mesh_from_memory), then the checks every loaded mesh must pass. A malformed input must end
// in an IoError; anything else escaping, a sanitizer report or a failed check is a finding.
#pragma once

#include <cstddef>
#include <cstdint>

namespace remora::fuzz {

enum class ReaderVariant { Obj, Off, PlyAscii, PlyBinary, PlyTristrips, StlAscii, StlBinary };

/// Runs one input (see inputs.h for what each variant makes of it). Returns 0; aborts with a
/// message on a failed check.
int run_reader(ReaderVariant variant, const std::uint8_t* data, std::size_t size);

} // namespace remora::fuzz
