// Object File Format (ascii): a header keyword, the counts, one vertex per line, one face per line.
#include <limits>

#include "remora/common/error.h"
#include "remora/mesh/io_detail.h"

namespace remora::io_detail {

namespace {

// The keyword is [ST][C][N][4][n]OFF; we read the 3D variants, whose extra per-vertex numbers
// (texture coordinates, colours, normals) follow x y z and are read past.
void check_keyword(std::string_view keyword, const std::string& name, std::uint64_t line) {
  if (!keyword.ends_with("OFF"))
    throw IoError(name,
                  "not an OFF file: the header starts with '" + std::string(keyword) +
                      "' instead of a keyword ending in 'OFF'",
                  line);
  const std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  if (prefix.find('4') != std::string_view::npos || prefix.find('n') != std::string_view::npos)
    throw IoError(name,
                  "unsupported OFF variant '" + std::string(keyword) +
                      "': only 3-dimensional OFF is supported (no 4 or n prefix)",
                  line);
  for (const std::string_view known : {"", "C", "N", "CN", "ST", "STC", "STN", "STCN"})
    if (prefix == known) return;
  throw IoError(name,
                "unknown OFF variant '" + std::string(keyword) +
                    "' (known: OFF, COFF, NOFF, CNOFF, STOFF and their combinations)",
                line);
}

// The lines with content of the file: '#' comments and blank lines may appear anywhere.
class ContentLines {
public:
  ContentLines(std::string_view bytes, const std::string& name) : lines_(bytes), name_(name) {}

