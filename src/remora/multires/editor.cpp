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
#include "remora/linalg/nested_dissection.h"
#include "remora/linalg/separator.h"
#include "remora/multires/editor_detail.h"

namespace remora {

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

// ---- the editor (its state: multires/editor_detail.h; the steps of set_region: editor_region.cpp)

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
  m.filter_input();
  Mesh s = m.input;
  set_positions(s, m.smooth);
  m.report.milliseconds["base"] = ms_since(t0);

  // 3. The base B: the area-equalizing remesh of S, with the correspondence.
  t0 = Clock::now();
  m.make_base(s);
  m.topology = triangle_topology(m.base);
  m.base_rest = positions_matrix(m.base);
  m.base_normals = vertex_normals(m.topology, m.base_rest);
  m.report.milliseconds["remesh"] = ms_since(t0);
  m.report.base_vertices = m.base.n_vertices();
  m.report.base_faces = m.base.n_faces();

  t0 = Clock::now();
  m.analyze_base();
  m.report.milliseconds["base report"] = ms_since(t0);
}

// O's low-pass filter (options.base), S = filter(O) into `smooth`, and the filter's figures.
void Editor::Impl::filter_input() {
  LowPassOptions filter_options = options.base;
  if (filter_options.threads == 0) filter_options.threads = options.threads;
  filter = std::make_shared<const LowPassFilter>(input, filter_options);
  smooth = filter->apply(input_positions);
  report.sigma = filter->stats().sigma;
  report.sigma_min = filter->stats().sigma_min;
  report.sigma_capped_vertices = filter->stats().capped;
  report.sigma_capped_loops = filter->stats().capped_loops;
  report.intrinsic_flips = filter->stats().laplacian_stats.flips;
  report.input_negative_weights = filter->stats().laplacian_stats.negative_before;
}

// B and the correspondence both ways: S remeshed, or, without remeshing, S itself (moved out of
// `s`), each vertex located at its corner of the first input face that has it.
void Editor::Impl::make_base(Mesh& s) {
  if (options.remesh) {
    RemeshOptions ro = options.remesh_options;
    ro.threads = options.threads;
    ro.progress = [this](std::string_view phase, int step, int steps) {
      progress(fmt::format("remesh: {}", phase), step, steps);
    };
    RemeshResult r = remesh(s, ro);
    report.base_target_length = r.report.target_length;
    base = std::move(r.mesh);
    base_on_input = std::move(r.output_on_input);
    input_on_base = std::move(r.input_on_output);
  } else {
    base = std::move(s);
    base_on_input.assign(base.n_vertices(), SurfacePoint{FaceHandle(), {1.0, 0.0, 0.0}});
    for (std::size_t f = 0; f < input_topology.faces.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        SurfacePoint& sp = base_on_input[static_cast<std::size_t>(
            input_topology.faces[f][static_cast<std::size_t>(k)])];
        if (sp.face.is_valid()) continue;
        sp.face = FaceHandle(static_cast<int>(f));
        sp.bary = {0.0, 0.0, 0.0};
        sp.bary[static_cast<std::size_t>(k)] = 1.0;
      }
    input_on_base = base_on_input;
  }
}

// B's Laplacian assembler, its edges with a negative cotan weight, its figures for the report
// and the index of the base vertices by their nearest input vertex.
void Editor::Impl::analyze_base() {
  assembler.emplace(base, options.threads);
  const SparseMatrix& minus_w = assembler->minus_w();
  for (Eigen::Index c = 0; c < minus_w.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(minus_w, c); it; ++it)
      if (it.row() < it.col() && it.value() > 0.0)
        negative_edges.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()));
  report.base_symmetry_defect = laplacian_symmetry_defect(base);
  report.base_quality = mesh_quality(base);
  statistics = base_statistics(base);
  index_base_nearest();
}

Editor::Editor(const std::function<void(EditorParts&)>& build, EditorOptions options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  check_options(options);
  m.options = std::move(options);
  build(m);
  const auto ni = static_cast<Eigen::Index>(m.input.n_vertices());
  const auto nb = static_cast<Eigen::Index>(m.base.n_vertices());
  if (!m.options.remesh || !m.filter || m.input_positions.rows() != ni || m.smooth.rows() != ni ||
      m.input_on_base.size() != std::size_t(ni) || m.base_rest.rows() != nb ||
      m.base_on_input.size() != std::size_t(nb) || m.topology.faces.size() != m.base.n_faces() ||
      m.input_topology.faces.size() != m.input.n_faces())
    throw InvalidArgument("editor parts: the sizes of the input, the base and their "
                          "correspondences disagree (or remesh is off)");
  if (m.base_normals.rows() != nb || m.base_normals.cols() != 3)
    m.base_normals = vertex_normals(m.topology, m.base_rest);
  if (m.statistics.mixed_areas.size() != nb || m.statistics.barycentric_areas.size() != nb ||
      m.statistics.rows.size() != nb)
    m.statistics = base_statistics(m.base);
  if (!m.assembler || m.assembler->vertex_count() != m.base.n_vertices())
    m.assembler.emplace(m.base, m.options.threads);
  if (m.base_order.size() != m.base.n_vertices()) { // none, or not this base's
    m.base_order.clear();
    m.base_order_k = 0;
  }
  // The tree holds a position for every key (a bake keeps the old tree, whatever the new size).
  if (m.base_order.empty() || std::any_of(m.base_order.begin(), m.base_order.end(), [&](int key) {
        return key < 0 || key >= static_cast<int>(m.base_order_tree.size());
      }))
    m.base_order_tree.clear();
  m.index_base_nearest();
}

