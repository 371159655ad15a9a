// The fuzz harnesses' seed corpora, written at build time (fuzz/CMakeLists.txt) so that no binary
// file lives in git: small meshes (a tetrahedron, a grid of quads, an icosphere, a patch of the
// bundled bunny) in every format and variant the readers take, the EDIT.json examples of
// docs/editing.md and a few more, and request scripts for the server harness.
//
//   remora_fuzz_seeds OUT_DIR REPO_DIR     writes OUT_DIR/<harness>/<seed> (REPO_DIR: data/ and
//                                          docs/ of the source tree)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "inputs.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"

namespace {

namespace fs = std::filesystem;
using namespace remora;
using fuzz::PlyLayout;

/// Points in [-1, 1]^3 and polygons: what every seed is written from.
struct Soup {
  std::vector<std::array<double, 3>> points;
  std::vector<std::vector<int>> faces;
};

Soup normalized(const Mesh& m) {
  Soup s;
  Vec3 lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
  for (const VertexHandle v : m.vertices()) lo.minimize(m.point(v)), hi.maximize(m.point(v));
  const Vec3 mid = 0.5 * (lo + hi);
  const double half = std::max(0.5 * (hi - lo).max(), 1e-300);
  for (const VertexHandle v : m.vertices()) {
    const Vec3 p = (m.point(v) - mid) / half;
    s.points.push_back({p[0], p[1], p[2]});
  }
  for (const FaceHandle f : m.faces()) {
    std::vector<int> ids;
    for (const VertexHandle v : m.fv_range(f)) ids.push_back(v.idx());
    s.faces.push_back(ids);
  }
  return s;
}

Soup tetrahedron() {
  return {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
          {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
}

/// 3 x 2 quads: polygons for the formats that take them.
Soup quads() {
  Soup s;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i) s.points.push_back({i * 0.5 - 1, j * 0.5 - 0.5, 0.1 * i * j});
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 3; ++i)
      s.faces.push_back({4 * j + i, 4 * j + i + 1, 4 * j + i + 5, 4 * j + i + 4});
  return s;
}

/// The faces of the bundled bunny within a small ball around its vertex 0, re-indexed.
Soup bunny_patch(const fs::path& repo) {
  const Mesh bunny = read_mesh((repo / "data" / "bunny.ply").string()).mesh;
  const Vec3 c = bunny.point(VertexHandle(0));
  std::vector<int> index(bunny.n_vertices(), -1);
  Mesh patch;
  for (const FaceHandle f : bunny.faces()) {
    std::vector<VertexHandle> corners;
    for (const VertexHandle v : bunny.fv_range(f))
      if ((bunny.point(v) - c).norm() < 0.006) corners.push_back(v);
    if (corners.size() != 3) continue;
    std::vector<VertexHandle> ids;
    for (const VertexHandle v : corners) {
      if (index[v.idx()] < 0) index[v.idx()] = patch.add_vertex(bunny.point(v)).idx();
      ids.push_back(VertexHandle(index[v.idx()]));
    }
    patch.add_face(ids);
  }
  return normalized(patch);
}

std::vector<std::array<int, 3>> triangles(const Soup& s) {
  std::vector<std::array<int, 3>> t;
  for (const auto& f : s.faces)
    for (std::size_t k = 1; k + 1 < f.size(); ++k) t.push_back({f[0], f[k], f[k + 1]});
  return t;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

/// OBJ in three styles: plain; with texture and normal indices, comments and groups; with
/// negative (relative) indices.
std::string obj(const Soup& s, int style) {
  std::string out = style == 1 ? "# seed\no part\ng group\nusemtl m\ns off\n" : "";
  for (const auto& p : s.points) out += "v " + num(p[0]) + " " + num(p[1]) + " " + num(p[2]) + "\n";
  if (style == 1) out += "vt 0 0\nvn 0 0 1\n";
  const auto n = static_cast<int>(s.points.size());
  for (const auto& f : s.faces) {
    out += "f";
    for (const int v : f) {
      if (style == 1)
        out += " " + std::to_string(v + 1) + "/1/1";
      else if (style == 2)
        out += " " + std::to_string(v - n);
      else
        out += " " + std::to_string(v + 1);
    }
    out += "\n";
  }
  return out;
}

/// OFF in three styles: plain; COFF with colours; counts on the next line after comments.
std::string off(const Soup& s, int style) {
  const std::string counts =
      std::to_string(s.points.size()) + " " + std::to_string(s.faces.size()) + " 0\n";
  std::string out = style == 1   ? "COFF\n" + counts
                    : style == 2 ? "OFF\n# seed\n\n" + counts
                                 : "OFF\n" + counts;
  for (const auto& p : s.points)
    out += num(p[0]) + " " + num(p[1]) + " " + num(p[2]) + (style == 1 ? " 255 0 0 255\n" : "\n");
  for (const auto& f : s.faces) {
    out += std::to_string(f.size());
    for (const int v : f) out += " " + std::to_string(v);
    out += "\n";
  }
  return out;
}

std::string stl_ascii(const Soup& s) {
  std::string out = "solid seed\n";
  for (const auto& t : triangles(s)) {
    out += " facet normal 0 0 1\n  outer loop\n";
    for (const int v : t) {
      const auto& p = s.points[static_cast<std::size_t>(v)];
      out += "   vertex " + num(p[0]) + " " + num(p[1]) + " " + num(p[2]) + "\n";
    }
    out += "  endloop\n endfacet\n";
  }
  return out + "endsolid seed\n";
}

template <class T>
void put_raw(std::string& out, T v, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof v);
  if (big) std::reverse(b, b + sizeof b);
  out.append(b, sizeof b);
}

/// binary_stl_file()'s input: the 50-byte records.
std::string stl_records(const Soup& s) {
  std::string out;
  for (const auto& t : triangles(s)) {
    for (int k = 0; k < 3; ++k) put_raw(out, k == 2 ? 1.0f : 0.0f, false);
    for (const int v : t)
      for (const double c : s.points[static_cast<std::size_t>(v)])
        put_raw(out, static_cast<float>(c), false);
    put_raw(out, std::uint16_t{0}, false);
  }
  return out;
}

/// One PLY value of scalar type `type` (inputs.cpp's order: char .. double).
void put(std::string& out, const PlyLayout& l, int type, double v) {
  if (l.ascii) {
    out += (type >= 6 ? num(v) : std::to_string(static_cast<long long>(v))) + " ";
    return;
  }
  const bool big = l.big_endian;
  switch (type) {
  case 0:
    return put_raw(out, static_cast<std::int8_t>(v), big);
  case 1:
    return put_raw(out, static_cast<std::uint8_t>(v), big);
  case 2:
    return put_raw(out, static_cast<std::int16_t>(v), big);
  case 3:
    return put_raw(out, static_cast<std::uint16_t>(v), big);
  case 4:
    return put_raw(out, static_cast<std::int32_t>(v), big);
  case 5:
    return put_raw(out, static_cast<std::uint32_t>(v), big);
  case 6:
    return put_raw(out, static_cast<float>(v), big);
  default:
    return put_raw(out, v, big);
  }
}

void end_record(std::string& out, const PlyLayout& l) {
  if (l.ascii && !out.empty() && out.back() == ' ') out.back() = '\n';
}

/// The body of a PLY file with layout `l` (its counts set here) for `s`; `strips`: the index
/// lists of the tristrips records.
std::string ply_body(PlyLayout& l, const Soup& s, const std::vector<std::vector<int>>& strips) {
  static constexpr int kCount[4] = {1, 3, 4, 5}, kIndex[4] = {4, 5, 2, 3};
  const std::vector<std::vector<int>>& records = l.strips ? strips : s.faces;
  l.vertices = static_cast<unsigned>(s.points.size());
  l.faces = static_cast<unsigned>(records.size());
  std::string out;
  if (l.camera) put(out, l, 6, 0.5), put(out, l, 6, -0.5), end_record(out, l);
  for (const auto& p : s.points) {
    for (const double c : p)
      put(out, l, l.coordinate_type, l.coordinate_type >= 6 ? c : std::round(40 * c + 50));
    if (l.normals) put(out, l, 6, 0), put(out, l, 6, 0), put(out, l, 6, 1);
    if (l.colours) put(out, l, 1, 200), put(out, l, 1, 100), put(out, l, 1, 0);
    end_record(out, l);
  }
  for (const auto& r : records) {
    put(out, l, kCount[l.count_type], static_cast<double>(r.size()));
    for (const int v : r) put(out, l, kIndex[l.index_type], v);
    if (l.face_flags) put(out, l, 1, 7);
    end_record(out, l);
  }
  if (l.material)
    put(out, l, 1, 3), put(out, l, 1, 'a'), put(out, l, 1, 'b'), put(out, l, 1, 'c'),
        end_record(out, l);
  return out;
}

/// Strips for `s`: every triangle a strip of its own, separated by -1, in one record; and for a
/// grid of two rows, one real strip.
std::vector<std::vector<int>> strips_of(const Soup& s) {
  std::vector<int> all;
  for (const auto& t : triangles(s)) all.insert(all.end(), {t[0], t[1], t[2], -1});
  all.pop_back();
  return {all};
}

Soup strip_grid() {
  Soup s;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 2; ++j) s.points.push_back({i * 0.25 - 1, j * 0.5, 0.05 * i * j});
  return s;
}

