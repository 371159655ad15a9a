#include "remora/multires/edit_request.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "remora/common/error.h"
#include "remora/geometry/selection.h"

namespace remora {
namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InvalidArgument(fmt::format("{}: {}", path, problem));
}

/// "a, b, c".
std::string listed(std::initializer_list<const char*> items) {
  std::string list;
  for (const char* item : items) list += std::string(list.empty() ? "" : ", ") + item;
  return list;
}

void only_keys(const json& j, const std::string& path, std::initializer_list<const char*> keys) {
  if (!j.is_object()) fail(path, "expected an object");
  for (const auto& item : j.items())
    if (std::none_of(keys.begin(), keys.end(), [&](const char* k) { return item.key() == k; }))
      fail(path, fmt::format("unknown key '{}' (allowed: {})", item.key(), listed(keys)));
}

double number(const json& j, const std::string& path) {
  if (!j.is_number()) fail(path, "expected a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) fail(path, "the number is not finite");
  return v;
}

int vertex_id(const json& j, const std::string& path) {
  if (!j.is_number_integer()) fail(path, "expected a vertex id (an integer)");
  const auto v = j.get<long long>();
  if (v < 0 || v > 2147483647LL) fail(path, fmt::format("vertex id {} is out of range", v));
  return static_cast<int>(v);
}

Eigen::Vector3d vec3(const json& j, const std::string& path) {
  if (!j.is_array() || j.size() != 3) fail(path, "expected an array of 3 numbers");
  return {number(j[0], path + "[0]"), number(j[1], path + "[1]"), number(j[2], path + "[2]")};
}

const json& member(const json& j, const std::string& path, const char* key) {
  if (!j.contains(key)) fail(path, fmt::format("missing '{}'", key));
  return j.at(key);
}

/// The "radius" of a sphere or geodesic region at `path`: a number >= 0.
double radius(const json& j, const std::string& path) {
  const double r = number(member(j, path, "radius"), path + ".radius");
  if (r < 0) fail(path + ".radius", "must be >= 0");
  return r;
}

std::vector<int> id_list(const json& j, const std::string& path) {
  if (!j.is_array()) fail(path, "expected an array of vertex ids");
  std::vector<int> ids;
  ids.reserve(j.size());
  for (std::size_t i = 0; i < j.size(); ++i)
    ids.push_back(vertex_id(j[i], fmt::format("{}[{}]", path, i)));
  return ids;
}

std::string name(const json& j, const std::string& path,
                 std::initializer_list<const char*> allowed) {
  if (!j.is_string()) fail(path, "expected a string");
  const auto s = j.get<std::string>();
  if (allowed.size() > 0 &&
      std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return s == a; }))
    fail(path, fmt::format("unknown value '{}' (allowed: {})", s, listed(allowed)));
  return s;
}

/// Unions nest at most this deep: the parse and the selection recurse once per level, and a
/// file of nested unions must not overflow the stack.
constexpr int kMaxUnionDepth = 32;

RegionSpec parse_region_at(const json& j, const std::string& path, int depth) {
  RegionSpec r;
  if (j.is_array()) {
    r.kind = RegionSpec::Kind::Vertices;
    r.vertices = id_list(j, path);
    return r;
  }
  only_keys(j, path, {"vertices", "sphere", "box", "geodesic", "union"});
  if (j.size() != 1) fail(path, "expected exactly one of vertices, sphere, box, geodesic, union");
  const auto first = j.begin();
  const std::string key = first.key();
  const json& value = first.value();
  const std::string sub = path + "." + key;
  if (key == "vertices") {
    r.kind = RegionSpec::Kind::Vertices;
    r.vertices = id_list(value, sub);
  } else if (key == "sphere") {
    only_keys(value, sub, {"center", "radius"});
    r.kind = RegionSpec::Kind::Sphere;
    r.center = vec3(member(value, sub, "center"), sub + ".center");
    r.radius = radius(value, sub);
  } else if (key == "box") {
    only_keys(value, sub, {"min", "max"});
    r.kind = RegionSpec::Kind::Box;
    r.min = vec3(member(value, sub, "min"), sub + ".min");
    r.max = vec3(member(value, sub, "max"), sub + ".max");
    for (int c = 0; c < 3; ++c)
      if (r.min[c] > r.max[c]) fail(sub, "min exceeds max; give the lower corner as min");
  } else if (key == "geodesic") {
    only_keys(value, sub, {"vertex", "radius"});
    r.kind = RegionSpec::Kind::Geodesic;
    r.vertex = vertex_id(member(value, sub, "vertex"), sub + ".vertex");
    r.radius = radius(value, sub);
  } else {
    r.kind = RegionSpec::Kind::Union;
    if (!value.is_array() || value.empty()) fail(sub, "expected a non-empty array of regions");
    if (depth >= kMaxUnionDepth)
      fail(sub, fmt::format("unions nested more than {} deep", kMaxUnionDepth));
    for (std::size_t i = 0; i < value.size(); ++i)
      r.parts.push_back(parse_region_at(value[i], fmt::format("{}[{}]", sub, i), depth + 1));
  }
  return r;
}

} // namespace

