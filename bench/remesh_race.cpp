// The race against CGAL: remora::remesh() and CGAL::Polygon_mesh_processing::isotropic_remeshing
// on the same meshes with the same target edge length l and the same number of cycles, timed in
// alternating runs (wall clock and process CPU time, so that our threads count in full), with the
// quality figures of both outputs. Built only with -DREMORA_WITH_CGAL=ON: CGAL is GPL and stays out
// of the library and the default build. Results go to docs/benchmarks.md with the machine.
//
//   remora_bench_remesh [--repeat N] [--cycles N] [--large] [--json] [--threads T]
//                       [--cgal-relax-boundary] [--write-dir DIR] [mesh files...]
//
// Without files: the CI meshes of ../shared/data/MANIFEST.md that load as manifolds (plus
// derived/igea_sub4.ply with --large). l = 0.9 x the loaded mesh's length scale (its mean edge
// length unless needles inflate it), as remesh() computes it; for both the number of cycles
// Remora's default options run on the mesh (at least 7, more while the cycles still change a CAD
// part: the first run of ours tells it), or exactly --cycles N for both. Ours runs twice per
// round: default options (cycles + the default equalization iterations) and cycles only
// (equalize_iterations = 0, the like-for-like comparison). CGAL keeps the mesh boundary by
// default: boundary edges are split at midpoints and collapsed onto boundary vertices, boundary
// vertices are not smoothed (--cgal-relax-boundary lets them slide along chords of the boundary
// polyline instead, which leaves the input boundary).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/version.h>
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "remora/common/memory.h"
#include "remora/common/timer.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/quality.h"
#include "remora/mesh/io.h"
#include "remora/remesh/remesh.h"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using remora::Clock;
using remora::ms_since;

constexpr double kLengthFactor = 0.9;

struct Args {
  int repeat = 3;
  int cycles = 0; // for both contenders; 0: as many as Remora's default options run
  bool large = false;
  bool json = false;
  int threads = 0;
  bool cgal_relax_boundary = false;
  double feature_angle = 0; // both keep the input's feature lines (0: none)
  bool fresh_memory = false;
  std::string write_dir;
  std::vector<std::string> files;
};

// ---------------------------------------------------------------------------------------------
// Timing

struct Timing {
  double wall_ms = 0;
  double cpu_ms = 0;
};

// Wall clock and process CPU time (all threads) of one call of f.
template <class F>
Timing timed(F&& f) {
  const std::clock_t c0 = std::clock();
  const auto t0 = Clock::now();
  f();
  const double wall_ms = ms_since(t0);
  const std::clock_t c1 = std::clock();
  return {wall_ms, 1000.0 * static_cast<double>(c1 - c0) / static_cast<double>(CLOCKS_PER_SEC)};
}

// ---------------------------------------------------------------------------------------------
// Conversions (never timed)

SurfaceMesh to_cgal(const remora::Mesh& mesh) {
  SurfaceMesh sm;
  sm.reserve(static_cast<SurfaceMesh::size_type>(mesh.n_vertices()),
             static_cast<SurfaceMesh::size_type>(mesh.n_edges()),
             static_cast<SurfaceMesh::size_type>(mesh.n_faces()));
  std::vector<SurfaceMesh::Vertex_index> map(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    const remora::Vec3& p = mesh.point(v);
    map[v.idx()] = sm.add_vertex(Kernel::Point_3(p[0], p[1], p[2]));
  }
  for (auto f : mesh.faces()) {
    std::array<SurfaceMesh::Vertex_index, 3> idx;
    std::size_t k = 0;
    for (auto v : mesh.fv_range(f)) idx.at(k++) = map[v.idx()];
    if (sm.add_face(idx[0], idx[1], idx[2]) == SurfaceMesh::null_face())
      throw std::runtime_error("CGAL::Surface_mesh rejected face " + std::to_string(f.idx()));
  }
  return sm;
}

