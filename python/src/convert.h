// The Python module's edge: numpy arrays and Python values to the library's types and back,
// with every check a caller from Python needs (the library assumes well-formed meshes).
//
// Arrays in: vertices are (n, 3) of a floating-point dtype, finite; faces (m, 3) of an integer
// dtype with ids in [0, n); index lists are 1-D integer arrays (ids in [0, n)) or boolean masks of
// length n. Any array-like (lists, tuples) is accepted. Every problem throws InvalidArgument
// (ValueError in Python) whose message starts with the argument's name.
// Arrays out: vertices (n, 3) float64 and faces (m, 3) int64, C-contiguous, one copy from the
// library's storage. A face's corners are face_vertices() (mesh/surface_point.h), so barycentric
// coordinates of a SurfacePoint weigh F[face, 0], F[face, 1], F[face, 2] in that order, and arrays
// -> mesh -> arrays gives the same arrays back.
//
// Functions that take py:: objects must be called with the GIL held.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "remora/common/error.h"
#include "remora/mesh/mesh.h"
#include "remora/mesh/surface_point.h"

namespace remora::python {

namespace py = pybind11;

/// Vertex positions of an (n, 3) array-like: floating point and finite.
std::vector<Vec3> points_arg(const py::handle& value, const char* name);
/// Triangles of an (m, 3) array-like of integers, each id in [0, n_vertices).
std::vector<std::array<std::uint32_t, 3>> faces_arg(const py::handle& value, const char* name,
                                                    std::size_t n_vertices);
/// A half-edge mesh from V and F (build_mesh()); InvalidArgument names the arguments, and for a
/// non-manifold or inconsistently oriented F says to call remora.repair(V, F) first.
Mesh mesh_arg(const py::handle& vertices, const py::handle& faces);
/// A mesh of isolated vertices (for the selections that need only positions).
Mesh points_mesh_arg(const py::handle& vertices, const char* name);
/// Sorted vertex ids from an index array or a boolean mask over `n` vertices; `allow_empty`
/// false throws for an empty selection.
std::vector<int> indices_arg(const py::handle& value, const char* name, std::size_t n,
                             bool allow_empty);
/// A vector of three finite numbers.
Eigen::Vector3d vector3_arg(const py::handle& value, const char* name);
/// A finite number.
double real_arg(const py::handle& value, const char* name);

py::array_t<double> vertices_array(const Mesh& mesh);
py::array_t<std::int64_t> faces_array(const Mesh& mesh);
/// An (n, 3) float64 array from an n × 3 Eigen matrix.
py::array_t<double> rows_array(const Eigen::MatrixXd& rows);
/// Surface points as (face ids (n,) int64, -1 for none; barycentric coordinates (n, 3)).
py::tuple surface_points_array(const std::vector<SurfacePoint>& points);
/// A JSON value as Python dicts, lists, numbers, strings, booleans and None.
py::object json_to_python(const nlohmann::json& value);

/// A progress callback for the library's options: calls `callback` (a Python callable taking
/// (phase, step, steps), or None) with the GIL, then checks for Ctrl+C; a Python exception from
/// either stops the library call and reaches the caller. Safe to copy and call without the GIL.
std::function<void(std::string_view, int, int)> progress_arg(const py::handle& callback);

/// Options given as keyword arguments, by name: each setter reads one Python value into the
/// options struct and throws InvalidArgument (or py::cast_error) for a wrong type or value.
template <class Options>
using OptionSetters = std::map<std::string, std::function<void(Options&, const py::handle&)>>;

/// Applies every entry of `kwargs`; an unknown name, or a value its setter refuses, throws
/// InvalidArgument naming `what`, the option and (for unknown ones) the options known.
template <class Options>
void apply_options(const char* what, const py::dict& kwargs, const OptionSetters<Options>& setters,
                   Options& options);

// Readers of one option value, for the setters: type-checked (a bool is not a number, a float
// is not an integer).
double option_real(const py::handle& value);
int option_int(const py::handle& value);
bool option_bool(const py::handle& value);
std::string option_string(const py::handle& value);

/// Setters of one field of an options struct: {"cycles", int_field(&RemeshOptions::cycles)}.
template <class O, class T>
auto real_field(T O::*member) {
  return [member](O& o, const py::handle& v) { o.*member = option_real(v); };
}
template <class O, class T>
auto int_field(T O::*member) {
  return [member](O& o, const py::handle& v) { o.*member = option_int(v); };
}
template <class O, class T>
auto bool_field(T O::*member) {
  return [member](O& o, const py::handle& v) { o.*member = option_bool(v); };
}
template <class O, class T>
auto string_field(T O::*member) {
  return [member](O& o, const py::handle& v) { o.*member = option_string(v); };
}

/// The message for an option a setter refused (what: option: problem).
[[noreturn]] void bad_option(const char* what, const std::string& name, const std::string& problem);
[[noreturn]] void unknown_option(const char* what, const std::string& name,
                                 const std::vector<std::string>& known);

template <class Options>
void apply_options(const char* what, const py::dict& kwargs, const OptionSetters<Options>& setters,
                   Options& options) {
  for (const auto& item : kwargs) {
    const std::string name = py::str(item.first);
    const auto it = setters.find(name);
    if (it == setters.end()) {
      std::vector<std::string> known;
      for (const auto& entry : setters) known.push_back(entry.first);
      unknown_option(what, name, known);
    }
    try {
      it->second(options, item.second);
    } catch (const py::cast_error& e) {
      bad_option(what, name, e.what());
    } catch (const std::invalid_argument& e) {
      bad_option(what, name, e.what());
    } catch (const InvalidArgument& e) {
      bad_option(what, name, e.what());
    }
  }
}

} // namespace remora::python
