// `remora edit`: one edit of the pipeline of paper Fig. 3 (multires/editor.h), described by an
// EDIT.json file (multires/edit_request.h, docs/editing.md) or by quick flags.
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "limit_options.h"
#include "remora/common/error.h"
#include "remora/common/json.h"
#include "remora/common/timer.h"
#include "remora/geometry/measures.h"
#include "remora/mesh/io.h"
#include "remora/mesh/refine.h"
#include "remora/multires/detail_retention.h"
#include "remora/multires/edit_request.h"
#include "remora/multires/editor.h"
#include "report.h"

namespace remora::cli {

namespace {

/// "x,y,z[,w]" -> numbers; `what` names the flag in the message.
std::vector<double> numbers(const std::string& text, std::size_t count, const std::string& what) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v))
      throw InvalidArgument(
          fmt::format("{}: '{}' is not a finite number (expected {} numbers separated by commas)",
                      what, item, count));
    out.push_back(v);
  }
  if (out.size() != count)
    throw InvalidArgument(
        fmt::format("{}: expected {} numbers separated by commas, got '{}'", what, count, text));
  return out;
}

RegionSpec sphere_flag(const std::string& text, const std::string& what) {
  const auto v = numbers(text, 4, what);
  if (v[3] < 0) throw InvalidArgument(what + ": the radius must be >= 0");
  RegionSpec r;
  r.kind = RegionSpec::Kind::Sphere;
  r.center = {v[0], v[1], v[2]};
  r.radius = v[3];
  return r;
}

std::string describe(const RegionSpec& r) {
  switch (r.kind) {
  case RegionSpec::Kind::Vertices:
    return fmt::format("a list of {} vertex ids", r.vertices.size());
  case RegionSpec::Kind::Sphere:
    return fmt::format("the sphere at ({:.6g}, {:.6g}, {:.6g}) of radius {:.6g}", r.center[0],
                       r.center[1], r.center[2], r.radius);
  case RegionSpec::Kind::Box:
    return "the box";
  case RegionSpec::Kind::Geodesic:
    return fmt::format("the geodesic disc of radius {:.6g} around vertex {}", r.radius, r.vertex);
  case RegionSpec::Kind::Union:
    return "the union";
  }
  return "the region";
}

