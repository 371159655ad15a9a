// Anderson acceleration of a fixed-point iteration u ← G(u) (Walker & Ni 2011, the "type II"
// form), used by the nonlinear deformer's local/global iterations (multires/nonlinear.h).
//
// From the newest pair g = G(u), f = g − u and the last `depth` differences of both, the
// extrapolation is g − ΔG θ with θ minimizing ‖f − ΔF θ‖ (normal equations, regularized by
// 10⁻¹² of the largest diagonal entry). The history's Gram matrix ΔFᵀΔF is kept: a new column
// needs its products with the others only. The long vectors go in fixed blocks on the threads,
// and each product is summed over the blocks in order, so the result does not depend on the
// number of threads. On an affine G with depth ≥ the dimension, the iterates are those of GMRES
// on (I − A) u = b, up to round-off (tests/test_anderson.cpp).
#pragma once

#include <Eigen/Core>

namespace remora {

class AndersonAcceleration {
public:
  /// `depth` ≥ 1 differences kept; `threads` for the long vectors (0 = all). Throws
  /// InvalidArgument for depth < 1.
  explicit AndersonAcceleration(int depth, int threads = 0);

  /// Forgets everything: the next pair starts a new history.
  void clear();
  /// Forgets the differences but keeps the newest pair, from which the next difference is taken
  /// (after an extrapolation that was refused).
  void restart();
  /// Differences held (0 … depth).
  int history() const;

  /// The extrapolated point from the history and the newest pair (g = G(u), f = g − u, of one
  /// length; a new length clears the history). Returns g while no difference is held.
  Eigen::VectorXd extrapolate(const Eigen::VectorXd& g, const Eigen::VectorXd& f);

private:
  int depth_, threads_;
  int count_ = 0;           // pairs since the last restart, less one
  Eigen::MatrixXd dg_, df_; // the differences, a column each (slot count % depth)
  Eigen::MatrixXd gram_;    // df_ᵀ df_ of the columns held
  Eigen::VectorXd last_g_, last_f_;
};

} // namespace remora
