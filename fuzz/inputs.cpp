#include "inputs.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "remora/mesh/primitives.h"

namespace remora::fuzz {

namespace {

constexpr const char* kScalarTypes[8] = {"char", "uchar", "short", "ushort",
                                         "int",  "uint",  "float", "double"};
constexpr const char* kCountTypes[4] = {"uchar", "ushort", "int", "uint"};
constexpr const char* kIndexTypes[4] = {"int", "uint", "short", "ushort"};

bool bit(unsigned char byte, int b) {
  return (byte >> b) & 1u;
}

} // namespace

PlyLayout PlyLayout::decode(std::string_view bytes) {
  unsigned char b[kBytes] = {};
  std::memcpy(b, bytes.data(), std::min(bytes.size(), kBytes));
  PlyLayout l;
  l.ascii = bit(b[0], 0);
  l.big_endian = bit(b[0], 1);
  l.coordinate_type = (b[0] >> 2) & 7;
  l.normals = bit(b[0], 5);
  l.colours = bit(b[0], 6);
  l.camera = bit(b[0], 7);
  l.count_type = b[1] & 3;
  l.index_type = (b[1] >> 2) & 3;
  l.strips = bit(b[1], 4);
  l.face_flags = bit(b[1], 5);
  l.material = bit(b[1], 6);
  l.comments = bit(b[1], 7);
  l.vertices = b[2] | (unsigned(b[3]) << 8);
  l.faces = b[4] | (unsigned(b[5]) << 8);
  return l;
}

std::string PlyLayout::encode() const {
  std::string out(kBytes, '\0');
  const auto b0 = static_cast<unsigned>(ascii) | unsigned(big_endian) << 1 |
                  unsigned(coordinate_type & 7) << 2 | unsigned(normals) << 5 |
                  unsigned(colours) << 6 | unsigned(camera) << 7;
  const auto b1 = unsigned(count_type & 3) | unsigned(index_type & 3) << 2 | unsigned(strips) << 4 |
                  unsigned(face_flags) << 5 | unsigned(material) << 6 | unsigned(comments) << 7;
  out[0] = static_cast<char>(b0);
  out[1] = static_cast<char>(b1);
  out[2] = static_cast<char>(vertices & 0xff);
  out[3] = static_cast<char>(vertices >> 8);
  out[4] = static_cast<char>(faces & 0xff);
  out[5] = static_cast<char>(faces >> 8);
  return out;
}

std::string PlyLayout::header() const {
  std::string h = "ply\nformat ";
  h += ascii ? "ascii" : (big_endian ? "binary_big_endian" : "binary_little_endian");
  h += " 1.0\n";
  if (comments) h += "comment made by the fuzzer\nobj_info layout\n";
  if (camera) h += "element camera 1\nproperty float view_px\nproperty float view_py\n";
  h += "element vertex " + std::to_string(vertices) + "\n";
  const std::string c = kScalarTypes[coordinate_type & 7];
  h += "property " + c + " x\nproperty " + c + " y\nproperty " + c + " z\n";
  if (normals) h += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colours) h += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  h += std::string("element ") + (strips ? "tristrips " : "face ") + std::to_string(faces) + "\n";
  h += std::string("property list ") + kCountTypes[count_type & 3] + " " +
       kIndexTypes[index_type & 3] + " vertex_indices\n";
  if (face_flags) h += "property uchar flags\n";
  if (material) h += "element material 1\nproperty list uchar uchar name\n";
  return h + "end_header\n";
}

std::string ply_file(std::string_view input, PlyVariant variant) {
  PlyLayout l = PlyLayout::decode(input);
  if (variant == PlyVariant::Binary) l.ascii = false;
  if (variant == PlyVariant::Tristrips) l.strips = true;
  const std::string_view body =
      input.size() > PlyLayout::kBytes ? input.substr(PlyLayout::kBytes) : std::string_view();
  return l.header() + std::string(body);
}

std::string binary_stl_file(std::string_view input) {
  const std::size_t count = input.size() / 50;
  std::string out = "solid made by the fuzzer";
  out.resize(80, ' ');
  for (int k = 0; k < 4; ++k) out += static_cast<char>((count >> (8 * k)) & 0xff);
  out.append(input.substr(0, 50 * count));
  return out;
}

std::string server_fixture_off() {
  const Mesh m = make_icosphere(2, 1.0);
  std::ostringstream s;
  s.precision(17);
  s << "OFF\n" << m.n_vertices() << " " << m.n_faces() << " 0\n";
  for (const VertexHandle v : m.vertices()) {
    const Vec3 p =
        m.point(v) * (1.0 + 0.03 * std::sin(9 * m.point(v)[0]) * std::sin(9 * m.point(v)[1]));
    s << p[0] << " " << p[1] << " " << p[2] << "\n";
  }
  for (const FaceHandle f : m.faces()) {
    s << 3;
    for (const VertexHandle v : m.fv_range(f)) s << " " << v.idx();
    s << "\n";
  }
  return s.str();
}

std::vector<ScriptRequest> parse_requests(std::string_view script, std::size_t max_requests) {
  std::vector<ScriptRequest> out;
  while (!script.empty() && out.size() < max_requests) {
    const std::size_t end = script.find(kRequestSeparator);
    const std::string_view one = script.substr(0, end);
    script = end == std::string_view::npos ? std::string_view()
                                           : script.substr(end + kRequestSeparator.size());
    const std::size_t eol = one.find('\n');
    const std::string_view line = one.substr(0, eol);
    ScriptRequest r;
    if (eol != std::string_view::npos) r.body = std::string(one.substr(eol + 1));
    const std::size_t space = line.find(' ');
    r.method = std::string(line.substr(0, space));
    const std::string_view target =
        space == std::string_view::npos ? std::string_view() : line.substr(space + 1);
    const std::size_t question = target.find('?');
    r.path = std::string(target.substr(0, question));
    std::string_view query =
        question == std::string_view::npos ? std::string_view() : target.substr(question + 1);
    while (!query.empty()) {
      const std::size_t amp = query.find('&');
      const std::string_view pair = query.substr(0, amp);
      query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
      const std::size_t eq = pair.find('=');
      r.query[std::string(pair.substr(0, eq))] =
          eq == std::string_view::npos ? std::string() : std::string(pair.substr(eq + 1));
    }
    out.push_back(std::move(r));
  }
  return out;
}

std::string write_requests(const std::vector<ScriptRequest>& requests) {
  std::string out;
  for (std::size_t i = 0; i < requests.size(); ++i) {
    const ScriptRequest& r = requests[i];
    if (i > 0) out += kRequestSeparator;
    out += r.method + " " + r.path;
    char sep = '?';
    for (const auto& [key, value] : r.query) {
      out += sep + key + "=" + value;
      sep = '&';
    }
    out += "\n" + r.body;
  }
  return out;
}

} // namespace remora::fuzz
