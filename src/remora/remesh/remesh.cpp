// remesh(): the options check and the paper's recipe (§4), step by step; each step lives in a
// file named after it (remesher.h lists them).
#include "remora/remesh/remesh.h"

#include <algorithm>
#include <cmath>

#include "remora/common/error.h"
#include "remora/common/timer.h"
#include "remora/remesh/remesher.h"

namespace remora {

namespace remesh_detail {

void check_options(const Mesh& input, const RemeshOptions& options) {
  if (input.n_faces() == 0) throw InvalidArgument("remesh: the input mesh has no faces");
  if (options.cycles < 0 || options.max_cycles < 0 || options.equalize_iterations < 0 ||
      options.threads < 0)
    throw InvalidArgument(
        "remesh: cycles, max_cycles, equalize_iterations and threads must be >= 0");
  if (!(options.settle_fraction >= 0 && options.settle_fraction <= 1))
    throw InvalidArgument("remesh: settle_fraction must be in [0, 1] (1 = no extra cycles)");
  if (!std::isfinite(options.target_length) || !(options.length_factor > 0) ||
      !std::isfinite(options.length_factor))
    throw InvalidArgument("remesh: the target length and length factor must be finite, and the "
                          "factor positive");
  if (!(options.lambda > 0 && options.lambda <= 1))
    throw InvalidArgument("remesh: lambda must be in (0, 1]");
  if (!(options.equalize_smoothing >= 0 && std::isfinite(options.equalize_smoothing)))
    throw InvalidArgument("remesh: equalize_smoothing must be finite and >= 0");
  if (!(options.equalize_momentum >= 0 && options.equalize_momentum < 1))
    throw InvalidArgument("remesh: equalize_momentum must be in [0, 1) (0 = off)");
  if (!(options.corner_angle_deg >= 0 && options.corner_angle_deg <= 180))
    throw InvalidArgument("remesh: corner_angle_deg must be in [0, 180] degrees");
  if (!(options.equalize_guard_deg >= 0 && options.equalize_guard_deg < 60))
    throw InvalidArgument("remesh: equalize_guard_deg must be in [0, 60) degrees (0 = off)");
  if (!(options.feature_angle_deg >= 0 && options.feature_angle_deg < 180))
    throw InvalidArgument("remesh: feature_angle_deg must be in [0, 180) degrees (0 = no "
                          "features)");
  if (!(options.boundary_spacing <= 4.0 / 3.0))
    throw InvalidArgument("remesh: boundary_spacing must be at most 4/3 (longer boundary edges "
                          "are split again; <= 1 turns the spacing off)");
}

} // namespace remesh_detail

namespace {

using namespace remesh_detail;

// Runs f and adds its wall time to the phase's entry of the report.
template <class F>
void timed(RemeshReport& report, const char* phase, F&& f) {
  const auto t0 = Clock::now();
  f();
  report.milliseconds[phase] += ms_since(t0);
}

// §4: cycles of split (> 4/3 l), collapse (< 4/5 l), valence flips and tangential smoothing. At
// least options.cycles, then more while the last one still reconnected more than
// settle_fraction of the faces (CAD parts keep doing so around their creases), up to
// max_cycles. The boundary is spaced once, at the start of the second cycle.
void run_cycles(Remesher& rm, RemeshReport& report) {
  const RemeshOptions& options = rm.options;
  const int max_cycles = std::max(options.cycles, options.max_cycles);
  for (int cycle = 0; cycle < max_cycles; ++cycle) {
    rm.progress("remesh", cycle, std::max(options.cycles, cycle + 1));
    if (cycle == 1 && options.boundary_spacing > 1)
      timed(report, "collapse", [&] { report.collapses += resample_boundary(rm); });
    const std::size_t before = report.splits + report.collapses + report.flips;
    timed(report, "split", [&] { report.splits += split_long_edges(rm); });
    timed(report, "collapse", [&] { report.collapses += collapse_short_edges(rm); });
    timed(report, "flip", [&] { report.flips += equalize_valences(rm); });
    const std::size_t changes = report.splits + report.collapses + report.flips - before;
    const bool last = cycle + 1 >= max_cycles ||
                      (cycle + 1 >= options.cycles &&
                       (options.settle_fraction >= 1 ||
                        static_cast<double>(changes) <=
                            options.settle_fraction * static_cast<double>(rm.live_faces)));
    timed(report, "smooth", [&] { tangential_smoothing(rm); });
    report.cycles = cycle + 1;
    if (last) break;
    if (cycle == 0) timed(report, "reorder", [&] { compact(rm); });
  }
}

// §4's fine-tuning: area-equalizing iterations, then the repair of the triangles they spoilt.
void fine_tune(Remesher& rm, RemeshReport& report) {
  const RemeshOptions& options = rm.options;
  rm.previous_points.clear(); // the first iteration has no previous move
  for (int it = 0; it < options.equalize_iterations; ++it) {
    rm.progress("equalize", it, options.equalize_iterations);
    report.delaunay_flips += equalize_areas(rm);
  }
  report.guarded_moves = rm.guarded;
  if (options.equalize_iterations > 0)
    report.repairs += repair_bad_triangles(rm, options.repair_angle_deg);
}

RemeshResult run(const Mesh& input, const RemeshOptions& options) {
  const auto t_total = Clock::now();
  RemeshResult result;
  RemeshReport& report = result.report;
  Remesher rm(input, options);
  report.length_from_area = rm.length_from_area;
  report.target_length = rm.length;
  if (options.compute_report) timed(report, "report", [&] { report_input(rm, report); });

  find_curves(rm);
  init_locations(rm);
  mark_corners(rm);
  report.feature_edges = rm.feature_count;
  init_points(rm);
  run_steps(rm, report);
  finish_correspondence(rm, result.output_on_input, result.input_on_output, report);
  rm.take_mesh(result.mesh);
  report.milliseconds["total"] = ms_since(t_total);
  return result;
}

} // namespace

namespace remesh_detail {

void run_steps(Remesher& rm, RemeshReport& report) {
  const RemeshOptions& options = rm.options;
  const bool figures = options.compute_report;
  run_cycles(rm, report);
  timed(report, "reorder", [&] { compact(rm); });
  timed(report, "repair",
        [&] { report.repairs += repair_bad_triangles(rm, options.repair_angle_deg); });
  if (figures) timed(report, "report", [&] { report_after_cycles(rm, report); });

  timed(report, "equalize", [&] { fine_tune(rm, report); });
  timed(report, "reorder", [&] { remove_deleted(rm); });
  if (figures) timed(report, "report", [&] { report_output(rm, report); });
}

void finish_correspondence(Remesher& rm, std::vector<SurfacePoint>& output_on_input,
                           std::vector<SurfacePoint>& input_on_output, RemeshReport& report) {
  timed(report, "correspondence", [&] {
    rm.progress("correspondence", 0, 1);
    output_on_input.resize(rm.mesh.n_vertices());
    for (auto v : rm.mesh.vertices())
      output_on_input[static_cast<std::size_t>(v.idx())] = rm.loc(v);
    reproject_points(rm); // the repair changed faces after the last moves
    input_on_output = closest_input_locations(rm, report);
  });
}

} // namespace remesh_detail

RemeshResult remesh(const Mesh& input, const RemeshOptions& options) {
  check_options(input, options);
  // A large input is remeshed in a spatial order (copy_in_order): its walks and its first cycle
  // then read memory close to what they read last. The correspondence goes back to the
  // caller's numbering at the end.
  const bool compact =
      input.n_vertices() ==
      static_cast<std::size_t>(std::distance(input.vertices().begin(), input.vertices().end()));
  if (input.n_faces() <= kSpatialOrderFaces || !compact) return run(input, options);
  const auto t0 = Clock::now();
  MeshOrder order;
  const Mesh sorted = copy_in_order(input, true, order);
  const double sort_ms = ms_since(t0);
  RemeshResult result = run(sorted, options);
  result.report.milliseconds["reorder"] += sort_ms;
  result.report.milliseconds["total"] += sort_ms;
  to_input_order(result, input, order);
  return result;
}

} // namespace remora
