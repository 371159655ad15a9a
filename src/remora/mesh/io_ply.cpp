// PLY 1.0: ascii, binary_little_endian, binary_big_endian; faces from `element face` or
// `element tristrips`; every other element is read past and reported.
#include <charconv>
#include <limits>

#include "remora/common/error.h"
#include "remora/mesh/io_detail.h"
#include "remora/mesh/io_ply_header.h"

namespace remora::io_detail {

namespace {

using namespace ply;

// Ascii records: one per line; a line with too few or too many values is an error.
class AsciiSource {
public:
  AsciiSource(std::string_view body, std::uint64_t lines_before, const std::string& name,
              const std::vector<PlyElement>& elements)
      : lines_(body, lines_before), name_(name), elements_(elements) {}

  void begin_record(std::size_t element, std::uint64_t record) {
    element_ = element;
    record_ = record;
    std::string_view raw;
    while (lines_.next(raw)) {
      rest_ = raw;
      for (const char c : raw)
        if (!is_blank(c)) return;
    }
    const PlyElement& e = elements_[element];
    throw IoError(name_,
                  "header declares " + count_phrase(e, e.count) + " but the file ends after " +
                      std::to_string(record),
                  lines_.line());
  }

  double read_double(const PlyProperty& p) {
    const std::string_view token = take(p);
    double v = 0;
    if (!parse_double(token, v)) to_double(token, name_, lines_.line(), what(p));
    return v;
  }

  std::int64_t read_int(const PlyProperty& p) {
    const std::string_view token = take(p);
    std::int64_t v = 0;
    if (!parse_int(token, v)) to_int(token, name_, lines_.line(), what(p));
    return v;
  }

  std::uint64_t read_count(const PlyProperty& p) {
    const std::int64_t n = read_int(p);
    if (n < 0) fail("negative list length " + std::to_string(n) + " (" + what(p) + ")");
    return static_cast<std::uint64_t>(n);
  }

  void skip(const PlyProperty& p) { take(p); }

  void skip_items(const PlyProperty& p, std::uint64_t n) {
    for (std::uint64_t i = 0; i < n; ++i) take(p);
  }

  void end_record() {
    if (!next_token(rest_).empty()) {
      const PlyElement& e = elements_[element_];
      fail(record_label(e, record_) + " has more values than its " +
           std::to_string(e.properties.size()) + " properties in the header");
    }
  }

  void skip_element(std::size_t element) {
    const PlyElement& e = elements_[element];
    for (std::uint64_t r = 0; r < e.count; ++r) {
      begin_record(element, r);
      for (const PlyProperty& p : e.properties) {
        if (p.list)
          skip_items(p, read_count(p));
        else
          skip(p);
      }
      end_record();
    }
  }

  void finish(const PlyElement& last) {
    std::string_view raw;
    while (lines_.next(raw)) {
      for (const char c : raw)
        if (!is_blank(c))
          fail("data continues after the " + count_phrase(last, last.count) +
               " the header declares");
    }
  }

  [[noreturn]] void fail(const std::string& problem) const {
    throw IoError(name_, problem, lines_.line());
  }
  [[noreturn]] void fail_record(const std::string& problem) const { fail(problem); }

private:
  std::string_view take(const PlyProperty& p) {
    const std::string_view token = next_token(rest_);
    if (token.empty()) {
      const PlyElement& e = elements_[element_];
      if (lines_.only_blank_left())
        fail("the file ends in the middle of " + record_label(e, record_) + " (property '" +
             p.name + "' is missing)");
      fail(record_label(e, record_) + " has too few values: property '" + p.name + "' is missing");
    }
    return token;
  }

  std::string what(const PlyProperty& p) const {
    return "property '" + p.name + "' of " + record_label(elements_[element_], record_);
  }

  LineReader lines_;
  const std::string& name_;
  const std::vector<PlyElement>& elements_;
  std::string_view rest_;
  std::size_t element_ = 0;
  std::uint64_t record_ = 0;
};

// Binary records, bounds-checked at every read.
class BinarySource {
public:
  BinarySource(std::string_view bytes, std::size_t start, bool big_endian, const std::string& name,
               const std::vector<PlyElement>& elements)
      : data_(bytes.data()), size_(bytes.size()), pos_(start), big_(big_endian), name_(name),
        elements_(elements) {}

