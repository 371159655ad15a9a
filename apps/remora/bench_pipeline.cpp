// `remora bench pipeline DIR`: every mesh of a data folder through the whole pipeline, with the
// checks an edit must pass on each: load with repair, the editor's preprocessing (base surface,
// area-equalizing remesh), a spherical support around the central vertex (within its connected
// component) with a spherical handle at its middle, the identity edit (the input to round-off),
// then a lift and a turn of the handle (finite positions, every vertex outside the support bit
// for bit where it was, the handle moved). Times per step in a Markdown table or JSON; exit code
// 1 when a check failed on any mesh (docs/benchmarks.md keeps the table).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "remora/common/error.h"
#include "remora/common/json.h"
#include "remora/common/timer.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/io.h"
#include "remora/mesh/topology.h"
#include "remora/multires/editor.h"
#include "report.h"

namespace remora::cli {

namespace {

namespace fs = std::filesystem;

struct PipelineArgs {
  std::string dir;
  double support = 0.2, handle = 0.05; // radii over the bounding-box diagonal
  int threads = 0;
  bool json = false;
};

struct PipelineRow {
  std::string mesh;
  std::size_t vertices = 0, faces = 0, base_vertices = 0, support = 0, handle = 0;
  double load_ms = 0, preprocess_ms = 0, set_region_ms = 0, frame_ms = 0;
  double identity_error = 0; ///< max |identity edit - input| / diagonal
  double handle_moved = 0;   ///< the handle's mean move along the lift, over the lift
  std::vector<std::string> failures;
};

/// The meshes of `dir`: the paths in backticks of its MANIFEST.md's table rows, else every mesh
/// file below it, sorted.
std::vector<fs::path> meshes_of(const fs::path& dir) {
  std::vector<fs::path> out;
  std::ifstream manifest(dir / "MANIFEST.md");
  for (std::string line; std::getline(manifest, line);) {
    if (line.rfind("| `", 0) != 0) continue;
    const std::size_t end = line.find('`', 3);
    if (end != std::string::npos) out.push_back(dir / line.substr(3, end - 3));
  }
  if (!out.empty()) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    try {
      format_from_path(e.path().string());
      out.push_back(e.path());
    } catch (const IoError&) {
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// The support (a ball within the central vertex's component) and the handle (a smaller ball
/// around the same vertex).
std::pair<std::vector<int>, std::vector<int>> region_of(const Mesh& mesh, const PipelineArgs& a) {
  const double diagonal = bounding_box_diagonal(mesh);
  const VertexHandle c = central_vertex(mesh);
  const std::vector<int> component = connected_components(mesh).vertex_component;
  std::vector<int> support, handle;
  for (const int v : select_sphere(mesh, mesh.point(c), a.support * diagonal))
    if (component[static_cast<std::size_t>(v)] == component[static_cast<std::size_t>(c.idx())])
      support.push_back(v);
  for (const int v : select_sphere(mesh, mesh.point(c), a.handle * diagonal))
    if (component[static_cast<std::size_t>(v)] == component[static_cast<std::size_t>(c.idx())])
      handle.push_back(v);
  return {support, handle};
}

/// The identity edit, then a lift by 5 % of the diagonal and a 10° turn about the handle's
/// centre, with their checks.
void check_edit(Editor& editor, const std::vector<int>& handle, PipelineRow& row) {
  const Mesh& input = editor.input();
  const double diagonal = bounding_box_diagonal(input);
  const Eigen::MatrixXd rest = positions_matrix(input);
  row.identity_error = (editor.positions() - rest).cwiseAbs().maxCoeff() / diagonal;
  if (!(row.identity_error <= 1e-9))
    row.failures.push_back(fmt::format("identity edit off by {:.2g}", row.identity_error));
  const Eigen::Vector3d lift(0, 0, 0.05 * diagonal);
  const Transform t =
      compose(translation(lift), rotation({1, 0, 0}, 10 * M_PI / 180, editor.handle_center(0)));
  editor.set_transform(0, t);
  const auto t0 = Clock::now();
  const Eigen::MatrixXd& p = editor.positions();
  row.frame_ms = ms_since(t0);
  if (!p.allFinite()) row.failures.push_back("non-finite positions");
  std::size_t far_moved = 0;
  for (Eigen::Index v = 0; v < p.rows(); ++v)
    if (!editor.in_support(static_cast<int>(v)) && p.row(v) != rest.row(v)) ++far_moved;
  if (far_moved > 0) row.failures.push_back(fmt::format("{} far vertices moved", far_moved));
  // The handle's vertices of O follow its base vertices through their details: those near its
  // rim decode against base triangles that also have free corners, so they move less than T.
  double along = 0;
  for (const int v : handle) along += (p.row(v) - rest.row(v)).dot(lift.transpose());
  row.handle_moved = along / double(handle.size()) / lift.squaredNorm();
  if (!(row.handle_moved >= 0.5 && row.handle_moved <= 1.5))
    row.failures.push_back(fmt::format("the handle moved {:.2f} of the lift", row.handle_moved));
}

PipelineRow run_one(const fs::path& path, const fs::path& dir, const PipelineArgs& a) {
  PipelineRow row;
  row.mesh = path.lexically_relative(dir).string();
  try {
    auto t0 = Clock::now();
    Mesh mesh = read_mesh(path.string()).mesh;
    row.load_ms = ms_since(t0);
    row.vertices = mesh.n_vertices();
    row.faces = mesh.n_faces();
    const auto [support, handle] = region_of(mesh, a);
    row.support = support.size();
    row.handle = handle.size();
    EditorOptions options;
    options.threads = a.threads;
    t0 = Clock::now();
    Editor editor(std::move(mesh), options);
    row.preprocess_ms = ms_since(t0);
    row.base_vertices = editor.base().n_vertices();
    t0 = Clock::now();
    editor.set_region(support, {handle});
    row.set_region_ms = ms_since(t0);
    check_edit(editor, handle, row);
  } catch (const Error& e) {
    row.failures.push_back(e.what());
  }
  return row;
}

void print_rows(const std::vector<PipelineRow>& rows, bool json) {
  if (json) {
    nlohmann::json out = nlohmann::json::array();
    for (const PipelineRow& r : rows)
      out.push_back({{"mesh", r.mesh},
                     {"vertices", r.vertices},
                     {"faces", r.faces},
                     {"base_vertices", r.base_vertices},
                     {"support", r.support},
                     {"handle", r.handle},
                     {"load_ms", r.load_ms},
                     {"preprocess_ms", r.preprocess_ms},
                     {"set_region_ms", r.set_region_ms},
                     {"frame_ms", r.frame_ms},
                     {"identity_error", r.identity_error},
                     {"handle_moved", r.handle_moved},
                     {"failures", r.failures}});
    std::cout << dump_json(out, 2) << "\n";
    return;
  }
  std::cout << "| mesh | V | F | base V | support | handle | load ms | preprocess ms | "
               "set_region ms | frame ms | identity / diag | handle moved | checks |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const PipelineRow& r : rows)
    std::cout << fmt::format(
        "| `{}` | {} | {} | {} | {} | {} | {:.0f} | {:.0f} | {:.0f} | {:.1f} | {:.1e} | {:.2f} | "
        "{} |\n",
        r.mesh, grouped(r.vertices), grouped(r.faces), grouped(r.base_vertices), grouped(r.support),
        grouped(r.handle), r.load_ms, r.preprocess_ms, r.set_region_ms, r.frame_ms,
        r.identity_error, r.handle_moved,
        r.failures.empty() ? "pass" : fmt::format("{}", fmt::join(r.failures, "; ")));
}

} // namespace

void add_bench_pipeline_command(CLI::App& bench) {
  auto* cmd = bench.add_subcommand(
      "pipeline", "Every mesh of a folder through load, preprocessing and an edit, with checks");
  auto a = std::make_shared<PipelineArgs>();
  cmd->add_option("dir", a->dir, "Folder of meshes (its MANIFEST.md's list, else every mesh file)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--support", a->support, "Support radius over the diagonal (default 0.2)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--handle", a->handle, "Handle radius over the diagonal (default 0.05)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--threads", a->threads, "Worker threads (default: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", a->json, "Print one JSON array");
  cmd->callback([a] {
    std::vector<PipelineRow> rows;
    for (const fs::path& path : meshes_of(a->dir)) {
      std::cerr << "pipeline: " << path.string() << std::endl;
      rows.push_back(run_one(path, a->dir, *a));
    }
    if (rows.empty()) throw InvalidArgument(a->dir + ": no mesh files found");
    print_rows(rows, a->json);
    const auto failed = std::count_if(rows.begin(), rows.end(),
                                      [](const PipelineRow& r) { return !r.failures.empty(); });
    if (failed > 0)
      throw Error(fmt::format("{} of {} meshes failed a check (the table says which)", failed,
                              rows.size()));
  });
}

} // namespace remora::cli
