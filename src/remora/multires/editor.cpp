#include "remora/multires/editor.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/common/timer.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/multires/frame.h"
#include "remora/multires/limits.h"
#include "remora/multires/multigrid.h"
#include "remora/multires/nonlinear_region.h"

namespace remora {
namespace {

int largest(const std::array<double, 3>& a) {
  return a[0] >= a[1] && a[0] >= a[2] ? 0 : (a[1] >= a[2] ? 1 : 2);
}

} // namespace

std::string to_string(DetailMode mode) {
  switch (mode) {
  case DetailMode::Normal:
    return "normal";
  case DetailMode::Displacement:
    return "displacement";
  case DetailMode::None:
    return "none";
  }
  return "?";
}

DetailMode parse_detail_mode(const std::string& name) {
  if (name == "normal") return DetailMode::Normal;
  if (name == "displacement") return DetailMode::Displacement;
  if (name == "none") return DetailMode::None;
  throw InvalidArgument(
      fmt::format("unknown detail mode '{}': use normal (the paper), displacement or none", name));
}

// ---- the editor ------------------------------------------------------------------------------

/// A region of the editor: its labels, basis functions, details and the frame's state; with the
/// report it was made with (set_region's figures) and the editor that made it.
struct Editor::Prepared::State {
  const void* owner = nullptr;
  EditReport report;
  // What it was prepared from (set_region's arguments and the system), to find it again.
  std::vector<int> support;
  std::vector<std::vector<int>> handle_ids;
  KHarmonicOptions system;
  std::vector<int> input_label; // per O vertex: kFixed, kFree or handle j
  std::vector<int> base_label;  // per B vertex
  int handles = 0;
  std::vector<int> free_vertices; // B vertices, in the row order of `basis`
  BasisRows basis;                // n_free × (3 + 4h)
  std::vector<std::vector<int>> handle_base;
  std::vector<Eigen::Vector3d> handle_centers;
  Eigen::MatrixXd rest;         // B0
  Eigen::MatrixXd rest_normals; // of B0
  std::vector<int> encoded;     // O vertices with a detail, in increasing order
  FrameDetails details;         // their details, decoded into the rows `encoded`
  NormalPlan affected;          // B vertices whose normal can change, and their faces
  std::vector<Transform> transforms;
  FrameRows frame; // B under the transforms: positions and normals
  Eigen::MatrixXd current_positions;
  std::vector<double> face_normals; // update_normals()'s scratch
  bool dirty = true;
  std::unique_ptr<NonlinearRegion> nonlinear; // method nonlinear (multires/nonlinear_region.h)
  std::shared_ptr<const RemeshResult> coarse; // its preview level (kept by the editor)
  std::uint64_t bytes = 0; // its estimated memory (region_bytes() of multires/limits.h)
};

using RegionState = Editor::Prepared::State;

struct Editor::Impl {
  EditorOptions options;
  Mesh input;
  Eigen::MatrixXd input_positions;
  TriangleTopology input_topology;
  std::shared_ptr<const LowPassFilter> filter; // immutable: editors made by a bake share it
  Eigen::MatrixXd smooth;                      // S = filter(O)
  Mesh base;
  TriangleTopology topology;
  Eigen::MatrixXd base_rest;    // B
  Eigen::MatrixXd base_normals; // of B
  std::vector<SurfacePoint> base_on_input, input_on_base;
  std::vector<std::pair<int, int>> negative_edges; // of B
  std::optional<KHarmonicAssembler> assembler;     // B's systems
  BaseStatistics statistics;                       // of B: what a bake updates the report from
  std::unique_ptr<MultigridSolver> multigrid;
  std::shared_ptr<const RemeshResult> coarse; // method nonlinear's preview level, for every region
  EditReport report;
  std::unique_ptr<RegionState> region;
  // The regions installed before the current one, the latest first: set_region() of one of them
  // again (an undo) installs it as it was, without the work.
  std::deque<std::unique_ptr<RegionState>> recent;
  static constexpr std::size_t kRecentRegions = 2;

  void progress(std::string_view phase, int step, int steps) const {
    if (options.progress) options.progress(phase, step, steps);
  }
  std::string solver_name(bool symmetric) const {
    if (!options.solver.name.empty()) return options.solver.name;
    return symmetric ? default_solver_name() : "lu";
  }
  RegionState& state() {
    if (!region) throw InvalidArgument("no region yet: call set_region() first");
    return *region;
  }
  void update(double budget_ms);
  void build_nonlinear(RegionState& r, EditReport& into);
  void deform_base(RegionState& r, bool moved, double budget_ms);

  // The steps of set_region(), in order, on a new state (the current region stays until all
  // succeed).
  std::unique_ptr<RegionState> paint(const std::vector<int>& support,
                                     const std::vector<std::vector<int>>& handles) const;
  void map_to_base(RegionState& r) const;
  void report_region(const RegionState& r, EditReport& out) const;
  Eigen::MatrixXd constrained_values(const RegionState& r, const std::vector<int>& vertices,
                                     bool by_vertex) const;
  void solve_basis(RegionState& r, EditReport& out, const std::stop_token& stop);
  void encode_details(RegionState& r, EditReport& out, const std::stop_token& stop) const;
  void find_affected(RegionState& r) const;

