#include "remora/multires/motion_blend.h"

#include <cmath>

#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/multires/rotation_blend.h"

namespace remora {

namespace {

using Matrix3 = Eigen::Matrix3d;
using Vector3 = Eigen::Vector3d;

Matrix3 cross_matrix(const Vector3& w) {
  Matrix3 m;
  m << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return m;
}

/// The coefficients (1 − cos θ)/θ² and (θ − sin θ)/θ³ of V = I + a W + b W², by their series
/// near 0 where the quotients lose their digits.
void left_jacobian_coefficients(double theta, double& a, double& b) {
  if (theta < 1e-4) {
    const double t2 = theta * theta;
    a = 0.5 - t2 / 24.0;
    b = 1.0 / 6.0 - t2 / 120.0;
    return;
  }
  a = (1.0 - std::cos(theta)) / (theta * theta);
  b = (theta - std::sin(theta)) / (theta * theta * theta);
}

} // namespace

ScrewTwist screw_log(const Matrix3& r, const Vector3& t) {
  ScrewTwist s;
  s.omega = rotation_log(r);
  const double theta = s.omega.norm();
  const Matrix3 w = cross_matrix(s.omega);
  // V⁻¹ = I − W/2 + c W², c = (1 − θ sin θ / (2 (1 − cos θ))) / θ².
  const double c =
      theta < 1e-4
          ? 1.0 / 12.0 + theta * theta / 720.0
          : (1.0 - theta * std::sin(theta) / (2.0 * (1.0 - std::cos(theta)))) / (theta * theta);
  s.v = t - 0.5 * (w * t) + c * (w * (w * t));
  return s;
}

void screw_exp(const ScrewTwist& twist, Matrix3& r, Vector3& t) {
  const double theta = twist.omega.norm();
  double a = 0.0, b = 0.0;
  left_jacobian_coefficients(theta, a, b);
  const Matrix3 w = cross_matrix(twist.omega);
  const Matrix3 w2 = w * w;
  // Rodrigues: R = I + (sin θ/θ) W + a W².
  const double s = theta < 1e-4 ? 1.0 - theta * theta / 6.0 : std::sin(theta) / theta;
  r = Matrix3::Identity() + s * w + a * w2;
  t = twist.v + a * (w * twist.v) + b * (w2 * twist.v);
}

Vector3 screw_apply(const ScrewTwist& twist, const Vector3& y) {
  const double theta = twist.omega.norm();
  double a = 0.0, b = 0.0;
  left_jacobian_coefficients(theta, a, b);
  const double s = theta < 1e-4 ? 1.0 - theta * theta / 6.0 : std::sin(theta) / theta;
  const Vector3& w = twist.omega;
  // R y + t with R = I + s W + a W², t = (I + a W + b W²) v, W u = ω × u.
  const Vector3 wy = w.cross(y), wv = w.cross(twist.v);
  return y + s * wy + a * w.cross(wy) + twist.v + a * wv + b * w.cross(wv);
}

HandleMotions handle_motions(const std::vector<Eigen::Matrix<double, 3, 4>>& maps,
                             const std::vector<Vector3>& pivots) {
  if (maps.size() != pivots.size())
    throw InvalidArgument(fmt::format("blended motions: {} maps for {} pivots (one each expected)",
                                      maps.size(), pivots.size()));
  HandleMotions h;
  for (std::size_t j = 0; j < maps.size(); ++j) {
    const Matrix3 m = maps[j].leftCols<3>();
    const Matrix3 rotation = polar_rotation(m);
    const Matrix3 stretch = polar_stretch(m);
    const Vector3 t = maps[j].col(3) + rotation * ((stretch - Matrix3::Identity()) * pivots[j]);
    h.twist.push_back(screw_log(rotation, t));
    h.stretch.push_back(stretch);
    h.pivot.push_back(pivots[j]);
    if (!(stretch - Matrix3::Identity()).isZero(1e-12)) h.stretched = true;
  }
  return h;
}

void blend_motions(const RowPoints& rest, const Eigen::MatrixXd& weights,
                   const std::vector<int>& vertices, const HandleMotions& motions, RowPoints& x,
                   int threads) {
  const std::size_t h = motions.twist.size();
  if (static_cast<std::size_t>(weights.cols()) != h || weights.rows() != rest.rows() ||
      x.rows() != rest.rows())
    throw InvalidArgument(
        fmt::format("blended motions: {} x {} weights, {} rest and {} output rows for {} handles",
                    weights.rows(), weights.cols(), rest.rows(), x.rows(), h));
  parallel_for(vertices.size(), threads, [&](std::size_t k) {
    const auto v = static_cast<Eigen::Index>(vertices[k]);
    const Vector3 p = rest.row(v).transpose();
    ScrewTwist sum;
    Vector3 y = p;
    for (std::size_t j = 0; j < h; ++j) {
      const double w = weights(v, static_cast<Eigen::Index>(j));
      sum.omega += w * motions.twist[j].omega;
      sum.v += w * motions.twist[j].v;
      if (motions.stretched)
        y += w * ((motions.stretch[j] - Matrix3::Identity()) * (p - motions.pivot[j]));
    }
    x.row(v) = screw_apply(sum, y).transpose();
  });
}

} // namespace remora
