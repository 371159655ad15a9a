#include "convert.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "remora/common/json.h"
#include "remora/mesh/build.h"

namespace remora::python {

namespace {

std::string shape_text(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) text += fmt::format("{}{}", d ? ", " : "", a.shape(d));
  return text + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtype_text(const py::array& a) {
  return py::str(a.dtype());
}

/// `value` as a numpy array (np.asarray), or InvalidArgument naming `name`.
py::array as_array(const py::handle& value, const char* name) {
  if (py::isinstance<py::array>(value)) return py::reinterpret_borrow<py::array>(value);
  if (value.is_none()) throw InvalidArgument(fmt::format("{}: expected an array, got None", name));
  py::array a = py::array::ensure(value);
  if (!a) // ensure() clears the Python error (a ragged list, an object numpy cannot convert)
    throw InvalidArgument(fmt::format("{}: expected an array of numbers, got a {} that numpy "
                                      "cannot convert",
                                      name,
                                      std::string(py::str(value.get_type().attr("__name__")))));
  return a;
}

/// A C-contiguous copy-if-needed of `a` as T (a dtype the caller has checked).
template <class T>
py::array_t<T, py::array::c_style | py::array::forcecast> contiguous(const py::array& a) {
  return py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
}

void check_rows_of_three(const py::array& a, const char* name, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw InvalidArgument(
        fmt::format("{}: expected an (n, 3) array of {}, got shape {}", name, what, shape_text(a)));
}

bool is_integer_kind(char kind) {
  return kind == 'i' || kind == 'u';
}

} // namespace

std::vector<Vec3> points_arg(const py::handle& value, const char* name) {
  const py::array a = as_array(value, name);
  check_rows_of_three(a, name, "vertex positions");
  if (a.dtype().kind() != 'f')
    throw InvalidArgument(fmt::format("{}: expected floating-point coordinates (float64), got "
                                      "dtype {}; convert with np.asarray({}, dtype=np.float64)",
                                      name, dtype_text(a), name));
  const auto d = contiguous<double>(a);
  const std::size_t n = static_cast<std::size_t>(d.shape(0));
  const double* p = d.data();
  std::vector<Vec3> points(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* row = p + 3 * i;
    if (!std::isfinite(row[0]) || !std::isfinite(row[1]) || !std::isfinite(row[2]))
      throw InvalidArgument(fmt::format("{}: row {} has a non-finite coordinate ({}, {}, {})", name,
                                        i, row[0], row[1], row[2]));
    points[i] = Vec3(row[0], row[1], row[2]);
  }
  return points;
}

std::vector<std::array<std::uint32_t, 3>> faces_arg(const py::handle& value, const char* name,
                                                    std::size_t n_vertices) {
  const py::array a = as_array(value, name);
  check_rows_of_three(a, name, "vertex ids (triangles)");
  if (!is_integer_kind(a.dtype().kind()) && a.size() > 0)
    throw InvalidArgument(fmt::format("{}: expected integer vertex ids, got dtype {}; convert with "
                                      "np.asarray({}, dtype=np.int64)",
                                      name, dtype_text(a), name));
  const auto d = contiguous<std::int64_t>(a);
  const std::size_t m = static_cast<std::size_t>(d.shape(0));
  const std::int64_t* p = d.data();
  std::vector<std::array<std::uint32_t, 3>> faces(m);
  for (std::size_t f = 0; f < m; ++f)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::int64_t id = p[3 * f + k];
      if (id < 0 || static_cast<std::uint64_t>(id) >= n_vertices)
        throw InvalidArgument(fmt::format("{}: row {} has vertex id {}, outside [0, {}) (ids are "
                                          "zero-based rows of the vertex array)",
                                          name, f, id, n_vertices));
      faces[f][k] = static_cast<std::uint32_t>(id);
    }
  return faces;
}

Mesh mesh_arg(const py::handle& vertices, const py::handle& faces) {
  const std::vector<Vec3> points = points_arg(vertices, "V");
  const auto triangles = faces_arg(faces, "F", points.size());
  try {
    return build_mesh(points, triangles);
  } catch (const InvalidArgument& e) {
    std::string problem = e.what();
    const std::string prefix = "build_mesh: ";
    if (problem.rfind(prefix, 0) == 0) problem.erase(0, prefix.size());
    throw InvalidArgument(fmt::format("F: {}; remora.repair(V, F) welds, orients and splits such "
                                      "a triangle soup into a manifold mesh",
                                      problem));
  }
}