RegionSpec parse_region(const json& j, const std::string& path) {
  return parse_region_at(j, path, 0);
}

TransformSpec parse_transform(const json& j, const std::string& path) {
  TransformSpec t;
  only_keys(j, path, {"matrix", "scale", "rotate", "translate"});
  if (j.contains("matrix")) {
    if (j.size() != 1) fail(path, "'matrix' cannot be combined with scale, rotate or translate");
    const json& m = j.at("matrix");
    const std::string sub = path + ".matrix";
    if (!m.is_array() || m.size() != 3) fail(sub, "expected 3 rows of 4 numbers");
    Transform matrix;
    for (int r = 0; r < 3; ++r) {
      const json& row = m[static_cast<std::size_t>(r)];
      if (!row.is_array() || row.size() != 4) fail(sub, "expected 3 rows of 4 numbers");
      for (int c = 0; c < 4; ++c)
        matrix(r, c) =
            number(row[static_cast<std::size_t>(c)], fmt::format("{}[{}][{}]", sub, r, c));
    }
    if (!(matrix.leftCols<3>().determinant() > 0.0))
      fail(sub, "the linear part mirrors or collapses the handle (det <= 0)");
    t.matrix = matrix;
    return t;
  }
  if (j.contains("scale")) {
    const json& s = j.at("scale");
    const std::string sub = path + ".scale";
    only_keys(s, sub, {"factors", "center"});
    t.scale = vec3(member(s, sub, "factors"), sub + ".factors");
    if (!(t.scale->minCoeff() > 0.0))
      fail(sub + ".factors", "must be > 0 on every axis (0 collapses the handle, < 0 mirrors it)");
    if (s.contains("center")) t.scale_center = vec3(s.at("center"), sub + ".center");
  }
  if (j.contains("rotate")) {
    const json& r = j.at("rotate");
    const std::string sub = path + ".rotate";
    only_keys(r, sub, {"axis", "degrees", "center"});
    t.rotate_axis = vec3(member(r, sub, "axis"), sub + ".axis");
    if (!(t.rotate_axis->norm() > 0)) fail(sub + ".axis", "must not be zero");
    t.rotate_degrees = number(member(r, sub, "degrees"), sub + ".degrees");
    if (r.contains("center")) t.rotate_center = vec3(r.at("center"), sub + ".center");
  }
  if (j.contains("translate")) t.translate = vec3(j.at("translate"), path + ".translate");
  return t;
}

EditRequest parse_edit_request(const json& j) {
  EditRequest r;
  only_keys(j, "edit",
            {"k", "solver", "areas", "details", "method", "energy", "remesh", "refine_support",
             "base_smoothing", "base_feature_cap", "support", "handles"});
  if (j.contains("k")) {
    if (!j.at("k").is_number_integer()) fail("edit.k", "expected 1, 2 or 3");
    r.k = j.at("k").get<int>();
    if (*r.k < 1 || *r.k > 3) fail("edit.k", fmt::format("{} is not 1, 2 or 3", *r.k));
  }
  if (j.contains("solver")) r.solver = name(j.at("solver"), "edit.solver", {});
  if (j.contains("areas"))
    r.areas = name(j.at("areas"), "edit.areas", {"mean", "mixed", "mixed-symmetric"});
  if (j.contains("details"))
    r.details = name(j.at("details"), "edit.details", {"normal", "displacement", "none"});
  if (j.contains("method")) r.method = name(j.at("method"), "edit.method", {"linear", "nonlinear"});
  if (j.contains("energy")) {
    r.energy = name(j.at("energy"), "edit.energy", {});
    try {
      parse_nonlinear_energy(*r.energy);
    } catch (const InvalidArgument& e) {
      fail("edit.energy", e.what());
    }
  }
  if (j.contains("remesh")) {
    if (!j.at("remesh").is_boolean()) fail("edit.remesh", "expected true or false");
    r.remesh = j.at("remesh").get<bool>();
  }
  if (j.contains("refine_support")) {
    if (!j.at("refine_support").is_boolean()) fail("edit.refine_support", "expected true or false");
    r.refine_support = j.at("refine_support").get<bool>();
  }
  if (j.contains("base_smoothing")) {
    r.base_smoothing = number(j.at("base_smoothing"), "edit.base_smoothing");
    if (*r.base_smoothing < 0) fail("edit.base_smoothing", "must be >= 0");
  }
  if (j.contains("base_feature_cap")) {
    r.base_feature_cap = number(j.at("base_feature_cap"), "edit.base_feature_cap");
    if (*r.base_feature_cap < 0) fail("edit.base_feature_cap", "must be >= 0");
  }
  r.support = parse_region(member(j, "edit", "support"), "edit.support");
  const json& handles = member(j, "edit", "handles");
  if (!handles.is_array() || handles.empty())
    fail("edit.handles", "expected a non-empty array of handles");
  for (std::size_t i = 0; i < handles.size(); ++i) {
    const std::string path = fmt::format("edit.handles[{}]", i);
    only_keys(handles[i], path, {"region", "transform"});
    HandleSpec h;
    h.region = parse_region(member(handles[i], path, "region"), path + ".region");
    if (handles[i].contains("transform"))
      h.transform = parse_transform(handles[i].at("transform"), path + ".transform");
    r.handles.push_back(std::move(h));
  }
  return r;
}