Editor::Editor(Editor&&) noexcept = default;
Editor& Editor::operator=(Editor&&) noexcept = default;
Editor::~Editor() = default;

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

void Editor::prepare_regions() {
  Impl& m = *impl_;
  const std::string solver = m.solver_name(m.options.system.areas != AreaWeights::Mixed);
  if (m.base.n_vertices() > kMaxPreparedBaseVertices || solver == "multigrid") return;
  m.assembler->keep_rows(m.options.system);
  // The order serves the two-half factor alone, which needs two threads.
  const int threads = m.options.threads > 0 ? m.options.threads : omp_get_max_threads();
  const int k = m.options.system.k;
  if ((!m.base_order.empty() && m.base_order_k == k) || solver != "cholmod" ||
      m.options.solver.ordering != "amd" || threads < 2)
    return;
  std::vector<int> keys;
  const Eigen::SparseMatrix<double> pattern = ring_pattern(m.assembler->minus_w(), k);
  try {
    keys = nested_dissection_keys(pattern);
  } catch (const NumericalError&) {
    return; // METIS failed: the regions order themselves, as without preparing
  }
  if (keys.empty()) return;
  m.base_order_tree = elimination_tree(pattern, keys);
  m.base_order = std::move(keys);
  m.base_order_k = k;
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

void Editor::set_nonlinear_energy(NonlinearEnergy energy) {
  Impl& m = *impl_;
  m.options.nonlinear.energy = energy;
  if (m.region) m.region->dirty = true;
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

// Method nonlinear, in a frame: r.current_base holds the blend (the linear result); the region's
// nonlinear state replaces its free rows, or leaves the blend with a message.
void Editor::Impl::deform_base(RegionState& r, bool moved, double budget_ms,
                               const std::function<bool()>& interrupt) {
  if (needs_nonlinear(r) && r.nonlinear_deferred && std::isfinite(budget_ms)) {
    report.method = "nonlinear"; // built apart (NonlinearBuild): the blend stands meanwhile
    report.nonlinear_energy = to_string(options.nonlinear.energy);
    report.nonlinear = NonlinearStats{};
    report.nonlinear_level = "preparing";
    report.fallback.clear();
    report.milliseconds["frame nonlinear"] = 0.0;
    return;
  }
  if (needs_nonlinear(r)) { // after set_method(), or a build apart that did not finish
    build_nonlinear(r, report);
    if (r.coarse) coarse = r.coarse;
    moved = true; // the new state has not seen the transforms
  }
  const auto t0 = Clock::now();
  RowPoints positions = r.frame.leftCols<3>();
  r.nonlinear->frame(r.transforms, moved, budget_ms, positions, interrupt);
  r.frame.leftCols<3>() = positions;
  report.method = "nonlinear";
  report.nonlinear_energy = to_string(options.nonlinear.energy);
  report.nonlinear = r.nonlinear->stats();
  report.nonlinear_level = r.nonlinear->level();
  report.fallback = r.nonlinear->fallback();
  report.milliseconds["frame nonlinear"] = ms_since(t0);
}

void Editor::Impl::update(double budget_ms, const std::function<bool()>& interrupt) {
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
  if (options.method == EditMethod::Nonlinear) deform_base(r, r.dirty, budget_ms, interrupt);
  const auto t_normals = Clock::now();
  // Normals where they can change.
  update_normals(r.affected, r.frame, r.face_normals, threads);
  const auto t_decode = Clock::now();
  report.milliseconds["frame normals"] = ms_since(t_normals);
  decode_details(r.frame, r.details, r.current_positions, threads);
  r.dirty = false;
  report.milliseconds["frame decode"] = ms_since(t_decode);
  report.milliseconds["frame"] = ms_since(t0);
}

const Eigen::MatrixXd& Editor::positions() {
  return positions(std::numeric_limits<double>::infinity());
}

const Eigen::MatrixXd& Editor::positions(double budget_ms) {
  return positions(budget_ms, {});
}

const Eigen::MatrixXd& Editor::positions(double budget_ms, const std::function<bool()>& interrupt) {
  impl_->update(budget_ms, interrupt);
  return impl_->region->current_positions;
}

bool Editor::converged() const {
  const RegionState* r = impl_->region.get();
  if (!r || impl_->options.method == EditMethod::Linear) return true;
  return !r->dirty && !impl_->needs_nonlinear(*r) && r->nonlinear->finished();
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
          m.negative_edges, m.statistics,      m.report,         *m.assembler,    m.base_normals,
          m.base_order,     m.base_order_k,    m.base_order_tree};
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
                 {"support_edge_ratio", r.support_edge_ratio},
                 {"coarse_support", r.coarse_support},
                 {"reused", r.region_reused}};
  j["solver"] = {{"name", r.solver},
                 {"solves", r.solves},
                 {"iterations", r.solver_stats.iterations},
                 {"residual", r.solver_stats.residual},
                 {"factor_bytes", r.solver_stats.factor_bytes},
                 {"separator_rows", r.solver_stats.separator_rows},
                 {"keyed_order", r.solver_stats.keyed_order},
                 {"tree_cut", r.solver_stats.tree_cut}};
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
