// The PLY header (internal to the PLY reader, io_ply.cpp): its elements and properties with the
// role each plays in the mesh, parsed and checked; the scalar types and their binary loads.
// parse_header() and assign_roles() throw IoError naming the file and the header line.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace remora::io_detail::ply {

enum class PlyType : std::uint8_t { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };

/// Bytes of one value of type t in a binary file.
std::size_t type_size(PlyType t);
bool is_integer(PlyType t);
/// A scalar of type t at p (big-endian when `big`), converted. Integers are read only for
/// integer types (the header check rejects float counts and indices).
double load_double(const char* p, PlyType t, bool big);
std::int64_t load_int(const char* p, PlyType t, bool big);

/// What a property is read for; everything else is read past.
enum class Role : std::uint8_t { Skip, X, Y, Z, Indices };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32; ///< the value type (of the entries, for a list)
  bool list = false;
  PlyType count_type = PlyType::Uint8;
  Role role = Role::Skip;
};

enum class Kind : std::uint8_t { Skip, Vertex, Face, Strips };

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  std::uint64_t line = 0; ///< header line of `element`
  Kind kind = Kind::Skip;
  std::size_t min_size = 0; ///< bytes of a binary record with every list empty
  bool fixed = true;        ///< no lists: every binary record has min_size bytes
};

struct PlyHeader {
  std::string encoding;
  bool ascii = true;
  bool big_endian = false;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0; ///< first byte after the end_header line
  std::uint64_t lines = 0;     ///< lines up to and including end_header
};

/// "3 vertices", "1 face", "2 'camera' records": for messages.
std::string count_phrase(const PlyElement& e, std::uint64_t n);
/// "vertex 7", "'camera' record 0": for messages.
std::string record_label(const PlyElement& e, std::uint64_t r);

/// a + b and a × b, saturating at the largest value (sizes computed from untrusted counts).
inline std::uint64_t sat_add(std::uint64_t a, std::uint64_t b) {
  return b > std::numeric_limits<std::uint64_t>::max() - a
             ? std::numeric_limits<std::uint64_t>::max()
             : a + b;
}
inline std::uint64_t sat_mul(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a)
    return std::numeric_limits<std::uint64_t>::max();
  return a * b;
}

/// The header of `bytes` (a file named `name`) up to and including end_header.
PlyHeader parse_header(std::string_view bytes, const std::string& name);
/// Gives every element and property its role, and checks that the faces can be read.
void assign_roles(PlyHeader& h, const std::string& name);

} // namespace remora::io_detail::ply
