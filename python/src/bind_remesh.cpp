// The area-equalizing remesh (remesh/remesh.h, paper §4) and the editor's low-pass filter
// (multires/base_surface.h). The Python package (python/remora/) documents both.
#include <nlohmann/json.hpp>

#include "bindings.h"
#include "convert.h"
#include "remora/common/timer.h"
#include "remora/linalg/kharmonic.h"
#include "remora/multires/base_surface.h"

namespace remora::python {

namespace {

Equalization parse_equalization(const std::string& name) {
  if (name == "newton") return Equalization::Newton;
  if (name == "gravity") return Equalization::Gravity;
  throw InvalidArgument("'" + name + "' is not a method: use newton or gravity");
}

SmoothingTarget parse_smoothing_target(const std::string& name) {
  if (name == "odt") return SmoothingTarget::Odt;
  if (name == "centroid") return SmoothingTarget::Centroid;
  throw InvalidArgument("'" + name + "' is not a target: use odt or centroid");
}

py::tuple remesh_arrays(const py::handle& vertices, const py::handle& faces,
                        const py::dict& kwargs) {
  RemeshOptions options;
  options.progress = progress_arg(py::none());
  apply_options("remesh", kwargs, remesh_setters(), options);
  const Mesh input = mesh_arg(vertices, faces);
  RemeshResult result;
  {
    py::gil_scoped_release release;
    const auto t0 = Clock::now();
    result = remesh(input, options);
    // The library call alone, against which the Python overhead is measured (bench/).
    result.report.milliseconds["library_call"] = ms_since(t0);
  }
  return py::make_tuple(vertices_array(result.mesh), faces_array(result.mesh),
                        surface_points_array(result.output_on_input),
                        surface_points_array(result.input_on_output),
                        json_to_python(to_json(result.report)));
}

const OptionSetters<LowPassOptions>& low_pass_setters() {
  using O = LowPassOptions;
  static const OptionSetters<O> setters = {
      {"smoothing", real_field(&O::smoothing)}, {"feature_cap", real_field(&O::feature_cap)},
      {"cap_slope", real_field(&O::cap_slope)}, {"steps", int_field(&O::steps)},
      {"tolerance", real_field(&O::tolerance)}, {"threads", int_field(&O::threads)},
  };
  return setters;
}

py::tuple low_pass(const py::handle& vertices, const py::handle& faces, const py::dict& kwargs) {
  LowPassOptions options;
  apply_options("low_pass", kwargs, low_pass_setters(), options);
  const Mesh mesh = mesh_arg(vertices, faces);
  Eigen::MatrixXd smooth;
  LowPassStats stats;
  {
    py::gil_scoped_release release;
    LowPassFilter filter(mesh, options);
    smooth = filter.apply(positions_matrix(mesh));
    stats = filter.stats();
  }
  py::dict s;
  s["sigma"] = stats.sigma;
  s["sigma_min"] = stats.sigma_min;
  s["sigma_capped_vertices"] = stats.capped;
  s["sigma_capped_loops"] = stats.capped_loops;
  s["intrinsic_flips"] = stats.laplacian_stats.flips;
  return py::make_tuple(rows_array(smooth), s);
}

} // namespace

const OptionSetters<RemeshOptions>& remesh_setters() {
  using O = RemeshOptions;
  static const OptionSetters<O> setters = {
      {"target_length", real_field(&O::target_length)},
      {"length_factor", real_field(&O::length_factor)},
      {"cycles", int_field(&O::cycles)},
      {"max_cycles", int_field(&O::max_cycles)},
      {"settle_fraction", real_field(&O::settle_fraction)},
      {"equalize_iterations", int_field(&O::equalize_iterations)},
      {"equalization",
       [](O& o, const py::handle& v) { o.equalization = parse_equalization(option_string(v)); }},
      {"lambda_", real_field(&O::lambda)},
      {"equalize_smoothing", real_field(&O::equalize_smoothing)},
      {"smoothing_target",
       [](O& o, const py::handle& v) {
         o.smoothing_target = parse_smoothing_target(option_string(v));
       }},
      {"equalize_momentum", real_field(&O::equalize_momentum)},
      {"equalize_flips", bool_field(&O::equalize_flips)},
      {"equalize_guard_deg", real_field(&O::equalize_guard_deg)},
      {"equalize_boundary", bool_field(&O::equalize_boundary)},
      {"project", bool_field(&O::project)},
      {"repair_angle_deg", real_field(&O::repair_angle_deg)},
      {"corner_angle_deg", real_field(&O::corner_angle_deg)},
      {"feature_angle_deg", real_field(&O::feature_angle_deg)},
      {"boundary_spacing", real_field(&O::boundary_spacing)},
      {"compute_report", bool_field(&O::compute_report)},
      {"threads", int_field(&O::threads)},
      {"progress", [](O& o, const py::handle& v) { o.progress = progress_arg(v); }},
  };
  return setters;
}

void bind_remesh(py::module_& m) {
  m.def("remesh", &remesh_arrays, py::arg("V"), py::arg("F"), py::arg("options"));
  m.def("low_pass", &low_pass, py::arg("V"), py::arg("F"), py::arg("options"));
}

} // namespace remora::python
