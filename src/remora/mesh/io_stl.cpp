// STL, binary and ascii. Every facet gets its own vertices: STL shares none, the repair welds.
#include <cctype>
#include <limits>

#include "remora/common/error.h"
#include "remora/mesh/io_detail.h"

namespace remora::io_detail {

namespace {

constexpr std::size_t kHeaderBytes = 84; // 80-byte header + uint32 triangle count
constexpr std::size_t kFacetBytes = 50;  // normal, 3 vertices (12 floats), uint16 attribute

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != b[i]) return false;
  return true;
}

SoupFile read_binary_stl(std::string_view bytes, std::uint32_t count, const std::string& name,
                         const ReadLimits& limits) {
  check_limit(count, limits.max_triangles,
              "the binary STL header declares " + std::to_string(count) + " triangles", "triangles",
              name, {}, 80);
  if (count == 0)
    throw IoError(name,
                  "no faces: the binary STL header declares 0 triangles (an empty mesh cannot be "
                  "loaded)",
                  {}, 80);
  SoupFile result;
  result.info.format = "stl";
  result.info.encoding = "binary_little_endian";
  PolygonSoup& soup = result.soup;
  soup.points.resize(3 * std::size_t{count});
  soup.indices.resize(3 * std::size_t{count});
  soup.offsets.resize(std::size_t{count} + 1);
  const char* data = bytes.data();
  for (std::size_t t = 0; t < count; ++t) {
    const std::size_t base = kHeaderBytes + kFacetBytes * t + 12; // after the facet normal
    for (std::size_t k = 0; k < 3; ++k) {
      const char* p = data + base + 12 * k;
      const Vec3 point(load<float>(p, false), load<float>(p + 4, false), load<float>(p + 8, false));
      if (!is_finite(point))
        throw_non_finite(point,
                         "triangle " + std::to_string(t) + " (vertex " + std::to_string(k) + ")",
                         name, {}, base + 12 * k);
      soup.points[3 * t + k] = point;
      soup.indices[3 * t + k] = static_cast<std::uint32_t>(3 * t + k);
    }
    soup.offsets[t + 1] = static_cast<std::uint32_t>(3 * (t + 1));
  }
  result.info.vertices_in_file = soup.points.size();
  result.info.faces_in_file = count;
  return result;
}

// The ascii STL grammar, one keyword line at a time: `solid`, then per facet `facet`,
// `outer loop`, `vertex x y z` lines, `endloop`, `endfacet`, and `endsolid`; solids may repeat.
// Each facet's vertices are appended to the soup as a new polygon.
class AsciiStlParser {
public:
  AsciiStlParser(const std::string& name, PolygonSoup& soup, const ReadLimits& limits)
      : name_(name), soup_(soup), limits_(limits) {}

  /// Takes line `line`, whose first token is `key` and the tokens after it `rest`; throws
  /// IoError where the grammar does not allow `key`.
  void take(std::string_view key, std::string_view rest, std::uint64_t line) {
    switch (state_) {
    case State::Outside:
      outside(key, line);
      break;
    case State::Solid:
      in_solid(key, line);
      break;
    case State::Facet:
      in_facet(key, rest, line);
      break;
    case State::Loop:
      in_loop(key, rest, line);
      break;
    case State::LoopDone:
      if (!iequals(key, "endfacet")) unexpected(key, "'endfacet'", line);
      state_ = State::Solid;
      break;
    }
    if (soup_.points.size() >= std::numeric_limits<std::uint32_t>::max())
      throw IoError(name_, "too many vertices", line);
  }

  /// Throws IoError unless every solid is closed; `last_line` is the file's last line.
  void finish(std::uint64_t last_line) const {
    if (state_ != State::Outside)
      throw IoError(name_,
                    "the file ends inside a " +
                        std::string(state_ == State::Solid ? "solid" : "facet") +
                        " (truncated: no 'endsolid' after " + std::to_string(soup_.num_polygons()) +
                        " facets)",
                    last_line);
  }

private:
  enum class State { Outside, Solid, Facet, Loop, LoopDone };

  // Between solids: only `solid` may come.
  void outside(std::string_view key, std::uint64_t line) {
    if (iequals(key, "solid")) {
      state_ = State::Solid;
    } else if (solids_ > 0) {
      throw IoError(name_,
                    "data continues after 'endsolid': found '" + std::string(key) +
                        "' where only another 'solid' may follow",
                    line);
    } else {
      unexpected(key, "'solid'", line);
    }
  }

