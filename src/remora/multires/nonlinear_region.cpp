#include "remora/multires/nonlinear_region.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/timer.h"
#include "remora/geometry/measures.h"
#include "remora/multires/face_patch.h"

namespace remora {

double coarse_length(double base_length, std::size_t free_vertices,
                     const NonlinearOptions& options) {
  const double ratio = double(free_vertices) / std::max(1.0, double(options.preview_vertices));
  return base_length * std::max(2.0, std::sqrt(ratio));
}

namespace {

// A coarse base serves regions whose free vertices lie this many coarse edge lengths inside its
// part of B, and is cut out with a wider margin, so that a region painted again a little larger
// or beside the last one keeps it.
constexpr double kServedMargin = 2.0, kCutMargin = 3.0;

// B's faces within `margin` coarse edge lengths of the free vertices (counted in rings of B),
// closed into a manifold part; in increasing order.
std::vector<int> margin_faces(const Mesh& base, const TriangleTopology& t,
                              const std::vector<int>& free_vertices, double base_length,
                              double coarse, double margin) {
  std::vector<char> in(t.faces.size(), 0);
  std::vector<int> faces;
  for (const int v : free_vertices) add_fan(t, v, in, faces);
  grow_rings(t, static_cast<int>(std::ceil(margin * coarse / base_length)), in, faces);
  close_patch(base, t, false, in, faces);
  std::sort(faces.begin(), faces.end());
  return faces;
}

// Throws NumericalError when a free vertex of `x` is not finite.
void require_finite(const RowPoints& x, const std::vector<int>& free, const char* what) {
  for (const int v : free)
    if (!x.row(v).allFinite())
      throw NumericalError(fmt::format("{} produced a non-finite position", what));
}

} // namespace

RemeshResult make_coarse_base(const Mesh& base, const TriangleTopology& topology,
                              const Eigen::MatrixXd& points, double base_length,
                              const std::vector<int>& free_vertices,
                              const NonlinearOptions& options) {
  RemeshOptions o;
  o.target_length = coarse_length(base_length, free_vertices.size(), options);
  o.compute_report = false;
  o.threads = options.threads;
  const std::vector<int> faces =
      margin_faces(base, topology, free_vertices, base_length, o.target_length, kCutMargin);
  // Most of the base: the whole of it costs no more, and serves every later region.
  if (2 * faces.size() > base.n_faces()) return remesh(base, o);
  std::vector<int> local(base.n_vertices(), -1), vertices;
  RemeshResult coarse = remesh(sub_mesh(topology, points, faces, local, vertices), o);
  for (SurfacePoint& sp : coarse.output_on_input) // on the part's faces -> on B's
    if (sp.face.is_valid()) sp.face = FaceHandle(faces[static_cast<std::size_t>(sp.face.idx())]);
  std::vector<SurfacePoint> on_coarse(base.n_vertices(),
                                      SurfacePoint{FaceHandle(), {1.0, 0.0, 0.0}});
  for (std::size_t l = 0; l < vertices.size(); ++l)
    on_coarse[static_cast<std::size_t>(vertices[l])] = coarse.input_on_output[l];
  coarse.input_on_output = std::move(on_coarse);
  return coarse;
}

bool coarse_base_serves(const RemeshResult& coarse, const Mesh& base,
                        const TriangleTopology& topology, double base_length,
                        const std::vector<int>& free_vertices, const NonlinearOptions& options) {
  const double wanted = coarse_length(base_length, free_vertices.size(), options);
  if (coarse.input_on_output.size() != base.n_vertices() ||
      std::abs(mean_edge_length(coarse.mesh) / wanted - 1.0) > 0.5)
    return false;
  for (const int f :
       margin_faces(base, topology, free_vertices, base_length, wanted, kServedMargin))
    for (const int v : topology.faces[static_cast<std::size_t>(f)])
      if (!coarse.input_on_output[static_cast<std::size_t>(v)].face.is_valid()) return false;
  return true;
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
      require_finite(base, free_, "the coarse preview");
      if (!stats_.finished() || ms_since(t0) >= budget_ms || (interrupt && interrupt())) return;
      // The handles moved in this frame: the preview is what it shows, and the fine level (one
      // iteration of which costs several of the preview's) starts once they rest.
      if (moved && std::isfinite(budget_ms)) return;
    }
    if (fine_stale_) { // start from the preview's result, or from the linear one
      if (preview_) preview_->compose(linear_, base);
      fine_->set_transforms(transforms, &base);
      fine_stale_ = false;
    }
    stats_ = fine_->solve(std::max(0.0, budget_ms - ms_since(t0)), interrupt);
    level_ = "fine";
    const RowPoints& x = fine_->positions();
    require_finite(x, free_, "the iteration");
    for (const int v : free_) base.row(v) = x.row(v);
  } catch (const Error& e) {
    fallback_ =
        fmt::format("the nonlinear iteration failed ({}); the linear result is shown", e.what());
    for (const int v : free_) base.row(v) = linear_.row(v);
  }
}

} // namespace remora
