// The remesher's report: quality figures of the input, after the cycles and of the output, the
// output's distance to the input, and the report's JSON form.

#include <algorithm>
#include <vector>

#include <nlohmann/json.hpp>

#include "remora/common/parallel.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/locate.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/quality.h"

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

namespace {

// How far the output lies from the input: its vertices (tracked locations) and its faces'
// centroids (located by a walk from a corner's location).
void measure_distances(const Remesher& rm, RemeshReport& report) {
  const double diag = bounding_box_diagonal(rm.input);
  if (!(diag > 0)) return;
  std::vector<double> vd(rm.mesh.n_vertices(), 0.0), fd(rm.mesh.n_faces(), 0.0);
  parallel_for(rm.mesh.n_vertices(), rm.options.threads, [&](std::size_t i) {
    const VertexHandle v(static_cast<int>(i));
    if (!rm.mesh.is_isolated(v)) vd[i] = (rm.mesh.point(v) - evaluate(rm.input, rm.loc(v))).norm();
  });
  parallel_for(rm.mesh.n_faces(), rm.options.threads, [&](std::size_t i) {
    const auto fv = face_vertices(rm.mesh, FaceHandle(static_cast<int>(i)));
    const Vec3 c = (rm.mesh.point(fv[0]) + rm.mesh.point(fv[1]) + rm.mesh.point(fv[2])) / 3.0;
    const SurfacePoint sp = walk_to_closest(rm.input, c, rm.loc(fv[0]).face);
    fd[i] = (c - evaluate(rm.input, sp)).norm();
  });
  auto summarize = [&](const std::vector<double>& d, double& mean, double& max) {
    double sum = 0;
    max = 0;
    for (double x : d) {
      sum += x;
      max = std::max(max, x);
    }
    mean = d.empty() ? 0.0 : sum / static_cast<double>(d.size()) / diag;
    max /= diag;
  };
  summarize(vd, report.vertex_distance_mean, report.vertex_distance_max);
  summarize(fd, report.centroid_distance_mean, report.centroid_distance_max);
}

} // namespace

void report_input(const Remesher& rm, RemeshReport& report) {
  report.input = mesh_quality(rm.input);
  report.symmetry_defect_input = laplacian_symmetry_defect(rm.input);
}

void report_after_cycles(const Remesher& rm, RemeshReport& report) {
  // The repair's few deleted elements stay until the end; the figures need them gone.
  Mesh compacted = rm.mesh;
  compacted.garbage_collection();
  report.after_cycles = mesh_quality(compacted);
  report.edges_in_band_cycles = percent_edges_within(compacted, 0.8 * rm.length, rm.hi);
  report.symmetry_defect_cycles = laplacian_symmetry_defect(compacted);
}

void report_output(const Remesher& rm, RemeshReport& report) {
  report.after_equalization = mesh_quality(rm.mesh);
  report.edges_in_band_output = percent_edges_within(rm.mesh, 0.8 * rm.length, rm.hi);
  report.symmetry_defect_output = laplacian_symmetry_defect(rm.mesh);
  report.symmetry_defect_output_interior =
      laplacian_symmetry_defect(rm.mesh, SymmetryRows::Interior);
  measure_distances(rm, report);
}

} // namespace remora::remesh_detail

namespace remora {

nlohmann::json to_json(const RemeshReport& r) {
  return {{"target_length", r.target_length},
          {"length_from_area", r.length_from_area},
          {"feature_edges", r.feature_edges},
          {"cycles", r.cycles},
          {"input", to_json(r.input)},
          {"after_cycles", to_json(r.after_cycles)},
          {"after_equalization", to_json(r.after_equalization)},
          {"edges_in_band_percent",
           {{"after_cycles", r.edges_in_band_cycles}, {"output", r.edges_in_band_output}}},
          {"symmetry_defect",
           {{"input", r.symmetry_defect_input},
            {"after_cycles", r.symmetry_defect_cycles},
            {"output", r.symmetry_defect_output},
            {"output_interior_rows", r.symmetry_defect_output_interior}}},
          {"distance_to_input",
           {{"vertex_mean", r.vertex_distance_mean},
            {"vertex_max", r.vertex_distance_max},
            {"centroid_mean", r.centroid_distance_mean},
            {"centroid_max", r.centroid_distance_max}}},
          {"correspondence",
           {{"tracked_excess_mean", r.tracked_excess_mean},
            {"tracked_excess_max", r.tracked_excess_max},
            {"tracked_same_face", r.tracked_same_face}}},
          {"splits", r.splits},
          {"collapses", r.collapses},
          {"flips", r.flips},
          {"delaunay_flips", r.delaunay_flips},
          {"guarded_moves", r.guarded_moves},
          {"repairs", r.repairs},
          {"milliseconds", r.milliseconds}};
}

} // namespace remora
