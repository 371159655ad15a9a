#include "remora/mesh/io_ply_header.h"

#include <charconv>

#include "remora/common/error.h"
#include "remora/mesh/io_detail.h"

namespace remora::io_detail::ply {

namespace {

struct TypeName {
  std::string_view name;
  PlyType type;
};
constexpr TypeName kTypeNames[] = {
    {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::Uint8},
    {"uint8", PlyType::Uint8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
    {"ushort", PlyType::Uint16},  {"uint16", PlyType::Uint16},   {"int", PlyType::Int32},
    {"int32", PlyType::Int32},    {"uint", PlyType::Uint32},     {"uint32", PlyType::Uint32},
    {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
    {"float64", PlyType::Float64}};

// A scalar of type t at p, converted to T. Integers are read only for integer types (the
// header check rejects float counts and indices).
template <class T>
T load_as(const char* p, PlyType t, bool big) {
  switch (t) {
  case PlyType::Int8:
    return static_cast<T>(load<std::int8_t>(p, big));
  case PlyType::Uint8:
    return static_cast<T>(load<std::uint8_t>(p, big));
  case PlyType::Int16:
    return static_cast<T>(load<std::int16_t>(p, big));
  case PlyType::Uint16:
    return static_cast<T>(load<std::uint16_t>(p, big));
  case PlyType::Int32:
    return static_cast<T>(load<std::int32_t>(p, big));
  case PlyType::Uint32:
    return static_cast<T>(load<std::uint32_t>(p, big));
  case PlyType::Float32:
    return static_cast<T>(load<float>(p, big));
  case PlyType::Float64:
    return static_cast<T>(load<double>(p, big));
  }
  return T{0};
}

PlyType parse_type(std::string_view token, const std::string& name, std::uint64_t line) {
  for (const TypeName& t : kTypeNames)
    if (t.name == token) return t.type;
  throw IoError(name,
                "unknown property type '" + std::string(token) +
                    "' (known: char uchar short ushort int uint float double, int8 uint8 int16 "
                    "uint16 int32 uint32 float32 float64)",
                line);
}

// `format ENCODING 1.0` (`rest`: what follows the keyword): sets the encoding of `h`; throws
// IoError for an unknown encoding, another version or a second format line.
void parse_format(std::string_view rest, const std::string& name, std::uint64_t line,
                  bool& have_format, PlyHeader& h) {
  const std::string_view encoding = next_token(rest);
  const std::string_view version = next_token(rest);
  if (encoding == "ascii") {
    h.ascii = true;
  } else if (encoding == "binary_little_endian") {
    h.ascii = false;
    h.big_endian = false;
  } else if (encoding == "binary_big_endian") {
    h.ascii = false;
    h.big_endian = true;
  } else {
    throw IoError(name,
                  "unknown PLY format '" + std::string(encoding) +
                      "' (known: ascii, binary_little_endian, binary_big_endian)",
                  line);
  }
  if (version != "1.0" || !next_token(rest).empty())
    throw IoError(
        name, "unsupported format line: expected 'format " + std::string(encoding) + " 1.0'", line);
  if (have_format) throw IoError(name, "a second 'format' line", line);
  have_format = true;
  h.encoding = encoding;
}

// `element NAME COUNT` (`rest`: what follows the keyword), without properties yet.
PlyElement parse_element(std::string_view rest, const std::string& name, std::uint64_t line) {
  PlyElement e;
  e.name = next_token(rest);
  const std::string_view count = next_token(rest);
  if (e.name.empty() || count.empty() || !next_token(rest).empty())
    throw IoError(name, "bad element line: expected 'element NAME COUNT'", line);
  const std::int64_t n = to_int(count, name, line, "element count");
  if (n < 0) throw IoError(name, "negative element count " + std::to_string(n), line);
  e.count = static_cast<std::uint64_t>(n);
  e.line = line;
  return e;
}

// `property TYPE NAME` or `property list COUNT_TYPE TYPE NAME` (`rest`: what follows the
// keyword); a list's length type must be an integer type.
PlyProperty parse_property(std::string_view rest, const std::string& name, std::uint64_t line) {
  PlyProperty p;
  const std::string_view type = next_token(rest);
  if (type == "list") {
    p.list = true;
    const std::string_view count_type = next_token(rest);
    const std::string_view item_type = next_token(rest);
    if (count_type.empty() || item_type.empty())
      throw IoError(name, "bad property line: expected 'property list COUNT_TYPE TYPE NAME'", line);
    p.count_type = parse_type(count_type, name, line);
    p.type = parse_type(item_type, name, line);
    if (!is_integer(p.count_type))
      throw IoError(
          name, "list length type '" + std::string(count_type) + "' is not an integer type", line);
  } else {
    if (type.empty()) throw IoError(name, "bad property line: no type", line);
    p.type = parse_type(type, name, line);
  }
  p.name = next_token(rest);
  if (p.name.empty() || !next_token(rest).empty())
    throw IoError(name, "bad property line: expected 'property TYPE NAME'", line);
  return p;
}

} // namespace

std::size_t type_size(PlyType t) {
  switch (t) {
  case PlyType::Int8:
  case PlyType::Uint8:
    return 1;
  case PlyType::Int16:
  case PlyType::Uint16:
    return 2;
  case PlyType::Int32:
  case PlyType::Uint32:
  case PlyType::Float32:
    return 4;
  case PlyType::Float64:
    return 8;
  }
  return 0;
}

bool is_integer(PlyType t) {
  return t != PlyType::Float32 && t != PlyType::Float64;
}

double load_double(const char* p, PlyType t, bool big) {
  return load_as<double>(p, t, big);
}
std::int64_t load_int(const char* p, PlyType t, bool big) {
  return load_as<std::int64_t>(p, t, big);
}

std::string count_phrase(const PlyElement& e, std::uint64_t n) {
  if (e.name == "vertex") return count_of(n, "vertex", "vertices");
  if (e.name == "face") return count_of(n, "face", "faces");
  return std::to_string(n) + " '" + e.name + "' record" + plural(n);
}

std::string record_label(const PlyElement& e, std::uint64_t r) {
  if (e.name == "vertex" || e.name == "face") return e.name + " " + std::to_string(r);
  return "'" + e.name + "' record " + std::to_string(r);
}

// The header up to and including `end_header`, each line checked to be text; throws IoError for
// a first line other than `ply`, an unknown or malformed line, or a missing format line.
PlyHeader parse_header(std::string_view bytes, const std::string& name) {
  if (bytes.empty()) throw IoError(name, "no faces: the file is empty");
  PlyHeader h;
  LineReader lines(bytes);
  std::string_view raw;
  bool have_format = false;
  bool ended = false;
  while (!ended) {
    const std::size_t start = lines.offset();
    if (!lines.next(raw)) {
      throw IoError(name, "the header has no 'end_header' line", lines.line());
    }
    const std::uint64_t line = lines.line();
    check_text(raw, name, line, start);
    std::string_view rest = raw;
    const std::string_view key = next_token(rest);
    if (line == 1) {
      if (key != "ply" || !next_token(rest).empty())
        throw IoError(name, "not a PLY file: the first line is not 'ply'", line);
      continue;
    }
    if (key.empty() || key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      ended = true;
    } else if (key == "format") {
      parse_format(rest, name, line, have_format, h);
    } else if (key == "element") {
      h.elements.push_back(parse_element(rest, name, line));
    } else if (key == "property") {
      if (h.elements.empty()) throw IoError(name, "'property' before any 'element' line", line);
      h.elements.back().properties.push_back(parse_property(rest, name, line));
    } else {
      throw IoError(name, "unknown header line starting with '" + std::string(key) + "'", line);
    }
  }
  if (!have_format) throw IoError(name, "the header has no 'format' line", lines.line());
  h.data_offset = lines.offset();
  h.lines = lines.line();
  return h;
}

// Gives every element and property its role, and checks that the faces can be read.
void assign_roles(PlyHeader& h, const std::string& name) {
  const PlyElement* vertex = nullptr;
  bool any_faces = false;
  for (PlyElement& e : h.elements) {
    for (const PlyProperty& p : e.properties) {
      e.min_size += type_size(p.list ? p.count_type : p.type);
      if (p.list) e.fixed = false;
    }
    if (e.name == "vertex") {
      if (vertex != nullptr) throw IoError(name, "a second 'vertex' element", e.line);
      e.kind = Kind::Vertex;
      vertex = &e;
      if (e.count >= std::numeric_limits<std::uint32_t>::max())
        throw IoError(name, "too many vertices: " + std::to_string(e.count), e.line);
      const char* axes[3] = {"x", "y", "z"};
      for (int k = 0; k < 3; ++k) {
        PlyProperty* found = nullptr;
        for (PlyProperty& p : e.properties)
          if (p.name == axes[k] && found == nullptr) found = &p;
        if (found == nullptr)
          throw IoError(name, std::string("element vertex has no property '") + axes[k] + "'",
                        e.line);
        if (found->list)
          throw IoError(name, std::string("property '") + axes[k] + "' of element vertex is a list",
                        e.line);
        found->role = static_cast<Role>(static_cast<int>(Role::X) + k);
      }
    } else if (e.name == "face" || e.name == "tristrips") {
      for (const PlyElement& other : h.elements) {
        if (&other == &e) break;
        if (other.name == e.name) throw IoError(name, "a second '" + e.name + "' element", e.line);
      }
      if (vertex == nullptr)
        throw IoError(name,
                      "element " + e.name +
                          " comes before element vertex (faces must follow the vertices they use)",
                      e.line);
      e.kind = e.name == "face" ? Kind::Face : Kind::Strips;
      PlyProperty* found = nullptr;
      for (PlyProperty& p : e.properties) {
        const bool match =
            p.name == "vertex_indices" || (e.kind == Kind::Face && p.name == "vertex_index");
        if (match && found == nullptr) found = &p;
      }
      if (found == nullptr)
        throw IoError(name,
                      "element " + e.name + " has no list property 'vertex_indices'" +
                          (e.kind == Kind::Face ? " or 'vertex_index'" : ""),
                      e.line);
      if (!found->list || !is_integer(found->type))
        throw IoError(name,
                      "property '" + found->name + "' of element " + e.name +
                          " must be a list of integers",
                      e.line);
      found->role = Role::Indices;
      any_faces = true;
    }
  }
  if (!any_faces)
    throw IoError(name, "no faces: the header declares no 'face' or 'tristrips' element (an empty "
                        "mesh cannot be loaded)");
}

} // namespace remora::io_detail::ply
