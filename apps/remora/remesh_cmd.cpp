#include <cstdio>
#include <iostream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "limit_options.h"
#include "remora/common/json.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/io.h"
#include "remora/multires/base_surface.h"
#include "remora/remesh/remesh.h"
#include "report.h"

namespace remora::cli {

namespace {

// A number in (lo, hi] (`open_low`) or in [lo, hi): CLI::Range includes both ends, and the
// library refuses the excluded one.
CLI::Validator half_open_range(double lo, double hi, bool open_low) {
  const std::string interval =
      open_low ? fmt::format("({}, {}]", lo, hi) : fmt::format("[{}, {})", lo, hi);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double x = 0;
        if (!CLI::detail::lexical_cast(text, x)) return "not a number: " + text;
        const bool inside = open_low ? x > lo && x <= hi : x >= lo && x < hi;
        return inside ? std::string() : fmt::format("{} is not in {}", text, interval);
      },
      "FLOAT in " + interval);
}

void print_remesh_report(std::ostream& os, const RemeshReport& r) {
  os << fmt::format("target edge length l = {:.6g}{}\n", r.target_length,
                    r.length_from_area ? " (from the area per vertex: needles inflate the mean "
                                         "edge length)"
                                       : "");
  os << fmt::format("{:<28}{:>12}{:>14}{:>14}\n", "", "input", "after cycles", "equalized");
  auto line = [&](const char* label, auto get, const char* fmt_spec) {
    os << fmt::format("{:<28}", label)
       << fmt::format(fmt::runtime(fmt_spec), get(r.input), get(r.after_cycles),
                      get(r.after_equalization))
       << "\n";
  };
  line(
      "vertices", [](const MeshQuality& q) { return q.vertices; }, "{:>12}{:>14}{:>14}");
  line(
      "faces", [](const MeshQuality& q) { return q.faces; }, "{:>12}{:>14}{:>14}");
  line(
      "min angle (deg)", [](const MeshQuality& q) { return q.angles.min_deg; },
      "{:>12.3f}{:>14.3f}{:>14.3f}");
  line(
      "mean |theta-60| (deg)",
      [](const MeshQuality& q) { return q.angles.mean_abs_deviation_from_60_deg; },
      "{:>12.3f}{:>14.3f}{:>14.3f}");
  line(
      "% angles < 30 deg", [](const MeshQuality& q) { return q.angles.percent_below_30; },
      "{:>12.2f}{:>14.2f}{:>14.2f}");
  line(
      "% interior valence 6", [](const MeshQuality& q) { return q.valence.percent_interior_6; },
      "{:>12.1f}{:>14.1f}{:>14.1f}");
  line(
      "edge length cv", [](const MeshQuality& q) { return q.edge_length.cv; },
      "{:>12.3f}{:>14.3f}{:>14.3f}");
  line(
      "mixed area rel MAD", [](const MeshQuality& q) { return q.mixed_area.rel_mad; },
      "{:>12.4f}{:>14.4f}{:>14.4f}");
  line(
      "mixed area rel std", [](const MeshQuality& q) { return q.mixed_area.rel_std; },
      "{:>12.4f}{:>14.4f}{:>14.4f}");
  os << fmt::format("{:<28}{:>12}{:>14.1f}{:>14.1f}\n", "% edges in [4/5 l, 4/3 l]", "",
                    r.edges_in_band_cycles, r.edges_in_band_output);
  os << fmt::format("{:<28}{:>12.4f}{:>14.4f}{:>14.4f}\n", "Laplacian symmetry defect",
                    r.symmetry_defect_input, r.symmetry_defect_cycles, r.symmetry_defect_output);
  if (r.symmetry_defect_output_interior != r.symmetry_defect_output)
    os << fmt::format("{:<28}{:>12}{:>14}{:>14.4f}\n", "  without boundary rows", "", "",
                      r.symmetry_defect_output_interior);
  os << fmt::format("distance to the input (of the bounding-box diagonal): vertices mean {:.2e} "
                    "max {:.2e}, face centroids mean {:.2e} max {:.2e}\n",
                    r.vertex_distance_mean, r.vertex_distance_max, r.centroid_distance_mean,
                    r.centroid_distance_max);
  os << fmt::format("input -> output locations, tracked through every operation: farther than "
                    "the closest point by {:.1e} l on average, {:.1e} l at most\n",
                    r.tracked_excess_mean, r.tracked_excess_max);
  if (r.feature_edges > 0)
    os << fmt::format("feature lines kept: {} input edges sharper than the feature angle\n",
                      grouped(r.feature_edges));
  os << fmt::format("operations: {} cycles; {} splits, {} collapses, {} flips, {} repairs; {} "
                    "Delaunay flips in the fine-tuning, {} of its moves shortened against "
                    "slivers\n",
                    r.cycles, grouped(r.splits), grouped(r.collapses), grouped(r.flips),
                    grouped(r.repairs), grouped(r.delaunay_flips), grouped(r.guarded_moves));
  std::string times;
  for (const auto& [phase, ms] : r.milliseconds) times += fmt::format("{} {:.0f} ms, ", phase, ms);
  if (!times.empty()) times.resize(times.size() - 2);
  os << "time: " << times << "\n";
}

