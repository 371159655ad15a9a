// The nonlinear method's blended motions (multires/motion_blend.h): the screw's exp and log, the
// exact cases (identity, one rigid or affine map of every handle, translations as the linear
// method), and the cylinder's twist and bend, whose rings keep their radius.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/selection.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/editor.h"
#include "remora/multires/motion_blend.h"

#include "nonlinear_support.h"

namespace remora {
namespace {

using namespace nonlinear_testing;

EditorOptions blended_options() {
  EditorOptions o;
  o.method = EditMethod::Nonlinear;
  o.nonlinear.energy = NonlinearEnergy::BlendedMotions;
  return o;
}

TEST(ScrewMotion, ExpInvertsLogAndHalfATwistTwiceIsTheWhole) {
  for (const double angle : {0.0, 1e-7, 0.3, 2.0, 3.1}) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(angle, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
    const Eigen::Vector3d t(0.4, -1.2, 2.5);
    Eigen::Matrix3d r2;
    Eigen::Vector3d t2;
    ScrewTwist s = screw_log(r, t);
    screw_exp(s, r2, t2);
    EXPECT_LT((r2 - r).norm(), 1e-12) << angle;
    EXPECT_LT((t2 - t).norm(), 1e-12) << angle;
    const Eigen::Vector3d y(0.3, 0.7, -1.1);
    EXPECT_LT((screw_apply(s, y) - (r * y + t)).norm(), 1e-12) << angle;
    s.omega *= 0.5;
    s.v *= 0.5;
    screw_exp(s, r2, t2); // the half motion, applied twice
    EXPECT_LT((r2 * r2 - r).norm(), 1e-12) << angle;
    EXPECT_LT((r2 * t2 + t2 - t).norm(), 1e-12) << angle;
  }
}

TEST(BlendedMotions, AreExactForTheIdentityAndOneRigidOrAffineMapOfEveryHandle) {
  const CappedSphere s = capped_sphere();
  Editor editor(s.mesh, blended_options());
  editor.set_region(s.support, s.handles);
  const Eigen::MatrixXd rest = editor.base_positions();
  for (const Transform& t : {some_rigid_map(), some_affine_map()})
    expect_one_map_moves_everything(editor, s, t, 0, rest);
  editor.set_transform(0, rotation({0, 1, 0}, 1.0, {0, 0, 1}));
  EXPECT_GT(max_row_distance(editor.base_positions(), rest), 0.1 * s.diagonal);
  editor.set_transform(0, identity_transform());
  editor.set_transform(1, identity_transform());
  EXPECT_EQ(editor.base_positions(), rest);
}

// Translations blend as translations: the linear method's result, to round-off, with two
// handles and a fixed rest (the weights do not sum to 1).
TEST(BlendedMotions, TranslationsGiveTheLinearMethodsResult) {
  const Cylinder c = bumpy_cylinder(24, 32);
  std::vector<int> middle;
  for (int s = 0; s < c.segments; ++s) middle.push_back(c.id(c.rings / 2, s));
  Editor linear(c.mesh), blended(c.mesh, blended_options());
  linear.set_region(c.support, {c.handle, middle});
  blended.set_region(c.support, {c.handle, middle});
  const Eigen::MatrixXd rest = linear.base_positions();
  linear.set_transform(0, translation({0.3, -0.1, 0.5}));
  blended.set_transform(0, translation({0.3, -0.1, 0.5}));
  linear.set_transform(1, translation({-0.2, 0.0, 0.1}));
  blended.set_transform(1, translation({-0.2, 0.0, 0.1}));
  const Eigen::MatrixXd a = linear.base_positions();
  EXPECT_GT((a - rest).norm(), 0.1);
  EXPECT_LT(max_row_distance(blended.base_positions(), a), 1e-12 * c.height);
}

// The goal of the nonlinear method: a twisted or bent tube keeps every ring's radius within 2 %
// and its bumps, at 90° and at 180°. With one handle every ring (vertices of one weight) moves
// rigidly, so what is left is the base's discretization.
TEST(BlendedMotions, KeepTheCylindersRingsAndBumpsWhenTwistedAndBent) {
  const Cylinder c = bumpy_cylinder();
  Editor linear(c.mesh), blended(c.mesh, blended_options());
  linear.set_region(c.support, {c.handle});
  blended.set_region(c.support, {c.handle});
  for (const double angle : {kPi / 2, kPi})
    for (const bool twisted : {true, false}) {
      const Transform t = twisted ? twist(c, angle) : bend(c, angle);
      linear.set_transform(0, t);
      blended.set_transform(0, t);
      const Rings l = rings(c, linear.positions()), b = rings(c, blended.positions());
      std::cout << (twisted ? "twist " : "bend ") << angle * 180 / kPi
                << " deg: radius error linear " << l.worst_radius_error << ", blended motions "
                << b.worst_radius_error << "; bumps " << b.amplitude << "\n";
      EXPECT_GT(l.worst_radius_error, 0.09);
      EXPECT_LT(b.worst_radius_error, 0.02);
      EXPECT_GT(b.amplitude, 0.95);
      EXPECT_LT(b.amplitude, 1.05);
      EXPECT_TRUE(blended.converged());
      EXPECT_TRUE(blended.report().fallback.empty());
      EXPECT_EQ(blended.report().nonlinear.iterations, 0);
    }
}

// A scaled handle: the stretch is blended about the handle's centroid by the weights, the rigid
// part as a screw. Scaling the top by 1.5 flares the tube as the linear method does; scaling it
// by 1.5 along x and twisting it by 90° flares it without the linear method's shrinking.
TEST(BlendedMotions, AScaledHandleFlaresTheTubeLikeTheLinearMethod) {
  const Cylinder c = bumpy_cylinder(24, 32);
  Editor linear(c.mesh), blended(c.mesh, blended_options());
  linear.set_region(c.support, {c.handle});
  blended.set_region(c.support, {c.handle});
  for (const bool twisted : {false, true}) {
    const Transform t = scaled_top(c, twisted);
    linear.set_transform(0, t);
    blended.set_transform(0, t);
    const Flare f = flare(c, linear.positions(), blended.positions());
    std::cout << (twisted ? "scaled and twisted" : "scaled") << " handle: radii differ from the "
              << "linear method's by at most " << f.worst_difference << "; smallest mean radius "
              << "linear " << f.smallest_linear << ", blended motions " << f.smallest << "\n";
    EXPECT_NEAR(f.top, f.top_linear, 0.01); // the top circle: where the handle puts it
    if (twisted) {
      EXPECT_LT(f.smallest_linear, 0.9);
      EXPECT_GT(f.smallest, 0.98);
    } else { // the k = 2 weights dip below 0 near the fixed circle: a slight waist there
      EXPECT_LT(f.worst_difference, 0.04);
    }
  }
}

TEST(BlendedMotions, RefuseMismatchedInput) {
  EXPECT_THROW(handle_motions({identity_transform()}, {}), InvalidArgument);
  const RowPoints rest = RowPoints::Zero(4, 3);
  RowPoints x = rest;
  EXPECT_THROW(blend_motions(rest, Eigen::MatrixXd::Zero(4, 2), {0, 1},
                             handle_motions({identity_transform()}, {Eigen::Vector3d::Zero()}), x),
               InvalidArgument);
}

} // namespace
} // namespace remora
