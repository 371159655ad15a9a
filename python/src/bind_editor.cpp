// The multiresolution editor (multires/editor.h, paper §3 and Fig. 3) and the handle transforms
// of EDIT.json (multires/edit_request.h). The Python package (python/remora/) documents both.
//
// Every call into the editor runs without the GIL and under the editor's own mutex (so that two
// Python threads cannot enter one editor at once). The mutex is only ever waited for without the
// GIL, so the two cannot deadlock.
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <pybind11/stl.h>

#include "bindings.h"
#include "convert.h"
#include "remora/linalg/solver.h"
#include "remora/multires/edit_request.h"
#include "remora/multires/editor.h"
#include "remora/multires/nonlinear.h"

namespace remora::python {

namespace {

const OptionSetters<SolverOptions>& solver_setters() {
  using O = SolverOptions;
  static const OptionSetters<O> setters = {
      {"ordering", string_field(&O::ordering)},
      {"preconditioner", string_field(&O::preconditioner)},
      {"tolerance", real_field(&O::tolerance)},
      {"max_iterations", int_field(&O::max_iterations)},
  };
  return setters;
}

/// A nested dict of options (remesh_options, solver_options).
template <class Options>
void apply_nested(const char* what, const py::handle& value, const OptionSetters<Options>& setters,
                  Options& options) {
  if (!py::isinstance<py::dict>(value))
    throw std::invalid_argument(std::string("expected a dict of ") + what);
  apply_options(what, py::reinterpret_borrow<py::dict>(value), setters, options);
}

/// Number options with a bound; InvalidArgument "must be > 0, got 0" otherwise.
double positive_real(const py::handle& value) {
  const double x = option_real(value);
  if (!(x > 0.0)) throw InvalidArgument(fmt::format("must be > 0, got {}", x));
  return x;
}
double non_negative_real(const py::handle& value) {
  const double x = option_real(value);
  if (!(x >= 0.0)) throw InvalidArgument(fmt::format("must be >= 0, got {}", x));
  return x;
}
int int_at_least(const py::handle& value, int low) {
  const int x = option_int(value);
  if (x < low) throw InvalidArgument(fmt::format("must be >= {}, got {}", low, x));
  return x;
}

/// nonlinear_options={...}: the NonlinearOptions fields a Python caller may set (its threads
/// are the editor's). The bounds are the deformer's: a value outside them would make every
/// frame fall back to the linear result, so they are refused here, by name.
const OptionSetters<NonlinearOptions>& nonlinear_setters() {
  using O = NonlinearOptions;
  static const OptionSetters<O> setters = {
      {"energy",
       [](O& o, const py::handle& v) { o.energy = parse_nonlinear_energy(option_string(v)); }},
      {"rigidity", [](O& o, const py::handle& v) { o.rigidity = positive_real(v); }},
      {"max_iterations", [](O& o, const py::handle& v) { o.max_iterations = int_at_least(v, 1); }},
      {"tolerance", [](O& o, const py::handle& v) { o.tolerance = positive_real(v); }},
      {"energy_tolerance",
       [](O& o, const py::handle& v) { o.energy_tolerance = non_negative_real(v); }},
      {"anderson", [](O& o, const py::handle& v) { o.anderson = int_at_least(v, 0); }},
      {"preview_vertices",
       [](O& o, const py::handle& v) { o.preview_vertices = int_at_least(v, 0); }},
      {"solver",
       [](O& o, const py::handle& v) {
         SolverOptions solver = o.solver;
         solver.name = option_string(v);
         (void)make_solver(solver); // throws for a name this build does not have
         o.solver = solver;
       }},
  };
  return setters;
}

/// Editor(V, F, **options): one entry per EditorOptions field a Python caller may set (a new
/// field is one more line here and in the docstring of python/remora/_editor.py).
const OptionSetters<EditorOptions>& editor_setters() {
  using O = EditorOptions;
  static const OptionSetters<O> setters = {
      {"k", [](O& o, const py::handle& v) { o.system.k = option_int(v); }},
      {"areas",
       [](O& o, const py::handle& v) { o.system.areas = parse_area_weights(option_string(v)); }},
      {"solver", [](O& o, const py::handle& v) { o.solver.name = option_string(v); }},
      {"solver_options",
       [](O& o, const py::handle& v) {
         apply_nested("solver_options", v, solver_setters(), o.solver);
       }},
      {"details",
       [](O& o, const py::handle& v) { o.details = parse_detail_mode(option_string(v)); }},
      {"method", [](O& o, const py::handle& v) { o.method = parse_edit_method(option_string(v)); }},
      {"nonlinear_options",
       [](O& o, const py::handle& v) {
         apply_nested("nonlinear_options", v, nonlinear_setters(), o.nonlinear);
       }},
      {"remesh", bool_field(&O::remesh)},
      {"base_smoothing", [](O& o, const py::handle& v) { o.base.smoothing = option_real(v); }},
      {"base_feature_cap", [](O& o, const py::handle& v) { o.base.feature_cap = option_real(v); }},
      {"remesh_options",
       [](O& o, const py::handle& v) {
         apply_nested("remesh_options", v, remesh_setters(), o.remesh_options);
       }},
      {"threads", int_field(&O::threads)},
      {"progress", [](O& o, const py::handle& v) { o.progress = progress_arg(v); }},
  };
  return setters;
}

/// A 3×4 affine map from a (3, 4) array or a (4, 4) one whose last row is 0, 0, 0, 1.
Transform transform_arg(const py::handle& value, const char* name) {
  py::array a = py::array::ensure(value);
  if (!a || a.ndim() != 2 || a.shape(1) != 4 || (a.shape(0) != 3 && a.shape(0) != 4) ||
      !(a.dtype().kind() == 'f' || a.dtype().kind() == 'i' || a.dtype().kind() == 'u'))
    throw InvalidArgument(fmt::format("{}: expected a (3, 4) or (4, 4) array of numbers "
                                      "(an affine map [M | t])",
                                      name));
  const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  const double* p = d.data();
  Transform t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) t(r, c) = p[4 * r + c];
  if (a.shape(0) == 4 && !(p[12] == 0.0 && p[13] == 0.0 && p[14] == 0.0 && p[15] == 1.0))
    throw InvalidArgument(fmt::format("{}: the last row of a (4, 4) transform must be 0, 0, 0, 1 "
                                      "(an affine map), got {}, {}, {}, {}",
                                      name, p[12], p[13], p[14], p[15]));
  return t;
}

py::array_t<double> transform_array(const Transform& t) {
  py::array_t<double> out({py::ssize_t(3), py::ssize_t(4)});
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out.mutable_data()[4 * r + c] = t(r, c);
  return out;
}

py::array_t<double> vector_array(const Eigen::Vector3d& v) {
  py::array_t<double> out(3);
  for (int k = 0; k < 3; ++k) out.mutable_data()[k] = v[k];
  return out;
}

class PyEditor {
  /// f() without the GIL and under the editor's mutex.
  template <class F>
  auto locked(F&& f) {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(mutex_);
    return f();
  }

public:
  PyEditor(const py::handle& vertices, const py::handle& faces, const py::dict& kwargs) {
    EditorOptions options;
    options.progress = progress_arg(py::none());
    apply_options("Editor", kwargs, editor_setters(), options);
    Mesh mesh = mesh_arg(vertices, faces);
    py::gil_scoped_release release;
    editor_ = std::make_unique<Editor>(std::move(mesh), std::move(options));
  }

