// Meshes in and out of files, the soup repair, the quality figures, the vertex selections and the
// refinement of a region (mesh/io.h, mesh/repair.h, geometry/quality.h, geometry/selection.h,
// mesh/refine.h). The Python package
// (python/remora/) documents every function.
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bindings.h"
#include "convert.h"
#include "remora/common/memory.h"
#include "remora/geometry/quality.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/io.h"
#include "remora/mesh/refine.h"
#include "remora/mesh/repair.h"

namespace remora::python {

namespace {

py::array_t<std::int64_t> ids_array(const std::vector<int>& ids) {
  py::array_t<std::int64_t> out(static_cast<py::ssize_t>(ids.size()));
  std::int64_t* p = out.mutable_data();
  for (std::size_t i = 0; i < ids.size(); ++i) p[i] = ids[i];
  return out;
}

py::tuple read(const std::string& path) {
  LoadResult loaded;
  {
    py::gil_scoped_release release;
    loaded = read_mesh(path);
  }
  return py::make_tuple(vertices_array(loaded.mesh), faces_array(loaded.mesh),
                        json_to_python(to_json(loaded.report)));
}

void write(const std::string& path, const py::handle& vertices, const py::handle& faces,
           bool binary) {
  const Mesh mesh = mesh_arg(vertices, faces);
  WriteOptions options;
  options.binary = binary;
  py::gil_scoped_release release;
  write_mesh(path, mesh, options);
}

const OptionSetters<RepairOptions>& repair_setters() {
  using O = RepairOptions;
  static const OptionSetters<O> setters = {
      {"weld", bool_field(&O::weld)},
      {"weld_tolerance", real_field(&O::weld_tolerance)},
      {"orient", bool_field(&O::orient)},
      {"outward", bool_field(&O::outward)},
  };
  return setters;
}

py::tuple repair(const py::handle& vertices, const py::handle& faces, const py::dict& kwargs) {
  RepairOptions options;
  apply_options("repair", kwargs, repair_setters(), options);
  PolygonSoup soup;
  soup.points = points_arg(vertices, "V");
  const auto triangles = faces_arg(faces, "F", soup.points.size());
  soup.indices.reserve(3 * triangles.size());
  soup.offsets.reserve(triangles.size() + 1);
  for (const auto& t : triangles) soup.add_triangle(t[0], t[1], t[2]);
  RepairResult result;
  {
    py::gil_scoped_release release;
    result = repair_soup(soup, options);
  }
  py::array_t<std::int64_t> source(static_cast<py::ssize_t>(result.source_vertex.size()));
  for (std::size_t i = 0; i < result.source_vertex.size(); ++i)
    source.mutable_data()[i] = result.source_vertex[i];
  return py::make_tuple(vertices_array(result.mesh), faces_array(result.mesh),
                        json_to_python(to_json(result.report)), source);
}

py::object quality(const py::handle& vertices, const py::handle& faces) {
  const Mesh mesh = mesh_arg(vertices, faces);
  MeshQuality q;
  {
    py::gil_scoped_release release;
    q = mesh_quality(mesh);
  }
  return json_to_python(to_json(q));
}

Vec3 vec3(const Eigen::Vector3d& v) {
  return Vec3(v[0], v[1], v[2]);
}

py::array_t<std::int64_t> sphere(const py::handle& vertices, const py::handle& center,
                                 const py::handle& radius) {
  const Mesh mesh = points_mesh_arg(vertices, "V");
  return ids_array(
      select_sphere(mesh, vec3(vector3_arg(center, "center")), real_arg(radius, "radius")));
}

py::array_t<std::int64_t> box(const py::handle& vertices, const py::handle& lo,
                              const py::handle& hi) {
  const Mesh mesh = points_mesh_arg(vertices, "V");
  return ids_array(
      select_box(mesh, vec3(vector3_arg(lo, "lower")), vec3(vector3_arg(hi, "upper"))));
}

py::array_t<std::int64_t> geodesic_disc(const py::handle& vertices, const py::handle& faces,
                                        const py::handle& seed, const py::handle& radius) {
  const Mesh mesh = mesh_arg(vertices, faces);
  const std::vector<int> s = indices_arg(seed, "seed", mesh.n_vertices(), false);
  if (s.size() != 1) throw InvalidArgument("seed: expected one vertex id");
  const double r = real_arg(radius, "radius");
  std::vector<int> ids;
  {
    py::gil_scoped_release release;
    ids = select_geodesic_disc(mesh, VertexHandle(s[0]), r);
  }
  return ids_array(ids);
}

py::tuple refine(const py::handle& vertices, const py::handle& faces, const py::handle& region,
                 const py::handle& max_length, const py::handle& max_vertices) {
  Mesh mesh = mesh_arg(vertices, faces);
  const std::vector<int> ids = indices_arg(region, "region", mesh.n_vertices(), true);
  const double length = real_arg(max_length, "max_length");
  if (!(length > 0)) throw InvalidArgument(fmt::format("max_length: must be > 0, not {}", length));
  std::size_t limit = std::numeric_limits<std::size_t>::max();
  if (!max_vertices.is_none()) {
    const double wanted = real_arg(max_vertices, "max_vertices");
    if (!(wanted >= 0) || wanted != std::floor(wanted))
      throw InvalidArgument("max_vertices: expected a whole number >= 0, or None");
    limit = static_cast<std::size_t>(wanted);
  }
  RefineResult r;
  {
    py::gil_scoped_release release;
    r = refine_region(mesh, ids, length, limit);
  }
  return py::make_tuple(vertices_array(mesh), faces_array(mesh), ids_array(r.region), r.added);
}

int nearest(const py::handle& vertices, const py::handle& point) {
  const Mesh mesh = points_mesh_arg(vertices, "V");
  return nearest_vertex(mesh, vec3(vector3_arg(point, "point"))).idx();
}

} // namespace

void bind_mesh(py::module_& m) {
  m.def("read_mesh", &read, py::arg("path"));
  m.def("write_mesh", &write, py::arg("path"), py::arg("V"), py::arg("F"), py::arg("binary"));
  m.def("repair", &repair, py::arg("V"), py::arg("F"), py::arg("options"));
  m.def("quality", &quality, py::arg("V"), py::arg("F"));
  m.def("select_sphere", &sphere, py::arg("V"), py::arg("center"), py::arg("radius"));
  m.def("select_box", &box, py::arg("V"), py::arg("lower"), py::arg("upper"));
  m.def("select_geodesic_disc", &geodesic_disc, py::arg("V"), py::arg("F"), py::arg("seed"),
        py::arg("radius"));
  m.def("nearest_vertex", &nearest, py::arg("V"), py::arg("point"));
  m.def("refine_region", &refine, py::arg("V"), py::arg("F"), py::arg("region"),
        py::arg("max_length"), py::arg("max_vertices"));
  m.def("keep_freed_memory", &keep_freed_memory);
}

} // namespace remora::python