  // The memory limit (options.memory_bytes; 0 = none). The preprocessing's estimate, by the input
  // triangles.
  std::uint64_t preprocessing_bytes() const { return kEditorBytesPerTriangle * input.n_faces(); }
  void bytes_for(RegionState& r) const;
  void make_room(std::uint64_t beside);
};

namespace {

void check_options(const EditorOptions& o) {
  if (o.system.k < 1 || o.system.k > 3)
    throw InvalidArgument(fmt::format("k = {} is not supported: use 1, 2 or 3", o.system.k));
  const bool symmetric = o.system.areas != AreaWeights::Mixed;
  const std::string& name = o.solver.name;
  if (name == "multigrid") {
    if (!symmetric)
      throw InvalidArgument("the multigrid solver needs a symmetric system: use the mean or "
                            "mixed-symmetric area weights");
    if (!o.remesh)
      throw InvalidArgument("the multigrid solver builds its hierarchy by remeshing the base; it "
                            "does not run in the no-remesh mode");
    return;
  }
  if (name.empty()) return;
  const auto solver = make_solver(o.solver); // throws for an unknown name
  if (solver->needs_spd() && !symmetric)
    throw InvalidArgument(fmt::format(
        "solver {} needs a symmetric positive definite system, and the mixed area weights give "
        "an unsymmetric one: use lu or bicgstab, or the mean or mixed-symmetric weights",
        name));
}

} // namespace

Editor::Editor(Mesh mesh, EditorOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  check_options(options);
  m.options = std::move(options);
  if (mesh.n_faces() == 0) throw InvalidArgument("the mesh has no faces: nothing to edit");
  if (mesh.has_vertex_status() && mesh.has_face_status()) {
    for (const VertexHandle v : mesh.all_vertices())
      if (mesh.status(v).deleted())
        throw InvalidArgument("the mesh has deleted vertices: call garbage_collection() first");
  }
  m.input = std::move(mesh);
  m.input_positions = positions_matrix(m.input);
  if (!m.input_positions.allFinite())
    throw InvalidArgument("the mesh has a non-finite coordinate (NaN or Inf)");
  m.input_topology = triangle_topology(m.input);
  m.report.input_vertices = m.input.n_vertices();
  m.report.input_faces = m.input.n_faces();
  m.report.remeshed = m.options.remesh;

  // 2. The base surface S: low-pass filtered O, same connectivity.
  m.progress("base surface", 0, 1);
  auto t0 = Clock::now();
  LowPassOptions filter_options = m.options.base;
  if (filter_options.threads == 0) filter_options.threads = m.options.threads;
  m.filter = std::make_shared<const LowPassFilter>(m.input, filter_options);
  m.smooth = m.filter->apply(m.input_positions);
  m.report.sigma = m.filter->stats().sigma;
  m.report.sigma_min = m.filter->stats().sigma_min;
  m.report.sigma_capped_vertices = m.filter->stats().capped;
  m.report.sigma_capped_loops = m.filter->stats().capped_loops;
  m.report.intrinsic_flips = m.filter->stats().laplacian_stats.flips;
  m.report.input_negative_weights = m.filter->stats().laplacian_stats.negative_before;
  Mesh s = m.input;
  set_positions(s, m.smooth);
  m.report.milliseconds["base"] = ms_since(t0);

  // 3. The base B: the area-equalizing remesh of S, with the correspondence.
  t0 = Clock::now();
  if (m.options.remesh) {
    RemeshOptions ro = m.options.remesh_options;
    ro.threads = m.options.threads;
    ro.progress = [&m](std::string_view phase, int step, int steps) {
      m.progress(fmt::format("remesh: {}", phase), step, steps);
    };
    RemeshResult r = remesh(s, ro);
    m.report.base_target_length = r.report.target_length;
    m.base = std::move(r.mesh);
    m.base_on_input = std::move(r.output_on_input);
    m.input_on_base = std::move(r.input_on_output);
  } else {
    m.base = std::move(s);
    m.base_on_input.assign(m.base.n_vertices(), SurfacePoint{FaceHandle(), {1.0, 0.0, 0.0}});
    for (std::size_t f = 0; f < m.input_topology.faces.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        SurfacePoint& sp = m.base_on_input[static_cast<std::size_t>(
            m.input_topology.faces[f][static_cast<std::size_t>(k)])];
        if (sp.face.is_valid()) continue;
        sp.face = FaceHandle(static_cast<int>(f));
        sp.bary = {0.0, 0.0, 0.0};
        sp.bary[static_cast<std::size_t>(k)] = 1.0;
      }
    m.input_on_base = m.base_on_input;
  }
  m.topology = triangle_topology(m.base);
  m.base_rest = positions_matrix(m.base);
  m.base_normals = vertex_normals(m.topology, m.base_rest);
  m.report.milliseconds["remesh"] = ms_since(t0);
  m.report.base_vertices = m.base.n_vertices();
  m.report.base_faces = m.base.n_faces();

  t0 = Clock::now();
  m.assembler.emplace(m.base, m.options.threads);
  const SparseMatrix& minus_w = m.assembler->minus_w();
  for (Eigen::Index c = 0; c < minus_w.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(minus_w, c); it; ++it)
      if (it.row() < it.col() && it.value() > 0.0)
        m.negative_edges.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()));
  m.report.base_symmetry_defect = laplacian_symmetry_defect(m.base);
  m.report.base_quality = mesh_quality(m.base);
  m.statistics = base_statistics(m.base);
  m.report.milliseconds["base report"] = ms_since(t0);
}

