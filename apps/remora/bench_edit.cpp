// `remora bench edit`: the editing kernel's timings (docs/benchmarks.md): preprocessing
// (base surface + remesh), set_region (map, factor, 3 + 4h basis functions, Phong encoding) for a
// geodesic support of a given number of free base vertices, and the time per frame (blend +
// decode, no solve) over a sequence of handle moves; with --bake-first, the regions and frames
// on the base baked after a move of a smaller region around the same seed (they then cross its
// patch).
#include <algorithm>
#include <iostream>
#include <map>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "remora/common/error.h"
#include "remora/common/json.h"
#include "remora/common/memory.h"
#include "remora/common/timer.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/io.h"
#include "remora/multires/bake.h"
#include "remora/multires/editor.h"
#include "remora/multires/limits.h"
#include "report.h"

namespace remora::cli {

namespace {

struct BenchEditArgs {
  std::string mesh = std::string(REMORA_REPO_DATA) + "/bunny.ply";
  int support = 31000, frames = 60, k = 2, threads = 0, regions = 1, bake_first = 0;
  std::string solver, method = "linear", energy = "rotated-laplacian";
  double frame_budget_ms = 6.0;
  bool json = false, no_prepare = false;
};

struct BenchEditTimes {
  double load_ms = 0, preprocess_ms = 0, warm_ms = 0, prepare_ms = 0, set_region_ms = 0;
  /// --regions: the later regions' set_region and its parts (medians)
  std::map<std::string, double> later_regions;
  std::vector<double> frames;                ///< sorted
  std::map<std::string, double> frame_parts; ///< medians of blend, normals, decode (nonlinear)
  double converge_ms = 0;                    ///< nonlinear: after the last frame, to converged
  int converge_iterations = 0;
  std::map<std::string, double> preprocess_parts; ///< base, remesh, base report
  double bake_ms = 0;                             ///< --bake-first: the bake
  std::string bake; ///< --bake-first: "local", or why it was a full re-preprocess
  std::map<std::string, double> bake_parts; ///< --bake-first: the bake report's milliseconds
};

/// A geodesic support around `seed` (the vertex nearest the centroid), sized so that about `support`
/// base vertices are free (times `grow`), and its innermost 3 % as the handle. Returns the
/// milliseconds of set_region alone (not the selection's).
double set_geodesic_region(Editor& editor, VertexHandle seed, int support, double grow = 1.0) {
  const Mesh& mesh = editor.input();
  const double ratio = double(mesh.n_vertices()) / double(editor.base().n_vertices());
  const auto wanted = static_cast<std::size_t>(
      std::min(double(support) * 1.03 * grow, 0.9 * double(editor.base().n_vertices())) * ratio);
  const std::vector<int> order = geodesic_order(mesh, seed, wanted);
  const std::vector<int> handle(order.begin(),
                                order.begin() + static_cast<long>(order.size() * 3 / 100 + 1));
  const auto t0 = Clock::now();
  editor.set_region(order, {handle});
  return ms_since(t0);
}

/// positions(budget) after each of `count` handle moves (a lift and a turn), in milliseconds,
/// sorted; the medians of the frame's parts (blend, normals, decode, and for the nonlinear method
/// its iterations and their count) go to `parts`.
std::vector<double> time_frames(Editor& editor, int count, double budget_ms,
                                std::map<std::string, double>& parts) {
  std::map<std::string, std::vector<double>> part_times;
  const double diagonal = bounding_box_diagonal(editor.input());
  const Eigen::Vector3d center = editor.handle_center(0);
  std::vector<double> frames;
  for (int f = 1; f <= count; ++f) {
    const double s = double(f) / count;
    editor.set_transform(0, compose(translation(Eigen::Vector3d(0, 0.05 * s * diagonal, 0)),
                                    rotation({1, 0, 0}, 0.5 * s, center)));
    const auto t0 = Clock::now();
    const Eigen::MatrixXd& p = editor.positions(budget_ms);
    frames.push_back(ms_since(t0));
    if (!p.allFinite()) throw NumericalError("bench edit: a frame has non-finite positions");
    const EditReport& r = editor.report();
    for (const char* part : {"blend", "normals", "decode", "nonlinear"})
      if (r.milliseconds.count(std::string("frame ") + part))
        part_times[part].push_back(r.milliseconds.at(std::string("frame ") + part));
    if (r.method == "nonlinear") part_times["iterations"].push_back(r.nonlinear.iterations);
  }
  std::sort(frames.begin(), frames.end());
  for (auto& [part, times] : part_times) {
    std::sort(times.begin(), times.end());
    parts[part] = times[times.size() / 2];
  }
  return frames;
}

/// Regions 2 .. a.regions, each 1 % larger than the one before (a stroke painted on), as a
/// session meets them after its first: medians of set_region and its parts; the first region
/// set again at the end (from the recent regions, or solved again).
void time_later_regions(Editor& editor, VertexHandle seed, const BenchEditArgs& a,
                        BenchEditTimes& t) {
  if (a.regions < 2) return;
  std::map<std::string, std::vector<double>> times;
  std::size_t free_before = editor.report().free_base_vertices;
  for (int r = 1; r < a.regions; ++r) {
    times["set_region"].push_back(set_geodesic_region(editor, seed, a.support, 1.0 + 0.01 * r));
    if (editor.report().free_base_vertices <= free_before)
      throw InvalidArgument(fmt::format(
          "bench edit --regions: region {} is no larger than the one before it (the support is "
          "capped at 90 % of the base's vertices); use a smaller --support or fewer --regions",
          r + 1));
    free_before = editor.report().free_base_vertices;
    for (const char* part : {"map", "assemble", "factor", "solve", "encode", "finish"})
      times[part].push_back(editor.report().milliseconds.at(part));
  }
  for (auto& [part, v] : times) {
    std::sort(v.begin(), v.end());
    t.later_regions[part] = v[v.size() / 2];
  }
  set_geodesic_region(editor, seed, a.support);
}

void print_bench_edit(const BenchEditArgs& a, const EditReport& r, const BenchEditTimes& t) {
  const double median = t.frames[t.frames.size() / 2];
  if (a.json) {
    nlohmann::json j = to_json(r);
    j["bench"] = {{"mesh", a.mesh},
                  {"load_ms", t.load_ms},
                  {"preprocess_ms", t.preprocess_ms},
                  {"warm_heap_ms", t.warm_ms},
                  {"prepare_regions_ms", t.prepare_ms},
                  {"set_region_ms", t.set_region_ms},
                  {"frame_ms_median", median},
                  {"frame_ms_max", t.frames.back()},
                  {"frame_parts_ms_median", t.frame_parts},
                  {"frames", t.frames.size()},
                  {"later_regions_ms_median", t.later_regions},
                  {"method", a.method},
                  {"frame_budget_ms", a.frame_budget_ms},
                  {"converge_ms", t.converge_ms},
                  {"converge_iterations", t.converge_iterations},
                  {"bake_first", a.bake_first},
                  {"bake_first_ms", t.bake_ms},
                  {"bake_first_kind", t.bake},
                  {"bake_first_parts_ms", t.bake_parts},
                  {"preprocess_parts_ms", t.preprocess_parts}};
    std::cout << dump_json(j, 2) << "\n";
    return;
  }
  std::cout << fmt::format("mesh {}: {} vertices, {} faces; base {} vertices\n", a.mesh,
                           grouped(r.input_vertices), grouped(r.input_faces),
                           grouped(r.base_vertices));
  std::cout << fmt::format(
      "preprocess {:.0f} ms (base {:.0f}, remesh {:.0f}, report {:.0f}); "
      "heap warmed for a region in {:.0f} ms and regions prepared in {:.0f} ms, "
      "as remora serve does\n",
      t.preprocess_ms, t.preprocess_parts.at("base"), t.preprocess_parts.at("remesh"),
      t.preprocess_parts.at("base report"), t.warm_ms, t.prepare_ms);
  if (a.bake_first > 0)
    std::cout << fmt::format("a move of a region of {} free base vertices baked in {:.0f} ms ({}); "
                             "the regions below are on the baked base, across its patch\n",
                             grouped(static_cast<std::size_t>(a.bake_first)), t.bake_ms, t.bake);
  std::cout << fmt::format(
      "set_region {:.0f} ms for {} free base vertices, {} handle base "
      "vertices, k = {} (map {:.0f}, assemble {:.0f}, factor {:.0f}, solve {:.0f}, "
      "encode {:.0f} of {} vertices, finish {:.0f}) with {}\n",
      t.set_region_ms, grouped(r.free_base_vertices), grouped(r.handle_base_vertices.at(0)), a.k,
      r.milliseconds.at("map"), r.milliseconds.at("assemble"), r.milliseconds.at("factor"),
      r.milliseconds.at("solve"), r.milliseconds.at("encode"), grouped(r.phong.encoded),
      r.milliseconds.at("finish"),
      r.solver_stats.separator_rows > 0
          ? fmt::format("{} in two halves (separator {} rows{})", r.solver,
                        grouped(static_cast<std::size_t>(r.solver_stats.separator_rows)),
                        r.solver_stats.keyed_order ? ", in the base's order" : "")
          : r.solver);
  if (!t.later_regions.empty())
    std::cout << fmt::format(
        "set_region, regions 2 to {} (each 1 % larger): median {:.0f} ms (map {:.0f}, assemble "
        "{:.0f}, factor {:.0f}, solve {:.0f}, encode {:.0f}, finish {:.0f})\n",
        a.regions, t.later_regions.at("set_region"), t.later_regions.at("map"),
        t.later_regions.at("assemble"), t.later_regions.at("factor"), t.later_regions.at("solve"),
        t.later_regions.at("encode"), t.later_regions.at("finish"));
  std::cout << fmt::format("frame (blend + decode): median {:.2f} ms, max {:.2f} ms over {} "
                           "frames (medians: blend {:.2f}, normals {:.2f}, decode {:.2f})\n",
                           median, t.frames.back(), t.frames.size(), t.frame_parts.at("blend"),
                           t.frame_parts.at("normals"), t.frame_parts.at("decode"));
  if (a.method == "nonlinear")
    std::cout << fmt::format(
        "nonlinear: per frame (budget {:.1f} ms) median {:.2f} ms, {:.0f} iterations; after the "
        "last frame converged in {:.0f} ms, {} iterations{}\n",
        a.frame_budget_ms, t.frame_parts.at("nonlinear"), t.frame_parts.at("iterations"),
        t.converge_ms, t.converge_iterations, r.fallback.empty() ? "" : " (" + r.fallback + ")");
}

void run_bench_edit(const BenchEditArgs& a) {
  BenchEditTimes t;
  auto t0 = Clock::now();
  const Mesh mesh = read_mesh(a.mesh).mesh;
  t.load_ms = ms_since(t0);
  const VertexHandle seed = central_vertex(mesh); // the input's ids outlive a bake
  EditorOptions options;
  options.system.k = a.k;
  options.solver.name = a.solver;
  options.threads = a.threads;
  options.method = parse_edit_method(a.method);
  options.nonlinear.energy = parse_nonlinear_energy(a.energy);
  ProgressLine progress;
  options.progress = [&](std::string_view phase, int step, int steps) {
    progress.update(phase, step, steps);
  };
  t0 = Clock::now();
  std::optional<Editor> edited(std::in_place, mesh, options);
  t.preprocess_ms = ms_since(t0);
  for (const char* part : {"base", "remesh", "base report"})
    t.preprocess_parts[part] = edited->report().milliseconds.at(part);
  progress.finish();
  t0 = Clock::now();
  warm_heap(warm_heap_bytes(edited->base().n_vertices(), a.k));
  t.warm_ms = ms_since(t0);
  t0 = Clock::now();
  if (!a.no_prepare) edited->prepare_regions();
  t.prepare_ms = ms_since(t0);
  if (a.bake_first > 0) { // a lift of a smaller region around the same seed, baked
    set_geodesic_region(*edited, seed, a.bake_first);
    const double diagonal = bounding_box_diagonal(edited->input());
    edited->set_transform(0, translation(Eigen::Vector3d(0, 0.01 * diagonal, 0)));
    t0 = Clock::now();
    BakeResult baked = remora::bake(*edited);
    t.bake_ms = ms_since(t0);
    progress.finish();
    t.bake = baked.report.local ? "local" : "full: " + baked.report.fallback;
    t.bake_parts = baked.report.milliseconds;
    edited.emplace(std::move(baked.editor));
  }
  Editor& editor = *edited;
  t.set_region_ms = set_geodesic_region(editor, seed, a.support);
  const EditReport first = editor.report(); // the later regions' reports replace it
  time_later_regions(editor, seed, a, t);
  t.frames = time_frames(editor, a.frames, a.frame_budget_ms, t.frame_parts);
  // The drag stops: the nonlinear iteration goes on to convergence.
  int iterations = 0;
  t0 = Clock::now();
  while (!editor.converged()) {
    editor.positions(a.frame_budget_ms);
    iterations += editor.report().nonlinear.iterations;
  }
  t.converge_ms = ms_since(t0);
  t.converge_iterations = iterations;
  // The first region's times (the later ones set it again at the end: its figures, not its times)
  EditReport r = editor.report();
  for (const auto& [key, ms] : first.milliseconds)
    if (key.rfind("frame", 0) != 0) r.milliseconds[key] = ms;
  print_bench_edit(a, r, t);
}

} // namespace

void add_bench_edit_command(CLI::App& bench) {
  auto* cmd = bench.add_subcommand(
      "edit", "The editor: preprocessing, set_region and per-frame times on a geodesic support");
  auto a = std::make_shared<BenchEditArgs>();
  cmd->add_option("mesh", a->mesh, "Mesh (default: the bundled bunny)");
  cmd->add_option("--support", a->support,
                  "Free base vertices wanted in the support (default 31000; capped at 90 % of "
                  "the base)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--frames", a->frames, "Handle moves to time (default 60)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--regions", a->regions,
                  "Set this many regions, each 1 % larger than the one before, and report the "
                  "later ones' median set_region too (default 1)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--k", a->k, "Order k (default 2)")->check(CLI::Range(1, 3));
  cmd->add_option("--solver", a->solver, "Solver (default: the direct one)");
  cmd->add_option("--method", a->method, "linear (default) or nonlinear")
      ->check(CLI::IsMember({"linear", "nonlinear"}));
  cmd->add_option("--energy", a->energy,
                  "Nonlinear: rotated-laplacian (default), propagated, blended-motions or arap "
                  "(docs/editing.md)")
      ->check(CLI::IsMember(nonlinear_energy_names()));
  cmd->add_option("--frame-budget", a->frame_budget_ms,
                  "Nonlinear: milliseconds of iterations per frame while dragging (default 6)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--threads", a->threads, "Worker threads (default: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--no-prepare", a->no_prepare,
                "Assemble and order each region by itself, without the rows and the nested "
                "dissection of the whole base that remora serve prepares "
                "(Editor::prepare_regions, docs/solvers.md)");
  cmd->add_option("--bake-first", a->bake_first,
                  "First move a region of this many free base vertices around the same seed and "
                  "bake it (multires/bake.h), then time everything on the baked base: regions "
                  "across the bake's patch (default 0: no bake)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] { run_bench_edit(*a); });
}

} // namespace remora::cli