void write(const fs::path& dir, const std::string& name, const std::string& bytes) {
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << bytes;
}

/// The layouts the PLY seeds use: types, endianness and the optional parts in turn.
std::vector<PlyLayout> layouts() {
  std::vector<PlyLayout> out;
  for (int i = 0; i < 8; ++i) {
    PlyLayout l;
    l.big_endian = i % 2 == 1;
    l.coordinate_type = i;
    l.count_type = i % 4;
    l.index_type = i % 2 == 0 ? 0 : 2; // signed: strips need -1
    l.normals = i == 2 || i == 6;
    l.colours = i == 3 || i == 6;
    l.camera = i == 4;
    l.face_flags = i == 5;
    l.material = i == 7;
    l.comments = i == 1;
    out.push_back(l);
  }
  return out;
}

void mesh_seeds(const fs::path& out, const std::vector<std::pair<std::string, Soup>>& soups) {
  for (const auto& [name, s] : soups) {
    const bool triangulated = triangles(s).size() == s.faces.size();
    for (int style = 0; style < 3; ++style) {
      write(out / "obj", name + std::to_string(style) + ".obj", obj(s, style));
      write(out / "off", name + std::to_string(style) + ".off", off(s, style));
    }
    if (triangulated || name == "quads") {
      write(out / "stl_ascii", name + ".stl", stl_ascii(s));
      write(out / "stl_binary", name, stl_records(s));
      // The raw STL harness reaches the binary reader through the size rule as well.
      write(out / "stl_ascii", name + "_binary.stl", fuzz::binary_stl_file(stl_records(s)));
    }
    int k = 0;
    for (PlyLayout l : layouts()) {
      const std::string id = name + std::to_string(k++);
      PlyLayout a = l;
      a.ascii = true;
      a.strips = false;
      std::string body = ply_body(a, s, {});
      write(out / "ply_ascii", id + ".ply", a.header() + body);
      l.strips = false;
      body = ply_body(l, s, {});
      write(out / "ply_binary", id, l.encode() + body);
      if (k == 1) write(out / "ply_ascii", id + "_binary.ply", l.header() + body);
      for (const bool ascii : {false, true}) {
        PlyLayout t = l;
        t.strips = true;
        t.ascii = ascii;
        t.count_type |= 2; // int or uint: a record holds every strip
        body = ply_body(t, s, strips_of(s));
        write(out / "ply_tristrips", id + (ascii ? "a" : "b"), t.encode() + body);
      }
    }
  }
  PlyLayout grid;
  grid.strips = true;
  const std::string body =
      ply_body(grid, strip_grid(), {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15}});
  write(out / "ply_tristrips", "grid", grid.encode() + body);
}