Editor::Editor(EditorParts parts, EditorOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  check_options(options);
  const auto ni = static_cast<Eigen::Index>(parts.input.n_vertices());
  const auto nb = static_cast<Eigen::Index>(parts.base.n_vertices());
  if (!options.remesh || !parts.filter || parts.input_positions.rows() != ni ||
      parts.smooth.rows() != ni || parts.input_on_base.size() != std::size_t(ni) ||
      parts.base_rest.rows() != nb || parts.base_on_input.size() != std::size_t(nb) ||
      parts.topology.faces.size() != parts.base.n_faces() ||
      parts.input_topology.faces.size() != parts.input.n_faces())
    throw InvalidArgument("editor parts: the sizes of the input, the base and their "
                          "correspondences disagree (or remesh is off)");
  m.options = std::move(options);
  m.input = std::move(parts.input);
  m.input_positions = std::move(parts.input_positions);
  m.input_topology = std::move(parts.input_topology);
  m.filter = std::move(parts.filter);
  m.smooth = std::move(parts.smooth);
  m.base = std::move(parts.base);
  m.topology = std::move(parts.topology);
  m.base_rest = std::move(parts.base_rest);
  m.base_on_input = std::move(parts.base_on_input);
  m.input_on_base = std::move(parts.input_on_base);
  m.negative_edges = std::move(parts.negative_edges);
  m.statistics = std::move(parts.statistics);
  m.report = std::move(parts.report);
  m.base_normals = vertex_normals(m.topology, m.base_rest);
  m.assembler.emplace(m.base, m.options.threads);
}

Editor::Editor(Editor&&) noexcept = default;
Editor& Editor::operator=(Editor&&) noexcept = default;
Editor::~Editor() = default;

// Validates the painted ids and labels the input vertices; the handles' centroids.
std::unique_ptr<RegionState>
Editor::Impl::paint(const std::vector<int>& support,
                    const std::vector<std::vector<int>>& handles) const {
  const auto n = static_cast<int>(input.n_vertices());
  if (support.empty()) throw InvalidArgument("the support is empty: paint at least one vertex");
  if (handles.empty())
    throw InvalidArgument("no handle: paint at least one handle inside the support");
  auto state = std::make_unique<RegionState>();
  RegionState& r = *state;
  r.handles = static_cast<int>(handles.size());
  r.input_label.assign(static_cast<std::size_t>(n), Region::kFixed);
  for (const int v : support) {
    if (v < 0 || v >= n)
      throw InvalidArgument(
          fmt::format("support vertex {} is out of range: the mesh has {} vertices (ids 0 to {})",
                      v, n, n - 1));
    r.input_label[static_cast<std::size_t>(v)] = Region::kFree;
  }
  for (int j = 0; j < r.handles; ++j) {
    const auto& h = handles[static_cast<std::size_t>(j)];
    if (h.empty()) throw InvalidArgument(fmt::format("handle {} has no vertex", j));
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    for (const int v : h) {
      if (v < 0 || v >= n)
        throw InvalidArgument(
            fmt::format("handle {}: vertex {} is out of range: the mesh has {} vertices", j, v, n));
      int& label = r.input_label[static_cast<std::size_t>(v)];
      if (label == Region::kFixed)
        throw InvalidArgument(fmt::format(
            "handle {}: vertex {} is outside the support; the support must contain every handle "
            "(paint the support over the handles)",
            j, v));
      if (label >= 0 && label != j)
        throw InvalidArgument(fmt::format(
            "vertex {} is in handle {} and in handle {}; handles must not overlap", v, label, j));
      label = j;
      center += input_positions.row(v).transpose();
    }
    r.handle_centers.push_back(center / double(h.size()));
  }
  return state;
}

