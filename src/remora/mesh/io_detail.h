// Internal to the mesh readers and writers (io*.cpp): the per-format parsers and the text
// scanning and number parsing they share. Not part of the public API.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "remora/mesh/mesh.h"
#include "remora/mesh/soup.h"

namespace remora::io_detail {

// Parsers: `bytes` is the whole file, `name` the path or name used in error messages.
// Each refuses what is over `limits` before allocating for it (soup.h).
SoupFile read_obj(std::string_view bytes, const std::string& name, const ReadLimits& limits);
SoupFile read_off(std::string_view bytes, const std::string& name, const ReadLimits& limits);
SoupFile read_ply(std::string_view bytes, const std::string& name, const ReadLimits& limits);
SoupFile read_stl(std::string_view bytes, const std::string& name, const ReadLimits& limits);

/// Throws IoError "<count> <what>: over the limit of <limit> <unit> ..." when `limit` is not 0
/// and `count` exceeds it; `line` or `byte` place it in the file.
void check_limit(std::uint64_t count, std::uint64_t limit, const std::string& what,
                 const char* unit, const std::string& name, std::optional<std::uint64_t> line = {},
                 std::optional<std::uint64_t> byte = {});

/// The non-deleted vertices and faces of a mesh with compact 0-based vertex ids.
struct CompactMesh {
  std::vector<Vec3> points;
  std::vector<std::uint32_t> triangles; ///< three ids per face
};
CompactMesh compact(const Mesh& mesh);

// Writers: append the whole file to `out`.
void write_obj(const CompactMesh& mesh, std::string& out);
void write_off(const CompactMesh& mesh, std::string& out);
void write_ply(const CompactMesh& mesh, bool binary, std::string& out);
void write_stl(const CompactMesh& mesh, bool binary, std::string& out);

/// Horizontal whitespace; '\n' ends a line and is handled by LineReader.
inline bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

/// The position of the first control byte other than \t \n \v \f \r (or DEL), or npos.
std::size_t find_control_byte(std::string_view text);

/// Throws IoError "not a text file" at the first control byte other than \t \n \v \f \r (or DEL).
/// `text` starts at line `first_line` and byte `first_offset` of the file.
void check_text(std::string_view text, const std::string& name, std::uint64_t first_line = 1,
                std::uint64_t first_offset = 0);

/// Splits text into lines (without the '\n'), counting 1-based line numbers.
class LineReader {
public:
  /// `lines_before`: how many lines of the file precede `text` (for numbering).
  explicit LineReader(std::string_view text, std::uint64_t lines_before = 0)
      : text_(text), line_(lines_before) {}

  /// The next line, or false at the end of the text. A final line without '\n' counts.
  bool next(std::string_view& line);
  /// The number of the line last returned by next() (0 before the first).
  std::uint64_t line() const { return line_; }
  /// Where the next line starts, in bytes from the start of `text`.
  std::size_t offset() const { return pos_; }
  /// True when only whitespace is left.
  bool only_blank_left() const;

private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::uint64_t line_ = 0;
};

/// Splits off the next whitespace-separated token of `rest`; empty when none is left.
inline std::string_view next_token(std::string_view& rest) {
  std::size_t i = 0;
  while (i < rest.size() && is_blank(rest[i])) ++i;
  std::size_t j = i;
  while (j < rest.size() && !is_blank(rest[j])) ++j;
  const std::string_view token = rest.substr(i, j - i);
  rest.remove_prefix(j);
  return token;
}

/// `line` without a '#' comment and without surrounding whitespace.
std::string_view strip_comment(std::string_view line);

/// The whole token as a double (a leading '+' allowed; "nan" and "inf" parse and are the
/// caller's to reject). False if the token is not a number or is out of a double's range
/// (overflow, or underflow to zero).
bool parse_double(std::string_view token, double& out);
/// The whole token as a signed 64-bit integer (a leading '+' allowed).
bool parse_int(std::string_view token, std::int64_t& out);

/// parse_double, throwing IoError "'tok' is not a number (what)" at `line`.
double to_double(std::string_view token, const std::string& name, std::uint64_t line,
                 std::string_view what);
/// parse_int, throwing IoError "'tok' is not an integer (what)" at `line`.
std::int64_t to_int(std::string_view token, const std::string& name, std::uint64_t line,
                    std::string_view what);

/// Parses the first three tokens of `rest` as the x, y, z of vertex `vertex` (numbered as the
/// format numbers it) at `line`; throws IoError for a missing or bad number or a NaN/Inf.
Vec3 parse_point(std::string_view& rest, std::size_t vertex, const std::string& name,
                 std::uint64_t line);

inline bool is_finite(const Vec3& p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

/// "<what> has a non-finite y coordinate (NaN)" for the first bad coordinate of `p`.
std::string non_finite_problem(const Vec3& p, const std::string& what);

/// Throws IoError "<what> has a non-finite y coordinate (NaN)" for the first bad coordinate of
/// `p` (call it when !is_finite(p)). Pass `line` for text formats, `byte_offset` for binary ones.
[[noreturn]] void throw_non_finite(const Vec3& p, const std::string& what, const std::string& name,
                                   std::optional<std::uint64_t> line,
                                   std::optional<std::uint64_t> byte_offset);

/// Appends `v` with 17 significant digits (printf's %.17g), so doubles round-trip exactly.
void append_double(std::string& out, double v);
/// Appends `v` in decimal.
void append_uint(std::string& out, std::uint64_t v);
/// "x y z\n" with append_double, after `prefix` (e.g. "v ").
void append_point_line(std::string& out, const char* prefix, const Vec3& p);
/// "<prefix> a b c\n" with every index plus `base` (1 for OBJ, 0 otherwise).
void append_triangle_line(std::string& out, const char* prefix, const std::uint32_t* ids,
                          std::uint64_t base);

/// Counts read-past lines per keyword, in the order first seen, for FileInfo::skipped.
class SkipCounter {
public:
  void add(std::string_view keyword);
  /// Appends e.g. "37 'vt' lines" per keyword.
  void report(std::vector<std::string>& out) const;

private:
  std::vector<std::pair<std::string, std::size_t>> counts_;
};

/// How many records to reserve for `count` records of at least `min_bytes` each in a file of
/// `file_size` bytes: a header that lies must not make us allocate terabytes.
inline std::size_t reserve_count(std::uint64_t count, std::size_t file_size,
                                 std::size_t min_bytes) {
  const std::uint64_t fit = file_size / (min_bytes == 0 ? 1 : min_bytes);
  return static_cast<std::size_t>(count < fit ? count : fit);
}

/// The T stored at `p` in little- or big-endian byte order.
template <class T>
T load(const char* p, bool big_endian) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

/// Appends `v` in little-endian byte order.
template <class T>
void append_le(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

/// "1 vertex", "2 vertices".
inline std::string count_of(std::uint64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

/// "s" unless n == 1.
inline const char* plural(std::uint64_t n) {
  return n == 1 ? "" : "s";
}

} // namespace remora::io_detail