remora::Mesh from_cgal(const SurfaceMesh& sm) {
  remora::Mesh mesh;
  mesh.reserve(sm.number_of_vertices(), sm.number_of_edges(), sm.number_of_faces());
  std::vector<remora::VertexHandle> map(sm.num_vertices());
  for (auto v : sm.vertices()) {
    const Kernel::Point_3& p = sm.point(v);
    map[v.idx()] = mesh.add_vertex(remora::Vec3(p.x(), p.y(), p.z()));
  }
  for (auto f : sm.faces()) {
    std::vector<remora::VertexHandle> vs;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) vs.push_back(map[v.idx()]);
    if (vs.size() != 3)
      throw std::runtime_error("CGAL output has a face with " + std::to_string(vs.size()) +
                               " vertices");
    if (!mesh.add_face(vs).is_valid())
      throw std::runtime_error("CGAL output face " + std::to_string(f.idx()) +
                               " is not manifold for OpenMesh");
  }
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// Figures

struct Segment {
  remora::Vec3 a, b;
};

std::vector<Segment> boundary_segments(const remora::Mesh& mesh) {
  std::vector<Segment> segments;
  for (auto h : mesh.halfedges())
    if (mesh.is_boundary(h))
      segments.push_back(
          {mesh.point(mesh.from_vertex_handle(h)), mesh.point(mesh.to_vertex_handle(h))});
  return segments;
}

double point_segment_distance(const remora::Vec3& p, const Segment& s) {
  const remora::Vec3 d = s.b - s.a;
  const double dd = d.sqrnorm();
  const double t = dd > 0 ? std::clamp(OpenMesh::dot(p - s.a, d) / dd, 0.0, 1.0) : 0.0;
  return (p - (s.a + t * d)).norm();
}

struct OutputFigures {
  std::size_t faces = 0;
  std::size_t vertices = 0;
  std::size_t boundary_loops = 0;
  std::size_t isolated_vertices = 0;
  double min_angle_deg = 0;
  double mean_abs_deviation_from_60_deg = 0;
  double mixed_area_rel_mad = 0;
  double mean_edge_over_l = 0;
  double percent_edges_in_band = 0; ///< edge length in [4/5 l, 4/3 l]
  double percent_interior_valence_6 = 0;
  /// Largest distance of an output boundary vertex to the input boundary, in units of l; NaN
  /// when the output has a boundary and the input has none.
  double boundary_deviation_over_l = 0;
};

OutputFigures output_figures(const remora::Mesh& mesh, double l,
                             const std::vector<Segment>& input_boundary) {
  const remora::MeshQuality q = remora::mesh_quality(mesh);
  OutputFigures out;
  out.faces = q.faces;
  out.vertices = q.vertices;
  out.boundary_loops = q.boundary_loops;
  out.isolated_vertices = q.isolated_vertices;
  out.min_angle_deg = q.angles.min_deg;
  out.mean_abs_deviation_from_60_deg = q.angles.mean_abs_deviation_from_60_deg;
  out.mixed_area_rel_mad = q.mixed_area.rel_mad;
  out.percent_interior_valence_6 = q.valence.percent_interior_6;
  out.mean_edge_over_l = q.edge_length.mean / l;
  out.percent_edges_in_band = remora::percent_edges_within(mesh, 0.8 * l, 4.0 / 3.0 * l);
  double deviation = 0;
  for (auto v : mesh.vertices()) {
    if (!mesh.is_boundary(v) || mesh.is_isolated(v)) continue;
    if (input_boundary.empty()) {
      deviation = std::numeric_limits<double>::quiet_NaN();
      break;
    }
    double d = std::numeric_limits<double>::infinity();
    for (const Segment& s : input_boundary)
      d = std::min(d, point_segment_distance(mesh.point(v), s));
    deviation = std::max(deviation, d);
  }
  out.boundary_deviation_over_l = deviation / l;
  return out;
}

// ---------------------------------------------------------------------------------------------
// One mesh