// Maps the region onto the base: a base vertex takes the label of the input vertex nearest to
// its location (largest barycentric weight); then every painted input vertex claims the base
// vertex nearest to its own location, so that small handles and supports are not lost.
void Editor::Impl::map_to_base(RegionState& r) const {
  const auto nb = static_cast<std::size_t>(base.n_vertices());
  r.base_label.assign(nb, Region::kFixed);
  if (options.remesh) {
    for (std::size_t v = 0; v < nb; ++v) {
      const SurfacePoint& sp = base_on_input[v];
      const int corner = input_topology.faces[static_cast<std::size_t>(sp.face.idx())]
                                             [static_cast<std::size_t>(largest(sp.bary))];
      r.base_label[v] = r.input_label[static_cast<std::size_t>(corner)];
    }
    for (std::size_t i = 0; i < r.input_label.size(); ++i) {
      const int label = r.input_label[i];
      const SurfacePoint& sp = input_on_base[i];
      if (label == Region::kFixed || !sp.face.is_valid()) continue;
      const int w = topology.faces[static_cast<std::size_t>(sp.face.idx())]
                                  [static_cast<std::size_t>(largest(sp.bary))];
      int& bl = r.base_label[static_cast<std::size_t>(w)];
      if (label >= 0 ? bl < 0 : bl == Region::kFixed) bl = label;
    }
  } else {
    r.base_label = r.input_label;
  }
  r.handle_base.assign(static_cast<std::size_t>(r.handles), {});
  for (std::size_t v = 0; v < nb; ++v)
    if (r.base_label[v] >= 0)
      r.handle_base[static_cast<std::size_t>(r.base_label[v])].push_back(static_cast<int>(v));
}

// The region's figures (the report takes them only when the whole of set_region succeeds).
void Editor::Impl::report_region(const RegionState& r, EditReport& out) const {
  out.support_vertices = 0;
  out.handle_vertices.assign(static_cast<std::size_t>(r.handles), 0);
  for (const int label : r.input_label) {
    if (label != Region::kFixed) ++out.support_vertices;
    if (label >= 0) ++out.handle_vertices[static_cast<std::size_t>(label)];
  }
  std::size_t free_count = 0, constrained = 0;
  for (const int label : r.base_label) (label == Region::kFree ? free_count : constrained)++;
  out.free_base_vertices = free_count;
  out.constrained_base_vertices = constrained;
  out.handle_base_vertices.clear();
  for (const auto& h : r.handle_base) out.handle_base_vertices.push_back(h.size());
  out.negative_weights_in_support = 0;
  for (const auto& [a, b] : negative_edges)
    if (r.base_label[static_cast<std::size_t>(a)] == Region::kFree ||
        r.base_label[static_cast<std::size_t>(b)] == Region::kFree)
      ++out.negative_weights_in_support;
}

// The constrained values of the 3 + 4h basis functions, one column each: the fixed vertices'
// x, y, z, and per handle its vertices' x, y, z and 1. A row per vertex of `vertices`, or with
// `by_vertex` a row per base vertex (the others zero).
Eigen::MatrixXd Editor::Impl::constrained_values(const RegionState& r,
                                                 const std::vector<int>& vertices,
                                                 bool by_vertex) const {
  const int columns = 3 + 4 * r.handles;
  Eigen::MatrixXd out =
      Eigen::MatrixXd::Zero(by_vertex ? static_cast<Eigen::Index>(base.n_vertices())
                                      : static_cast<Eigen::Index>(vertices.size()),
                            columns);
  for (std::size_t c = 0; c < vertices.size(); ++c) {
    const int v = vertices[c];
    const int label = r.base_label[static_cast<std::size_t>(v)];
    const Eigen::Index row = by_vertex ? v : static_cast<Eigen::Index>(c);
    const Eigen::RowVector3d p = base_rest.row(v);
    if (label == Region::kFixed) {
      out.block<1, 3>(row, 0) = p;
    } else if (label >= 0) {
      out.block<1, 3>(row, 3 + 4 * label) = p;
      out(row, 3 + 4 * label + 3) = 1.0;
    }
  }
  return out;
}

// The system on the base, factored once; the 3 + 4h basis functions.
void Editor::Impl::solve_basis(RegionState& r, EditReport& out, const std::stop_token& stop) {
  const Region labels{r.base_label};
  const std::string on_base =
      options.remesh
          ? fmt::format("on the remeshed base (edge length {:.4g}): ", out.base_target_length)
          : std::string("on the mesh itself: ");
  auto t0 = Clock::now();
  const std::string name = solver_name(options.system.areas != AreaWeights::Mixed);
  try {
    if (name == "multigrid") {
      if (!multigrid) {
        MultigridOptions mo;
        mo.k = options.system.k;
        mo.areas = options.system.areas;
        mo.tolerance = options.solver.tolerance;
        mo.threads = options.threads;
        multigrid = std::make_unique<MultigridSolver>(base, mo);
      }
      multigrid->set_region(labels);
      out.milliseconds["assemble"] = 0.0;
      out.milliseconds["factor"] = ms_since(t0);
      t0 = Clock::now();
      std::vector<int> all(base.n_vertices());
      for (std::size_t v = 0; v < all.size(); ++v) all[v] = static_cast<int>(v);
      r.basis = multigrid->solve(constrained_values(r, all, true));
      r.free_vertices = multigrid->fine_system().free_vertices;
      int iterations = 0;
      for (const auto& level : multigrid->stats())
        iterations = std::max(iterations, level.iterations);
      out.solver_stats = SolverStats{};
      out.solver_stats.iterations = iterations;
    } else {
      const KHarmonicSystem system = assembler->assemble(labels, options.system);
      out.milliseconds["assemble"] = ms_since(t0);
      t0 = Clock::now();
      SolverOptions so = options.solver;
      so.name = name;
      const std::unique_ptr<Solver> solver = make_solver(so);
      if (stop.stop_requested()) return;
      solver->compute(system.matrix);
      out.milliseconds["factor"] = ms_since(t0);
      if (stop.stop_requested()) return;
      t0 = Clock::now();
      r.basis =
          solver->solve(system.rhs(constrained_values(r, system.constrained_vertices, false)));
      r.free_vertices = system.free_vertices;
      out.solver_stats = solver->stats();
    }
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(on_base + e.what());
  } catch (const NumericalError& e) {
    throw NumericalError(on_base + e.what());
  }
  out.milliseconds["solve"] = ms_since(t0);
  out.solver = name;
  out.solves = 3 + 4 * r.handles;
  if (!r.basis.allFinite())
    throw NumericalError(on_base + "the solver returned non-finite values; try a direct solver");
}