void print_edit_report(std::ostream& os, const EditReport& r, double load_ms, double retention,
                       double max_move) {
  os << fmt::format("input: {} vertices, {} faces\n", grouped(r.input_vertices),
                    grouped(r.input_faces));
  os << fmt::format("base: {} ({} vertices, {} faces), low-pass sigma {:.4g}, {} intrinsic flips "
                    "({} negative cotan weights in the input)\n",
                    r.remeshed ? fmt::format("remeshed at l = {:.4g}", r.base_target_length)
                               : std::string("not remeshed"),
                    grouped(r.base_vertices), grouped(r.base_faces), r.sigma,
                    grouped(r.intrinsic_flips), grouped(r.input_negative_weights));
  if (r.sigma_capped_vertices + r.sigma_capped_loops > 0)
    os << "base filter: "
       << capped_sigma_line(r.sigma_capped_vertices, r.sigma_min, r.sigma_capped_loops) << "\n";
  os << fmt::format("base quality: min angle {:.2f} deg, mean |theta-60| {:.2f} deg, mixed area "
                    "rel MAD {:.4f}, Laplacian symmetry defect {:.4f}\n",
                    r.base_quality.angles.min_deg,
                    r.base_quality.angles.mean_abs_deviation_from_60_deg,
                    r.base_quality.mixed_area.rel_mad, r.base_symmetry_defect);
  std::string handles;
  for (std::size_t j = 0; j < r.handle_vertices.size(); ++j)
    handles += fmt::format("{}{} ({} on the base)", j ? ", " : "", grouped(r.handle_vertices[j]),
                           grouped(r.handle_base_vertices[j]));
  os << fmt::format("region: support {} vertices, handles {}; on the base {} free, {} "
                    "constrained, {} negative cotan weights in the support\n",
                    grouped(r.support_vertices), handles, grouped(r.free_base_vertices),
                    grouped(r.constrained_base_vertices), grouped(r.negative_weights_in_support));
  if (!r.coarse_support.empty()) os << "warning: " << r.coarse_support << "\n";
  os << fmt::format("solver: {}, {} right-hand sides", r.solver, r.solves);
  if (r.solver_stats.iterations > 0)
    os << fmt::format(", {} iterations, residual {:.2e}", r.solver_stats.iterations,
                      r.solver_stats.residual);
  if (r.solver_stats.factor_bytes > 0)
    os << fmt::format(", factor {:.1f} MB", double(r.solver_stats.factor_bytes) / 1e6);
  if (r.solver_stats.separator_rows > 0)
    os << fmt::format(" in two halves around a separator of {} rows",
                      grouped(static_cast<std::size_t>(r.solver_stats.separator_rows)));
  os << "\n";
  os << fmt::format("details: {} encoded, {} walk steps, {} extrapolated, {} fallbacks\n",
                    grouped(r.phong.encoded), grouped(r.phong.walk_steps),
                    grouped(r.phong.extrapolated), grouped(r.phong.fallbacks));
  if (r.method == "nonlinear") {
    const NonlinearStats& n = r.nonlinear;
    if (!r.fallback.empty())
      os << "deformation: nonlinear, " << r.fallback << "\n";
    else if (r.nonlinear_energy == "blended-motions")
      os << "deformation: nonlinear, blended-motions (closed form, no iteration)\n";
    else
      os << fmt::format("deformation: nonlinear, {} iterations ({} extrapolated), {}, energy "
                        "{:.4g} -> {:.4g}\n",
                        n.total_iterations, n.accelerated,
                        n.converged ? "converged" : "not converged (max_iterations)",
                        n.energy.empty() ? 0.0 : n.energy.front(),
                        n.energy.empty() ? 0.0 : n.energy.back());
  }
  os << fmt::format("result: largest move {:.4g} of the bounding-box diagonal, detail retention "
                    "{:.3f}\n",
                    max_move, retention);
  auto ms = [&](const char* key) {
    const auto it = r.milliseconds.find(key);
    return it == r.milliseconds.end() ? 0.0 : it->second;
  };
  os << fmt::format(
      "time: load {:.0f} ms, base {:.0f} ms, remesh {:.0f} ms, set_region {:.0f} ms "
      "(assemble {:.0f}, factor {:.0f}, solve {:.0f}, encode {:.0f}), frame {:.1f} ms\n",
      load_ms, ms("base"), ms("remesh"), ms("set_region"), ms("assemble"), ms("factor"),
      ms("solve"), ms("encode"), ms("frame"));
}

struct EditArgs {
  std::string in, out, edit;
  std::string support_sphere, handle_sphere, translate, rotate, scale;
  int k = 0, threads = 0;
  std::string solver, areas, details, method, energy;
  double base_smoothing = -1, base_feature_cap = -1, length_factor = -1;
  bool no_remesh = false, report = false, json = false, refine_support = false;
  std::uint64_t max_triangles = 0;
  int max_handles = kMaxHandles;
};

