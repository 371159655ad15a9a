// What the fuzz harnesses make of their input bytes, shared with the seed generator
// (make_seeds.cpp) so that seeds and harnesses agree on one encoding.
//
// The text readers (OBJ, OFF, PLY ascii, STL ascii) take the input as a whole file. The binary
// readers take a layout and a body, so that the mutations land in the records rather than in a
// header they would mostly break:
//  - PLY: 6 layout bytes (PlyLayout::decode) give the header (encoding, scalar types, optional
//    properties and elements, the vertex and face counts); the rest of the input is the body.
//    Raw headers are fuzzed by the PLY ascii harness.
//  - binary STL: the input is the records after an 80-byte header that begins with "solid" and a
//    triangle count of input size / 50 (the trailing partial record is cut), so every input is
//    read as binary. The size-based recognition is fuzzed by the STL ascii harness.
// The server harness reads a script of requests (parse_requests).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace remora::fuzz {

/// The PLY file a layout describes: header text and the body encoding.
struct PlyLayout {
  bool ascii = false, big_endian = false, strips = false;
  int coordinate_type = 6; ///< index into the PLY scalar types, char..double (6 = float)
  int count_type = 0;      ///< uchar, ushort, int, uint
  int index_type = 0;      ///< int, uint, short, ushort
  bool normals = false;    ///< float nx ny nz after x y z
  bool colours = false;    ///< uchar red green blue
  bool camera = false;     ///< an element camera (1 record of 2 floats) before the vertices
  bool face_flags = false; ///< a uchar after each face's index list
  bool material = false;   ///< an element material (1 record with a list) after the faces
  bool comments = false;   ///< comment and obj_info lines
  unsigned vertices = 0, faces = 0;

  static constexpr std::size_t kBytes = 6;
  /// From the first kBytes bytes of an input (zeros where the input is shorter).
  static PlyLayout decode(std::string_view bytes);
  std::string encode() const;
  std::string header() const;
};

enum class PlyVariant { Binary, Tristrips };

/// The PLY file of a harness input: the layout (binary forced for Binary, strips forced for
/// Tristrips) and the body.
std::string ply_file(std::string_view input, PlyVariant variant);

/// The binary STL file of a harness input (see above).
std::string binary_stl_file(std::string_view input);

/// The mesh the server harness loads before each script, as OFF text: a bumpy icosphere of 162
/// vertices (tests/server_support.h's sphere, one subdivision less).
std::string server_fixture_off();

/// The separator between requests in a server script.
inline constexpr std::string_view kRequestSeparator = "\n%%\n";

/// A request of a server script: "METHOD PATH?key=value&key=value\nBODY".
struct ScriptRequest {
  std::string method, path;
  std::map<std::string, std::string> query;
  std::string body;
};

/// The requests of a script, at most `max_requests` (the rest is ignored).
std::vector<ScriptRequest> parse_requests(std::string_view script, std::size_t max_requests);
/// A script of requests (the inverse of parse_requests for bodies without the separator).
std::string write_requests(const std::vector<ScriptRequest>& requests);

} // namespace remora::fuzz