// B0 (the fill-in with the handles undeformed), its normals (B's outside r.affected, where no face
// moved), and the Phong details of the painted input vertices against it.
void Editor::Impl::encode_details(RegionState& r, EditReport& out,
                                  const std::stop_token& stop) const {
  const auto t0 = Clock::now();
  r.rest = base_rest;
  for (std::size_t row = 0; row < r.free_vertices.size(); ++row) {
    Eigen::RowVector3d p = r.basis.block<1, 3>(static_cast<Eigen::Index>(row), 0);
    for (int j = 0; j < r.handles; ++j)
      p += r.basis.block<1, 3>(static_cast<Eigen::Index>(row), 3 + 4 * j);
    r.rest.row(r.free_vertices[row]) = p;
  }
  r.rest_normals = base_normals;
  update_vertex_normals(topology, r.rest, r.affected.vertices, r.rest_normals, options.threads);
  std::vector<int> starts;
  for (std::size_t i = 0; i < r.input_label.size(); ++i) {
    const SurfacePoint& sp = input_on_base[i];
    if (r.input_label[i] == Region::kFixed || !sp.face.is_valid()) continue;
    r.encoded.push_back(static_cast<int>(i));
    starts.push_back(sp.face.idx());
  }
  Eigen::MatrixXd points(static_cast<Eigen::Index>(r.encoded.size()), 3);
  for (std::size_t e = 0; e < r.encoded.size(); ++e)
    points.row(static_cast<Eigen::Index>(e)) = input_positions.row(r.encoded[e]);
  if (stop.stop_requested()) return;
  const std::vector<PhongDetail> details = encode_phong(
      topology, r.rest, r.rest_normals, points, starts, options.phong, &out.phong, options.threads);
  std::vector<Eigen::Vector3d> rest_offsets; // DetailMode::Displacement: p − b on B0
  if (options.details == DetailMode::Displacement) {
    rest_offsets.resize(details.size());
    for (std::size_t e = 0; e < details.size(); ++e) {
      PhongDetail foot = details[e];
      foot.offset = 0.0;
      foot.residual = false;
      rest_offsets[e] = points.row(static_cast<Eigen::Index>(e)).transpose() -
                        decode_phong(topology, r.rest, r.rest_normals, foot);
    }
  }
  r.details =
      frame_details(details, r.encoded, options.details == DetailMode::Normal, rest_offsets);
  out.milliseconds["encode"] = ms_since(t0);
}

// The base vertices whose normals can change: every corner of a face with a moving vertex.
void Editor::Impl::find_affected(RegionState& r) const {
  std::vector<char> affected(base.n_vertices(), 0);
  for (const auto& f : topology.faces)
    if (r.base_label[static_cast<std::size_t>(f[0])] != Region::kFixed ||
        r.base_label[static_cast<std::size_t>(f[1])] != Region::kFixed ||
        r.base_label[static_cast<std::size_t>(f[2])] != Region::kFixed)
      for (const int v : f) affected[static_cast<std::size_t>(v)] = 1;
  std::vector<int> vertices;
  for (std::size_t v = 0; v < affected.size(); ++v)
    if (affected[v]) vertices.push_back(static_cast<int>(v));
  r.affected = plan_normals(topology, vertices);
}

