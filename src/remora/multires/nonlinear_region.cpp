#include "remora/multires/nonlinear_region.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/timer.h"
#include "remora/geometry/measures.h"

namespace remora {

double coarse_length(double base_length, std::size_t free_vertices,
                     const NonlinearOptions& options) {
  const double ratio = double(free_vertices) / std::max(1.0, double(options.preview_vertices));
  return base_length * std::max(2.0, std::sqrt(ratio));
}

RemeshResult make_coarse_base(const Mesh& base, std::size_t free_vertices,
                              const NonlinearOptions& options) {
  RemeshOptions o;
  o.target_length = coarse_length(mean_edge_length(base), free_vertices, options);
  o.compute_report = false;
  o.threads = options.threads;
  return remesh(base, o);
}

NonlinearRegion::NonlinearRegion(const Mesh& base, const RemeshResult* coarse,
                                 const Eigen::MatrixXd& rest, const std::vector<int>& labels,
                                 const Eigen::MatrixXd& handle_weights,
                                 const NonlinearOptions& options) {
  for (std::size_t v = 0; v < labels.size(); ++v)
    if (labels[v] == Region::kFree) free_.push_back(static_cast<int>(v));
  try {
    fine_ = std::make_unique<NonlinearDeformer>(base, rest, labels, handle_weights, options);
  } catch (const Error& e) {
    setup_error_ = fmt::format("the nonlinear method is off for this region ({}); the linear "
                               "result is shown",
                               e.what());
    return;
  }
  if (!coarse) return;
  try {
    preview_ =
        std::make_unique<NonlinearPreview>(base, *coarse, rest, labels, handle_weights, options);
  } catch (const Error&) {
    preview_.reset(); // the fine level alone, which works
  }
}

NonlinearRegion::~NonlinearRegion() = default;

std::size_t NonlinearRegion::coarse_free_vertices() const {
  return preview_ ? preview_->coarse_free_vertices() : 0;
}

bool NonlinearRegion::finished() const {
  if (!fallback_.empty() || !fine_) return true;
  return !fine_stale_ && fine_->stats().finished();
}

void NonlinearRegion::frame(const std::vector<AffineMap>& transforms, bool moved, double budget_ms,
                            RowPoints& base, const std::function<bool()>& interrupt) {
  if (!fine_) {
    fallback_ = setup_error_;
    return;
  }
  if (moved) fallback_.clear();
  if (!fallback_.empty()) return;
  const auto t0 = Clock::now();
  if (linear_.rows() != base.rows()) linear_.setZero(base.rows(), 3);
  for (const int v : free_) linear_.row(v) = base.row(v);
  try {
    if (moved) {
      fine_stale_ = true;
      if (preview_) preview_->set_transforms(transforms, base);
    }
    if (preview_ && fine_stale_ && !preview_->stats().finished()) {
      stats_ = preview_->solve(budget_ms, interrupt);
      level_ = "coarse";
      preview_->compose(linear_, base);
      if (!stats_.finished() || ms_since(t0) >= budget_ms || (interrupt && interrupt())) return;
    }
    if (fine_stale_) { // start from the preview's result, or from the linear one
      if (preview_) preview_->compose(linear_, base);
      fine_->set_transforms(transforms, &base);
      fine_stale_ = false;
    }
    stats_ = fine_->solve(std::max(0.0, budget_ms - ms_since(t0)), interrupt);
    level_ = "fine";
    const RowPoints& x = fine_->positions();
    for (const int v : free_)
      if (!x.row(v).allFinite())
        throw NumericalError("the iteration produced a non-finite position");
    for (const int v : free_) base.row(v) = x.row(v);
  } catch (const Error& e) {
    fallback_ =
        fmt::format("the nonlinear iteration failed ({}); the linear result is shown", e.what());
    for (const int v : free_) base.row(v) = linear_.row(v);
  }
}

} // namespace remora