  bool next(std::string_view& out) {
    std::string_view raw;
    while (lines_.next(raw)) {
      out = strip_comment(raw);
      if (!out.empty()) return true;
    }
    return false;
  }
  /// The line of record i of the `count` the header declares (`one`, `many`: "vertex",
  /// "vertices"); throws IoError when the file ends before it.
  std::string_view record(std::uint64_t i, std::uint64_t count, const char* one, const char* many) {
    std::string_view out;
    if (!next(out))
      throw IoError(name_,
                    "header declares " + count_of(count, one, many) + " but the file ends after " +
                        std::to_string(i),
                    lines_.line());
    return out;
  }
  std::uint64_t line() const { return lines_.line(); }

private:
  LineReader lines_;
  const std::string& name_;
};

struct Counts {
  std::int64_t vertices = 0, faces = 0;
};

// The keyword and the counts, which may follow it on the same line.
Counts read_header(ContentLines& lines, const std::string& name) {
  std::string_view line;
  if (!lines.next(line))
    throw IoError(name, "no faces: the file is empty (no OFF header; an empty mesh cannot be "
                        "loaded)");
  const std::uint64_t header_line = lines.line();
  std::string_view counts = line;
  const std::string_view keyword = next_token(counts);
  check_keyword(keyword, name, header_line);
  std::string_view first = next_token(counts);
  if (first == "BINARY")
    throw IoError(name,
                  "unsupported: binary OFF ('" + std::string(keyword) +
                      " BINARY'); save the mesh as ascii OFF, PLY or STL",
                  header_line);
  std::uint64_t counts_line = header_line;
  if (first.empty()) {
    if (!lines.next(line))
      throw IoError(name,
                    "the file ends after the '" + std::string(keyword) +
                        "' keyword, before the vertex and face counts",
                    header_line);
    counts_line = lines.line();
    counts = line;
    first = next_token(counts);
  }
  const std::string_view second = next_token(counts);
  const std::string_view third = next_token(counts); // edge count: unused by readers
  if (second.empty() || !next_token(counts).empty())
    throw IoError(name, "expected the counts 'vertices faces edges' after the OFF keyword",
                  counts_line);
  const Counts c{to_int(first, name, counts_line, "vertex count"),
                 to_int(second, name, counts_line, "face count")};
  if (!third.empty()) to_int(third, name, counts_line, "edge count");
  if (c.vertices < 0 || c.faces < 0)
    throw IoError(name, "negative vertex or face count in the header", counts_line);
  if (c.vertices >= static_cast<std::int64_t>(std::numeric_limits<std::uint32_t>::max()))
    throw IoError(name, "too many vertices: " + std::to_string(c.vertices), counts_line);
  if (c.faces == 0)
    throw IoError(name,
                  "no faces: the header declares " + std::to_string(c.vertices) +
                      " vertices and 0 faces (an empty mesh cannot be loaded)",
                  counts_line);
  return c;
}

// Face f's line: the corner count, then as many vertex indices below `nv`; whatever follows is a
// face colour, read past.
void read_face(std::string_view rest, std::uint64_t f, std::int64_t nv, const std::string& name,
               std::uint64_t line_no, std::vector<std::uint32_t>& corners) {
  const std::int64_t n = to_int(next_token(rest), name, line_no, "corner count of a face");
  if (n < 3)
    throw IoError(name,
                  "face " + std::to_string(f) + " has " + std::to_string(n) +
                      " corners; a face needs at least 3",
                  line_no);
  corners.clear();
  for (std::int64_t k = 0; k < n; ++k) {
    const std::string_view token = next_token(rest);
    if (token.empty())
      throw IoError(name,
                    "face " + std::to_string(f) + " declares " + std::to_string(n) +
                        " corners but the line has only " + std::to_string(k) + " vertex indices",
                    line_no);
    const std::int64_t index = to_int(token, name, line_no, "vertex index of a face");
    if (index < 0 || index >= nv)
      throw IoError(
          name,
          "face " + std::to_string(f) + " refers to vertex " + std::to_string(index) +
              (index < 0 ? " (negative)" : " but the file has " + std::to_string(nv) + " vertices"),
          line_no);
    corners.push_back(static_cast<std::uint32_t>(index));
  }
}

} // namespace

SoupFile read_off(std::string_view bytes, const std::string& name, const ReadLimits& limits) {
  check_text(bytes, name);
  if (bytes.starts_with("\xEF\xBB\xBF")) bytes.remove_prefix(3); // UTF-8 byte-order mark
  ContentLines lines(bytes, name);
  const Counts counts = read_header(lines, name);
  check_limit(static_cast<std::uint64_t>(counts.vertices), limits.max_vertices(),
              "the header declares " + std::to_string(counts.vertices) + " vertices", "vertices",
              name, lines.line());
  check_limit(static_cast<std::uint64_t>(counts.faces), limits.max_triangles,
              "the header declares " + std::to_string(counts.faces) + " faces", "triangles", name,
              lines.line());

  SoupFile result;
  result.info.format = "off";
  result.info.encoding = "ascii";
  PolygonSoup& soup = result.soup;
  const auto vertex_count = static_cast<std::uint64_t>(counts.vertices);
  const auto face_count = static_cast<std::uint64_t>(counts.faces);
  soup.points.reserve(reserve_count(vertex_count, bytes.size(), 6));
  soup.offsets.reserve(reserve_count(face_count, bytes.size(), 8) + 1);
  soup.indices.reserve(3 * reserve_count(face_count, bytes.size(), 8));
  for (std::uint64_t v = 0; v < vertex_count; ++v) {
    std::string_view rest = lines.record(v, vertex_count, "vertex", "vertices");
    soup.points.push_back(parse_point(rest, v, name, lines.line()));
  }
  std::vector<std::uint32_t> corners;
  for (std::uint64_t f = 0; f < face_count; ++f) {
    const std::string_view line = lines.record(f, face_count, "face", "faces");
    read_face(line, f, counts.vertices, name, lines.line(), corners);
    soup.add_polygon(corners.data(), corners.size());
  }
  std::string_view extra;
  if (lines.next(extra))
    throw IoError(name,
                  "data continues after the " + count_of(face_count, "face", "faces") +
                      " the header declares",
                  lines.line());
  result.info.vertices_in_file = soup.points.size();
  result.info.faces_in_file = soup.num_polygons();
  return result;
}

void write_off(const CompactMesh& m, std::string& out) {
  out.reserve(out.size() + 64 * m.points.size() + 24 * m.triangles.size());
  out += "OFF\n";
  append_uint(out, m.points.size());
  out += ' ';
  append_uint(out, m.triangles.size() / 3);
  out += " 0\n";
  for (const Vec3& p : m.points) append_point_line(out, "", p);
  for (std::size_t i = 0; i < m.triangles.size(); i += 3)
    append_triangle_line(out, "3", &m.triangles[i], 0);
}

} // namespace remora::io_detail