struct Variant {
  std::string name;
  std::vector<Timing> runs;
  OutputFigures figures;
  std::map<std::string, double> phase_ms; ///< ours: remesh()'s phases in the fastest run

  double best_wall() const {
    double b = std::numeric_limits<double>::infinity();
    for (const Timing& t : runs) b = std::min(b, t.wall_ms);
    return b;
  }
  double best_cpu() const {
    double b = std::numeric_limits<double>::infinity();
    for (const Timing& t : runs) b = std::min(b, t.cpu_ms);
    return b;
  }
  double us_per_triangle(double ms) const {
    return figures.faces ? 1000.0 * ms / static_cast<double>(figures.faces) : 0.0;
  }
};

struct MeshRace {
  std::string name;
  std::string path;
  std::string status = "ok"; ///< "ok", "missing" or "error"
  std::string error;
  std::size_t input_faces = 0;
  std::size_t input_vertices = 0;
  std::size_t input_boundary_loops = 0;
  double target_length = 0;
  double load_ms = 0;
  int cycles = 0; ///< cycles both ran
  Variant ours_eq{
      fmt::format("ours (+{} equalize)", remora::RemeshOptions{}.equalize_iterations), {}, {}, {}};
  Variant ours_cycles{"ours (cycles only)", {}, {}, {}};
  Variant cgal{"CGAL " CGAL_VERSION_STR, {}, {}, {}};
};