  std::size_t n_vertices() const { return editor_->input().n_vertices(); }

  void set_region(const py::handle& support, const py::sequence& handles) {
    const std::size_t n = n_vertices();
    const std::vector<int> s = indices_arg(support, "support", n, false);
    std::vector<std::vector<int>> h;
    for (std::size_t j = 0; j < handles.size(); ++j) {
      const std::string name = fmt::format("handles[{}]", j);
      h.push_back(indices_arg(handles[j], name.c_str(), n, false));
    }
    locked([&] { editor_->set_region(s, h); });
  }

  void set_transform(int handle, const py::handle& value) {
    const Transform t = transform_arg(value, "T");
    locked([&] { editor_->set_transform(handle, t); });
  }

  void set_method(const std::string& name, const std::optional<std::string>& energy_name) {
    EditMethod method = EditMethod::Linear;
    std::optional<NonlinearEnergy> energy;
    try {
      method = parse_edit_method(name);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(fmt::format("method: {}", e.what()));
    }
    try {
      if (energy_name) energy = parse_nonlinear_energy(*energy_name);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(fmt::format("energy: {}", e.what()));
    }
    locked([&] {
      if (energy) editor_->set_nonlinear_energy(*energy);
      editor_->set_method(method);
    });
  }

  std::string method() {
    return locked([&] { return to_string(editor_->options().method); });
  }

  bool converged() {
    return locked([&] { return editor_->converged(); });
  }

  py::array_t<double> positions(const py::handle& out, const py::handle& budget) {
    double budget_ms = std::numeric_limits<double>::infinity();
    if (!budget.is_none()) {
      budget_ms = real_arg(budget, "budget_ms");
      if (!(budget_ms >= 0.0))
        throw InvalidArgument(fmt::format(
            "budget_ms: must be >= 0, got {} (None: iterate until converged)", budget_ms));
    }
    const auto n = static_cast<py::ssize_t>(n_vertices());
    py::array_t<double> result;
    if (out.is_none()) {
      result = py::array_t<double>({n, py::ssize_t(3)});
    } else {
      if (!py::isinstance<py::array_t<double>>(out))
        throw InvalidArgument("out: expected a float64 array");
      result = py::reinterpret_borrow<py::array_t<double>>(out);
      if (result.ndim() != 2 || result.shape(0) != n || result.shape(1) != 3 ||
          !(result.flags() & py::array::c_style) || !result.writeable())
        throw InvalidArgument(fmt::format("out: expected a writeable C-contiguous ({}, 3) float64 "
                                          "array",
                                          n));
    }
    double* target = result.mutable_data();
    locked([&] {
      const Eigen::MatrixXd& p = editor_->positions(budget_ms);
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(target, n, 3) = p;
    });
    return result;
  }

