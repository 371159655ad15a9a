// `remora bench bake`: the editor's bake (multires/bake.h; docs/benchmarks.md). Builds the editor,
// moves a geodesic support, and times the local bake of the result and its parts; with
// --compare also the full preprocess of the same result, and how far the two editors agree:
// their base surfaces, their bases' area figures, and their final surfaces after the same next
// edit. With --session N, N successive bakes through the browser editor's session (region, move,
// commit, next region) and the resident memory after each.
#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "remora/common/error.h"
#include "remora/common/json.h"
#include "remora/common/timer.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/quality.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/io.h"
#include "remora/multires/bake.h"
#include "report.h"
#include "session.h"

namespace remora::cli {

namespace {

struct BenchBakeArgs {
  std::string mesh = std::string(REMORA_REPO_DATA) + "/bunny.ply";
  int support = 31000; ///< input vertices moved
  int repeat = 3;
  double move = 0.05; ///< the handle's lift, in bounding-box diagonals
  double margin = BakeOptions{}.margin;
  double max_fraction = BakeOptions{}.max_fraction;
  bool compare = false;
  int session = 0;
  int threads = 0;
};

/// A geodesic support of `count` input vertices around `seed`, its innermost 3 % the handle.
std::pair<std::vector<int>, std::vector<int>> geodesic_region(const Mesh& mesh, VertexHandle seed,
                                                              std::size_t count) {
  std::vector<int> support = geodesic_order(mesh, seed, count);
  std::vector<int> handle(support.begin(),
                          support.begin() + static_cast<long>(support.size() * 3 / 100 + 1));
  std::sort(support.begin(), support.end());
  return {support, handle};
}

/// The handle lifted by `lift` along the seed's normal and turned by 0.3 rad about an axis across.
Transform lift_and_turn(const Editor& editor, VertexHandle seed, double lift) {
  Mesh mesh = editor.input();
  mesh.request_vertex_normals();
  mesh.request_face_normals();
  mesh.update_normals();
  const Vec3 n = mesh.normal(seed);
  const Eigen::Vector3d normal(n[0], n[1], n[2]);
  const Eigen::Vector3d across = normal.unitOrthogonal();
  const Eigen::Vector3d center = editor.handle_center(0);
  return compose(translation(lift * normal), rotation(across, 0.3, center));
}

struct BaseFigures {
  double rel_mad = 0, mean_angle_deviation = 0, min_angle = 0, band = 0, defect = 0;
};

BaseFigures base_figures(const Editor& editor) {
  const Mesh& base = editor.base();
  const MeshQuality q = mesh_quality(base);
  const double l = editor.report().base_target_length;
  return {q.mixed_area.rel_mad, q.angles.mean_abs_deviation_from_60_deg, q.angles.min_deg,
          percent_edges_within(base, 0.8 * l, 4.0 / 3.0 * l), laplacian_symmetry_defect(base)};
}

nlohmann::json to_json(const BaseFigures& f) {
  return {{"rel_mad", f.rel_mad},
          {"mean_abs_deviation_deg", f.mean_angle_deviation},
          {"min_angle_deg", f.min_angle},
          {"edges_in_band_percent", f.band},
          {"symmetry_defect", f.defect}};
}

/// Mean and largest row distance of a and b over the diagonal.
std::pair<double, double> distances(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                    double diagonal) {
  const Eigen::VectorXd d = (a - b).rowwise().norm();
  return {d.mean() / diagonal, d.maxCoeff() / diagonal};
}

/// The local and the full bake of the same edit, and the same next edit (a support 1.5 times
/// as large around the same seed, lifted the other way) on both.
nlohmann::json compare(Editor& edited, Editor& local, const BenchBakeArgs& a, VertexHandle seed) {
  const auto t0 = Clock::now();
  BakeOptions full_options;
  full_options.force_full = true;
  BakeResult full = bake(edited, full_options);
  const double full_ms = ms_since(t0);
  const double diagonal = bounding_box_diagonal(edited.input());
  const auto [s_mean, s_max] =
      distances(local.parts().smooth, full.editor.parts().smooth, diagonal);
  // S + F(O' - O) with F solved on the whole mesh: the band's truncation, and what the metric of
  // O' (the full preprocess's filter) changes.
  const EditorPartsView old = edited.parts();
  const Eigen::MatrixXd global =
      old.smooth + old.filter->apply(edited.positions() - old.input_positions);
  const auto [t_mean, t_max] = distances(local.parts().smooth, global, diagonal);
  const auto [m_mean, m_max] = distances(global, full.editor.parts().smooth, diagonal);
  // A second full preprocess whose base is another, equally good remesh (l 1 % shorter): how far
  // two bases of the same shape put the same next edit apart.
  EditorOptions other = edited.options();
  other.remesh_options.length_factor *= 0.99;
  Editor floor(edited.result(), other);
  const auto [support, handle] =
      geodesic_region(local.input(), seed, static_cast<std::size_t>(1.5 * a.support));
  Eigen::MatrixXd after[3];
  Editor* editors[3] = {&local, &full.editor, &floor};
  for (int e = 0; e < 3; ++e) {
    editors[e]->set_region(support, {handle});
    editors[e]->set_transform(0, lift_and_turn(*editors[e], seed, -a.move));
    after[e] = editors[e]->positions();
  }
  const auto [p_mean, p_max] = distances(after[0], after[1], diagonal);
  const auto [f_mean, f_max] = distances(after[2], after[1], diagonal);
  return {{"full_ms", full_ms},
          {"smooth_distance", {{"mean", s_mean}, {"max", s_max}}},
          {"band_truncation", {{"mean", t_mean}, {"max", t_max}}},
          {"metric_change", {{"mean", m_mean}, {"max", m_max}}},
          {"next_edit_distance", {{"mean", p_mean}, {"max", p_max}}},
          {"next_edit_two_full", {{"mean", f_mean}, {"max", f_max}}},
          {"base_local", to_json(base_figures(local))},
          {"base_full", to_json(base_figures(full.editor))}};
}

/// CPU time of the process, all threads, in milliseconds (the wall time of a shared machine
/// says little about a part's own work).
double cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

long resident_kb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return 0;
}

/// `bakes` successive bakes through a session: region, move, commit; the resident memory and
/// the region job's time after each.
nlohmann::json session_bakes(const BenchBakeArgs& a, int bakes) {
  server::SessionOptions so;
  so.threads = a.threads;
  server::Session session(so);
  std::ifstream file(a.mesh, std::ios::binary);
  std::stringstream bytes;
  bytes << file.rdbuf();
  session.start_load(bytes.str(), a.mesh);
  session.wait();
  const Mesh mesh = read_mesh(a.mesh).mesh;
  const VertexHandle seed = central_vertex(mesh);
  const auto [support, handle] = geodesic_region(mesh, seed, static_cast<std::size_t>(a.support));
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i <= bakes; ++i) {
    const auto t0 = Clock::now();
    session.start_region(support, {handle}, 2);
    session.wait();
    const double ms = ms_since(t0);
    const nlohmann::json status = session.status();
    if (status.contains("error")) throw Error("bench bake: " + status["error"].get<std::string>());
    rows.push_back({{"region_ms", ms},
                    {"rss_mb", static_cast<double>(resident_kb()) / 1024.0},
                    {"status", status["base"]}});
    const double s = (i % 2 == 0 ? 1.0 : -1.0) * a.move * bounding_box_diagonal(mesh);
    session.set_transform(0, translation(Eigen::Vector3d(0, s, 0)));
    session.commit();
  }
  return rows;
}