  // Inside a solid, between facets.
  void in_solid(std::string_view key, std::uint64_t line) {
    if (iequals(key, "facet")) {
      state_ = State::Facet; // the stored normal is ignored: the vertex order is what counts
    } else if (iequals(key, "endsolid")) {
      state_ = State::Outside;
      ++solids_;
    } else {
      unexpected(key, "'facet' or 'endsolid'", line);
    }
  }

  // After `facet`: `outer loop` opens the facet's vertices.
  void in_facet(std::string_view key, std::string_view rest, std::uint64_t line) {
    if (!iequals(key, "outer")) unexpected(key, "'outer loop'", line);
    if (!iequals(next_token(rest), "loop")) unexpected(key, "'outer loop'", line);
    state_ = State::Loop;
    loop_start_ = soup_.points.size();
  }

  // Inside the loop: a vertex, or `endloop`, which adds the facet.
  void in_loop(std::string_view key, std::string_view rest, std::uint64_t line) {
    if (iequals(key, "vertex")) {
      soup_.points.push_back(parse_point(rest, soup_.points.size(), name_, line));
      check_limit(soup_.points.size(), limits_.max_vertices(), "more vertices", "vertices", name_,
                  line);
    } else if (iequals(key, "endloop")) {
      add_facet(line);
      state_ = State::LoopDone;
    } else {
      unexpected(key, "'vertex' or 'endloop'", line);
    }
  }

  // The vertices since the loop opened as one polygon; throws IoError for fewer than 3.
  void add_facet(std::uint64_t line) {
    const std::size_t n = soup_.points.size() - loop_start_;
    if (n < 3)
      throw IoError(name_,
                    "facet loop has " + std::to_string(n) + " vertices; a facet needs at least 3",
                    line);
    corners_.clear();
    for (std::size_t i = loop_start_; i < soup_.points.size(); ++i)
      corners_.push_back(static_cast<std::uint32_t>(i));
    triangles_ += n - 2;
    check_limit(triangles_, limits_.max_triangles, "the facets make more triangles", "triangles",
                name_, line);
    soup_.add_polygon(corners_.data(), corners_.size());
  }

  // Throws IoError "expected <expected> but found '<found>'" at `line`.
  [[noreturn]] void unexpected(std::string_view found, const char* expected,
                               std::uint64_t line) const {
    throw IoError(name_,
                  "expected " + std::string(expected) + " but found '" + std::string(found) + "'",
                  line);
  }

  const std::string& name_;
  PolygonSoup& soup_;
  const ReadLimits& limits_;
  std::uint64_t triangles_ = 0; // made by the facets so far
  State state_ = State::Outside;
  std::size_t solids_ = 0;     // solids closed so far
  std::size_t loop_start_ = 0; // the first vertex of the open loop
  std::vector<std::uint32_t> corners_;
};

SoupFile read_ascii_stl(std::string_view bytes, const std::string& name, const ReadLimits& limits) {
  check_text(bytes, name);
  if (bytes.starts_with("\xEF\xBB\xBF")) bytes.remove_prefix(3); // UTF-8 byte-order mark
  SoupFile result;
  result.info.format = "stl";
  result.info.encoding = "ascii";
  PolygonSoup& soup = result.soup;
  AsciiStlParser parser(name, soup, limits);

  LineReader lines(bytes);
  std::string_view raw;
  while (lines.next(raw)) {
    std::string_view rest = raw;
    const std::string_view key = next_token(rest);
    if (!key.empty()) parser.take(key, rest, lines.line());
  }
  parser.finish(lines.line());
  if (soup.num_polygons() == 0)
    throw IoError(name, "no faces: the ascii STL has no facets (an empty mesh cannot be loaded)");
  result.info.vertices_in_file = soup.points.size();
  result.info.faces_in_file = soup.num_polygons();
  return result;
}

// A file that begins with "solid" is ascii if it is all text or if a facet follows the solid
// line; otherwise it is a binary file whose header happens to begin with "solid" (and whose size
// is wrong, or the caller would not ask).
bool looks_like_ascii(std::string_view bytes, std::size_t solid) {
  if (bytes.size() < kHeaderBytes || find_control_byte(bytes) == std::string_view::npos)
    return true;
  const std::size_t eol = bytes.find('\n', solid);
  if (eol == std::string_view::npos) return false;
  std::size_t i = eol + 1;
  while (i < bytes.size() && (is_blank(bytes[i]) || bytes[i] == '\n')) ++i;
  std::string_view rest = bytes.substr(i, 16);
  const std::string_view key = next_token(rest);
  return iequals(key, "facet") || iequals(key, "endsolid");
}

