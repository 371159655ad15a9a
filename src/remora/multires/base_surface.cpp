#include "remora/multires/base_surface.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/SparseCore>
#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"

namespace remora {

LowPassFilter::LowPassFilter(const Mesh& mesh, const LowPassOptions& options)
    : n_(static_cast<Eigen::Index>(mesh.n_vertices())), steps_(options.steps) {
  if (!(options.smoothing >= 0.0) || !std::isfinite(options.smoothing) || options.steps < 1 ||
      !(options.tolerance > 0.0))
    throw InvalidArgument(fmt::format(
        "low-pass filter: smoothing {} must be finite and >= 0, steps {} >= 1, tolerance {} > 0",
        options.smoothing, options.steps, options.tolerance));
  stats_.sigma = options.smoothing * length_scale(mesh).length;
  if (!(stats_.sigma > 0.0)) return; // identity
  IntrinsicLaplacian lap = intrinsic_delaunay_laplacian(mesh);
  Eigen::VectorXd mass = std::move(lap.mass);
  // Isolated vertices (no face, zero mass) get an identity row.
  for (Eigen::Index i = 0; i < n_; ++i)
    if (!(mass[i] > 0.0)) mass[i] = 1.0;
  const double t = stats_.sigma * stats_.sigma;

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
  // no boundary block: its matrix is built in place (igea_sub4: 0.25 s less than the triplets).
  Eigen::SparseMatrix<double> a;
  std::vector<Eigen::Triplet<double>> couple;
  mass_.resize(ni);
  if (nb == 0) {
    mass_ = mass;
    a = -t * lap.weights;
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
          couple.emplace_back(br, bc, t * it.value());
        else
          inner.emplace_back(br, bc, -t * it.value());
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
  // half the adjacent lengths; each boundary vertex has exactly two boundary neighbours.
  if (nb > 0) {
    const double floor = 1e-9 * stats_.sigma;
    std::vector<Eigen::Triplet<double>> curve;
    boundary_mass_ = Eigen::VectorXd::Zero(nb);
    for (auto h : mesh.halfedges()) {
      if (!mesh.is_boundary(h)) continue;
      const auto i = block[static_cast<std::size_t>(mesh.from_vertex_handle(h).idx())];
      const auto j = block[static_cast<std::size_t>(mesh.to_vertex_handle(h).idx())];
      const double length = std::max(mesh.calc_edge_length(h), floor);
      const double w = t / length;
      curve.emplace_back(i, i, w);
      curve.emplace_back(j, j, w);
      curve.emplace_back(i, j, -w);
      curve.emplace_back(j, i, -w);
      boundary_mass_[i] += 0.5 * length;
      boundary_mass_[j] += 0.5 * length;
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