  void begin_record(std::size_t element, std::uint64_t record) {
    element_ = element;
    record_ = record;
    record_start_ = pos_;
  }

  double read_double(const PlyProperty& p) {
    return load_double(take(type_size(p.type)), p.type, big_);
  }

  std::int64_t read_int(const PlyProperty& p) {
    return load_int(take(type_size(p.type)), p.type, big_);
  }

  std::uint64_t read_count(const PlyProperty& p) {
    const std::int64_t n = load_int(take(type_size(p.count_type)), p.count_type, big_);
    if (n < 0)
      fail("negative list length " + std::to_string(n) + " (property '" + p.name + "' of " +
           record_label(elements_[element_], record_) + ")");
    return static_cast<std::uint64_t>(n);
  }

  void skip(const PlyProperty& p) { take(type_size(p.type)); }

  void skip_items(const PlyProperty& p, std::uint64_t n) { take(sat_mul(n, type_size(p.type))); }

  void end_record() {}

  void skip_element(std::size_t element) {
    const PlyElement& e = elements_[element];
    if (e.fixed) {
      // Fixed-size records are skipped in one step.
      const std::uint64_t total = sat_mul(e.count, e.min_size);
      if (total > size_ - pos_) {
        begin_record(element, (size_ - pos_) / e.min_size);
        pos_ = record_start_ = pos_ + record_ * e.min_size;
        truncated(e.min_size);
      }
      pos_ += static_cast<std::size_t>(total);
      return;
    }
    for (std::uint64_t r = 0; r < e.count; ++r) {
      begin_record(element, r);
      for (const PlyProperty& p : e.properties) {
        if (p.list)
          skip_items(p, read_count(p));
        else
          skip(p);
      }
    }
  }

  void finish(const PlyElement& last) {
    if (pos_ < size_)
      throw IoError(name_,
                    "data continues after the " + count_phrase(last, last.count) +
                        " the header declares (" +
                        count_of(size_ - pos_, "extra byte", "extra bytes") + ")",
                    {}, pos_);
  }

  /// At the value last read.
  [[noreturn]] void fail(const std::string& problem) const {
    throw IoError(name_, problem, {}, value_start_);
  }
  /// At the start of the current record.
  [[noreturn]] void fail_record(const std::string& problem) const {
    throw IoError(name_, problem, {}, record_start_);
  }

private:
  const char* take(std::uint64_t n) {
    if (n > size_ - pos_) truncated(n);
    value_start_ = pos_;
    const char* p = data_ + pos_;
    pos_ += static_cast<std::size_t>(n);
    return p;
  }

  // The file ends inside the current record. `n`: bytes the failing read wanted.
  [[noreturn]] void truncated(std::uint64_t n) const {
    const PlyElement& e = elements_[element_];
    // The least the header's counts need: this record with its lists as read so far, the rest
    // of this element and the later ones with every list empty.
    std::uint64_t need = std::max<std::uint64_t>(sat_add(pos_, n), record_start_ + e.min_size);
    need = sat_add(need, sat_mul(e.count - record_ - 1, e.min_size));
    bool exact = e.fixed;
    for (std::size_t i = element_ + 1; i < elements_.size(); ++i) {
      need = sat_add(need, sat_mul(elements_[i].count, elements_[i].min_size));
      exact = exact && elements_[i].fixed;
    }
    throw IoError(name_,
                  "file ends at byte " + std::to_string(size_) + " but the header's counts need " +
                      (exact ? "" : "at least ") + std::to_string(need) + " bytes (" +
                      record_label(e, record_) + " of " + std::to_string(e.count) + " is cut off)",
                  {}, record_start_);
  }

