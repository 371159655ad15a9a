#include "remora/multires/rotation_blend.h"

#include <cmath>

#include <Eigen/SVD>

namespace remora {

Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  if ((u * svd.matrixV().transpose()).determinant() < 0.0) u.col(2) = -u.col(2);
  return u * svd.matrixV().transpose();
}

Eigen::Matrix3d polar_stretch(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixV() * svd.singularValues().asDiagonal() * svd.matrixV().transpose();
}

Eigen::Vector3d rotation_log(const Eigen::Matrix3d& r) {
  Eigen::Quaterniond q(r);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double s = q.vec().norm();
  if (s < 1e-300) return Eigen::Vector3d::Zero();
  const double angle = 2.0 * std::atan2(s, q.w()); // in [0, π]
  return q.vec() * (angle / s);
}

Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

Eigen::Matrix3d blend_rotations(const std::vector<Eigen::Vector3d>& logs,
                                const Eigen::Ref<const Eigen::RowVectorXd>& weights) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < logs.size(); ++j)
    v += weights[static_cast<Eigen::Index>(j)] * logs[j];
  return rotation_exp(v);
}

} // namespace remora