struct RemeshArgs {
  std::string in, out;
  RemeshOptions options; ///< the library's defaults until a flag says otherwise
  double low_pass = 0;   ///< σ of the base-surface filter, in mean edge lengths; 0 = off
  LowPassOptions filter; ///< the editor's filter defaults but for the strength
  std::string method = "newton";
  std::string smoothing_target = "odt";
  bool no_project = false, report = false, json = false;
  std::uint64_t max_triangles = 0;
};

// The cycles: target length and cycle counts.
void add_cycle_options(CLI::App* cmd, RemeshArgs& a) {
  RemeshOptions& o = a.options;
  auto* length = cmd->add_option("--length", o.target_length, "Target edge length l (absolute)")
                     ->check(CLI::PositiveNumber);
  cmd->add_option("--length-factor", o.length_factor,
                  "l = factor x the input's mean edge length, area-based on needle meshes")
      ->check(CLI::PositiveNumber)
      ->excludes(length)
      ->capture_default_str();
  cmd->add_option("--cycles", o.cycles,
                  "Split/collapse/flip/smooth cycles, at least (more while they still change "
                  "the mesh, up to --max-cycles)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--max-cycles", o.max_cycles,
                  "At most this many cycles (at or below --cycles: exactly --cycles)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--settle", o.settle_fraction,
                  "Add a cycle while the last one split, collapsed or flipped more than this "
                  "fraction of the faces (1 = never)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
}

// The boundary and feature lines, and the threads.
void add_boundary_options(CLI::App* cmd, RemeshArgs& a) {
  RemeshOptions& o = a.options;
  cmd->add_option("--boundary-spacing", o.boundary_spacing,
                  "Spacing of the boundary vertices in l, set after the first cycle (<= 1: as the "
                  "cycles leave it)")
      ->check(CLI::Range(0.0, 4.0 / 3.0))
      ->capture_default_str();
  cmd->add_option("--corner-angle", o.corner_angle_deg,
                  "A boundary or feature-line vertex where its curve turns by more than this "
                  "many degrees (at the scale of l) is a corner and stays")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  cmd->add_option("--feature-angle", o.feature_angle_deg,
                  "Keep the input's feature lines: edges whose faces' normals differ by more than "
                  "this many degrees (0 = none)")
      ->check(CLI::Range(0.0, 179.0))
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "Worker threads (default: all)")
      ->check(CLI::NonNegativeNumber);
}

// The area equalization (paper §4) after the cycles.
void add_equalization_options(CLI::App* cmd, RemeshArgs& a) {
  RemeshOptions& o = a.options;
  cmd->add_option("--equalize", o.equalize_iterations, "Area-equalizing iterations")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--lambda", o.lambda, "Damping of the area-equalizing update, in (0, 1]")
      ->check(half_open_range(0.0, 1.0, true))
      ->capture_default_str();
  cmd->add_option("--method", a.method,
                  "Area equalization: newton (default) or gravity (the paper's update)")
      ->check(CLI::IsMember({"newton", "gravity"}));
  cmd->add_option("--smoothing", o.equalize_smoothing,
                  "newton: weight of the shape-keeping smoothing term")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--smoothing-target", a.smoothing_target,
                  "newton: where the smoothing term pulls: odt (default; the one-ring's "
                  "circumcentres weighted by area) or centroid (weaker pull: try --smoothing 1.5)")
      ->check(CLI::IsMember({"odt", "centroid"}));
  cmd->add_option("--momentum", o.equalize_momentum,
                  "newton: each fine-tuning move adds this fraction of the vertex's previous move "
                  "(heavy-ball momentum; 0 = off)")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  cmd->add_flag("!--no-equalize-flips", o.equalize_flips,
                "Skip the Delaunay flips after each area-equalizing iteration");
  cmd->add_option("--guard-angle", o.equalize_guard_deg,
                  "newton: shorten fine-tuning moves that would bring a face below this angle "
                  "(degrees; 0 = off)")
      ->check(half_open_range(0.0, 60.0, false))
      ->capture_default_str();
  cmd->add_flag("!--no-boundary-equalization", o.equalize_boundary,
                "newton: leave the boundary vertices' areas out of the fine-tuning (next to the "
                "boundary, tangential smoothing only)");
}