  const char* data_;
  std::size_t size_;
  std::size_t pos_;
  bool big_;
  const std::string& name_;
  const std::vector<PlyElement>& elements_;
  std::size_t element_ = 0;
  std::uint64_t record_ = 0;
  std::size_t record_start_ = 0;
  std::size_t value_start_ = 0;
};

// Strip s yields triangles (s[i], s[i+1], s[i+2]), every other one with the first two swapped so
// that all keep the strip's winding. Degenerate "swap" triangles are kept: the repair counts them.
void add_strip(const std::vector<std::uint32_t>& s, PolygonSoup& soup, std::size_t& triangles) {
  for (std::size_t i = 0; i + 2 < s.size(); ++i) {
    if (i % 2 == 0)
      soup.add_triangle(s[i], s[i + 1], s[i + 2]);
    else
      soup.add_triangle(s[i + 1], s[i], s[i + 2]);
    ++triangles;
  }
}

// Reads past property p of the current record (a list with its length).
template <class Source>
void skip_property(Source& src, const PlyProperty& p) {
  if (p.list)
    src.skip_items(p, src.read_count(p));
  else
    src.skip(p);
}

// The vertex element e (number ei in the header): x y z of each record into soup.points, the
// other properties read past; fails at a point that is not finite. Reserves `reserve` points.
template <class Source>
void read_vertices(Source& src, const PlyElement& e, std::size_t ei, std::size_t reserve,
                   PolygonSoup& soup) {
  soup.points.reserve(reserve);
  for (std::uint64_t r = 0; r < e.count; ++r) {
    src.begin_record(ei, r);
    Vec3 point(0, 0, 0);
    for (const PlyProperty& p : e.properties) {
      if (p.list || p.role == Role::Skip)
        skip_property(src, p);
      else
        point[static_cast<int>(p.role) - static_cast<int>(Role::X)] = src.read_double(p);
    }
    src.end_record();
    if (!is_finite(point))
      src.fail_record(non_finite_problem(point, "vertex " + std::to_string(r)));
    soup.points.push_back(point);
  }
}

// The index list p of record r of the face or strip element e into `corners`, each index below
// `vertex_count`; in a strip, -1 ends the strip so far, whose triangles go into soup and are
// counted in `faces`. Fails at a face of fewer than 3 corners or an index out of range.
template <class Source>
void read_indices(Source& src, const PlyProperty& p, const PlyElement& e, std::uint64_t r,
                  std::uint64_t vertex_count, std::vector<std::uint32_t>& corners,
                  PolygonSoup& soup, std::size_t& faces) {
  const bool strips = e.kind == Kind::Strips;
  const std::uint64_t n = src.read_count(p);
  if (!strips && n < 3)
    src.fail("face " + std::to_string(r) + " has " + std::to_string(n) +
             " corners; a face needs at least 3");
  for (std::uint64_t k = 0; k < n; ++k) {
    const std::int64_t index = src.read_int(p);
    if (index >= 0 && static_cast<std::uint64_t>(index) < vertex_count) {
      corners.push_back(static_cast<std::uint32_t>(index));
    } else if (strips && index == -1) {
      add_strip(corners, soup, faces);
      corners.clear();
    } else if (index < 0) {
      src.fail(record_label(e, r) + " has the negative vertex index " + std::to_string(index) +
               (strips ? " (only -1 may separate strips)" : ""));
    } else {
      src.fail(record_label(e, r) + " refers to vertex " + std::to_string(index) +
               " but the file has " + std::to_string(vertex_count) + " vertices");
    }
  }
}

// The face or strip element e (number ei in the header) into soup: a polygon per face record,
// the triangles of its strips per strip record; returns how many faces it added. Reserves room
// for `reserve` faces of a face element.
template <class Source>
std::size_t read_faces(Source& src, const PlyElement& e, std::size_t ei, std::uint64_t vertex_count,
                       std::size_t reserve, PolygonSoup& soup) {
  const bool strips = e.kind == Kind::Strips;
  if (!strips) {
    soup.offsets.reserve(soup.offsets.size() + reserve);
    soup.indices.reserve(soup.indices.size() + 3 * reserve);
  }
  std::vector<std::uint32_t> corners;
  std::size_t faces = 0;
  for (std::uint64_t r = 0; r < e.count; ++r) {
    src.begin_record(ei, r);
    corners.clear();
    for (const PlyProperty& p : e.properties) {
      if (p.role == Role::Indices)
        read_indices(src, p, e, r, vertex_count, corners, soup, faces);
      else
        skip_property(src, p);
    }
    src.end_record();
    if (strips) {
      add_strip(corners, soup, faces);
    } else {
      soup.add_polygon(corners.data(), corners.size());
      ++faces;
    }
  }
  return faces;
}

// "element NAME (COUNT)", for FileInfo::skipped.
std::string skipped_element(const PlyElement& e) {
  return "element " + e.name + " (" + std::to_string(e.count) + ")";
}

// The records of every element in header order: vertices and faces into result.soup, the other
// elements read past and listed in result.info.skipped; fails at data after the last element.
template <class Source>
void read_body(Source& src, const PlyHeader& h, std::size_t file_size, const ReadLimits& limits,
               const std::string& name, SoupFile& result) {
  PolygonSoup& soup = result.soup;
  std::uint64_t vertex_count = 0;
  for (std::size_t ei = 0; ei < h.elements.size(); ++ei) {
    const PlyElement& e = h.elements[ei];
    if (e.properties.empty()) {
      // Records without properties occupy no bytes and no text.
      if (e.kind == Kind::Skip) result.info.skipped.push_back(skipped_element(e));
      continue;
    }
    const std::size_t reserve = reserve_count(e.count, file_size, h.ascii ? 6 : e.min_size);
    switch (e.kind) {
    case Kind::Skip:
      src.skip_element(ei);
      result.info.skipped.push_back(skipped_element(e));
      break;
    case Kind::Vertex:
      check_limit(e.count, limits.max_vertices(),
                  "the header declares " + std::to_string(e.count) + " vertices", "vertices", name,
                  e.line);
      vertex_count = e.count;
      read_vertices(src, e, ei, reserve, soup);
      result.info.vertices_in_file = soup.points.size();
      break;
    case Kind::Face:
    case Kind::Strips:
      if (e.kind == Kind::Face)
        check_limit(e.count, limits.max_triangles,
                    "the header declares " + std::to_string(e.count) + " faces", "triangles", name,
                    e.line);
      result.info.faces_in_file += read_faces(src, e, ei, vertex_count, reserve, soup);
      break;
    }
  }
  src.finish(h.elements.back());
}

} // namespace

SoupFile read_ply(std::string_view bytes, const std::string& name, const ReadLimits& limits) {
  PlyHeader h = parse_header(bytes, name);
  assign_roles(h, name);

  SoupFile result;
  result.info.format = "ply";
  result.info.encoding = h.encoding;
  if (h.ascii) {
    const std::string_view body = bytes.substr(h.data_offset);
    check_text(body, name, h.lines + 1, h.data_offset);
    AsciiSource src(body, h.lines, name, h.elements);
    read_body(src, h, bytes.size(), limits, name, result);
  } else {
    BinarySource src(bytes, h.data_offset, h.big_endian, name, h.elements);
    read_body(src, h, bytes.size(), limits, name, result);
  }
  if (result.soup.num_polygons() == 0)
    throw IoError(name, "no faces: the file declares " +
                            std::to_string(result.info.vertices_in_file) +
                            " vertices and no faces (an empty mesh cannot be loaded)");
  return result;
}

void write_ply(const CompactMesh& m, bool binary, std::string& out) {
  const std::size_t faces = m.triangles.size() / 3;
  out += "ply\nformat ";
  out += binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment written by Remora\nelement vertex ";
  append_uint(out, m.points.size());
  out += "\nproperty double x\nproperty double y\nproperty double z\nelement face ";
  append_uint(out, faces);
  out += "\nproperty list uchar int vertex_indices\nend_header\n";
  if (binary) {
    out.reserve(out.size() + 24 * m.points.size() + 13 * faces);
    for (const Vec3& p : m.points)
      for (int k = 0; k < 3; ++k) append_le(out, p[k]);
    for (std::size_t f = 0; f < faces; ++f) {
      append_le(out, std::uint8_t{3});
      for (std::size_t k = 0; k < 3; ++k)
        append_le(out, static_cast<std::int32_t>(m.triangles[3 * f + k]));
    }
    return;
  }
  out.reserve(out.size() + 64 * m.points.size() + 24 * faces);
  for (const Vec3& p : m.points) append_point_line(out, "", p);
  for (std::size_t i = 0; i < m.triangles.size(); i += 3)
    append_triangle_line(out, "3", &m.triangles[i], 0);
}

} // namespace remora::io_detail