void run_bench_bake(const BenchBakeArgs& a) {
  nlohmann::json out;
  if (a.session > 0) {
    out["session"] = session_bakes(a, a.session);
    std::cout << dump_json(out, 2) << "\n";
    return;
  }
  const Mesh mesh = read_mesh(a.mesh).mesh;
  EditorOptions options;
  options.threads = a.threads;
  auto t0 = Clock::now();
  Editor editor(mesh, options);
  out["preprocess_ms"] = ms_since(t0);
  const VertexHandle seed = central_vertex(mesh);
  const auto [support, handle] = geodesic_region(mesh, seed, static_cast<std::size_t>(a.support));
  editor.set_region(support, {handle});
  editor.set_transform(0, lift_and_turn(editor, seed, a.move * bounding_box_diagonal(mesh)));
  std::vector<nlohmann::json> runs;
  std::optional<BakeResult> last;
  for (int r = 0; r < a.repeat; ++r) {
    last.reset();
    BakeOptions bo;
    bo.margin = a.margin;
    bo.max_fraction = a.max_fraction;
    const double cpu0 = cpu_ms();
    last.emplace(bake(editor, bo));
    const double cpu = cpu_ms() - cpu0;
    const BakeReport& b = last->report;
    runs.push_back({{"local", b.local},
                    {"cpu_ms", cpu},
                    {"fallback", b.fallback},
                    {"milliseconds", b.milliseconds},
                    {"cpu_milliseconds", b.cpu_milliseconds},
                    {"changed", b.changed_vertices},
                    {"band", b.band_vertices},
                    {"moved_base", b.moved_base_vertices},
                    {"patch_faces", b.patch_faces},
                    {"patch_faces_after", b.patch_faces_after},
                    {"reference_faces", b.reference_faces},
                    {"rewalked", b.rewalked_input_vertices}});
  }
  out["bakes"] = runs;
  if (a.compare) out["compare"] = compare(editor, last->editor, a, seed);
  std::cout << dump_json(out, 2) << "\n";
}

} // namespace

void add_bench_bake_command(CLI::App& bench) {
  auto* cmd = bench.add_subcommand(
      "bake", "The editor's bake after a move: local, against the full preprocess, over time");
  auto a = std::make_shared<BenchBakeArgs>();
  cmd->add_option("mesh", a->mesh, "Mesh (default: the bundled bunny)");
  cmd->add_option("--support", a->support, "Input vertices in the moved support (default 31000)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--repeat", a->repeat, "Bakes of the same edit to time (default 3)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--move", a->move, "The handle's lift in bounding-box diagonals (0.05)");
  cmd->add_option("--margin", a->margin, "The filter's band in σ (BakeOptions::margin)");
  cmd->add_option("--max-fraction", a->max_fraction,
                  "The band's or patch's share above which the full preprocess runs");
  cmd->add_flag("--compare", a->compare,
                "Also the full preprocess, and the agreement after the same next edit");
  cmd->add_option("--session", a->session,
                  "N successive bakes through the server's session, with the memory after each")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--threads", a->threads, "Worker threads (default: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([a] { run_bench_bake(*a); });
}

} // namespace remora::cli