std::string mesh_name(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

void race(MeshRace& r, const Args& args) {
  const auto t0 = Clock::now();
  const remora::LoadResult loaded = remora::read_mesh(r.path);
  r.load_ms = ms_since(t0);
  const remora::Mesh& input = loaded.mesh;
  r.input_faces = input.n_faces();
  r.input_vertices = input.n_vertices();
  r.input_boundary_loops = remora::mesh_quality(input).boundary_loops;
  const double l = kLengthFactor * remora::length_scale(input).length; // the default l
  r.target_length = l;

  remora::RemeshOptions eq_options;
  eq_options.target_length = l; // what the default (length_factor 0.9) gives; explicit = same l
  if (args.cycles > 0) eq_options.cycles = eq_options.max_cycles = args.cycles;
  r.cycles = args.cycles; // else known after ours' first run
  eq_options.threads = args.threads;
  eq_options.feature_angle_deg = args.feature_angle;
  // CGAL computes no quality figures either; both outputs are measured afterwards, untimed.
  eq_options.compute_report = false;
  remora::RemeshOptions cycles_options = eq_options;
  cycles_options.equalize_iterations = 0;

  // With --feature-angle, CGAL's own detection (the same dihedral test) marks the lines it
  // keeps; its constrained edges may still be split and collapsed along them.
  SurfaceMesh cgal_marked = to_cgal(input);
  auto constrained =
      cgal_marked.add_property_map<SurfaceMesh::Edge_index, bool>("e:constrained", false).first;
  if (args.feature_angle > 0)
    CGAL::Polygon_mesh_processing::detect_sharp_edges(cgal_marked, args.feature_angle, constrained);
  // The map of the mesh being remeshed (the copy carries the property along).
  auto cgal_parameters = [&](SurfaceMesh& sm) {
    return CGAL::parameters::number_of_iterations(r.cycles)
        .protect_constraints(false)
        .relax_constraints(args.cgal_relax_boundary)
        .edge_is_constrained_map(
            sm.property_map<SurfaceMesh::Edge_index, bool>("e:constrained").first);
  };

  std::optional<remora::Mesh> ours_eq_out, ours_cycles_out;
  std::optional<SurfaceMesh> cgal_out;
  auto run_ours = [&](Variant& variant, const remora::RemeshOptions& options,
                      std::optional<remora::Mesh>& out) {
    std::optional<remora::RemeshResult> result;
    const Timing t = timed([&] { result.emplace(remora::remesh(input, options)); });
    if (variant.runs.empty() || t.wall_ms < variant.best_wall())
      variant.phase_ms = result->report.milliseconds;
    if (r.cycles == 0) { // the count Remora's options ran: CGAL and the cycles-only run get it
      r.cycles = result->report.cycles;
      cycles_options.cycles = cycles_options.max_cycles = r.cycles;
    }
    variant.runs.push_back(t);
    out = std::move(result->mesh);
    return t;
  };
  for (int round = 0; round < args.repeat; ++round) {
    const Timing a = run_ours(r.ours_eq, eq_options, ours_eq_out);

    SurfaceMesh sm = cgal_marked; // the copy is not timed
    const Timing b = timed([&] {
      CGAL::Polygon_mesh_processing::isotropic_remeshing(faces(sm), l, sm, cgal_parameters(sm));
    });
    r.cgal.runs.push_back(b);
    cgal_out = std::move(sm);

    const Timing c = run_ours(r.ours_cycles, cycles_options, ours_cycles_out);
    fmt::print(
        stderr,
        "[{}] round {}/{}: ours+eq {:.1f} ms, CGAL {:.1f} ms, ours cycles {:.1f} ms (wall)\n",
        r.name, round + 1, args.repeat, a.wall_ms, b.wall_ms, c.wall_ms);
  }

  const std::vector<Segment> input_boundary = boundary_segments(input);
  const remora::Mesh cgal_mesh = from_cgal(*cgal_out);
  r.ours_eq.figures = output_figures(*ours_eq_out, l, input_boundary);
  r.ours_cycles.figures = output_figures(*ours_cycles_out, l, input_boundary);
  r.cgal.figures = output_figures(cgal_mesh, l, input_boundary);

  if (!args.write_dir.empty()) {
    std::filesystem::create_directories(args.write_dir);
    const std::filesystem::path dir(args.write_dir);
    remora::write_mesh((dir / (r.name + "_ours.ply")).string(), *ours_eq_out);
    remora::write_mesh((dir / (r.name + "_ours_cycles.ply")).string(), *ours_cycles_out);
    remora::write_mesh((dir / (r.name + "_cgal.ply")).string(), cgal_mesh);
  }
}

// ---------------------------------------------------------------------------------------------
// Output

double ratio(double num, double den) {
  return den > 0 ? num / den : std::numeric_limits<double>::quiet_NaN();
}

nlohmann::json number_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

nlohmann::json to_json(const Variant& v) {
  nlohmann::json runs = nlohmann::json::array();
  for (const Timing& t : v.runs) runs.push_back({{"wall_ms", t.wall_ms}, {"cpu_ms", t.cpu_ms}});
  const OutputFigures& f = v.figures;
  nlohmann::json j = {
      {"name", v.name},
      {"runs", runs},
      {"best_wall_ms", v.best_wall()},
      {"best_cpu_ms", v.best_cpu()},
      {"wall_us_per_output_triangle", v.us_per_triangle(v.best_wall())},
      {"cpu_us_per_output_triangle", v.us_per_triangle(v.best_cpu())},
      {"output",
       {{"faces", f.faces},
        {"vertices", f.vertices},
        {"boundary_loops", f.boundary_loops},
        {"isolated_vertices", f.isolated_vertices},
        {"min_angle_deg", f.min_angle_deg},
        {"mean_abs_deviation_from_60_deg", f.mean_abs_deviation_from_60_deg},
        {"mixed_area_rel_mad", f.mixed_area_rel_mad},
        {"mean_edge_over_l", f.mean_edge_over_l},
        {"percent_edges_in_band", f.percent_edges_in_band},
        {"percent_interior_valence_6", f.percent_interior_valence_6},
        {"boundary_deviation_over_l", number_or_null(f.boundary_deviation_over_l)}}}};
  if (!v.phase_ms.empty()) j["phase_ms_fastest_run"] = v.phase_ms;
  return j;
}

nlohmann::json to_json(const MeshRace& r) {
  nlohmann::json j = {{"name", r.name}, {"path", r.path}, {"status", r.status}};
  if (r.status == "missing") return j;
  if (r.status == "error") {
    j["error"] = r.error;
    return j;
  }
  j["input"] = {{"faces", r.input_faces},
                {"vertices", r.input_vertices},
                {"boundary_loops", r.input_boundary_loops},
                {"load_ms", r.load_ms}};
  j["target_length"] = r.target_length;
  j["cycles"] = r.cycles;
  j["ours_equalized"] = to_json(r.ours_eq);
  j["ours_cycles_only"] = to_json(r.ours_cycles);
  j["cgal"] = to_json(r.cgal);
  j["cgal_over_ours"] = {
      {"wall_equalized", number_or_null(ratio(r.cgal.best_wall(), r.ours_eq.best_wall()))},
      {"wall_cycles_only", number_or_null(ratio(r.cgal.best_wall(), r.ours_cycles.best_wall()))},
      {"cpu_equalized", number_or_null(ratio(r.cgal.best_cpu(), r.ours_eq.best_cpu()))},
      {"cpu_cycles_only", number_or_null(ratio(r.cgal.best_cpu(), r.ours_cycles.best_cpu()))},
      {"cpu_per_output_triangle_equalized",
       number_or_null(ratio(r.cgal.us_per_triangle(r.cgal.best_cpu()),
                            r.ours_eq.us_per_triangle(r.ours_eq.best_cpu())))},
      {"cpu_per_output_triangle_cycles_only",
       number_or_null(ratio(r.cgal.us_per_triangle(r.cgal.best_cpu()),
                            r.ours_cycles.us_per_triangle(r.ours_cycles.best_cpu())))}};
  return j;
}

std::string fixed_or_na(double x, int digits) {
  return std::isfinite(x) ? fmt::format("{:.{}f}", x, digits) : std::string("n/a");
}

void print_variant(const Variant& v) {
  const OutputFigures& f = v.figures;
  fmt::print("| {} | {} | {:.1f} | {:.1f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.3f} | {:.3f} | "
             "{:.1f} | {:.1f} | {} |\n",
             v.name, f.faces, v.best_wall(), v.best_cpu(), v.us_per_triangle(v.best_wall()),
             v.us_per_triangle(v.best_cpu()), f.min_angle_deg, f.mean_abs_deviation_from_60_deg,
             f.mixed_area_rel_mad, f.mean_edge_over_l, f.percent_edges_in_band,
             f.percent_interior_valence_6, fixed_or_na(f.boundary_deviation_over_l, 4));
}

void print_race(const MeshRace& r, int repeat) {
  if (r.status == "missing") {
    fmt::print("## {}: skipped, file missing: {}\n\n", r.name, r.path);
    return;
  }
  if (r.status == "error") {
    fmt::print("## {}: error: {}\n\n", r.name, r.error);
    return;
  }
  fmt::print("## {} ({} faces, {} boundary loops), l = {:.6g} (0.9 x length scale), {} cycles, "
             "best of {}\n\n",
             r.name, r.input_faces, r.input_boundary_loops, r.target_length, r.cycles, repeat);
  fmt::print("| variant | faces out | wall ms | CPU ms | wall us/tri | CPU us/tri | min angle | "
             "mean abs(angle-60) | mixed area rel MAD | mean edge / l | % edges in [4/5,4/3]l | "
             "% val 6 | boundary dev / l |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  print_variant(r.ours_eq);
  print_variant(r.ours_cycles);
  print_variant(r.cgal);
  fmt::print("\nCGAL/ours time: with equalization {:.2f}x wall, {:.2f}x CPU; cycles only {:.2f}x "
             "wall, {:.2f}x CPU\n",
             ratio(r.cgal.best_wall(), r.ours_eq.best_wall()),
             ratio(r.cgal.best_cpu(), r.ours_eq.best_cpu()),
             ratio(r.cgal.best_wall(), r.ours_cycles.best_wall()),
             ratio(r.cgal.best_cpu(), r.ours_cycles.best_cpu()));
  std::string phases;
  for (const auto& [phase, ms] : r.ours_eq.phase_ms)
    phases += fmt::format("{}{} {:.1f}", phases.empty() ? "" : ", ", phase, ms);
  fmt::print("{} phases, fastest run, wall ms: {}\n\n", r.ours_eq.name, phases);
}

void print_summary(const std::vector<MeshRace>& races) {
  fmt::print("## Summary (best of N; CGAL/ours > 1 means ours is faster)\n\n");
  fmt::print(
      "| mesh | faces in | faces out ours / CGAL | wall ms ours+eq / ours cyc / CGAL | CPU ms "
      "ours+eq / ours cyc / CGAL | CPU us/tri ours+eq / ours cyc / CGAL | CGAL/ours wall "
      "eq / cyc | CGAL/ours CPU eq / cyc | CGAL/ours CPU per tri eq / cyc |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|\n");
  for (const MeshRace& r : races) {
    if (r.status != "ok") {
      fmt::print("| {} | {} | | | | | | | |\n", r.name, r.status);
      continue;
    }
    const Variant& e = r.ours_eq;
    const Variant& c = r.ours_cycles;
    const Variant& g = r.cgal;
    fmt::print(
        "| {} | {} | {} / {} | {:.0f} / {:.0f} / {:.0f} | {:.0f} / {:.0f} / {:.0f} | {:.2f} / "
        "{:.2f} / {:.2f} | {:.2f}x / {:.2f}x | {:.2f}x / {:.2f}x | {:.2f}x / {:.2f}x |\n",
        r.name, r.input_faces, e.figures.faces, g.figures.faces, e.best_wall(), c.best_wall(),
        g.best_wall(), e.best_cpu(), c.best_cpu(), g.best_cpu(), e.us_per_triangle(e.best_cpu()),
        c.us_per_triangle(c.best_cpu()), g.us_per_triangle(g.best_cpu()),
        ratio(g.best_wall(), e.best_wall()), ratio(g.best_wall(), c.best_wall()),
        ratio(g.best_cpu(), e.best_cpu()), ratio(g.best_cpu(), c.best_cpu()),
        ratio(g.us_per_triangle(g.best_cpu()), e.us_per_triangle(e.best_cpu())),
        ratio(g.us_per_triangle(g.best_cpu()), c.us_per_triangle(c.best_cpu())));
  }
}

// The first "model name" of /proc/cpuinfo, empty where there is none.
std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      return colon == std::string::npos ? std::string() : line.substr(colon + 2);
    }
  return {};
}