// Method nonlinear: its deformers from B0, the labels and the handles' scalar weights (the basis
// functions' "1" columns); for a large support the coarse base of its preview, made once and
// kept while the regions' sizes call for about the same coarse edge length.
void Editor::Impl::build_nonlinear(RegionState& r, EditReport& into) {
  const auto t0 = Clock::now();
  Eigen::MatrixXd weights = Eigen::MatrixXd::Zero(r.rest.rows(), r.handles);
  for (std::size_t row = 0; row < r.free_vertices.size(); ++row)
    for (int j = 0; j < r.handles; ++j)
      weights(r.free_vertices[row], j) =
          static_cast<double>(r.basis(static_cast<Eigen::Index>(row), 3 + 4 * j + 3));
  for (int j = 0; j < r.handles; ++j)
    for (const int v : r.handle_base[static_cast<std::size_t>(j)]) weights(v, j) = 1.0;
  NonlinearOptions o = options.nonlinear;
  o.threads = options.threads;
  const std::size_t n_free = r.free_vertices.size();
  // Propagated rotations take one solve per frame, blended motions none: no preview.
  const bool preview = o.energy != NonlinearEnergy::PropagatedRotations &&
                       o.energy != NonlinearEnergy::BlendedMotions && o.preview_vertices > 0 &&
                       n_free > 2 * static_cast<std::size_t>(o.preview_vertices);
  if (preview) {
    const double wanted = coarse_length(mean_edge_length(base), n_free, o);
    r.coarse = coarse;
    if (!r.coarse || std::abs(mean_edge_length(r.coarse->mesh) / wanted - 1.0) > 0.5) {
      const auto t1 = Clock::now();
      r.coarse = std::make_shared<const RemeshResult>(make_coarse_base(base, n_free, o));
      into.milliseconds["nonlinear coarse base"] = ms_since(t1);
    }
  }
  r.nonlinear = std::make_unique<NonlinearRegion>(base, preview ? r.coarse.get() : nullptr, r.rest,
                                                  r.base_label, weights, o);
  into.milliseconds["nonlinear setup"] = ms_since(t0);
}

// Method nonlinear, in a frame: r.current_base holds the blend (the linear result); the region's
// nonlinear state replaces its free rows, or leaves the blend with a message.
void Editor::Impl::deform_base(RegionState& r, bool moved, double budget_ms) {
  if (!r.nonlinear) { // after set_method()
    build_nonlinear(r, report);
    if (r.coarse) coarse = r.coarse;
  }
  const auto t0 = Clock::now();
  RowPoints positions = r.frame.leftCols<3>();
  r.nonlinear->frame(r.transforms, moved, budget_ms, positions);
  r.frame.leftCols<3>() = positions;
  report.method = "nonlinear";
  report.nonlinear_energy = to_string(options.nonlinear.energy);
  report.nonlinear = r.nonlinear->stats();
  report.nonlinear_level = r.nonlinear->level();
  report.fallback = r.nonlinear->fallback();
  report.milliseconds["frame nonlinear"] = ms_since(t0);
}

// Sets r.bytes; throws InvalidArgument when the region and the preprocessing exceed the limit.
void Editor::Impl::bytes_for(RegionState& r) const {
  const auto free_vertices =
      static_cast<std::size_t>(std::count(r.base_label.begin(), r.base_label.end(), Region::kFree));
  r.bytes = region_bytes(free_vertices, options.system.k, r.handles);
  const std::uint64_t held = preprocessing_bytes();
  if (options.memory_bytes == 0 || held + r.bytes <= options.memory_bytes) return;
  throw InvalidArgument(fmt::format(
      "the region has {} free base vertices: at k = {} with {} handle{} it needs about {} MB, "
      "more than the {} MB left to a region here (paint a smaller support, or use a lower k)",
      free_vertices, options.system.k, r.handles, r.handles == 1 ? "" : "s", r.bytes / 1000000,
      (options.memory_bytes > held ? options.memory_bytes - held : 0) / 1000000));
}

// The regions kept for an undo go, the oldest first, until `beside` bytes of regions fit beside
// them and the preprocessing.
void Editor::Impl::make_room(std::uint64_t beside) {
  if (options.memory_bytes == 0) return;
  const auto kept = [&] {
    std::uint64_t sum = 0;
    for (const auto& r : recent) sum += r->bytes;
    return sum;
  };
  while (!recent.empty() && preprocessing_bytes() + beside + kept() > options.memory_bytes)
    recent.pop_back();
}

Editor::Prepared::Prepared() = default;
Editor::Prepared::Prepared(Prepared&&) noexcept = default;
Editor::Prepared& Editor::Prepared::operator=(Prepared&&) noexcept = default;
Editor::Prepared::~Prepared() = default;

Editor::Prepared Editor::prepare_region(const std::vector<int>& support,
                                        const std::vector<std::vector<int>>& handles,
                                        const std::stop_token& stop) {
  Impl& m = *impl_;
  const auto t_start = Clock::now();
  const auto check = [&] {
    if (stop.stop_requested())
      throw Cancelled("set_region was cancelled; the previous region stays in place");
  };
  for (auto it = m.recent.begin(); it != m.recent.end(); ++it) {
    RegionState& old = **it;
    if (old.support != support || old.handle_ids != handles || old.system.k != m.options.system.k ||
        old.system.areas != m.options.system.areas)
      continue;
    Prepared prepared;
    prepared.state_ = std::move(*it);
    m.recent.erase(it);
    RegionState& r = *prepared.state_;
    r.transforms.assign(static_cast<std::size_t>(r.handles), identity_transform());
    r.dirty = true;
    r.report.region_reused = true;
    r.report.milliseconds["set_region"] = ms_since(t_start);
    return prepared;
  }
  std::unique_ptr<RegionState> state = m.paint(support, handles);
  RegionState& r = *state;
  r.owner = impl_.get();
  r.support = support;
  r.handle_ids = handles;
  r.system = m.options.system;
  r.report = m.report;
  r.report.region_reused = false;
  m.map_to_base(r);
  m.bytes_for(r);
  m.make_room(r.bytes);
  m.report_region(r, r.report);
  check();
  m.solve_basis(r, r.report, stop);
  check();
  m.find_affected(r);
  m.encode_details(r, r.report, stop);
  check();
  if (m.options.method == EditMethod::Nonlinear) m.build_nonlinear(r, r.report);
  r.transforms.assign(static_cast<std::size_t>(r.handles), identity_transform());
  r.frame = frame_rows(r.rest, r.rest_normals);
  r.rest_normals.resize(0, 0); // in the frame now
  r.current_positions = m.input_positions;
  r.dirty = true;
  r.report.milliseconds["set_region"] = ms_since(t_start);
  Prepared prepared;
  prepared.state_ = std::move(state);
  return prepared;
}