  // The input and the base never change after the constructor: no lock.
  py::tuple base() const {
    return py::make_tuple(vertices_array(editor_->base()), faces_array(editor_->base()));
  }

  py::array_t<double> base_positions() {
    Eigen::MatrixXd p = locked([&] { return editor_->base_positions(); });
    return rows_array(p);
  }

  py::array_t<double> low_pass(const py::handle& values) {
    const std::vector<Vec3> v = points_arg(values, "values");
    Eigen::MatrixXd m(static_cast<Eigen::Index>(v.size()), 3);
    for (std::size_t i = 0; i < v.size(); ++i)
      m.row(static_cast<Eigen::Index>(i)) << v[i][0], v[i][1], v[i][2];
    Eigen::MatrixXd smooth = locked([&] { return editor_->low_pass(m); });
    return rows_array(smooth);
  }

  void set_system(int k, const std::string& areas) {
    KHarmonicOptions system;
    system.k = k;
    system.areas = parse_area_weights(areas);
    locked([&] { editor_->set_system(system); });
  }

  void prepare_regions() {
    locked([&] { editor_->prepare_regions(); });
  }

  int handle_count() {
    return locked([&] { return editor_->handle_count(); });
  }
  py::array_t<std::int64_t> movable_vertices() {
    const std::vector<int> ids = locked([&] { return editor_->movable_vertices(); });
    py::array_t<std::int64_t> out(static_cast<py::ssize_t>(ids.size()));
    for (std::size_t i = 0; i < ids.size(); ++i) out.mutable_data()[i] = ids[i];
    return out;
  }
  py::array_t<double> handle_center(int handle) {
    return vector_array(locked([&] { return editor_->handle_center(handle); }));
  }
  py::array_t<double> transform(int handle) {
    return transform_array(locked([&] { return editor_->transform(handle); }));
  }
  py::object report() {
    const nlohmann::json j = locked([&] { return to_json(editor_->report()); });
    return json_to_python(j);
  }

private:
  std::unique_ptr<Editor> editor_;
  std::mutex mutex_;
};

py::array_t<double> handle_transform(const py::handle& center, const py::handle& scale,
                                     const py::handle& rotate_axis, double rotate_degrees,
                                     const py::handle& translate) {
  TransformSpec spec;
  if (!scale.is_none()) spec.scale = vector3_arg(scale, "scale");
  if (!rotate_axis.is_none()) spec.rotate_axis = vector3_arg(rotate_axis, "rotate_axis");
  if (!std::isfinite(rotate_degrees)) throw InvalidArgument("rotate_degrees: not finite");
  spec.rotate_degrees = rotate_degrees;
  if (!translate.is_none()) spec.translate = vector3_arg(translate, "translate");
  return transform_array(resolve_transform(spec, vector3_arg(center, "center")));
}

} // namespace

void bind_editor(py::module_& m) {
  py::class_<PyEditor>(m, "Editor")
      .def(py::init<const py::handle&, const py::handle&, const py::dict&>(), py::arg("V"),
           py::arg("F"), py::arg("options"))
      .def_property_readonly("n_vertices", &PyEditor::n_vertices)
      .def("set_region", &PyEditor::set_region, py::arg("support"), py::arg("handles"))
      .def("set_transform", &PyEditor::set_transform, py::arg("handle"), py::arg("T"))
      .def("positions", &PyEditor::positions, py::arg("out"), py::arg("budget_ms"))
      .def("set_method", &PyEditor::set_method, py::arg("method"), py::arg("energy") = std::nullopt)
      .def("method", &PyEditor::method)
      .def("converged", &PyEditor::converged)
      .def("base", &PyEditor::base)
      .def("base_positions", &PyEditor::base_positions)
      .def("low_pass", &PyEditor::low_pass, py::arg("values"))
      .def("set_system", &PyEditor::set_system, py::arg("k"), py::arg("areas"))
      .def("prepare_regions", &PyEditor::prepare_regions)
      .def("handle_count", &PyEditor::handle_count)
      .def("movable_vertices", &PyEditor::movable_vertices)
      .def("handle_center", &PyEditor::handle_center, py::arg("handle"))
      .def("transform", &PyEditor::transform, py::arg("handle"))
      .def("report", &PyEditor::report);
  m.def("handle_transform", &handle_transform, py::arg("center"), py::arg("scale"),
        py::arg("rotate_axis"), py::arg("rotate_degrees"), py::arg("translate"));
}

} // namespace remora::python