// The 1-minute load average (other work on the machine inflates the wall times), or NaN.
double load_average() {
  std::ifstream in("/proc/loadavg");
  double load = std::numeric_limits<double>::quiet_NaN();
  in >> load;
  return load;
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"Remora's isotropic remesher against CGAL's isotropic_remeshing"};
  Args args;
  app.add_option("meshes", args.files, "Mesh files (default: the CI meshes of ../shared/data)");
  app.add_option("--repeat", args.repeat, "Alternating rounds per mesh; best of N is reported")
      ->check(CLI::PositiveNumber);
  app.add_option("--cycles", args.cycles,
                 "Cycles for both contenders, exactly (default: as many as Remora's defaults run)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--large", args.large, "Also run derived/igea_sub4.ply (1.07M triangles)");
  app.add_flag("--json", args.json, "Print one JSON object instead of Markdown tables");
  app.add_option("--threads", args.threads, "Worker threads for ours (default: all)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--cgal-relax-boundary", args.cgal_relax_boundary,
               "CGAL relax_constraints(true): boundary vertices slide along boundary chords");
  app.add_option("--feature-angle", args.feature_angle,
                 "Both keep the input's feature lines: edges whose faces' normals differ by more "
                 "than this many degrees (CGAL: detect_sharp_edges)")
      ->check(CLI::Range(0.0, 179.0));
  app.add_option("--write-dir", args.write_dir, "Write both outputs of every mesh as PLY here");
  app.add_flag("--fresh-memory", args.fresh_memory,
               "Leave glibc's defaults (the remora CLI keeps freed memory for reuse, so does this "
               "benchmark unless told so; it applies to both contenders)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  // Both contenders run in this process under the same allocator settings, those of the CLI.
  const bool kept = !args.fresh_memory && remora::keep_freed_memory();
  const std::string shared = REMORA_SHARED_DATA;
  std::vector<std::string> paths = args.files;
  if (paths.empty())
    for (const char* rel :
         {"cad/fandisk.obj", "scans/bunny.ply", "scans/lucy.ply", "scans/armadillo.obj",
          "genus/fertility.off", "open/camelhead.off", "heightfield/AcrossRiver.stl"})
      paths.push_back(shared + "/" + rel);
  if (args.large) paths.push_back(shared + "/derived/igea_sub4.ply");

  const double load_before = load_average();
  if (!args.json)
    fmt::print("# remora::remesh vs CGAL {} isotropic_remeshing\n\nmachine: {}, {} hardware "
               "threads; ours: {}; CGAL: 1 thread, boundary {}; freed memory {}; 1-min load "
               "average at start {}\n\n",
               CGAL_VERSION_STR, cpu_model(), std::thread::hardware_concurrency(),
               args.threads == 1  ? std::string("1 thread")
               : args.threads > 1 ? fmt::format("{} threads", args.threads)
                                  : std::string("all threads"),
               args.cgal_relax_boundary ? "relaxed along chords (relax_constraints)"
                                        : "kept (CGAL default)",
               kept ? "kept for reuse (as the CLI)" : "returned (glibc defaults)",
               fixed_or_na(load_before, 2));
  std::fflush(stdout);

  std::vector<MeshRace> races;
  for (const std::string& path : paths) {
    MeshRace r;
    r.name = mesh_name(path);
    r.path = path;
    if (!std::filesystem::exists(path)) {
      r.status = "missing";
      fmt::print(stderr, "[{}] skipped: missing {}\n", r.name, path);
    } else {
      try {
        race(r, args);
      } catch (const std::exception& e) {
        r.status = "error";
        r.error = e.what();
        fmt::print(stderr, "[{}] error: {}\n", r.name, e.what());
      }
    }
    if (!args.json) print_race(r, args.repeat);
    std::fflush(stdout);
    races.push_back(std::move(r));
  }

  if (args.json) {
    nlohmann::json j = {{"cgal_version", CGAL_VERSION_STR},
                        {"cpu_model", cpu_model()},
                        {"hardware_threads", std::thread::hardware_concurrency()},
                        {"load_average_start", number_or_null(load_before)},
                        {"load_average_end", number_or_null(load_average())},
                        {"threads_ours", args.threads},
                        // null: each mesh's own count (as many as Remora's defaults ran)
                        {"cycles", args.cycles > 0 ? nlohmann::json(args.cycles) : nullptr},
                        {"equalize_iterations", remora::RemeshOptions{}.equalize_iterations},
                        {"length_factor", kLengthFactor},
                        {"repeat", args.repeat},
                        {"cgal_relax_boundary", args.cgal_relax_boundary},
                        {"freed_memory_kept", kept},
                        {"meshes", nlohmann::json::array()}};
    for (const MeshRace& r : races) j["meshes"].push_back(to_json(r));
    std::cout << j.dump(2) << "\n";
  } else {
    print_summary(races);
    fmt::print("\n1-min load average at the end {}\n", fixed_or_na(load_average(), 2));
  }
  const bool any_error = std::any_of(races.begin(), races.end(),
                                     [](const MeshRace& r) { return r.status == "error"; });
  return any_error ? 1 : 0;
}
