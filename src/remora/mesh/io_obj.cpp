// Wavefront OBJ: `v` and `f` lines; every other keyword is counted and read past.
#include <limits>

#include "remora/common/error.h"
#include "remora/mesh/io_detail.h"

namespace remora::io_detail {

namespace {

std::string_view trim_right(std::string_view s) {
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

struct ForwardReference {
  std::int64_t vertex; // 0-based
  std::uint64_t line;
};

// `line` trimmed on the right; when it ends in a backslash, it and the lines it continues onto
// (taken from `lines`), joined with spaces into `joined` in place of the backslashes.
std::string_view join_continued(std::string_view line, LineReader& lines, std::string& joined) {
  line = trim_right(line);
  if (line.empty() || line.back() != '\\') return line;
  joined.assign(line.substr(0, line.size() - 1));
  std::string_view more;
  while (lines.next(more)) {
    more = trim_right(more);
    joined += ' ';
    if (more.empty() || more.back() != '\\') {
      joined += more;
      break;
    }
    joined += more.substr(0, more.size() - 1);
  }
  return joined;
}

// The 0-based vertex of a face corner `i`, `i/t`, `i//n` or `i/t/n` (a negative i counts back
// from the `seen` vertices read so far); throws IoError for index 0, a relative index before the
// first vertex, or an index too large for 32 bits.
std::int64_t corner_vertex(std::string_view token, std::int64_t seen, const std::string& name,
                           std::uint64_t line_no) {
  const std::string_view vertex_token = token.substr(0, token.find('/'));
  const std::int64_t index = to_int(vertex_token, name, line_no, "vertex index of a face");
  std::int64_t vertex = 0;
  if (index > 0) {
    vertex = index - 1;
  } else if (index < 0) {
    vertex = seen + index;
    if (vertex < 0)
      throw IoError(name,
                    "relative vertex index " + std::to_string(index) +
                        " points before the first vertex (only " + std::to_string(seen) +
                        " vertices precede this face)",
                    line_no);
  } else {
    throw IoError(name, "vertex index 0 in a face (OBJ indices start at 1)", line_no);
  }
  if (vertex >= static_cast<std::int64_t>(std::numeric_limits<std::uint32_t>::max()))
    throw IoError(name, "vertex index " + std::to_string(index) + " is too large", line_no);
  return vertex;
}

// The corners of an `f` statement (`rest`: what follows the keyword) into `corners`; a corner
// past the `seen` vertices read so far goes into `forward`. Throws IoError for fewer than 3.
void read_face(std::string_view rest, std::int64_t seen, const std::string& name,
               std::uint64_t line_no, std::vector<std::uint32_t>& corners,
               std::vector<ForwardReference>& forward) {
  corners.clear();
  for (std::string_view token = next_token(rest); !token.empty(); token = next_token(rest)) {
    const std::int64_t vertex = corner_vertex(token, seen, name, line_no);
    if (vertex >= seen) forward.push_back({vertex, line_no});
    corners.push_back(static_cast<std::uint32_t>(vertex));
  }
  if (corners.size() < 3)
    throw IoError(name,
                  "face has " + std::to_string(corners.size()) + " corner" +
                      plural(corners.size()) + "; a face needs at least 3",
                  line_no);
}

// Throws IoError at the first face corner that refers past the file's `count` vertices.
void check_forward(const std::vector<ForwardReference>& forward, std::int64_t count,
                   const std::string& name) {
  for (const ForwardReference& ref : forward) {
    if (ref.vertex >= count)
      throw IoError(name,
                    "face refers to vertex " + std::to_string(ref.vertex + 1) +
                        " but the file has " + std::to_string(count) + " vertices",
                    ref.line);
  }
}

} // namespace

SoupFile read_obj(std::string_view bytes, const std::string& name, const ReadLimits& limits) {
  check_text(bytes, name);
  if (bytes.starts_with("\xEF\xBB\xBF")) bytes.remove_prefix(3); // UTF-8 byte-order mark

  SoupFile result;
  result.info.format = "obj";
  result.info.encoding = "ascii";
  PolygonSoup& soup = result.soup;
  SkipCounter skipped;
  // Indices beyond the vertices read so far are legal if the vertex comes later; checked at the end.
  std::vector<ForwardReference> forward;
  std::vector<std::uint32_t> corners;
  std::string joined;
  std::uint64_t triangles = 0;

  LineReader lines(bytes);
  std::string_view raw;
  while (lines.next(raw)) {
    const std::uint64_t line_no = lines.line();
    const std::string_view line = strip_comment(join_continued(raw, lines, joined));
    if (line.empty()) continue;

    std::string_view rest = line;
    const std::string_view key = next_token(rest);
    if (key == "v") {
      // `v x y z [w] [r g b]`: anything after z is read past.
      soup.points.push_back(parse_point(rest, soup.points.size() + 1, name, line_no));
      check_limit(soup.points.size(), limits.max_vertices(), "more vertices", "vertices", name,
                  line_no);
    } else if (key == "f") {
      read_face(rest, static_cast<std::int64_t>(soup.points.size()), name, line_no, corners,
                forward);
      triangles += corners.size() - 2;
      check_limit(triangles, limits.max_triangles, "the faces make more triangles", "triangles",
                  name, line_no);
      soup.add_polygon(corners.data(), corners.size());
    } else {
      skipped.add(key);
    }
  }

  const auto count = static_cast<std::int64_t>(soup.points.size());
  check_forward(forward, count, name);
  if (soup.num_polygons() == 0)
    throw IoError(name, "no faces: the file has " + std::to_string(count) +
                            " vertices and no 'f' lines (an empty mesh cannot be loaded)");

  result.info.vertices_in_file = soup.points.size();
  result.info.faces_in_file = soup.num_polygons();
  skipped.report(result.info.skipped);
  return result;
}

void write_obj(const CompactMesh& m, std::string& out) {
  out.reserve(out.size() + 64 * m.points.size() + 24 * m.triangles.size());
  for (const Vec3& p : m.points) append_point_line(out, "v ", p);
  for (std::size_t i = 0; i < m.triangles.size(); i += 3)
    append_triangle_line(out, "f", &m.triangles[i], 1);
}

} // namespace remora::io_detail
