// `remora bench solvers [MESH]`: the paper's Table 1 set-up (§5.3) on our solver suite. The mesh
// is remeshed (the base the editor solves on); for each support size a geodesic disc around the
// vertex nearest the centroid is grown: its inner 5 % is the handle, the next N vertices are free,
// the rest is fixed. Thin plate (k = 2) with mean areas (the SPD system) for the Cholesky-type and
// CG solvers, the unsymmetric mixed-area system for bicgstab and lu. Each solver: precomputation
// (analysis + factorization or preconditioner), the factorization again with the analysis kept,
// 3 solutions (x, y, z of a handle translation) as one block for a sequence of handle moves on the
// one factor (median, and the first move apart), iterations, residual, factor memory, and the
// largest difference to the reference (the first solver), relative to the handle displacement.
// "basis" is the editor's path: the 7 basis functions solved once, a product per move.
#include <algorithm>
#include <functional>
#include <iostream>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "remora/common/error.h"
#include "remora/common/json.h"
#include "remora/common/timer.h"
#include "remora/geometry/selection.h"
#include "remora/linalg/kharmonic.h"
#include "remora/linalg/solver.h"
#include "remora/mesh/io.h"
#include "remora/multires/multigrid.h"
#include "remora/remesh/remesh.h"

namespace remora::cli {

namespace {

struct Row {
  std::string solver, system;
  double precompute_s = 0, solve_s = 0, first_solve_s = 0;
  double refactor_s = 0; ///< factorize() again with the analysis kept (values change, pattern not)
  int solves = 0;        ///< handle moves timed; solve_s is their median
  int iterations = 0;
  double residual = 0, max_difference = 0;
  std::size_t factor_bytes = 0;
  std::string note;
};

nlohmann::json to_json(const Row& r) {
  return {{"solver", r.solver},
          {"system", r.system},
          {"precompute_s", r.precompute_s},
          {"solve3_s", r.solve_s},
          {"first_solve3_s", r.first_solve_s},
          {"refactor_s", r.refactor_s},
          {"moves_timed", r.solves},
          {"iterations", r.iterations},
          {"residual", r.residual},
          {"factor_bytes", r.factor_bytes},
          {"max_difference", r.max_difference},
          {"note", r.note}};
}

struct SolversArgs {
  std::string mesh = std::string(REMORA_REPO_DATA) + "/bunny.ply";
  std::vector<int> sizes = {15000, 31000};
  std::vector<std::string> solvers;
  int k = 2;
  bool no_remesh = false, json = false;
  double length_factor = 0.9;
  int max_iterations = 20000;
};

/// Every solver of this build, the variants (METIS ordering, incomplete Cholesky) next to their
/// plain forms, the unsymmetric ones last but multigrid; or the ones asked for.
std::vector<std::string> solver_list(const std::vector<std::string>& asked) {
  if (!asked.empty()) return asked;
  std::vector<std::string> names;
  for (const std::string& name : solver_names()) {
    names.push_back(name);
    if (name == "cholmod") names.push_back("cholmod-metis");
    if (name == default_solver_name()) names.push_back("basis");
    if (name == "cg") names.push_back("cg-ichol");
  }
  names.push_back("multigrid");
  return names;
}

/// One support: the geodesic disc of `size` free vertices around the seed with its inner 5 % as
/// handle 0, the rest of the mesh fixed, and the edit.
struct Support {
  int size = 0;
  std::size_t handle = 0; ///< handle vertices
  Region region;
  /// The handle moves by a tenth of the support's extent along x, y and z.
  Eigen::RowVector3d shift;
  /// A drag is a sequence of handle moves on one factored system: move m translates the handle
  /// by (1 + m/4) × shift. Move 0 gives the solution compared between solvers.
  Eigen::RowVector3d move(int m) const { return (1.0 + 0.25 * m) * shift; }
};

Support make_support(const Mesh& mesh, VertexHandle seed, int size) {
  Support s;
  s.size = size;
  s.handle = static_cast<std::size_t>(size) / 19; // 5 % of the disc
  const std::vector<int> order =
      geodesic_order(mesh, seed, s.handle + static_cast<std::size_t>(size));
  if (order.size() < s.handle + static_cast<std::size_t>(size) || order.size() >= mesh.n_vertices())
    throw InvalidArgument(
        fmt::format("bench solvers: the mesh has {} vertices, too few for a support of {} free "
                    "vertices with a fixed rest; use a larger mesh or smaller --sizes",
                    mesh.n_vertices(), size));
  s.region = Region::all_fixed(mesh.n_vertices());
  for (std::size_t i = 0; i < order.size(); ++i)
    s.region.label[static_cast<std::size_t>(order[i])] = i < s.handle ? 0 : Region::kFree;
  double extent = 0;
  for (int v : order)
    extent = std::max(extent, (mesh.point(VertexHandle(v)) - mesh.point(seed)).norm());
  s.shift = Eigen::RowVector3d(0.1 * extent, 0.05 * extent, -0.08 * extent);
  return s;
}

/// One solver's case: the support's system and the constrained values at rest.
struct Case {
  const Support& support;
  const Eigen::MatrixXd& positions; ///< every vertex at rest
  const KHarmonicSystem& system;
  Eigen::MatrixXd rest;                  ///< the constrained vertices' positions
  std::vector<Eigen::Index> handle_rows; ///< rows of `rest` that belong to the handle