Mesh points_mesh_arg(const py::handle& vertices, const char* name) {
  return build_mesh(points_arg(vertices, name), {});
}

std::vector<int> indices_arg(const py::handle& value, const char* name, std::size_t n,
                             bool allow_empty) {
  const py::array a = as_array(value, name);
  std::vector<int> ids;
  const char kind = a.dtype().kind();
  if (kind == 'b') {
    if (a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != n)
      throw InvalidArgument(fmt::format("{}: a boolean mask needs one entry per vertex ({}), got "
                                        "shape {}",
                                        name, n, shape_text(a)));
    const auto d = contiguous<bool>(a);
    for (std::size_t i = 0; i < n; ++i)
      if (d.data()[i]) ids.push_back(static_cast<int>(i));
  } else if (a.size() > 0) {
    if (!is_integer_kind(kind))
      throw InvalidArgument(fmt::format("{}: expected vertex ids (integers) or a boolean mask, "
                                        "got dtype {}",
                                        name, dtype_text(a)));
    if (a.ndim() > 1)
      throw InvalidArgument(
          fmt::format("{}: expected a 1-D array of vertex ids, got shape {}", name, shape_text(a)));
    const auto d = contiguous<std::int64_t>(a);
    ids.reserve(static_cast<std::size_t>(d.size()));
    for (py::ssize_t i = 0; i < d.size(); ++i) {
      const std::int64_t id = d.data()[i];
      if (id < 0)
        throw InvalidArgument(fmt::format("{}: vertex id {} is negative (ids are zero-based; "
                                          "negative indexing does not apply)",
                                          name, id));
      if (static_cast<std::uint64_t>(id) >= n)
        throw InvalidArgument(fmt::format("{}: vertex id {} is out of range: the mesh has {} "
                                          "vertices",
                                          name, id, n));
      ids.push_back(static_cast<int>(id));
    }
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  }
  if (ids.empty() && !allow_empty)
    throw InvalidArgument(fmt::format("{}: selects no vertex", name));
  return ids;
}

Eigen::Vector3d vector3_arg(const py::handle& value, const char* name) {
  const py::array a = as_array(value, name);
  if (a.size() != 3 || a.ndim() != 1 ||
      !(is_integer_kind(a.dtype().kind()) || a.dtype().kind() == 'f'))
    throw InvalidArgument(fmt::format("{}: expected three numbers, got an array of shape {} and "
                                      "dtype {}",
                                      name, shape_text(a), dtype_text(a)));
  const auto d = contiguous<double>(a);
  const Eigen::Vector3d v(d.data()[0], d.data()[1], d.data()[2]);
  if (!v.allFinite())
    throw InvalidArgument(fmt::format("{}: ({}, {}, {}) is not finite", name, v[0], v[1], v[2]));
  return v;
}

double real_arg(const py::handle& value, const char* name) {
  double x = 0.0;
  try {
    x = option_real(value);
  } catch (const std::invalid_argument& e) {
    throw InvalidArgument(fmt::format("{}: {}", name, e.what()));
  }
  if (!std::isfinite(x)) throw InvalidArgument(fmt::format("{}: {} is not finite", name, x));
  return x;
}

py::array_t<double> vertices_array(const Mesh& mesh) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "OpenMesh points are three packed doubles");
  const std::size_t n = mesh.n_vertices();
  py::array_t<double> out({static_cast<py::ssize_t>(n), py::ssize_t(3)});
  if (n > 0) std::memcpy(out.mutable_data(), mesh.points(), n * sizeof(Vec3));
  return out;
}

py::array_t<std::int64_t> faces_array(const Mesh& mesh) {
  const std::size_t m = mesh.n_faces();
  py::array_t<std::int64_t> out({static_cast<py::ssize_t>(m), py::ssize_t(3)});
  std::int64_t* p = out.mutable_data();
  for (std::size_t f = 0; f < m; ++f) {
    const auto corners = face_vertices(mesh, FaceHandle(static_cast<int>(f)));
    for (std::size_t k = 0; k < 3; ++k) p[3 * f + k] = corners[k].idx();
  }
  return out;
}