void add_edit_options(CLI::App* cmd, EditArgs& a) {
  cmd->add_option("input", a.in, "Input mesh (.obj .off .ply .stl)")->required();
  cmd->add_option("-o,--output", a.out, "Output mesh; the format follows the extension")
      ->required();
  auto* edit = cmd->add_option("--edit", a.edit,
                               "EDIT.json: k, solver, support, handles and "
                               "their transforms (docs/editing.md)");
  auto* support = cmd->add_option("--support-sphere", a.support_sphere,
                                  "x,y,z,r: the support is the vertices in this sphere");
  auto* handle = cmd->add_option("--handle-sphere", a.handle_sphere,
                                 "x,y,z,r: the handle is the vertices in this sphere (inside the "
                                 "support)");
  auto* translate =
      cmd->add_option("--translate", a.translate, "dx,dy,dz: move the handle by this offset");
  auto* rotate =
      cmd->add_option("--rotate", a.rotate, "ax,ay,az,deg: rotate the handle about its centroid");
  auto* scale =
      cmd->add_option("--scale", a.scale, "sx,sy,sz: scale the handle about its centroid");
  for (auto* quick : {support, handle, translate, rotate, scale}) quick->excludes(edit);
  support->needs(handle);
  handle->needs(support);
  cmd->add_option("--k", a.k, "1 (membrane), 2 (thin plate, default), 3")->check(CLI::Range(1, 3));
  cmd->add_option("--solver", a.solver,
                  "Solver name (remora bench solvers lists them) or "
                  "multigrid; default: the direct solver");
  cmd->add_option("--areas", a.areas, "mean (default, symmetric), mixed, mixed-symmetric")
      ->check(CLI::IsMember({"mean", "mixed", "mixed-symmetric"}));
  cmd->add_option("--details", a.details, "normal (default, Phong), displacement, none")
      ->check(CLI::IsMember({"normal", "displacement", "none"}));
  cmd->add_option("--method", a.method,
                  "linear (default, the paper) or nonlinear (keeps rotated parts from shrinking)")
      ->check(CLI::IsMember({"linear", "nonlinear"}));
  cmd->add_option("--energy", a.energy,
                  "Method nonlinear: rotated-laplacian (default), propagated, blended-motions or "
                  "arap (docs/nonlinear.md)")
      ->check(CLI::IsMember(nonlinear_energy_names()));
  cmd->add_option("--base-smoothing", a.base_smoothing,
                  "Low-pass length of the base surface, in mean edge lengths (area-based on needle "
                  "meshes; default 2)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--base-feature-cap", a.base_feature_cap,
                  "The base filter's sigma at most this many times the part's local half-width, "
                  "so thin tubes and small holes are not pinched (default 1; 0 = off)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--length-factor", a.length_factor,
                  "Base remesh edge length = factor x the mean edge length (area-based on needle "
                  "meshes; default 0.9)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--refine-support", a.refine_support,
                "Split the support's own edges longer than the base's (midpoints: the surface "
                "stays) so that a coarse CAD support bends smoothly; adds vertices to the output");
  cmd->add_flag("--no-remesh", a.no_remesh,
                "Solve on the input's own connectivity (the baseline the paper improves on)");
  cmd->add_option("--threads", a.threads, "Worker threads (default: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--report", a.report, "Print timings and quality figures");
  cmd->add_flag("--json", a.json, "Print the report as one JSON object");
  add_max_triangles_option(cmd, a.max_triangles, 1);
  add_max_handles_option(cmd, a.max_handles);
}

EditRequest read_edit_file(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw IoError(path, "cannot open the edit file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(file);
  } catch (const nlohmann::json::parse_error& e) {
    throw IoError(path, fmt::format("not valid JSON: {}", e.what()));
  }
  try {
    return parse_edit_request(j);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(fmt::format("{}: {}", path, e.what()));
  }
}