Vec3 unit_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  Vec3 n = OpenMesh::cross(b - a, c - a);
  const double len = n.norm();
  return len > 0 ? n / len : Vec3(0, 0, 0);
}

void append_float3(std::string& out, const Vec3& p) {
  for (int k = 0; k < 3; ++k) {
    out += ' ';
    // STL holds floats; the float's exact value in 17 digits reads back as that same float.
    append_double(out, static_cast<double>(static_cast<float>(p[k])));
  }
}

} // namespace

SoupFile read_stl(std::string_view bytes, const std::string& name, const ReadLimits& limits) {
  if (bytes.size() >= kHeaderBytes) {
    // The size test decides: binary files may begin with "solid" too.
    const auto count = load<std::uint32_t>(bytes.data() + 80, false);
    if (bytes.size() == kHeaderBytes + kFacetBytes * std::uint64_t{count})
      return read_binary_stl(bytes, count, name, limits);
  }
  std::size_t i = 0;
  if (bytes.starts_with("\xEF\xBB\xBF")) i = 3; // UTF-8 byte-order mark
  while (i < bytes.size() && (is_blank(bytes[i]) || bytes[i] == '\n')) ++i;
  const bool solid = bytes.size() - i >= 5 && iequals(bytes.substr(i, 5), "solid");
  if (solid && looks_like_ascii(bytes, i)) return read_ascii_stl(bytes, name, limits);
  if (bytes.empty()) throw IoError(name, "no faces: the file is empty");
  if (bytes.size() < kHeaderBytes)
    throw IoError(name, "not an STL file: " + std::to_string(bytes.size()) +
                            " bytes is too short for a binary STL (84-byte header) and the file "
                            "does not start with 'solid'");
  const auto count = load<std::uint32_t>(bytes.data() + 80, false);
  throw IoError(name,
                "binary STL header declares " + std::to_string(count) + " triangles (84+50*" +
                    std::to_string(count) + " = " +
                    std::to_string(kHeaderBytes + kFacetBytes * std::uint64_t{count}) +
                    " bytes) but the file has " + std::to_string(bytes.size()) + " bytes" +
                    (solid ? " (it begins with 'solid' but is not text, so not an ascii STL)" : ""),
                {}, 80);
}

void write_stl(const CompactMesh& m, bool binary, std::string& out) {
  const std::size_t count = m.triangles.size() / 3;
  if (binary) {
    out.reserve(out.size() + kHeaderBytes + kFacetBytes * count);
    // The header must not begin with "solid", or readers take the file for ascii.
    std::string header = "binary STL written by Remora";
    header.resize(80, ' ');
    out += header;
    append_le(out, static_cast<std::uint32_t>(count));
    for (std::size_t t = 0; t < count; ++t) {
      const Vec3& a = m.points[m.triangles[3 * t]];
      const Vec3& b = m.points[m.triangles[3 * t + 1]];
      const Vec3& c = m.points[m.triangles[3 * t + 2]];
      const Vec3 n = unit_normal(a, b, c);
      for (const Vec3* p : {&n, &a, &b, &c})
        for (int k = 0; k < 3; ++k) append_le(out, static_cast<float>((*p)[k]));
      append_le(out, std::uint16_t{0});
    }
    return;
  }
  out.reserve(out.size() + 256 * count + 32);
  out += "solid remora\n";
  for (std::size_t t = 0; t < count; ++t) {
    const Vec3& a = m.points[m.triangles[3 * t]];
    const Vec3& b = m.points[m.triangles[3 * t + 1]];
    const Vec3& c = m.points[m.triangles[3 * t + 2]];
    out += "  facet normal";
    append_float3(out, unit_normal(a, b, c));
    out += "\n    outer loop\n";
    for (const Vec3* p : {&a, &b, &c}) {
      out += "      vertex";
      append_float3(out, *p);
      out += '\n';
    }
    out += "    endloop\n  endfacet\n";
  }
  out += "endsolid remora\n";
}

} // namespace remora::io_detail