py::array_t<double> rows_array(const Eigen::MatrixXd& rows) {
  const Eigen::Index n = rows.rows();
  py::array_t<double> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(rows.cols())});
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      out.mutable_data(), n, rows.cols()) = rows;
  return out;
}

py::tuple surface_points_array(const std::vector<SurfacePoint>& points) {
  const auto n = static_cast<py::ssize_t>(points.size());
  py::array_t<std::int64_t> faces(n);
  py::array_t<double> bary({n, py::ssize_t(3)});
  std::int64_t* f = faces.mutable_data();
  double* b = bary.mutable_data();
  for (std::size_t i = 0; i < points.size(); ++i) {
    f[i] = points[i].face.is_valid() ? points[i].face.idx() : -1;
    for (std::size_t k = 0; k < 3; ++k) b[3 * i + k] = points[i].bary[k];
  }
  return py::make_tuple(faces, bary);
}

py::object json_to_python(const nlohmann::json& value) {
  return py::module_::import("json").attr("loads")(dump_json(value));
}

namespace {

// Holds a Python callable for library callbacks: copies share it without touching Python
// reference counts, and the last one lets it go with the GIL.
struct PythonCallable {
  py::object function;
  PythonCallable() = default;
  PythonCallable(const PythonCallable&) = delete;
  PythonCallable& operator=(const PythonCallable&) = delete;
  ~PythonCallable() {
    if (!function) return;
    py::gil_scoped_acquire gil;
    function = py::object();
  }
};

} // namespace

std::function<void(std::string_view, int, int)> progress_arg(const py::handle& callback) {
  auto holder = std::make_shared<PythonCallable>();
  if (!callback.is_none()) {
    if (!PyCallable_Check(callback.ptr()))
      throw std::invalid_argument("expected a callable f(phase, step, steps) or None");
    holder->function = py::reinterpret_borrow<py::object>(callback);
  }
  return [holder](std::string_view phase, int step, int steps) {
    py::gil_scoped_acquire gil;
    if (holder->function) holder->function(std::string(phase), step, steps);
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  };
}

double option_real(const py::handle& value) {
  if (PyBool_Check(value.ptr()) || PyUnicode_Check(value.ptr()) || !PyNumber_Check(value.ptr()))
    throw std::invalid_argument(fmt::format(
        "expected a number, got {}", std::string(py::str(value.get_type().attr("__name__")))));
  return py::cast<double>(value);
}

int option_int(const py::handle& value) {
  if (PyBool_Check(value.ptr()) || !PyIndex_Check(value.ptr()))
    throw std::invalid_argument(
        fmt::format("expected an integer, got {}", std::string(py::str(py::repr(value)))));
  const long long x = py::cast<long long>(value);
  if (x < std::numeric_limits<int>::min() || x > std::numeric_limits<int>::max())
    throw std::invalid_argument(fmt::format("{} is out of range", x));
  return static_cast<int>(x);
}

bool option_bool(const py::handle& value) {
  const std::string type = py::str(value.get_type().attr("__name__"));
  if (!PyBool_Check(value.ptr()) && type != "bool_")
    throw std::invalid_argument(
        fmt::format("expected True or False, got {}", std::string(py::str(py::repr(value)))));
  return PyObject_IsTrue(value.ptr()) == 1;
}

std::string option_string(const py::handle& value) {
  if (!PyUnicode_Check(value.ptr()))
    throw std::invalid_argument(
        fmt::format("expected a string, got {}", std::string(py::str(py::repr(value)))));
  return py::str(value);
}

void bad_option(const char* what, const std::string& name, const std::string& problem) {
  throw InvalidArgument(fmt::format("{}: option {}: {}", what, name, problem));
}

void unknown_option(const char* what, const std::string& name,
                    const std::vector<std::string>& known) {
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  throw InvalidArgument(fmt::format("{}: unknown option '{}' (options: {})", what, name, list));
}

} // namespace remora::python
