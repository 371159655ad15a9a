// The Phong decode's arithmetic (phong.h), shared by decode_phong() and the editor's frame
// (frame.h) so that both give the same doubles. Internal to src/remora/multires/.
#pragma once

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace remora::phong_detail {

using V3 = Eigen::Vector3d;

/// A face's frame: edge 0-1, normal × edge, normal. False for a face without area.
inline bool face_frame(const V3 (&x)[3], V3& t1, V3& t2, V3& nf) {
  const V3 e1 = x[1] - x[0];
  const V3 cross = e1.cross(x[2] - x[0]);
  const double len = e1.norm(), area2 = cross.norm();
  if (!(area2 > 1e-14 * std::max(len * len, (x[2] - x[0]).squaredNorm())) || !(len > 0.0))
    return false;
  t1 = e1 / len;
  nf = cross / area2;
  t2 = nf.cross(t1);
  return true;
}

/// b + offset n̂(b) on the face with corner positions x and normals n, b = Σ bary_k x_k, plus the
/// residual (in the face's frame) when there is one.
inline V3 phong_point(const V3 (&x)[3], const V3 (&n)[3], const std::array<double, 3>& bary,
                      double offset, const std::array<double, 3>* residual) {
  const V3 b = bary[0] * x[0] + bary[1] * x[1] + bary[2] * x[2];
  const V3 normal = bary[0] * n[0] + bary[1] * n[1] + bary[2] * n[2];
  const double len = normal.norm();
  V3 p = b;
  if (len > 0.0) p += (offset / len) * normal;
  if (residual) {
    const std::array<double, 3>& r = *residual;
    V3 t1, t2, nf;
    if (face_frame(x, t1, t2, nf))
      p += r[0] * t1 + r[1] * t2 + r[2] * nf;
    else
      p += V3(r[0], r[1], r[2]);
  }
  return p;
}

} // namespace remora::phong_detail
