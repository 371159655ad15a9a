// The nonlinear deformation (multires/nonlinear.h) on a coarse remesh of the base, carried to the
// fine base as a correction of the linear result: what the editor shows while a handle is
// dragged over a large support, until the fine iteration takes over (docs/nonlinear.md).
// The coarse level is a remesh of B, or of its part around the support (make_coarse_base() of
// nonlinear_region.h), at a longer edge length (the remesher of paper §4, as the multigrid
// hierarchy of §5.2 builds its levels), linked to B by the remesher's correspondence both ways.
//
// With lin the fine linear result, R lin its values at the coarse vertices' places on B
// (barycentric interpolation) and x_c the coarse nonlinear solution started from R lin, the fine
// free vertices go to
//   x = lin + P (x_c − R lin),
// P interpolating at each fine vertex's place on the coarse mesh, the correction taken as 0 on
// constrained coarse vertices. Exact where the nonlinear method is: all transforms identity
// gives x⁰, one rigid motion of every constraint gives that motion (to round-off).
//
// Coarse labels: a coarse vertex takes the label of the fine vertex nearest its place (the
// corner of largest barycentric weight), then every fine handle vertex claims the coarse vertex
// nearest its own place, so that no handle vanishes. Throws InvalidArgument when the coarse
// region is unusable (no free coarse vertex) and NumericalError when its matrix cannot be
// factored; the editor then iterates on the fine base alone.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "remora/mesh/mesh.h"
#include "remora/multires/nonlinear.h"
#include "remora/remesh/remesh.h"

namespace remora {

class NonlinearPreview {
public:
  /// `fine`: B; `coarse`: remesh(B) with its correspondences; `rest`, `labels`,
  /// `handle_weights`: as for NonlinearDeformer, on B.
  NonlinearPreview(const Mesh& fine, const RemeshResult& coarse, const Eigen::MatrixXd& rest,
                   const std::vector<int>& labels, const Eigen::MatrixXd& handle_weights,
                   const NonlinearOptions& options);

  /// New handle maps; `linear` (B's vertices, n × 3) is the fine linear result under them.
  void set_transforms(const std::vector<AffineMap>& transforms, const RowPoints& linear);
  /// Coarse iterations (NonlinearDeformer::solve).
  const NonlinearStats& solve(double budget_ms, const std::function<bool()>& interrupt = {});
  const NonlinearStats& stats() const;
  /// out.row(v) = linear.row(v) + the interpolated correction, for every free vertex v of B.
  void compose(const RowPoints& linear, RowPoints& out) const;
  std::size_t coarse_free_vertices() const;

private:
  struct Corner3 {
    std::array<int, 3> vertex{0, 0, 0};
    std::array<double, 3> weight{1.0, 0.0, 0.0};
  };
  std::vector<int> fine_free_;
  std::vector<Corner3> prolong_;  // per fine free vertex: its place on the coarse mesh
  std::vector<Corner3> restrict_; // per coarse vertex: its place on B
  std::vector<char> coarse_free_;
  RowPoints restricted_; // R lin under the current transforms
  std::unique_ptr<NonlinearDeformer> deformer_;
  int threads_ = 0;
};

} // namespace remora