std::vector<int> select_region(const Mesh& mesh, const RegionSpec& r) {
  const auto n = static_cast<int>(mesh.n_vertices());
  std::vector<int> out;
  const auto v3 = [](const Eigen::Vector3d& p) { return Vec3(p[0], p[1], p[2]); };
  switch (r.kind) {
  case RegionSpec::Kind::Vertices:
    for (const int v : r.vertices)
      if (v < 0 || v >= n)
        throw InvalidArgument(
            fmt::format("vertex {} is out of range: the mesh has {} vertices", v, n));
    out = r.vertices;
    break;
  case RegionSpec::Kind::Sphere:
    out = select_sphere(mesh, v3(r.center), r.radius);
    break;
  case RegionSpec::Kind::Box:
    out = select_box(mesh, v3(r.min), v3(r.max));
    break;
  case RegionSpec::Kind::Geodesic:
    if (r.vertex < 0 || r.vertex >= n)
      throw InvalidArgument(fmt::format(
          "geodesic region: vertex {} is out of range: the mesh has {} vertices", r.vertex, n));
    out = select_geodesic_disc(mesh, VertexHandle(r.vertex), r.radius);
    break;
  case RegionSpec::Kind::Union:
    for (const RegionSpec& part : r.parts) {
      const std::vector<int> p = select_region(mesh, part);
      out.insert(out.end(), p.begin(), p.end());
    }
    break;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void map_file_vertex_ids(RegionSpec& region, const std::vector<std::uint32_t>& source_vertex) {
  // file id -> loaded ids, as a sorted list of (file id, loaded id).
  std::vector<std::pair<std::uint32_t, int>> pairs(source_vertex.size());
  for (std::size_t v = 0; v < source_vertex.size(); ++v)
    pairs[v] = {source_vertex[v], static_cast<int>(v)};
  std::sort(pairs.begin(), pairs.end());
  const auto copies = [&](int id) {
    const auto lo = std::lower_bound(pairs.begin(), pairs.end(),
                                     std::make_pair(static_cast<std::uint32_t>(id), -1));
    std::vector<int> out;
    for (auto it = lo; it != pairs.end() && it->first == static_cast<std::uint32_t>(id); ++it)
      out.push_back(it->second);
    if (out.empty())
      throw InvalidArgument(fmt::format(
          "vertex {} of the file is not part of the loaded mesh (an unreferenced vertex the "
          "loader dropped, or an id beyond the file's vertices; `remora info` lists what loading "
          "changed)",
          id));
    return out;
  };
  switch (region.kind) {
  case RegionSpec::Kind::Vertices: {
    std::vector<int> mapped;
    for (const int id : region.vertices) {
      const auto c = copies(id);
      mapped.insert(mapped.end(), c.begin(), c.end());
    }
    region.vertices = std::move(mapped);
    break;
  }
  case RegionSpec::Kind::Geodesic:
    region.vertex = copies(region.vertex).front();
    break;
  case RegionSpec::Kind::Union:
    for (RegionSpec& part : region.parts) map_file_vertex_ids(part, source_vertex);
    break;
  default:
    break;
  }
}

Transform resolve_transform(const TransformSpec& spec, const Eigen::Vector3d& center) {
  if (spec.matrix) return *spec.matrix;
  Transform t = identity_transform();
  if (spec.scale) t = compose(scaling(*spec.scale, spec.scale_center.value_or(center)), t);
  if (spec.rotate_axis)
    t = compose(rotation(*spec.rotate_axis, spec.rotate_degrees * 3.14159265358979323846 / 180.0,
                         spec.rotate_center.value_or(center)),
                t);
  if (spec.translate) t = compose(translation(*spec.translate), t);
  return t;
}

void apply_request_options(const EditRequest& r, EditorOptions& o) {
  if (r.k) o.system.k = *r.k;
  if (r.solver) o.solver.name = *r.solver;
  if (r.areas) o.system.areas = parse_area_weights(*r.areas);
  if (r.details) o.details = parse_detail_mode(*r.details);
  if (r.method) o.method = parse_edit_method(*r.method);
  if (r.energy) o.nonlinear.energy = parse_nonlinear_energy(*r.energy);
  if (r.remesh) o.remesh = *r.remesh;
  if (r.base_smoothing) o.base.smoothing = *r.base_smoothing;
  if (r.base_feature_cap) o.base.feature_cap = *r.base_feature_cap;
}

} // namespace remora
