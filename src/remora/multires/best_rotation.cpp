// The local step's rotation when Newton's method (best_rotation.h) does not settle: Horn's
// quaternion power iteration with an SVD fallback.
#include "remora/multires/best_rotation.h"

#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace remora {

namespace {

using Matrix3 = Eigen::Matrix3d;

/// The rotation R maximizing tr(R P) by SVD (orthogonal Procrustes; Sorkine & Alexa 2007,
/// Eq. 6): the power iteration's fallback.
Matrix3 best_rotation_svd(const Matrix3& p) {
  const Eigen::JacobiSVD<Matrix3> svd(p, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3 v = svd.matrixV();
  Matrix3 r = v * svd.matrixU().transpose();
  if (r.determinant() < 0.0) {
    v.col(2) = -v.col(2); // the smallest singular value's direction flips
    r = v * svd.matrixU().transpose();
  }
  return r;
}

} // namespace

namespace rotation_detail {

// tr(R(q) P) = qᵀ N q for unit quaternions q (Horn 1987, §4 with P = Σ p qᵀ, rest times current):
// the best rotation is the eigenvector of N's largest eigenvalue. N + c I with c >= ‖N‖₂ (c =
// √3 ‖P‖_F bounds the nuclear norm of P, hence every |λ(N)|) is positive semi-definite, and the
// Rayleigh quotient of a PSD matrix does not decrease under multiplication by it, so
// (N + c I)^(2^k) q₀ is at least as good as the start q₀ and converges to the best: up to eight
// squarings, fewer once q is an eigenvector to round-off (a warm start). One call reaches the best
// unless N's two largest eigenvalues nearly coincide; the iteration's next local step goes on.
Eigen::Matrix3d best_rotation_power(const Eigen::Matrix3d& p, const Eigen::Matrix3d& start) {
  const double sxx = p(0, 0), sxy = p(0, 1), sxz = p(0, 2), syx = p(1, 0), syy = p(1, 1),
               syz = p(1, 2), szx = p(2, 0), szy = p(2, 1), szz = p(2, 2);
  Eigen::Matrix4d n;
  n << sxx + syy + szz, syz - szy, szx - sxz, sxy - syx, //
      syz - szy, sxx - syy - szz, sxy + syx, szx + sxz,  //
      szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy, //
      sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz;
  const double scale = std::sqrt(3.0) * p.norm();
  if (!(scale > 0.0) || !std::isfinite(scale)) return start;
  n /= scale;
  n.diagonal().array() += 1.0;
  const Eigen::Matrix4d shifted = n;
  const Eigen::Quaterniond q0(start);
  const Eigen::Vector4d start_q(q0.w(), q0.x(), q0.y(), q0.z());
  Eigen::Vector4d q = start_q;
  for (int k = 0; k < 8; ++k) {
    n = (n * n).eval();
    n /= n.cwiseAbs().maxCoeff();
    if (k % 2 == 0) continue;
    // Every second squaring: done when q is an eigenvector to round-off (a warm start).
    q = n * start_q;
    const double length = q.norm();
    if (!(length > 1e-150) || !std::isfinite(length)) return best_rotation_svd(p);
    q /= length;
    const Eigen::Vector4d nq = shifted * q;
    if ((nq - q.dot(nq) * q).norm() < 1e-13) break;
  }
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
}

} // namespace rotation_detail

} // namespace remora