  Case(const Support& s, const Eigen::MatrixXd& p, const KHarmonicSystem& sys)
      : support(s), positions(p), system(sys), rest(sys.gather_constrained(p)) {
    for (std::size_t c = 0; c < system.constrained_vertices.size(); ++c)
      if (s.region.label[static_cast<std::size_t>(system.constrained_vertices[c])] == 0)
        handle_rows.push_back(static_cast<Eigen::Index>(c));
  }
  Eigen::MatrixXd rhs_of_move(int m) const {
    Eigen::MatrixXd constrained = rest;
    for (Eigen::Index c : handle_rows) constrained.row(c) += support.move(m);
    return system.rhs(constrained);
  }
};

using Input = std::function<Eigen::MatrixXd(int)>;
using Solve = std::function<Eigen::MatrixXd(const Eigen::MatrixXd&)>;

// Times solve(input(m)) for moves m = 0, 1, ... until kMoves are done or a second has passed
// (iterative solvers take seconds: one move); input(m) is built untimed. "3 solves" is the
// median, the first move is reported apart. Returns the solution of move 0.
Eigen::MatrixXd time_moves(Row& row, const Input& input, const Solve& solve) {
  constexpr int kMoves = 7;
  std::vector<double> seconds;
  Eigen::MatrixXd first;
  const auto start = Clock::now();
  for (int m = 0; m < kMoves && (m == 0 || ms_since(start) < 1000.0); ++m) {
    const Eigen::MatrixXd in = input(m);
    const auto t0 = Clock::now();
    Eigen::MatrixXd x = solve(in);
    seconds.push_back(ms_since(t0) / 1e3);
    if (m == 0) first = std::move(x);
  }
  row.first_solve_s = seconds.front();
  row.solves = static_cast<int>(seconds.size());
  std::sort(seconds.begin(), seconds.end());
  row.solve_s = seconds[seconds.size() / 2];
  return first;
}

Eigen::MatrixXd run_multigrid(MultigridSolver& multigrid, double hierarchy_s, const Case& c,
                              Row& row) {
  const auto t0 = Clock::now();
  multigrid.set_region(c.support.region);
  row.precompute_s = ms_since(t0) / 1e3;
  auto moved = [&](int m) { // all positions, the handle's moved
    Eigen::MatrixXd p = c.positions;
    for (std::size_t v = 0; v < c.support.region.label.size(); ++v)
      if (c.support.region.label[v] == 0) p.row(static_cast<Eigen::Index>(v)) += c.support.move(m);
    return p;
  };
  Eigen::MatrixXd x =
      time_moves(row, moved, [&](const Eigen::MatrixXd& p) { return multigrid.solve(p); });
  const auto stats = multigrid.stats();
  row.iterations = stats.front().iterations;
  std::string sizes;
  for (const auto& level : stats)
    sizes += fmt::format("{}{}", sizes.empty() ? "" : "/", level.free);
  row.note = fmt::format("V-cycle PCG; free per level {}; hierarchy {:.2f} s once per mesh", sizes,
                         hierarchy_s);
  return x;
}

// The editor's path: factor once, solve once for the basis functions of the region (the rest's
// part, and the handle's affine part: its positions and 1), then every move is a dense product
// with the 7 × 3 matrix of the handle's affine transform (here a translation).
Eigen::MatrixXd run_basis(const SolverOptions& options, const Case& c, Row& row) {
  auto solver = make_solver(options);
  const auto t0 = Clock::now();
  solver->compute(c.system.matrix);
  Eigen::MatrixXd values = Eigen::MatrixXd::Zero(c.rest.rows(), 7);
  values.leftCols(3) = c.rest;
  for (Eigen::Index r : c.handle_rows) {
    values.row(r).head(3).setZero();
    values.row(r).segment(3, 3) = c.rest.row(r);
    values(r, 6) = 1.0;
  }
  const Eigen::MatrixXd basis = solver->solve(c.system.rhs(values));
  row.precompute_s = ms_since(t0) / 1e3;
  auto coefficients = [&](int m) {
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(7, 3);
    k.topRows(3).setIdentity();       // the rest
    k.middleRows(3, 3).setIdentity(); // the handle's linear part
    k.row(6) = c.support.move(m);     // its translation
    return k;
  };
  row.note = "precomputation includes the 7 basis solves; a move is a product";
  return time_moves(row, coefficients,
                    [&](const Eigen::MatrixXd& k) { return Eigen::MatrixXd(basis * k); });
}

Eigen::MatrixXd run_factored(const SolverOptions& options, const Case& c, Row& row) {
  auto solver = make_solver(options);
  const auto t0 = Clock::now();
  solver->compute(c.system.matrix);
  row.precompute_s = ms_since(t0) / 1e3;
  // New values on the same pattern (another k-harmonic weighting, a region edited back): only
  // the numbers are factored again.
  if (row.precompute_s < 5.0) {
    const auto t2 = Clock::now();
    solver->factorize(c.system.matrix);
    row.refactor_s = ms_since(t2) / 1e3;
  }
  Eigen::MatrixXd x = time_moves(
      row, [&](int m) { return c.rhs_of_move(m); },
      [&](const Eigen::MatrixXd& b) { return solver->solve(b); });
  const SolverStats stats = solver->stats();
  row.iterations = stats.iterations;
  row.factor_bytes = stats.factor_bytes;
  if (stats.bandwidth > 0) row.note = fmt::format("half-bandwidth {}", stats.bandwidth);
  return x;
}

SolverOptions solver_options(const std::string& full, int max_iterations) {
  SolverOptions options;
  options.name = full == "basis" ? default_solver_name() : full;
  options.max_iterations = max_iterations;
  if (full == "cholmod-metis") {
    options.name = "cholmod";
    options.ordering = "metis";
  }
  if (full == "cg-ichol") {
    options.name = "cg";
    options.preconditioner = "ichol";
  }
  return options;
}

/// The solvers of `names` on one support, as table rows; the first solution is the reference.
std::vector<Row> bench_support(const Mesh& mesh, const Support& support,
                               const std::vector<std::string>& names, const SolversArgs& a,
                               MultigridSolver* multigrid, double hierarchy_s, double& assemble_s) {
  const Eigen::MatrixXd positions = positions_matrix(mesh);
  std::vector<Row> rows;
  Eigen::MatrixXd reference;
  std::map<std::string, KHarmonicSystem> systems;
  for (const std::string& full : names) {
    const bool unsymmetric = full == "bicgstab" || full == "lu";
    const std::string system_name = unsymmetric ? "mixed" : "mean";
    if (!systems.count(system_name)) {
      const auto t0 = Clock::now();
      systems[system_name] = assemble_kharmonic(
          mesh, support.region,
          {.k = a.k, .areas = unsymmetric ? AreaWeights::Mixed : AreaWeights::Mean});
      if (system_name == "mean") assemble_s = ms_since(t0) / 1e3;
    }
    const Case c(support, positions, systems[system_name]);
    const SolverOptions options = solver_options(full, a.max_iterations);
    Row row;
    row.solver = full == "llt"     ? "llt (libigl path)"
                 : full == "basis" ? default_solver_name() + " + handle basis"
                                   : full;
    row.system = system_name;
    try {
      const Eigen::MatrixXd x = full == "multigrid" ? run_multigrid(*multigrid, hierarchy_s, c, row)
                                : full == "basis"   ? run_basis(options, c, row)
                                                    : run_factored(options, c, row);
      const Eigen::MatrixXd b0 = c.rhs_of_move(0);
      row.residual = (c.system.matrix * x - b0).norm() / b0.norm();
      if (reference.size() == 0) reference = x;
      row.max_difference = (x - reference).cwiseAbs().maxCoeff() / support.shift.norm();
    } catch (const Error& e) {
      row.note = e.what();
    }
    rows.push_back(row);
  }
  return rows;
}

void print_support_table(const Support& support, double assemble_s, const std::vector<Row>& rows) {
  std::cout << fmt::format("\n## {} free vertices, handle {}, assembly {:.3f} s\n\n", support.size,
                           support.handle, assemble_s);
  std::cout
      << "| solver | system | precompute s | refactor s | 3 solves ms (median) | first move ms "
         "| moves | iterations | residual | factor MB | max diff / shift | note |\n"
         "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
  for (const Row& r : rows)
    std::cout << fmt::format("| {} | {} | {:.3f} | {:.3f} | {:.2f} | {:.2f} | {} | {} | {:.1e} "
                             "| {:.1f} | {:.1e} | {} "
                             "|\n",
                             r.solver, r.system, r.precompute_s, r.refactor_s, 1e3 * r.solve_s,
                             1e3 * r.first_solve_s, r.solves, r.iterations, r.residual,
                             static_cast<double>(r.factor_bytes) / 1e6, r.max_difference, r.note);
}

void run_bench_solvers(const SolversArgs& a) {
  const auto t_load = Clock::now();
  Mesh mesh = read_mesh(a.mesh).mesh;
  const double load_s = ms_since(t_load) / 1e3;
  double remesh_s = 0;
  if (!a.no_remesh) {
    const auto t0 = Clock::now();
    RemeshOptions options;
    options.compute_report = false;
    options.length_factor = a.length_factor;
    mesh = remesh(mesh, options).mesh;
    remesh_s = ms_since(t0) / 1e3;
  }
  const VertexHandle seed = central_vertex(mesh);
  const std::vector<std::string> names = solver_list(a.solvers);
  nlohmann::json out = {{"mesh", a.mesh},   {"vertices", mesh.n_vertices()},
                        {"load_s", load_s}, {"remesh_s", remesh_s},
                        {"k", a.k},         {"supports", nlohmann::json::array()}};
  if (!a.json)
    std::cout << fmt::format("# Solvers on {} ({} vertices after remeshing in {:.2f} s), k = {}\n",
                             a.mesh, mesh.n_vertices(), remesh_s, a.k);
  // The multigrid hierarchy depends on the mesh only: built once, timed apart.
  std::unique_ptr<MultigridSolver> multigrid;
  double hierarchy_s = 0;
  if (std::find(names.begin(), names.end(), "multigrid") != names.end()) {
    const auto t0 = Clock::now();
    multigrid = std::make_unique<MultigridSolver>(mesh, MultigridOptions{.k = a.k});
    hierarchy_s = ms_since(t0) / 1e3;
  }
  out["multigrid_hierarchy_s"] = hierarchy_s;
  for (int size : a.sizes) {
    const Support support = make_support(mesh, seed, size);
    double assemble_s = 0;
    const std::vector<Row> rows =
        bench_support(mesh, support, names, a, multigrid.get(), hierarchy_s, assemble_s);
    nlohmann::json entry = {{"free", size},
                            {"handle", support.handle},
                            {"assemble_s", assemble_s},
                            {"rows", nlohmann::json::array()}};
    for (const Row& r : rows) entry["rows"].push_back(to_json(r));
    out["supports"].push_back(entry);
    if (!a.json) print_support_table(support, assemble_s, rows);
  }
  if (a.json) {
    std::cout << dump_json(out, 2) << "\n";
    return;
  }
  std::cout << "\nThe paper's Table 1 (2004, 3 GHz P4), precomputation / 3 solutions: 15k free "
               "vertices: iterative 7.2 s / 7.4 s, multigrid 4.5 s / 0.8 s, direct 2.4 s / 0.07 "
               "s; 31k: 15.2 s / 25.5 s, 8.8 s / 2.0 s, 6.7 s / 0.16 s.\n";
}

} // namespace

void add_bench_command(CLI::App& app) {
  auto* bench = app.add_subcommand("bench", "Benchmarks (docs/benchmarks.md)");
  bench->require_subcommand(1);
  add_bench_edit_command(*bench);
  add_bench_serve_command(*bench);
  add_bench_pipeline_command(*bench);
  add_bench_bake_command(*bench);
  auto* cmd = bench->add_subcommand(
      "solvers", "The paper's Table 1: every solver on the thin-plate system of geodesic supports");
  auto a = std::make_shared<SolversArgs>();
  cmd->add_option("mesh", a->mesh, "Mesh (default: the bundled bunny)");
  cmd->add_option("--sizes", a->sizes, "Free vertices per support (default 15000 31000)")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  cmd->add_option("--solvers", a->solvers,
                  "Solvers to run (default: all); the libigl-style path is 'llt', 'basis' is the "
                  "editor's (the default solver, 7 basis functions, a product per move)")
      ->delimiter(',');
  cmd->add_option("--k", a->k, "Order k of the system (default 2)")->check(CLI::Range(1, 3));
  cmd->add_option("--max-iterations", a->max_iterations, "Iterative solvers' limit (default 20000)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--no-remesh", a->no_remesh, "Solve on the mesh as loaded");
  cmd->add_option("--length-factor", a->length_factor,
                  "Remesh at this factor × the length scale (default 0.9; 0.65 doubles the "
                  "vertex count, for supports of ~1M free vertices on igea_sub4)")
      ->check(CLI::Range(0.1, 10.0));
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] { run_bench_solvers(*a); });
}

} // namespace remora::cli
