// The steps of Editor::set_region() (multires/editor.h; paper §3 and §5): the painted ids
// validated and labelled, the labels mapped onto the base, the k-harmonic system factored and
// the basis functions solved, B0 and the details encoded against it, the normals a frame must
// update; and the region's memory against the editor's limit. prepare_region() runs them on a new
// state, install_region() makes it current.
#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/common/timer.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/multires/editor_detail.h"

namespace remora {

namespace {

int largest(const std::array<double, 3>& a) {
  return a[0] >= a[1] && a[0] >= a[2] ? 0 : (a[1] >= a[2] ? 1 : 2);
}

} // namespace

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

void Editor::Impl::index_base_nearest() {
  const std::size_t ni = input.n_vertices(), nb = base_on_input.size();
  std::vector<int> corner(nb);
  base_nearest_begin.assign(ni + 1, 0);
  for (std::size_t v = 0; v < nb; ++v) {
    const SurfacePoint& sp = base_on_input[v];
    corner[v] = sp.face.is_valid()
                    ? input_topology.faces[static_cast<std::size_t>(sp.face.idx())]
                                          [static_cast<std::size_t>(largest(sp.bary))]
                    : -1; // an isolated vertex without --remesh: on no face
    if (corner[v] >= 0) ++base_nearest_begin[static_cast<std::size_t>(corner[v]) + 1];
  }
  for (std::size_t i = 0; i < ni; ++i) base_nearest_begin[i + 1] += base_nearest_begin[i];
  std::vector<int> fill(base_nearest_begin.begin(), base_nearest_begin.end() - 1);
  base_nearest.resize(static_cast<std::size_t>(base_nearest_begin[ni]));
  for (std::size_t v = 0; v < nb; ++v)
    if (corner[v] >= 0)
      base_nearest[static_cast<std::size_t>(fill[static_cast<std::size_t>(corner[v])]++)] =
          static_cast<int>(v);
}

// Maps the region onto the base: a base vertex takes the label of the input vertex nearest to
// its location (largest barycentric weight); then every painted input vertex claims the base
// vertex nearest to its own location, so that small handles and supports are not lost (a handle
// over the support, and of two handles the one of lower index).
void Editor::Impl::map_to_base(RegionState& r) const {
  const auto nb = static_cast<std::size_t>(base.n_vertices());
  r.base_label.assign(nb, Region::kFixed);
  if (options.remesh) {
    // Only the painted vertices' base vertices take a label other than kFixed.
    for (const int i : r.support)
      for (int k = base_nearest_begin[static_cast<std::size_t>(i)];
           k < base_nearest_begin[static_cast<std::size_t>(i) + 1]; ++k)
        r.base_label[static_cast<std::size_t>(base_nearest[static_cast<std::size_t>(k)])] =
            r.input_label[static_cast<std::size_t>(i)];
    for (const int v : r.support) {
      const auto i = static_cast<std::size_t>(v);
      const int label = r.input_label[i];
      const SurfacePoint& sp = input_on_base[i];
      if (label == Region::kFixed || !sp.face.is_valid()) continue;
      const int w = topology.faces[static_cast<std::size_t>(sp.face.idx())]
                                  [static_cast<std::size_t>(largest(sp.bary))];
      int& bl = r.base_label[static_cast<std::size_t>(w)];
      if (label >= 0 ? bl < 0 || label < bl : bl == Region::kFixed) bl = label;
    }
  } else {
    r.base_label = r.input_label;
  }
  r.handle_base.assign(static_cast<std::size_t>(r.handles), {});
  for (std::size_t v = 0; v < nb; ++v)
    if (r.base_label[v] >= 0)
      r.handle_base[static_cast<std::size_t>(r.base_label[v])].push_back(static_cast<int>(v));
  // A handle without a base vertex (each went to a handle of lower index, or its vertices lie on
  // no face of the base) would move nothing.
  for (int j = 0; j < r.handles; ++j)
    if (r.handle_base[static_cast<std::size_t>(j)].empty())
      throw InvalidArgument(fmt::format(
          "handle {} has no vertex of its own on the base (edge length {:.4g}): its vertices are "
          "nearest to base vertices of a handle of lower index, or on no face; paint it wider or "
          "farther from the other handles",
          j, report.base_target_length));
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
  // The support's own edges against the base's: a support of long triangles bends in facets.
  // Every edge with both ends painted leaves a painted vertex in one of its faces (as the side
  // from a face's corner to the next).
  double longest = 0.0;
  for (const int v : r.support) {
    const auto u = static_cast<std::size_t>(v);
    const Eigen::Vector3d p = input_positions.row(v).transpose();
    for (int i = input_topology.vertex_offsets[u]; i < input_topology.vertex_offsets[u + 1]; ++i) {
      const auto& f =
          input_topology.faces[static_cast<std::size_t>(input_topology.vertex_faces[i])];
      const std::size_t k = f[0] == v ? 0 : f[1] == v ? 1 : 2;
      const int b = f[(k + 1) % 3];
      if (r.input_label[static_cast<std::size_t>(b)] != Region::kFixed)
        longest = std::max(longest, (input_positions.row(b).transpose() - p).norm());
    }
  }
  const double unit =
      out.base_target_length > 0.0 ? out.base_target_length : mean_edge_length(base);
  out.support_edge_ratio = unit > 0.0 ? longest / unit : 0.0;
  out.coarse_support.clear();
  if (out.support_edge_ratio > kCoarseSupportRatio)
    out.coarse_support = fmt::format(
        "the support's own triangles have edges up to {:.0f} times the base's: only their corners "
        "move, so the support bends in facets (edit a finer tessellation of the part)",
        out.support_edge_ratio);
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
      if (so.threads == 0) so.threads = options.threads;
      const std::unique_ptr<Solver> solver = make_solver(so);
      if (!base_order.empty() && base_order_k == options.system.k) {
        std::vector<int> keys(system.free_vertices.size());
        for (std::size_t row = 0; row < keys.size(); ++row)
          keys[row] = base_order[static_cast<std::size_t>(system.free_vertices[row])];
        solver->set_order_keys(std::move(keys));
      }
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
  r.details = frame_details(topology, details, r.encoded, options.details == DetailMode::Normal,
                            rest_offsets);
  out.milliseconds["encode"] = ms_since(t0);
}

// The base vertices whose normals can change: every corner of a face with a moving vertex.
void Editor::Impl::find_affected(RegionState& r) const {
  std::vector<char> affected(base.n_vertices(), 0);
  for (std::size_t u = 0; u < affected.size(); ++u) {
    if (r.base_label[u] == Region::kFixed) continue;
    for (int i = topology.vertex_offsets[u]; i < topology.vertex_offsets[u + 1]; ++i)
      for (const int v :
           topology
               .faces[static_cast<std::size_t>(topology.vertex_faces[static_cast<std::size_t>(i)])])
        affected[static_cast<std::size_t>(v)] = 1;
  }
  std::vector<int> vertices;
  for (std::size_t v = 0; v < affected.size(); ++v)
    if (affected[v]) vertices.push_back(static_cast<int>(v));
  r.affected = plan_normals(topology, vertices);
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
                                        const std::stop_token& stop, bool defer_nonlinear) {
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
  const auto t_map = Clock::now();
  std::unique_ptr<RegionState> state = m.paint(support, handles);
  RegionState& r = *state;
  r.owner = impl_.get();
  r.serial = ++m.regions_prepared;
  r.support = support;
  r.handle_ids = handles;
  r.system = m.options.system;
  r.report = m.report;
  r.report.region_reused = false;
  for (const char* step : kSetRegionSteps)
    r.report.milliseconds.erase(step); // the last region's: this one's are measured below
  m.map_to_base(r);
  m.bytes_for(r);
  m.make_room(r.bytes);
  m.report_region(r, r.report);
  r.report.milliseconds["map"] = ms_since(t_map);
  check();
  m.solve_basis(r, r.report, stop);
  check();
  auto t_finish = Clock::now();
  m.find_affected(r);
  double finish_ms = ms_since(t_finish);
  m.encode_details(r, r.report, stop);
  check();
  if (m.options.method == EditMethod::Nonlinear && !defer_nonlinear) m.build_nonlinear(r, r.report);
  t_finish = Clock::now();
  r.transforms.assign(static_cast<std::size_t>(r.handles), identity_transform());
  r.frame = frame_rows(r.rest, r.rest_normals);
  r.rest_normals.resize(0, 0); // in the frame now
  r.current_positions = m.input_positions;
  r.dirty = true;
  r.report.milliseconds["finish"] = finish_ms + ms_since(t_finish);
  r.report.milliseconds["set_region"] = ms_since(t_start);
  Prepared prepared;
  prepared.state_ = std::move(state);
  return prepared;
}

void Editor::install_region(Prepared&& prepared) {
  if (!prepared.state_ || prepared.state_->owner != impl_.get())
    throw InvalidArgument("install_region: the region was not prepared by this editor (or was "
                          "installed already)");
  // The report's region figures and set_region's times; the last frame's figures (its times, the
  // method and the nonlinear iteration's) stay the editor's. A copy: the region keeps its own for
  // when it is set again from the recent ones.
  EditReport& r = prepared.state_->report;
  const EditReport& last = impl_->report;
  for (const auto& [key, ms] : last.milliseconds)
    if (key.rfind("frame", 0) == 0) r.milliseconds[key] = ms;
  r.method = last.method;
  r.nonlinear = last.nonlinear;
  r.nonlinear_level = last.nonlinear_level;
  r.fallback = last.fallback;
  impl_->report = r;
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

} // namespace remora