/// The request of --edit, or of the quick flags (one spherical handle).
EditRequest edit_request(const EditArgs& a) {
  if (!a.edit.empty()) return read_edit_file(a.edit);
  if (a.support_sphere.empty())
    throw InvalidArgument("nothing to edit: give --edit EDIT.json, or --support-sphere and "
                          "--handle-sphere with --translate, --rotate or --scale");
  EditRequest request;
  request.support = sphere_flag(a.support_sphere, "--support-sphere");
  HandleSpec h;
  h.region = sphere_flag(a.handle_sphere, "--handle-sphere");
  if (!a.scale.empty()) {
    const auto v = numbers(a.scale, 3, "--scale");
    h.transform.scale = Eigen::Vector3d(v[0], v[1], v[2]);
    if (!(h.transform.scale->minCoeff() > 0.0))
      throw InvalidArgument(
          "--scale: every factor must be > 0 (0 collapses the handle, < 0 mirrors it)");
  }
  if (!a.rotate.empty()) {
    const auto v = numbers(a.rotate, 4, "--rotate");
    h.transform.rotate_axis = Eigen::Vector3d(v[0], v[1], v[2]);
    if (!(h.transform.rotate_axis->norm() > 0))
      throw InvalidArgument("--rotate: the axis must not be zero");
    h.transform.rotate_degrees = v[3];
  }
  if (!a.translate.empty()) {
    const auto v = numbers(a.translate, 3, "--translate");
    h.transform.translate = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  request.handles.push_back(h);
  return request;
}

/// The request's options, then the flags over them.
EditorOptions editor_options(const EditRequest& request, const EditArgs& a) {
  EditorOptions options;
  apply_request_options(request, options);
  if (a.k > 0) options.system.k = a.k;
  if (!a.solver.empty()) options.solver.name = a.solver;
  if (!a.areas.empty()) options.system.areas = parse_area_weights(a.areas);
  if (!a.details.empty()) options.details = parse_detail_mode(a.details);
  if (!a.method.empty()) options.method = parse_edit_method(a.method);
  if (!a.energy.empty()) options.nonlinear.energy = parse_nonlinear_energy(a.energy);
  if (a.base_smoothing >= 0) options.base.smoothing = a.base_smoothing;
  if (a.base_feature_cap >= 0) options.base.feature_cap = a.base_feature_cap;
  if (a.length_factor > 0) options.remesh_options.length_factor = a.length_factor;
  if (a.no_remesh) options.remesh = false;
  options.threads = a.threads;
  options.memory_bytes = editor_memory_share(physical_memory_bytes(), 1);
  // The unsymmetric system needs a solver for it.
  if (options.system.areas == AreaWeights::Mixed && options.solver.name.empty())
    options.solver.name = "lu";
  return options;
}

struct Selection {
  std::vector<int> support;
  std::vector<std::vector<int>> handles;
};

/// The request's regions on the loaded mesh; throws InvalidArgument for a region that selects
/// nothing. Vertex ids in the request are the file's (the loader may drop or split vertices).
Selection select_regions(EditRequest& request, const LoadResult& loaded, const std::string& in) {
  const Mesh& mesh = loaded.mesh;
  map_file_vertex_ids(request.support, loaded.source_vertex);
  for (HandleSpec& h : request.handles) map_file_vertex_ids(h.region, loaded.source_vertex);
  Selection s{select_region(mesh, request.support), {}};
  if (s.support.empty()) {
    const BoundingBox box = bounding_box(mesh);
    throw InvalidArgument(fmt::format(
        "the support ({}) selects no vertex of {}; its bounding box is ({:.6g}, {:.6g}, {:.6g}) "
        "to ({:.6g}, {:.6g}, {:.6g})",
        describe(request.support), in, box.min[0], box.min[1], box.min[2], box.max[0], box.max[1],
        box.max[2]));
  }
  for (std::size_t j = 0; j < request.handles.size(); ++j) {
    s.handles.push_back(select_region(mesh, request.handles[j].region));
    if (s.handles.back().empty())
      throw InvalidArgument(fmt::format("handle {} ({}) selects no vertex of {}", j,
                                        describe(request.handles[j].region), in));
  }
  return s;
}

/// The figures after the edit: the largest move, and the detail retention in the support.
void report_edit(const EditArgs& a, Editor& editor, const Selection& s, double load_ms,
                 std::size_t refined) {
  const Mesh& mesh = editor.input();
  const Eigen::MatrixXd input = positions_matrix(mesh);
  const Eigen::MatrixXd& output = editor.positions();
  const double max_move =
      (output - input).rowwise().norm().maxCoeff() / bounding_box_diagonal(mesh);
  const double retention = detail_retention(editor, s.support);
  if (a.json) {
    nlohmann::json j = to_json(editor.report());
    j["milliseconds"]["load"] = load_ms;
    j["refined_vertices"] = refined;
    j["result"] = {
        {"output", a.out}, {"max_move_relative", max_move}, {"detail_retention", retention}};
    std::cout << dump_json(j, 2) << "\n";
    return;
  }
  print_edit_report(std::cout, editor.report(), load_ms, retention, max_move);
  std::cout << "wrote " << a.out << "\n";
}

void run_edit(const EditArgs& a) {
  format_from_path(a.out); // fail on an unknown extension before the long work
  EditRequest request = edit_request(a);
  if (request.handles.size() > static_cast<std::size_t>(a.max_handles))
    throw InvalidArgument(fmt::format("the edit has {} handles; at most {} are accepted "
                                      "(--max-handles)",
                                      request.handles.size(), a.max_handles));
  EditorOptions options = editor_options(request, a);
  const auto t0 = Clock::now();
  ReadLimits limits;
  limits.max_triangles = a.max_triangles;
  const LoadResult loaded = read_mesh(a.in, {}, limits);
  const double load_ms = ms_since(t0);
  // Regions first: a bad selection should fail before the preprocessing.
  Selection s = select_regions(request, loaded, a.in);
  Mesh mesh = loaded.mesh;
  std::size_t refined = 0;
  if (a.refine_support || request.refine_support.value_or(false)) {
    if (!options.remesh)
      throw InvalidArgument("--refine-support (EDIT.json \"refine_support\") splits the support "
                            "to the remeshed base's edge length; it does not combine with "
                            "--no-remesh (\"remesh\": false)");
    // The base's edge length on the input as loaded, kept for the refined one.
    if (options.remesh_options.target_length <= 0.0)
      options.remesh_options.target_length =
          options.remesh_options.length_factor * length_scale(mesh).length;
    // At most as many vertices as --max-triangles allows triangles: the editor's own limit.
    const std::size_t limit = a.max_triangles > 0 ? static_cast<std::size_t>(a.max_triangles)
                                                  : std::numeric_limits<std::size_t>::max();
    const RefineResult r =
        refine_region(mesh, s.support, options.remesh_options.target_length, limit);
    s.support = r.region;
    refined = r.added;
  }

  ProgressLine progress;
  options.progress = [&](std::string_view phase, int step, int steps) {
    progress.update(phase, step, steps);
  };
  Editor editor(std::move(mesh), options);
  progress.update("set_region", 0, 1);
  editor.set_region(s.support, s.handles);
  progress.finish();
  for (std::size_t j = 0; j < request.handles.size(); ++j) {
    const int h = static_cast<int>(j);
    editor.set_transform(h,
                         resolve_transform(request.handles[j].transform, editor.handle_center(h)));
  }
  const Mesh result = editor.result();
  write_mesh(a.out, result);
  if (a.report || a.json) {
    if (refined > 0 && !a.json)
      std::cout << "refined: " << grouped(refined) << " vertices added in the support\n";
    report_edit(a, editor, s, load_ms, refined);
    return;
  }
  std::cout << "wrote " << a.out << " (" << grouped(result.n_vertices()) << " vertices, "
            << grouped(result.n_faces()) << " faces; " << grouped(s.support.size())
            << " in the support"
            << (refined > 0 ? fmt::format(", {} added by --refine-support", grouped(refined)) : "")
            << ")\n";
}

} // namespace

void add_edit_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "edit", "Deform a mesh: move, rotate or scale handles; the support bends k-harmonically "
              "and the details ride along (paper section 3)");
  auto a = std::make_shared<EditArgs>();
  add_edit_options(cmd, *a);
  cmd->callback([a] { run_edit(*a); });
}

} // namespace remora::cli
