// The local step of as-rigid-as-possible iterations (Sorkine & Alexa 2007, Eq. 6): the rotation
// that best turns a vertex's rest cell into its current one. Used by NonlinearDeformer
// (multires/nonlinear.h), once per cell and iteration, hence inline: Newton's steps from the
// cell's last rotation; the power iteration of best_rotation.cpp when they do not settle.
#pragma once

#include <cmath>

#include <Eigen/Core>

namespace remora {

namespace rotation_detail {

/// tr(R P) without forming R P.
inline double trace_of_product(const Eigen::Matrix3d& r, const Eigen::Matrix3d& p) {
  return r.row(0).dot(p.col(0)) + r.row(1).dot(p.col(1)) + r.row(2).dot(p.col(2));
}

/// r × exp([ω]) to second order in ω, exactly orthogonal: r times the Cayley transform of ω (the
/// rotation of the quaternion (1, ω/2)).
inline Eigen::Matrix3d times_cayley(const Eigen::Matrix3d& r, double w0, double w1, double w2) {
  const double x = 0.5 * w0, y = 0.5 * w1, z = 0.5 * w2;
  const double s = 2.0 / (1.0 + x * x + y * y + z * z);
  Eigen::Matrix3d c;
  c << 1.0 - s * (y * y + z * z), s * (x * y - z), s * (x * z + y), //
      s * (x * y + z), 1.0 - s * (x * x + z * z), s * (y * z - x),  //
      s * (x * z - y), s * (y * z + x), 1.0 - s * (x * x + y * y);
  return r * c;
}

/// Newton's method for the R maximizing tr(R P), from `r`. With M = P R, f(R exp[ω]) =
/// tr(exp[ω] M) = tr M + gᵀω − ½ ωᵀ H ω + O(|ω|³), g = (M₂₃ − M₃₂, M₃₁ − M₁₃, M₁₂ − M₂₁) and
/// H = tr(M) I − (M + Mᵀ)/2; a step is ω = H⁻¹ g. True with `r` the best rotation to round-off
/// when H was positive definite at every step (Sylvester's criterion, the leading minors well
/// above round-off) and the last step was below 10⁻⁸: tr(R P) on SO(3) has one local maximum,
/// the global one, and H is its negated Hessian (at the other critical points, R with P R
/// symmetric, H is not positive definite). False (r then unspecified) when a step leaves that
/// basin or four do not settle.
[[gnu::always_inline]] inline bool newton_rotation(const Eigen::Matrix3d& p, Eigen::Matrix3d& r) {
  for (int step = 0; step < 4; ++step) {
    const Eigen::Matrix3d m = p * r;
    const double t = m.trace();
    const double g0 = m(1, 2) - m(2, 1), g1 = m(2, 0) - m(0, 2), g2 = m(0, 1) - m(1, 0);
    const double h00 = t - m(0, 0), h11 = t - m(1, 1), h22 = t - m(2, 2);
    const double h01 = -0.5 * (m(0, 1) + m(1, 0)), h02 = -0.5 * (m(0, 2) + m(2, 0)),
                 h12 = -0.5 * (m(1, 2) + m(2, 1));
    // The adjugate's entries; the leading minors are h00, c22 and the determinant.
    const double c00 = h11 * h22 - h12 * h12, c01 = h02 * h12 - h01 * h22,
                 c02 = h01 * h12 - h02 * h11, c11 = h00 * h22 - h02 * h02,
                 c12 = h01 * h02 - h00 * h12, c22 = h00 * h11 - h01 * h01;
    const double det = h00 * c00 + h01 * c01 + h02 * c02;
    const double scale = std::abs(t) + 1e-300;
    if (!(h00 > 1e-10 * scale && c22 > 1e-10 * scale * scale &&
          det > 1e-10 * scale * scale * scale))
      return false;
    const double inv = 1.0 / det;
    const double w0 = inv * (c00 * g0 + c01 * g1 + c02 * g2),
                 w1 = inv * (c01 * g0 + c11 * g1 + c12 * g2),
                 w2 = inv * (c02 * g0 + c12 * g1 + c22 * g2);
    const double length = w0 * w0 + w1 * w1 + w2 * w2;
    if (!(length < 0.25)) return false; // beyond half a radian: not yet where Newton is sure
    r = times_cayley(r, w0, w1, w2);
    if (length < 1e-16) return true;
  }
  return false;
}

/// Power iterations on Horn's quaternion matrix (1987) from `start` (best_rotation.cpp).
Eigen::Matrix3d best_rotation_power(const Eigen::Matrix3d& p, const Eigen::Matrix3d& start);

} // namespace rotation_detail

/// The local step's rotation: R maximizing tr(R P) (orthogonal Procrustes), never worse than
/// `start`. From a warm start (the cell's rotation of the last iteration) Newton's method on SO(3)
/// usually settles in two or three steps of about a hundred flops, certified the best to
/// round-off; otherwise power iterations on Horn's quaternion matrix: the best to round-off
/// unless P is nearly degenerate (then still no worse than `start`).
[[gnu::always_inline]] inline Eigen::Matrix3d best_rotation(const Eigen::Matrix3d& p,
                                                            const Eigen::Matrix3d& start) {
  using namespace rotation_detail;
  if (Eigen::Matrix3d r = start;
      newton_rotation(p, r) && trace_of_product(r, p) >= trace_of_product(start, p))
    return r;
  return best_rotation_power(p, start);
}

} // namespace remora
