#include "remora/multires/base_surface.h"

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
  mass_ = std::move(lap.mass);
  // Isolated vertices (no face, zero mass) get an identity row.
  for (Eigen::Index i = 0; i < n_; ++i)
    if (!(mass_[i] > 0.0)) mass_[i] = 1.0;
  const double t = stats_.sigma * stats_.sigma;
  Eigen::SparseMatrix<double> a = -t * lap.weights;
  for (Eigen::Index i = 0; i < n_; ++i) a.coeffRef(i, i) += mass_[i];
  a.makeCompressed();
  lap.weights.resize(0, 0);
  stats_.laplacian_stats = std::move(lap);
  SolverOptions solver_options;
  solver_options.name = "cg";
  solver_options.tolerance = options.tolerance;
  solver_ = make_solver(solver_options);
  solver_->compute(a);
}

LowPassFilter::LowPassFilter(LowPassFilter&&) noexcept = default;
LowPassFilter& LowPassFilter::operator=(LowPassFilter&&) noexcept = default;
LowPassFilter::~LowPassFilter() = default;

Eigen::MatrixXd LowPassFilter::apply(const Eigen::MatrixXd& values) {
  if (values.rows() != n_)
    throw InvalidArgument(
        fmt::format("low-pass filter: {} rows given for a mesh of {} vertices", values.rows(), n_));
  if (!solver_) return values;
  Eigen::MatrixXd x = values;
  for (int s = 0; s < steps_; ++s) {
    const Eigen::MatrixXd b = mass_.asDiagonal() * x;
    x = solver_->solve(b, &x);
    stats_.iterations = solver_->stats().iterations;
  }
  return x;
}

} // namespace remora
