// The affine maps of multires/editor.h: handle transforms as 3×4 matrices [M | t].
#include <cmath>

#include <Eigen/Geometry>

#include "remora/common/error.h"
#include "remora/multires/editor.h"

namespace remora {

Transform identity_transform() {
  Transform t = Transform::Zero();
  t.leftCols<3>().setIdentity();
  return t;
}

Transform translation(const Eigen::Vector3d& offset) {
  Transform t = identity_transform();
  t.col(3) = offset;
  return t;
}

Transform rotation(const Eigen::Vector3d& axis, double radians, const Eigen::Vector3d& center) {
  if (!axis.allFinite() || !(axis.norm() > 0.0) || !std::isfinite(radians) || !center.allFinite())
    throw InvalidArgument("rotation: the axis must be finite and non-zero, the angle and the "
                          "center finite");
  Transform t;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(radians, axis.normalized()).toRotationMatrix();
  t.leftCols<3>() = r;
  t.col(3) = center - r * center;
  return t;
}

Transform scaling(const Eigen::Vector3d& factors, const Eigen::Vector3d& center) {
  if (!factors.allFinite() || !center.allFinite())
    throw InvalidArgument("scaling: the factors and the center must be finite");
  Transform t = Transform::Zero();
  t.leftCols<3>() = factors.asDiagonal();
  t.col(3) = center - factors.cwiseProduct(center);
  return t;
}

Transform compose(const Transform& a, const Transform& b) {
  Transform t;
  t.leftCols<3>() = a.leftCols<3>() * b.leftCols<3>();
  t.col(3) = a.leftCols<3>() * b.col(3) + a.col(3);
  return t;
}

} // namespace remora
