// What the nonlinear method's tests (tests/test_nonlinear.cpp, tests/test_motion_blend.cpp)
// share: the bumpy cylinder, the linear method's known failure (a twisted or bent tube that
// shrinks), measured ring by ring; and the bumpy sphere with two caps as handles and nothing
// fixed, on which one map of both handles must move everything by it.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "remora/geometry/measures.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/editor.h"
#include "support.h"

namespace remora::nonlinear_testing {

using testing::kPi;
using testing::max_row_distance;

/// An open cylinder of radius 1 and height 4 about the z axis with radial bumps of the given
/// amplitude: 12 around, wavelength 0.5 along z (8 base edge lengths). The support is every
/// circle but the bottom one, the handle the top circle.
struct Cylinder {
  int rings = 70, segments = 96;
  double amplitude = 0.02, height = 4.0;
  Mesh mesh;
  std::vector<int> support, handle;
  int id(int k, int s) const { return k * segments + s; }
  double bump(int k, int s) const {
    const double phi = 2.0 * kPi * (s + (k % 2 ? 0.5 : 0.0)) / segments;
    return std::sin(12.0 * phi) * std::sin(2.0 * kPi * (height * k / rings) / 0.5);
  }
};

inline Cylinder bumpy_cylinder(int rings = 70, int segments = 96) {
  Cylinder c;
  c.rings = rings;
  c.segments = segments;
  c.mesh = make_cylinder(rings, segments, 1.0, c.height);
  for (int k = 0; k <= rings; ++k)
    for (int s = 0; s < segments; ++s) {
      const VertexHandle v(c.id(k, s));
      Vec3 p = c.mesh.point(v);
      const double r = 1.0 + c.amplitude * c.bump(k, s);
      p[0] *= r;
      p[1] *= r;
      c.mesh.set_point(v, p);
      if (k > 0) c.support.push_back(v.idx());
      if (k == rings) c.handle.push_back(v.idx());
    }
  return c;
}

struct Rings {
  double worst_radius_error = 0.0; ///< the largest |mean radius − 1| of a circle of the input
  double amplitude = 0.0;          ///< the bumps' least-squares amplitude over the input's
};

/// Each circle of the input (k = 0 .. rings) in `p`: its mean distance from its centroid, and the
/// bumps as the least-squares multiple of the input's pattern in the distances' deviations.
inline Rings rings(const Cylinder& c, const Eigen::MatrixXd& p) {
  Rings f;
  double dot = 0.0, norm = 0.0;
  for (int k = 0; k <= c.rings; ++k) {
    Eigen::RowVector3d centre = Eigen::RowVector3d::Zero();
    for (int s = 0; s < c.segments; ++s) centre += p.row(c.id(k, s));
    centre /= c.segments;
    std::vector<double> r;
    double mean = 0.0;
    for (int s = 0; s < c.segments; ++s) {
      r.push_back((p.row(c.id(k, s)) - centre).norm());
      mean += r.back() / c.segments;
    }
    f.worst_radius_error = std::max(f.worst_radius_error, std::abs(mean - 1.0));
    for (int s = 0; s < c.segments; ++s) {
      dot += (r[static_cast<std::size_t>(s)] - mean) * c.bump(k, s);
      norm += c.bump(k, s) * c.bump(k, s);
    }
  }
  f.amplitude = dot / (norm * c.amplitude);
  return f;
}

inline Transform twist(const Cylinder& c, double radians) {
  return rotation({0, 0, 1}, radians, {0, 0, c.height});
}

/// The top circle where bending the axis into an arc of length `height` that turns by `radians`
/// about y puts it: turned by `radians`, its centre at the arc's end.
inline Transform bend(const Cylinder& c, double radians) {
  const double rho = c.height / radians;
  Transform t = rotation({0, 1, 0}, radians, {0, 0, 0});
  const Eigen::Vector3d end(rho * (1.0 - std::cos(radians)), 0.0, rho * std::sin(radians));
  t.col(3) = end - t.leftCols<3>() * Eigen::Vector3d(0, 0, c.height);
  return t;
}

/// The scaled handles of the nonlinear tests: the top scaled by 1.5 about its centre, or by 1.5
/// along x and then twisted by 90°.
inline Transform scaled_top(const Cylinder& c, bool twisted) {
  return twisted ? compose(twist(c, kPi / 2), scaling({1.5, 1.0, 1.0}, {0, 0, c.height}))
                 : scaling({1.5, 1.5, 1.5}, {0, 0, c.height});
}

/// A scaled top's flare, ring by ring (each ring's mean distance from the axis): how far a
/// method's radii are from the linear method's, the smallest of each, and the top ring's.
struct Flare {
  double worst_difference = 0.0, smallest_linear = 0.0, smallest = 0.0, top_linear = 0.0, top = 0.0;
};

inline Flare flare(const Cylinder& c, const Eigen::MatrixXd& linear, const Eigen::MatrixXd& other) {
  const auto radii = [&c](const Eigen::MatrixXd& p) {
    std::vector<double> r(static_cast<std::size_t>(c.rings + 1), 0.0);
    for (int k = 0; k <= c.rings; ++k)
      for (int s = 0; s < c.segments; ++s)
        r[static_cast<std::size_t>(k)] += p.row(c.id(k, s)).head<2>().norm() / c.segments;
    return r;
  };
  const std::vector<double> a = radii(linear), b = radii(other);
  Flare f;
  for (std::size_t k = 0; k < a.size(); ++k)
    f.worst_difference = std::max(f.worst_difference, std::abs(b[k] - a[k]));
  f.smallest_linear = *std::min_element(a.begin(), a.end());
  f.smallest = *std::min_element(b.begin(), b.end());
  f.top_linear = a.back();
  f.top = b.back();
  return f;
}

/// A bumpy unit sphere: every vertex in the support, its caps above z = 0.5 and below −0.5 the two
/// handles, nothing fixed (the weights sum to 1).
struct CappedSphere {
  Mesh mesh;
  std::vector<int> support;
  std::vector<std::vector<int>> handles;
  double diagonal = 0.0;
};

inline CappedSphere capped_sphere() {
  CappedSphere s;
  s.mesh = make_icosphere(3, 1.0);
  for (const VertexHandle v : s.mesh.vertices()) {
    const Vec3 p = s.mesh.point(v);
    s.mesh.set_point(v, p * (1.0 + 0.03 * std::sin(9 * p[0]) * std::sin(9 * p[1])));
    s.support.push_back(v.idx());
  }
  s.handles = {select_sphere(s.mesh, Vec3(0, 0, 1), 0.5),
               select_sphere(s.mesh, Vec3(0, 0, -1), 0.5)};
  s.diagonal = bounding_box_diagonal(s.mesh);
  return s;
}

/// The rigid map of the exact-case tests, and an affine one (that map after a stretch).
inline Transform some_rigid_map() {
  return compose(translation({0.4, -0.2, 1.5}), rotation({1, 2, 3}, 2.0, {0.1, 0.2, 0.3}));
}
inline Transform some_affine_map() {
  return compose(some_rigid_map(), scaling({1.5, 0.7, 1.1}, {0.1, 0.0, 0.2}));
}

/// The rows of p mapped by t.
inline Eigen::MatrixXd mapped(const Transform& t, const Eigen::MatrixXd& p) {
  return ((t.leftCols<3>() * p.transpose()).colwise() + t.col(3)).transpose();
}

/// `editor` holds the capped sphere's region: `t` of both handles moves the base by t, and
/// (t rigid) the details with it; report().nonlinear.total_iterations stays at most
/// `max_iterations`.
inline void expect_one_map_moves_everything(Editor& editor, const CappedSphere& s,
                                            const Transform& t, int max_iterations,
                                            const Eigen::MatrixXd& rest) {
  editor.set_transform(0, t);
  editor.set_transform(1, t);
  EXPECT_LT(max_row_distance(editor.base_positions(), mapped(t, rest)), 1e-9 * s.diagonal);
  EXPECT_TRUE(editor.converged());
  EXPECT_LE(editor.report().nonlinear.total_iterations, max_iterations);
  if (t.leftCols<3>().isUnitary(1e-12)) {
    EXPECT_LT(max_row_distance(editor.positions(), mapped(t, positions_matrix(s.mesh))),
              1e-9 * s.diagonal);
  }
}

} // namespace remora::nonlinear_testing