void Editor::install_region(Prepared&& prepared) {
  if (!prepared.state_ || prepared.state_->owner != impl_.get())
    throw InvalidArgument("install_region: the region was not prepared by this editor (or was "
                          "installed already)");
  // The report's region figures and set_region's times; the rest stays the editor's.
  EditReport& r = prepared.state_->report;
  for (const auto& [key, ms] : impl_->report.milliseconds)
    if (key.rfind("frame", 0) == 0) r.milliseconds[key] = ms;
  impl_->report = std::move(r);
  if (impl_->region) {
    impl_->recent.push_front(std::move(impl_->region));
    if (impl_->recent.size() > Impl::kRecentRegions) impl_->recent.pop_back();
  }
  if (prepared.state_->coarse) impl_->coarse = prepared.state_->coarse;
  impl_->region = std::move(prepared.state_);
  impl_->make_room(impl_->region->bytes);
}

void Editor::set_region(const std::vector<int>& support,
                        const std::vector<std::vector<int>>& handles, const std::stop_token& stop) {
  install_region(prepare_region(support, handles, stop));
}

namespace {
void check_handle(const RegionState& r, int handle) {
  if (handle < 0 || handle >= r.handles)
    throw InvalidArgument(
        fmt::format("handle {} does not exist: there are {} handles", handle, r.handles));
}
} // namespace

int Editor::handle_count() const {
  return impl_->region ? impl_->region->handles : 0;
}

const std::vector<int>& Editor::movable_vertices() const {
  static const std::vector<int> none;
  return impl_->region ? impl_->region->encoded : none;
}

void Editor::set_system(const KHarmonicOptions& system) {
  EditorOptions o = impl_->options;
  o.system = system;
  check_options(o);
  impl_->options.system = system;
}

void Editor::set_method(EditMethod method) {
  Impl& m = *impl_;
  m.options.method = method;
  if (!m.region) return;
  m.region->dirty = true;
}

Eigen::Vector3d Editor::handle_center(int handle) const {
  const RegionState& r = impl_->state();
  check_handle(r, handle);
  return r.handle_centers[static_cast<std::size_t>(handle)];
}

void Editor::set_transform(int handle, const Transform& transform) {
  RegionState& r = impl_->state();
  check_handle(r, handle);
  if (!transform.allFinite())
    throw InvalidArgument(
        fmt::format("the transform of handle {} has a NaN or infinite entry", handle));
  // A mirror (det M < 0) turns the patch inside out; a collapse (a singular value near 0)
  // crumples it: neither is an edit a user means.
  const Eigen::Matrix3d m = transform.leftCols<3>();
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::Matrix3d>(m).singularValues();
  if (!(m.determinant() > 0.0) || !(singular[2] > 1e-6 * singular[0]))
    throw InvalidArgument(fmt::format(
        "the transform of handle {} {} the handle (det M = {:.3g}): scale by a positive factor "
        "on every axis",
        handle, m.determinant() < 0.0 ? "mirrors" : "collapses", m.determinant()));
  r.transforms[static_cast<std::size_t>(handle)] = transform;
  r.dirty = true;
}

const Transform& Editor::transform(int handle) const {
  const RegionState& r = impl_->state();
  check_handle(r, handle);
  return r.transforms[static_cast<std::size_t>(handle)];
}

void Editor::Impl::update(double budget_ms) {
  RegionState& r = state();
  const bool iterating =
      options.method == EditMethod::Nonlinear && r.nonlinear && !r.nonlinear->finished();
  if (!r.dirty && !iterating) return;
  const auto t0 = Clock::now();
  // Blend: X_free = Φ_0 + Σ_j Φ_j [M_jᵀ; t_jᵀ].
  Eigen::MatrixXd coefficients(3 + 4 * r.handles, 3);
  coefficients.topRows<3>().setIdentity();
  for (int j = 0; j < r.handles; ++j)
    coefficients.block<4, 3>(3 + 4 * j, 0) = r.transforms[static_cast<std::size_t>(j)].transpose();
  const int threads = options.threads;
  blend_basis(r.basis, coefficients, r.free_vertices, r.frame, threads);
  for (int j = 0; j < r.handles; ++j) {
    const Transform& t = r.transforms[static_cast<std::size_t>(j)];
    for (const int v : r.handle_base[static_cast<std::size_t>(j)])
      r.frame.row(v).head<3>() =
          (t.leftCols<3>() * base_rest.row(v).transpose() + t.col(3)).transpose();
  }
  report.milliseconds["frame blend"] = ms_since(t0);
  report.method = to_string(options.method);
  if (options.method == EditMethod::Nonlinear) deform_base(r, r.dirty, budget_ms);
  const auto t_normals = Clock::now();
  // Normals where they can change.
  update_normals(topology, r.affected, r.frame, r.face_normals, threads);
  const auto t_decode = Clock::now();
  report.milliseconds["frame normals"] = ms_since(t_normals);
  decode_details(topology, r.frame, r.details, r.current_positions, threads);
  r.dirty = false;
  report.milliseconds["frame decode"] = ms_since(t_decode);
  report.milliseconds["frame"] = ms_since(t0);
}