/// docs/editing.md's EDIT.json examples and requests that reach every region and transform kind
/// on the harness's icosphere (162 vertices).
void edit_seeds(const fs::path& out, const fs::path& repo) {
  std::ifstream in(repo / "docs" / "editing.md");
  std::stringstream doc;
  doc << in.rdbuf();
  const std::string text = doc.str();
  int k = 0;
  for (std::size_t at = text.find("```json\n"); at != std::string::npos;
       at = text.find("```json\n", at + 1)) {
    const std::size_t begin = at + 8, end = text.find("```", begin);
    write(out / "edit_request", "doc" + std::to_string(k++) + ".json",
          text.substr(begin, end - begin));
  }
  const char* crafted[] = {
      R"({"k": 1, "solver": "ldlt", "areas": "mixed", "details": "displacement", "remesh": false,
          "base_smoothing": 1.5, "base_feature_cap": 0.5, "support": [0, 1, 2, 3, 4, 5],
          "handles": [{"region": {"vertices": [0]}, "transform": {"matrix": [[1, 0, 0, 0.1],
          [0, 1, 0, 0], [0, 0, 1, 0]]}}]})",
      R"({"support": {"union": [{"box": {"min": [-1, -1, 0], "max": [1, 1, 1]}},
          {"geodesic": {"vertex": 11, "radius": 0.3}}]}, "handles": [{"region": {"sphere":
          {"center": [0, 0, 1], "radius": 0.2}}, "transform": {"scale": {"factors": [1, 1, 1.5],
          "center": [0, 0, 1]}, "rotate": {"axis": [1, 0, 0], "degrees": 20, "center": [0, 0, 0]},
          "translate": [0, 0, 0.1]}}, {"region": [12, 10]}]})",
      R"({"k": 3, "details": "none", "support": {"vertices": [161, 160, 5]},
          "handles": [{"region": {"union": [[5], {"vertices": [160]}]}}]})",
      R"({"method": "nonlinear", "k": 2, "support": {"sphere": {"center": [0, 0, 1],
          "radius": 0.8}}, "handles": [{"region": {"sphere": {"center": [0, 0, 1], "radius":
          0.2}}, "transform": {"rotate": {"axis": [0, 1, 0], "degrees": 90}}}]})"};
  for (const char* c : crafted)
    write(out / "edit_request", "crafted" + std::to_string(k++) + ".json", c);
}

