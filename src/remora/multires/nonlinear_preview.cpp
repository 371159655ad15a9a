#include "remora/multires/nonlinear_preview.h"

#include <algorithm>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/linalg/kharmonic.h"

namespace remora {

namespace {

/// The corner of largest barycentric weight.
int nearest_corner(const std::array<int, 3>& vertex, const std::array<double, 3>& weight) {
  return vertex[static_cast<std::size_t>(std::max_element(weight.begin(), weight.end()) -
                                         weight.begin())];
}

} // namespace

NonlinearPreview::NonlinearPreview(const Mesh& fine, const RemeshResult& coarse,
                                   const Eigen::MatrixXd& rest, const std::vector<int>& labels,
                                   const Eigen::MatrixXd& handle_weights,
                                   const NonlinearOptions& options)
    : threads_(options.threads) {
  const std::size_t nc = coarse.mesh.n_vertices();
  if (coarse.output_on_input.size() != nc || coarse.input_on_output.size() != fine.n_vertices())
    throw InvalidArgument("nonlinear preview: the coarse remesh's correspondence does not match "
                          "the meshes");
  const auto place = [](const Mesh& mesh, const SurfacePoint& sp) {
    Corner3 c;
    if (!sp.face.is_valid()) return c; // an isolated vertex: weight 1 on vertex 0, never used
    const auto fv = face_vertices(mesh, sp.face);
    for (int k = 0; k < 3; ++k) {
      c.vertex[static_cast<std::size_t>(k)] = fv[static_cast<std::size_t>(k)].idx();
      c.weight[static_cast<std::size_t>(k)] = sp.bary[static_cast<std::size_t>(k)];
    }
    return c;
  };
  restrict_.resize(nc);
  std::vector<int> coarse_label(nc, Region::kFixed);
  for (std::size_t c = 0; c < nc; ++c) {
    restrict_[c] = place(fine, coarse.output_on_input[c]);
    if (coarse.output_on_input[c].face.is_valid())
      coarse_label[c] = labels[static_cast<std::size_t>(
          nearest_corner(restrict_[c].vertex, restrict_[c].weight))];
  }
  for (std::size_t v = 0; v < fine.n_vertices(); ++v) {
    const SurfacePoint& sp = coarse.input_on_output[v];
    if (labels[v] < 0 || !sp.face.is_valid()) continue;
    const Corner3 c = place(coarse.mesh, sp);
    coarse_label[static_cast<std::size_t>(nearest_corner(c.vertex, c.weight))] = labels[v];
  }
  // The coarse rest shape and weights, interpolated from B's.
  const auto h = handle_weights.cols();
  Eigen::MatrixXd coarse_rest(static_cast<Eigen::Index>(nc), 3);
  Eigen::MatrixXd coarse_weights = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nc), h);
  coarse_free_.assign(nc, 0);
  for (std::size_t c = 0; c < nc; ++c) {
    const Corner3& r = restrict_[c];
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k) {
      p += r.weight[k] * rest.row(r.vertex[k]);
      coarse_weights.row(static_cast<Eigen::Index>(c)) +=
          r.weight[k] * handle_weights.row(r.vertex[k]);
    }
    coarse_rest.row(static_cast<Eigen::Index>(c)) = p;
    const int label = coarse_label[c];
    if (label >= 0) {
      coarse_weights.row(static_cast<Eigen::Index>(c)).setZero();
      coarse_weights(static_cast<Eigen::Index>(c), label) = 1.0;
    } else if (label == Region::kFixed) {
      coarse_weights.row(static_cast<Eigen::Index>(c)).setZero();
    }
    coarse_free_[c] = label == Region::kFree ? 1 : 0;
  }
  for (std::size_t v = 0; v < fine.n_vertices(); ++v)
    if (labels[v] == Region::kFree) {
      fine_free_.push_back(static_cast<int>(v));
      prolong_.push_back(place(coarse.mesh, coarse.input_on_output[v]));
    }
  const KHarmonicSystem check = assemble_kharmonic(coarse.mesh, Region{coarse_label}, {1});
  (void)check; // throws InvalidArgument for a coarse region that cannot be solved
  deformer_ = std::make_unique<NonlinearDeformer>(coarse.mesh, coarse_rest, coarse_label,
                                                  coarse_weights, options);
  restricted_ = coarse_rest;
}

void NonlinearPreview::set_transforms(const std::vector<AffineMap>& transforms,
                                      const RowPoints& linear) {
  parallel_for(restrict_.size(), threads_, [&](std::size_t c) {
    const Corner3& r = restrict_[c];
    restricted_.row(static_cast<Eigen::Index>(c)) = r.weight[0] * linear.row(r.vertex[0]) +
                                                    r.weight[1] * linear.row(r.vertex[1]) +
                                                    r.weight[2] * linear.row(r.vertex[2]);
  });
  deformer_->set_transforms(transforms, &restricted_);
}

const NonlinearStats& NonlinearPreview::solve(double budget_ms,
                                              const std::function<bool()>& interrupt) {
  return deformer_->solve(budget_ms, interrupt);
}

const NonlinearStats& NonlinearPreview::stats() const {
  return deformer_->stats();
}

std::size_t NonlinearPreview::coarse_free_vertices() const {
  return deformer_->free_vertices().size();
}

void NonlinearPreview::compose(const RowPoints& linear, RowPoints& out) const {
  const RowPoints& x = deformer_->positions();
  parallel_for(fine_free_.size(), threads_, [&](std::size_t i) {
    const Corner3& p = prolong_[i];
    Eigen::RowVector3d d = Eigen::RowVector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k) {
      const auto c = static_cast<Eigen::Index>(p.vertex[k]);
      if (coarse_free_[static_cast<std::size_t>(c)])
        d += p.weight[k] * (x.row(c) - restricted_.row(c));
    }
    const int v = fine_free_[i];
    out.row(v) = linear.row(v) + d;
  });
}

} // namespace remora