const Eigen::MatrixXd& Editor::positions() {
  return positions(std::numeric_limits<double>::infinity());
}

const Eigen::MatrixXd& Editor::positions(double budget_ms) {
  impl_->update(budget_ms);
  return impl_->region->current_positions;
}

bool Editor::converged() const {
  const RegionState* r = impl_->region.get();
  if (!r || impl_->options.method == EditMethod::Linear) return true;
  return !r->dirty && r->nonlinear && r->nonlinear->finished();
}

Mesh Editor::result() {
  const Eigen::MatrixXd& p = positions();
  Mesh out = impl_->input;
  for (const int v : impl_->region->encoded)
    out.set_point(VertexHandle(v), Vec3(p(v, 0), p(v, 1), p(v, 2)));
  return out;
}

const Mesh& Editor::input() const {
  return impl_->input;
}
const Mesh& Editor::base() const {
  return impl_->base;
}

Eigen::MatrixXd Editor::base_positions() {
  impl_->update(std::numeric_limits<double>::infinity());
  return impl_->region->frame.leftCols<3>();
}

Eigen::MatrixXd Editor::low_pass(const Eigen::MatrixXd& values) {
  return impl_->filter->apply(values);
}

bool Editor::in_support(int vertex) const {
  const RegionState& r = impl_->state();
  if (vertex < 0 || vertex >= static_cast<int>(r.input_label.size()))
    throw InvalidArgument(fmt::format("vertex {} is out of range", vertex));
  return r.input_label[static_cast<std::size_t>(vertex)] != Region::kFixed;
}

const EditReport& Editor::report() const {
  return impl_->report;
}
const EditorOptions& Editor::options() const {
  return impl_->options;
}

EditorPartsView Editor::parts() const {
  const Impl& m = *impl_;
  return {m.input,          m.input_positions, m.input_topology, m.filter,        m.smooth,
          m.base,           m.topology,        m.base_rest,      m.base_on_input, m.input_on_base,
          m.negative_edges, m.statistics,      m.report};
}

nlohmann::json to_json(const EditReport& r) {
  nlohmann::json j;
  j["input"] = {{"vertices", r.input_vertices}, {"faces", r.input_faces}};
  j["base"] = {{"vertices", r.base_vertices},
               {"faces", r.base_faces},
               {"remeshed", r.remeshed},
               {"sigma", r.sigma},
               {"sigma_min", r.sigma_min},
               {"sigma_capped_vertices", r.sigma_capped_vertices},
               {"sigma_capped_loops", r.sigma_capped_loops},
               {"intrinsic_flips", r.intrinsic_flips},
               {"input_negative_cotan_weights", r.input_negative_weights},
               {"target_length", r.base_target_length},
               {"symmetry_defect", r.base_symmetry_defect},
               {"quality", to_json(r.base_quality)}};
  j["region"] = {{"support_vertices", r.support_vertices},
                 {"handle_vertices", r.handle_vertices},
                 {"free_base_vertices", r.free_base_vertices},
                 {"constrained_base_vertices", r.constrained_base_vertices},
                 {"handle_base_vertices", r.handle_base_vertices},
                 {"negative_cotan_weights_in_support", r.negative_weights_in_support},
                 {"reused", r.region_reused}};
  j["solver"] = {{"name", r.solver},
                 {"solves", r.solves},
                 {"iterations", r.solver_stats.iterations},
                 {"residual", r.solver_stats.residual},
                 {"factor_bytes", r.solver_stats.factor_bytes}};
  j["phong"] = {{"encoded", r.phong.encoded},
                {"walk_steps", r.phong.walk_steps},
                {"extrapolated", r.phong.extrapolated},
                {"fallbacks", r.phong.fallbacks},
                {"max_abs_offset", r.phong.max_abs_offset}};
  j["method"] = r.method;
  if (r.method == "nonlinear") {
    const NonlinearStats& n = r.nonlinear;
    j["nonlinear"] = {{"iterations", n.iterations},        {"total_iterations", n.total_iterations},
                      {"accelerated", n.accelerated},      {"converged", n.converged},
                      {"last_move", n.last_move},          {"energy", n.energy},
                      {"energy_name", r.nonlinear_energy}, {"fallback", r.fallback}};
  }
  j["milliseconds"] = r.milliseconds;
  return j;
}

} // namespace remora
