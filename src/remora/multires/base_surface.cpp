#include "remora/multires/base_surface.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <queue>
#include <utility>
#include <vector>

#include <Eigen/SparseCore>
#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/thickness.h"

namespace remora {

namespace {

void check_options(const LowPassOptions& o) {
  if (!(o.smoothing >= 0.0) || !std::isfinite(o.smoothing) || !(o.feature_cap >= 0.0) ||
      !std::isfinite(o.feature_cap) || !(o.cap_slope > 0.0) || !std::isfinite(o.cap_slope) ||
      o.steps < 1 || !(o.tolerance > 0.0))
    throw InvalidArgument(fmt::format(
        "low-pass filter: smoothing {} and feature_cap {} must be finite and >= 0, cap_slope {} "
        "finite and > 0, steps {} >= 1, tolerance {} > 0",
        o.smoothing, o.feature_cap, o.cap_slope, o.steps, o.tolerance));
}

} // namespace

Eigen::VectorXd smoothing_field(const Mesh& mesh, double sigma, const LowPassOptions& options) {
  check_options(options);
  if (!(sigma >= 0.0) || !std::isfinite(sigma))
    throw InvalidArgument(fmt::format("low-pass filter: σ {} must be finite and >= 0", sigma));
  const auto n = static_cast<Eigen::Index>(mesh.n_vertices());
  Eigen::VectorXd field = Eigen::VectorXd::Constant(n, sigma);
  if (options.feature_cap == 0.0 || sigma == 0.0) return field;
  // Faces met closer than a thousandth of σ are the vertex's own folds, not the far side; a
  // half-width beyond σ / cap caps nothing.
  const Eigen::VectorXd half = vertex_half_widths(
      mesh, {.min_distance = 1e-3 * sigma,
             .max_distance = std::max(2 * sigma / options.feature_cap, 2e-3 * sigma),
             .threads = options.threads});
  // The largest field below min(σ, cap × half-width) that grows by at most cap_slope per unit
  // length along edges: Dijkstra from every vertex at once.
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (Eigen::Index i = 0; i < n; ++i) {
    field[i] = std::min(sigma, options.feature_cap * half[i]);
    if (field[i] < sigma) queue.emplace(field[i], static_cast<int>(i));
  }
  while (!queue.empty()) {
    const auto [value, i] = queue.top();
    queue.pop();
    if (value > field[i]) continue;
    const VertexHandle v(i);
    for (const VertexHandle w : mesh.vv_range(v)) {
      const double reach = value + options.cap_slope * (mesh.point(w) - mesh.point(v)).norm();
      if (reach < field[w.idx()]) {
        field[w.idx()] = reach;
        queue.emplace(reach, w.idx());
      }
    }
  }
  return field;
}

LowPassFilter::LowPassFilter(const Mesh& mesh, const LowPassOptions& options)
    : n_(static_cast<Eigen::Index>(mesh.n_vertices())), steps_(options.steps) {
  check_options(options);
  stats_.sigma = stats_.sigma_min = options.smoothing * length_scale(mesh).length;
  if (!(stats_.sigma > 0.0)) return; // identity
  const Eigen::VectorXd field = smoothing_field(mesh, stats_.sigma, options);
  for (Eigen::Index i = 0; i < n_; ++i) {
    stats_.sigma_min = std::min(stats_.sigma_min, field[i]);
    stats_.capped += field[i] < stats_.sigma ? 1 : 0;
  }
  IntrinsicLaplacian lap = intrinsic_delaunay_laplacian(mesh);
  Eigen::VectorXd mass = std::move(lap.mass);
  // Isolated vertices (no face, zero mass) get an identity row.
  for (Eigen::Index i = 0; i < n_; ++i)
    if (!(mass[i] > 0.0)) mass[i] = 1.0;
  // Edge weights times σ_i σ_j (σ² everywhere when nothing is capped: exactly t W, as without
  // the cap), the diagonal again minus the row's sum.
  const double t = stats_.sigma * stats_.sigma;
  const bool uniform = stats_.capped == 0;
  auto edge_t = [&](Eigen::Index i, Eigen::Index j) { return uniform ? t : field[i] * field[j]; };
  if (!uniform) {
    for (int k = 0; k < lap.weights.outerSize(); ++k) {
      double sum = 0.0;
      double* diagonal = nullptr;
      for (Eigen::SparseMatrix<double>::InnerIterator it(lap.weights, k); it; ++it) {
        if (it.row() == it.col()) {
          diagonal = &it.valueRef();
        } else {
          it.valueRef() *= edge_t(it.row(), it.col());
          sum += it.value();
        }
      }
      if (diagonal) *diagonal = -sum;
    }
  }
  const double scale = uniform ? t : 1.0; // what multiplies lap.weights from here on

  // Rows: interior vertices, then boundary ones (each index's place in its own block).
  // Isolated vertices count as interior (OpenMesh calls them boundary).
  std::vector<char> on_boundary(static_cast<std::size_t>(n_), 0);
  std::vector<Eigen::Index> block(static_cast<std::size_t>(n_));
  for (Eigen::Index i = 0; i < n_; ++i) {
    const VertexHandle v(static_cast<int>(i));
    on_boundary[static_cast<std::size_t>(i)] = !mesh.is_isolated(v) && mesh.is_boundary(v);
    auto& list = on_boundary[static_cast<std::size_t>(i)] ? boundary_ : interior_;
    block[static_cast<std::size_t>(i)] = static_cast<Eigen::Index>(list.size());
    list.push_back(i);
  }
  const auto ni = static_cast<Eigen::Index>(interior_.size());
  const auto nb = static_cast<Eigen::Index>(boundary_.size());
  auto is_boundary = [&](Eigen::Index i) { return on_boundary[static_cast<std::size_t>(i)] != 0; };

  // The interior system (M − tW)_II, and t W_IB for the boundary's values. A closed mesh has
  // no boundary block: its matrix is built in place, faster than from triplets.
  Eigen::SparseMatrix<double> a;
  std::vector<Eigen::Triplet<double>> couple;
  mass_.resize(ni);
  if (nb == 0) {
    mass_ = mass;
    a = -scale * lap.weights;
    for (Eigen::Index i = 0; i < ni; ++i) a.coeffRef(i, i) += mass_[i];
    a.makeCompressed();
  } else {
    std::vector<Eigen::Triplet<double>> inner;
    for (int k = 0; k < lap.weights.outerSize(); ++k)
      for (Eigen::SparseMatrix<double>::InnerIterator it(lap.weights, k); it; ++it) {
        const Eigen::Index r = it.row(), c = it.col();
        if (is_boundary(r)) continue;
        const auto br = block[static_cast<std::size_t>(r)], bc = block[static_cast<std::size_t>(c)];
        if (is_boundary(c))
          couple.emplace_back(br, bc, scale * it.value());
        else
          inner.emplace_back(br, bc, -scale * it.value());
      }
    for (Eigen::Index i = 0; i < ni; ++i) {
      mass_[i] = mass[interior_[static_cast<std::size_t>(i)]];
      inner.emplace_back(i, i, mass_[i]);
    }
    a.resize(ni, ni);
    a.setFromTriplets(inner.begin(), inner.end());
  }
  lap.weights.resize(0, 0);
  stats_.laplacian_stats = std::move(lap);
  SolverOptions solver_options;
  solver_options.name = "cg";
  solver_options.tolerance = options.tolerance;
  if (ni > 0) {
    solver_ = make_solver(solver_options);
    solver_->compute(a);
  }
  coupling_.resize(ni, nb);
  coupling_.setFromTriplets(couple.begin(), couple.end());

  // The loops' curve system: weights 1/length (floored, for coincident boundary vertices), mass
  // half the adjacent lengths; each boundary vertex has exactly two boundary neighbours. A loop
  // is a curve: what shrinks it is its own size, not the part's width, so its σ is capped by
  // its radius (perimeter / 2π), one σ along the loop.
  if (nb > 0) {
    const double floor = 1e-9 * stats_.sigma;
    std::vector<Eigen::Triplet<double>> curve;
    boundary_mass_ = Eigen::VectorXd::Zero(nb);
    std::vector<char> done(mesh.n_halfedges(), 0);
    std::vector<HalfedgeHandle> loop;
    for (auto start : mesh.halfedges()) {
      if (!mesh.is_boundary(start) || done[static_cast<std::size_t>(start.idx())]) continue;
      loop.clear();
      double perimeter = 0.0;
      for (HalfedgeHandle h = start; !done[static_cast<std::size_t>(h.idx())];
           h = mesh.next_halfedge_handle(h)) {
        done[static_cast<std::size_t>(h.idx())] = 1;
        loop.push_back(h);
        perimeter += mesh.calc_edge_length(h);
      }
      const double sigma =
          options.feature_cap > 0.0
              ? std::min(stats_.sigma, options.feature_cap * perimeter / (2.0 * std::numbers::pi))
              : stats_.sigma;
      stats_.capped_loops += sigma < stats_.sigma ? 1 : 0;
      for (const HalfedgeHandle h : loop) {
        const auto i = block[static_cast<std::size_t>(mesh.from_vertex_handle(h).idx())];
        const auto j = block[static_cast<std::size_t>(mesh.to_vertex_handle(h).idx())];
        const double length = std::max(mesh.calc_edge_length(h), floor);
        const double w = sigma * sigma / length;
        curve.emplace_back(i, i, w);
        curve.emplace_back(j, j, w);
        curve.emplace_back(i, j, -w);
        curve.emplace_back(j, i, -w);
        boundary_mass_[i] += 0.5 * length;
        boundary_mass_[j] += 0.5 * length;
      }
    }
    for (Eigen::Index i = 0; i < nb; ++i) curve.emplace_back(i, i, boundary_mass_[i]);
    Eigen::SparseMatrix<double> loops(nb, nb);
    loops.setFromTriplets(curve.begin(), curve.end());
    boundary_solver_ = make_solver(solver_options);
    boundary_solver_->compute(loops);
  }
  solved_ = true;
}

LowPassFilter::LowPassFilter(LowPassFilter&&) noexcept = default;
LowPassFilter& LowPassFilter::operator=(LowPassFilter&&) noexcept = default;
LowPassFilter::~LowPassFilter() = default;

Eigen::MatrixXd LowPassFilter::apply(const Eigen::MatrixXd& values) {
  if (values.rows() != n_)
    throw InvalidArgument(
        fmt::format("low-pass filter: {} rows given for a mesh of {} vertices", values.rows(), n_));
  if (!solved_) return values;
  const Eigen::Index cols = values.cols();
  const auto ni = static_cast<Eigen::Index>(interior_.size());
  const auto nb = static_cast<Eigen::Index>(boundary_.size());
  Eigen::MatrixXd xi(ni, cols), xb(nb, cols);
  for (Eigen::Index i = 0; i < ni; ++i) xi.row(i) = values.row(interior_[std::size_t(i)]);
  for (Eigen::Index i = 0; i < nb; ++i) xb.row(i) = values.row(boundary_[std::size_t(i)]);
  stats_.iterations = 0;
  for (int s = 0; s < steps_; ++s) {
    if (nb > 0) {
      const Eigen::MatrixXd b = boundary_mass_.asDiagonal() * xb;
      xb = boundary_solver_->solve(b, &xb);
      stats_.iterations = std::max(stats_.iterations, boundary_solver_->stats().iterations);
    }
    if (ni > 0) {
      Eigen::MatrixXd b = mass_.asDiagonal() * xi;
      if (nb > 0) b += coupling_ * xb;
      xi = solver_->solve(b, &xi);
      stats_.iterations = std::max(stats_.iterations, solver_->stats().iterations);
    }
  }
  Eigen::MatrixXd x(n_, cols);
  for (Eigen::Index i = 0; i < ni; ++i) x.row(interior_[std::size_t(i)]) = xi.row(i);
  for (Eigen::Index i = 0; i < nb; ++i) x.row(boundary_[std::size_t(i)]) = xb.row(i);
  return x;
}

} // namespace remora
