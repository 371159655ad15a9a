// The bodies of the fuzz harnesses, a library (remora_fuzz_harness) so that the regression tests
// (tests/test_fuzz.cpp) run a kept input through exactly what its harness ran. Each takes the
// input bytes (inputs.h says what each makes of them) and catches the clean error a malformed
// input must end in; a broken promise throws CheckFailed, and any other exception escapes. Both
// are findings: libFuzzer reports an escaping exception as a crash.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace remora::fuzz {

/// A promise an entry point broke (the message says which), found by a harness's checks.
class CheckFailed : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

enum class ReaderVariant { Obj, Off, PlyAscii, PlyBinary, PlyTristrips, StlAscii, StlBinary };

/// One input through a reader, the repair and the half-edge build (read_mesh_from_memory). It may
/// only end in IoError; a mesh it loads has faces, finite points, a valid manifold half-edge
/// structure of triangles, a source for every vertex and a repair account that balances, and
/// loads again with the same faces once written as binary PLY.
void run_reader(ReaderVariant variant, std::string_view input);

/// JSON text through parse_edit_request, apply_request_options, map_file_vertex_ids,
/// select_region (on a 162-vertex icosphere) and resolve_transform. It may only end in
/// InvalidArgument; the regions selected are sorted, unique and in range.
void run_edit_request(std::string_view input);

/// A script of up to 12 requests to handle_api on a session that has just loaded a 162-vertex
/// bumpy sphere, every job waited for. Every answer is a documented status (2xx, 400, 404, 405,
/// 409, 413, 422), errors are JSON objects with a message, a 405 has Allow, JSON answers parse
/// and Float32 arrays are finite.
void run_server_script(std::string_view input);

/// The harness a name names ("obj", "ply_binary", "edit_request", "server", ...), run on
/// `input`. Throws std::invalid_argument for an unknown name.
void run_harness(const std::string& name, std::string_view input);

} // namespace remora::fuzz