/// Request scripts on the server harness's fixture: an edit round trip, a bake and undo through
/// it, picks and views, a broken and a good upload, wrong methods and paths, the nonlinear method
/// with its relax steps.
void server_seeds(const fs::path& out) {
  using R = fuzz::ScriptRequest;
  const std::string fixture = fuzz::server_fixture_off();
  const Mesh m = read_mesh_from_memory(fixture, MeshFormat::Off, "sphere.off").mesh;
  std::vector<int> support, handle;
  for (const VertexHandle v : m.vertices()) {
    if (m.point(v)[2] > 0.2) support.push_back(v.idx());
    if (m.point(v)[2] > 0.9) handle.push_back(v.idx());
  }
  const std::string region =
      nlohmann::json{{"support", support}, {"handles", {handle}}, {"k", 2}}.dump();
  // The nonlinear region's support as ranges of consecutive ids, as the page sends it.
  nlohmann::json ranges = nlohmann::json::array();
  for (std::size_t i = 0; i < support.size();) {
    std::size_t j = i + 1;
    while (j < support.size() && support[j] == support[j - 1] + 1) ++j;
    ranges.push_back({support[i], j - i});
    i = j;
  }
  const std::string nonlinear = nlohmann::json{
      {"support", {{"ranges", ranges}}},
      {"handles", {handle}},
      {"k", 2},
      {"method", "nonlinear"}}.dump();
  const std::string lift = R"({"handle": 0, "matrix": [1,0,0,0,0,1,0,0,0,0,1,0.3]})";
  const std::string twist = R"({"handle": 0, "matrix": [0.9,-0.1,0,0,0.1,0.9,0,0,0,0,1.2,0.1]})";
  const std::string pick = R"({"origin": [0.1, 0.2, 3], "direction": [0, 0, -1], "radius": 0.3})";
  const std::vector<std::vector<R>> scripts = {
      {{"GET", "/api/status", {}, ""},
       {"POST", "/api/region", {}, region},
       {"GET", "/api/status", {{"wait", "100"}}, ""},
       {"POST", "/api/transform", {}, lift},
       {"POST", "/api/commit", {}, ""},
       {"POST", "/api/undo", {}, ""},
       {"POST", "/api/redo", {}, ""},
       {"GET", "/api/mesh/positions", {}, ""},
       {"GET", "/api/export", {{"format", "obj"}}, ""}},
      {{"POST", "/api/region", {}, region},
       {"POST", "/api/transform", {}, twist},
       {"POST", "/api/commit", {}, ""},
       {"POST", "/api/region", {}, region},
       {"POST", "/api/undo", {}, ""},
       {"POST", "/api/undo", {}, ""},
       {"POST", "/api/redo", {}, ""},
       {"GET", "/api/base/areas", {}, ""},
       {"GET", "/api/base/indices", {}, ""},
       {"GET", "/api/base/positions", {}, ""},
       {"GET", "/api/movable", {}, ""}},
      {{"POST", "/api/pick", {}, pick},
       {"POST",
        "/api/pick",
        {},
        R"({"origin": [0, 0, 3], "direction": [0, 0, -1], "radius": 0.5, "brush": "sphere"})"},
       {"GET", "/api/region", {}, ""},
       {"GET", "/api/mesh/indices", {}, ""},
       {"POST",
        "/api/region",
        {},
        nlohmann::json{{"support", support}, {"handles", {handle}}, {"k", 1}}.dump()},
       {"POST",
        "/api/region",
        {},
        nlohmann::json{{"support", support}, {"handles", {handle}}, {"k", 3}}.dump()}},
      {{"POST",
        "/api/load",
        {{"name", "broken.off"}},
        "OFF\n3 1 0\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n"},
       {"GET", "/api/status", {}, ""},
       {"POST", "/api/load", {{"name", "tet.obj"}}, obj(tetrahedron(), 0)},
       {"POST", "/api/region", {}, R"({"support": [0, 1, 2, 3], "handles": [[3]]})"},
       {"POST", "/api/transform", {}, lift},
       {"GET", "/api/export", {{"format", "stl"}}, ""}},
      {{"DELETE", "/api/status", {}, ""},
       {"PUT", "/api/region", {}, "{}"},
       {"GET", "/api/transform", {}, ""},
       {"GET", "/api/nowhere", {}, ""},
       {"POST", "/api/region", {}, R"({"support": [1, 2)"},
       {"POST", "/api/transform", {}, R"({"handle": 0, "matrix": [1e400]})"},
       {"GET", "/api/status", {{"wait", "soon"}}, ""},
       {"GET", "/api/export", {{"format", "doc"}}, ""}},
      {{"POST", "/api/region", {}, nonlinear},
       {"POST", "/api/transform", {}, twist},
       {"POST", "/api/relax", {}, R"({"budget_ms": 20})"},
       {"POST", "/api/relax", {}, ""},
       {"POST", "/api/relax", {}, R"({"budget_ms": 0})"},
       {"GET", "/api/relax", {}, ""},
       {"POST", "/api/region", {}, region},
       {"POST", "/api/undo", {}, ""},
       {"POST", "/api/region", {}, R"({"support": [1], "handles": [[1]], "method": "cubic"})"}}};
  int k = 0;
  for (const auto& script : scripts)
    write(out / "server", "script" + std::to_string(k++), fuzz::write_requests(script));
}

} // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: remora_fuzz_seeds OUT_DIR REPO_DIR\n");
    return 2;
  }
  const fs::path out = argv[1], repo = argv[2];
  try {
    mesh_seeds(out, {{"tetrahedron", tetrahedron()},
                     {"quads", quads()},
                     {"icosphere", normalized(make_icosphere(1, 1.0))},
                     {"bunny", bunny_patch(repo)}});
    edit_seeds(out, repo);
    server_seeds(out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "remora_fuzz_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