// Projection, report, and the low-pass filter of the editor's base surface.
void add_output_options(CLI::App* cmd, RemeshArgs& a) {
  cmd->add_flag("--no-project", a.no_project,
                "Keep vertex updates in the tangent plane instead of projecting onto the input");
  cmd->add_flag("--report", a.report, "Print quality figures, operation counts and timings");
  cmd->add_flag("--json", a.json, "Print the report as one JSON object");
  auto* low_pass_flag =
      cmd->add_option(
             "--low-pass", a.low_pass,
             "Remesh the low-pass filtered surface instead, as `remora edit` builds its base "
             "(sigma in mean edge lengths; the editor's default is 2)")
          ->check(CLI::NonNegativeNumber);
  cmd->add_option("--low-pass-cap", a.filter.feature_cap,
                  "With --low-pass: sigma at most this many times the part's local half-width, so "
                  "thin tubes and small holes are not pinched (0 = one sigma everywhere)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str()
      ->needs(low_pass_flag);
}

void run_remesh(const RemeshArgs& a) {
  format_from_path(a.out); // fail on an unknown extension before the long work
  ReadLimits limits;
  limits.max_triangles = a.max_triangles;
  LoadResult loaded = read_mesh(a.in, {}, limits);
  std::optional<LowPassStats> low_pass;
  if (a.low_pass > 0) {
    // The editor's base surface S (multires/base_surface.h): same connectivity, smooth points.
    LowPassOptions filter_options = a.filter;
    filter_options.smoothing = a.low_pass;
    filter_options.threads = a.options.threads;
    LowPassFilter filter(loaded.mesh, filter_options);
    set_positions(loaded.mesh, filter.apply(positions_matrix(loaded.mesh)));
    low_pass = filter.stats();
  }
  RemeshOptions options = a.options;
  options.equalization = a.method == "gravity" ? Equalization::Gravity : Equalization::Newton;
  options.smoothing_target =
      a.smoothing_target == "centroid" ? SmoothingTarget::Centroid : SmoothingTarget::Odt;
  options.project = !a.no_project;
  options.compute_report = a.report || a.json; // the figures take time: only when asked
  ProgressLine progress;
  options.progress = [&](std::string_view phase, int step, int steps) {
    progress.update(phase, step, steps);
  };
  const RemeshResult result = remesh(loaded.mesh, options);
  progress.finish();
  write_mesh(a.out, result.mesh);
  if (a.json) {
    nlohmann::json j = to_json(result.report);
    j["output"] = a.out;
    if (low_pass)
      j["low_pass"] = {{"sigma", low_pass->sigma},
                       {"sigma_min", low_pass->sigma_min},
                       {"sigma_capped_vertices", low_pass->capped},
                       {"sigma_capped_loops", low_pass->capped_loops}};
    std::cout << dump_json(j, 2) << "\n";
    return;
  }
  if (a.report && low_pass)
    std::cout << fmt::format("low-pass filter: sigma {:.4g}", low_pass->sigma)
              << (low_pass->capped + low_pass->capped_loops > 0
                      ? ", " + capped_sigma_line(low_pass->capped, low_pass->sigma_min,
                                                 low_pass->capped_loops)
                      : std::string())
              << "\n";
  if (a.report) print_remesh_report(std::cout, result.report);
  std::cout << "wrote " << a.out << " (" << grouped(result.mesh.n_vertices()) << " vertices, "
            << grouped(result.mesh.n_faces()) << " faces)\n";
}

} // namespace

void add_remesh_command(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("remesh", "Isotropic, area-equalizing remesh (paper section 4) of a mesh");
  auto a = std::make_shared<RemeshArgs>();
  cmd->add_option("input", a->in, "Input mesh (.obj .off .ply .stl)")->required();
  cmd->add_option("-o,--output", a->out, "Output mesh; the format follows the extension")
      ->required();
  add_cycle_options(cmd, *a);
  add_equalization_options(cmd, *a);
  add_boundary_options(cmd, *a);
  add_output_options(cmd, *a);
  add_max_triangles_option(cmd, a->max_triangles, 1);
  cmd->callback([a] { run_remesh(*a); });
}

} // namespace remora::cli
