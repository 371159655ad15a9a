// The nonlinear method's pieces alone: the blend of the handles' rotations
// (multires/rotation_blend.h), the local/global deformer (multires/nonlinear.h) from different
// starts and under an interrupt, and the per-vertex best rotation (multires/best_rotation.h)
// against the SVD's.
#include <random>
#include <stop_token>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/best_rotation.h"
#include "remora/multires/editor.h"
#include "remora/multires/nonlinear.h"
#include "remora/multires/rotation_blend.h"
#include "support.h"

namespace remora {
namespace {

using testing::kPi;

// The blend of the handles' rotations (multires/rotation_blend.h).
TEST(RotationBlend, IsTheSlerpForOneHandleAndExactForAPartitionOfUnity) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
  const Eigen::Matrix3d r = Eigen::AngleAxisd(2.5, axis).toRotationMatrix();
  const Eigen::Matrix3d stretch = Eigen::Vector3d(1.5, 0.7, 1.1).asDiagonal();
  const Eigen::Matrix3d m = r * stretch;
  EXPECT_LT((polar_rotation(m) - r).norm(), 1e-12);
  EXPECT_LT((polar_rotation(m) * polar_stretch(m) - m).norm(), 1e-12);
  const std::vector<Eigen::Vector3d> one{rotation_log(r)};
  for (const double w : {0.0, 0.3, 1.0}) {
    const Eigen::Matrix3d b = blend_rotations(one, Eigen::RowVectorXd::Constant(1, w));
    EXPECT_LT((b - Eigen::AngleAxisd(w * 2.5, axis).toRotationMatrix()).norm(), 1e-12) << w;
  }
  // The shorter way: a turn by 3π/2 is blended as one by −π/2.
  const Eigen::Matrix3d long_turn = Eigen::AngleAxisd(1.5 * kPi, axis).toRotationMatrix();
  EXPECT_LT((blend_rotations({rotation_log(long_turn)}, Eigen::RowVectorXd::Constant(1, 0.5)) -
             Eigen::AngleAxisd(-0.25 * kPi, axis).toRotationMatrix())
                .norm(),
            1e-12);
  const Eigen::RowVector2d weights(0.25, 0.75);
  EXPECT_LT((blend_rotations({one[0], one[0]}, weights) - r).norm(), 1e-12);
}

// A cylinder of 17 rings of 24 (height 2) for the deformer alone: the bottom ring fixed, the
// top ring handle 0, the handle's weight growing linearly with the height.
struct DeformerCylinder {
  Mesh m = make_cylinder(16, 24, 1.0, 2.0);
  Eigen::MatrixXd rest = positions_matrix(m);
  std::vector<int> labels = std::vector<int>(m.n_vertices(), Region::kFree);
  Eigen::MatrixXd weights = rest.col(2) / 2.0;
  DeformerCylinder() {
    for (int s = 0; s < 24; ++s) {
      labels[static_cast<std::size_t>(s)] = Region::kFixed;
      labels[static_cast<std::size_t>(16 * 24 + s)] = 0;
    }
  }
};

// The deformer alone: the same minimizer from two different starts.
TEST(NonlinearDeformer, ConvergesToTheSameShapeFromDifferentStarts) {
  const DeformerCylinder c;
  const Mesh& m = c.m;
  const Eigen::MatrixXd& rest = c.rest;
  const std::vector<int>& labels = c.labels;
  const Eigen::MatrixXd& weights = c.weights;
  NonlinearOptions o;
  o.tolerance = 1e-9;
  o.energy_tolerance = 0.0;
  o.max_iterations = 2000;
  const AffineMap t = rotation({0, 0, 1}, 1.2, {0, 0, 2});
  RowPoints results[2];
  for (int start = 0; start < 2; ++start) {
    NonlinearDeformer d(m, rest, labels, weights, o);
    RowPoints guess = rest;
    for (Eigen::Index v = 0; v < rest.rows(); ++v) // a quarter of the twist, or a squeeze
      guess.row(v) = start == 0
                         ? Eigen::RowVector3d(
                               Eigen::AngleAxisd(0.3 * rest(v, 2) / 2.0, Eigen::Vector3d::UnitZ()) *
                               rest.row(v).transpose())
                         : Eigen::RowVector3d(0.7 * rest(v, 0), 0.7 * rest(v, 1), rest(v, 2));
    d.set_transforms({t}, &guess);
    const NonlinearStats& s = d.solve();
    EXPECT_TRUE(s.converged) << start;
    results[start] = d.positions();
  }
  EXPECT_LT((results[0] - results[1]).rowwise().norm().maxCoeff(), 1e-6);
}

// An interrupt (a server with another request waiting) ends a solve after the iteration under
// way, whatever the budget; the next solve goes on from there to the same convergence.
TEST(NonlinearDeformer, AnInterruptEndsTheSolveAfterTheIterationUnderWay) {
  const DeformerCylinder c;
  NonlinearDeformer d(c.m, c.rest, c.labels, c.weights);
  d.set_transforms({rotation({0, 0, 1}, 1.2, {0, 0, 2})});
  int asked = 0;
  const NonlinearStats& first = d.solve(1e300, [&] { return ++asked > 0; });
  EXPECT_EQ(first.iterations, 1);
  EXPECT_EQ(asked, 1);
  EXPECT_FALSE(first.finished());
  asked = 0;
  const NonlinearStats& rest_of_it = d.solve(1e300, [&] { return ++asked < 0; });
  EXPECT_TRUE(rest_of_it.converged);
  EXPECT_EQ(rest_of_it.total_iterations, rest_of_it.iterations + 1);
  EXPECT_EQ(asked, rest_of_it.iterations - 1); // asked before each further iteration
}

// The local step's rotation against the SVD's (the optimum of tr(R P)), from the identity, on
// random full-rank and planar (rank 2) matrices; and never worse than its start.
TEST(NonlinearDeformer, BestRotationMatchesTheSvdAndNeverLosesToItsStart) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int close = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Eigen::Matrix3d p;
    for (int i = 0; i < 9; ++i) p(i / 3, i % 3) = u(rng);
    if (trial % 2) p.col(2) = 0.3 * p.col(0) - 0.7 * p.col(1); // rank 2
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(p, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d v = svd.matrixV();
    if ((v * svd.matrixU().transpose()).determinant() < 0) v.col(2) = -v.col(2);
    const double best = (v * svd.matrixU().transpose() * p).trace();
    const Eigen::Matrix3d start =
        Eigen::AngleAxisd(u(rng) * kPi, Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())
            .toRotationMatrix();
    const Eigen::Matrix3d r = best_rotation(p, start);
    EXPECT_NEAR((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
    EXPECT_GE((r * p).trace(), (start * p).trace() - 1e-12);
    EXPECT_LE((r * p).trace(), best + 1e-12);
    close += (r * p).trace() > best - 1e-9 ? 1 : 0;
  }
  EXPECT_GT(close, 385); // a few nearly degenerate draws need more than one call
}

// Newton's steps from a warm start (the start near the optimum, as in an iteration's later local
// steps) end at the SVD's optimum to round-off. From another critical point (the optimum turned
// half a turn about an axis of P's SVD: P R symmetric, H not positive definite) or with a
// degenerate P they give way to the power iteration, whose result is no worse than the start.
TEST(NonlinearDeformer, BestRotationFromAWarmStartIsTheSvdsOptimum) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    Eigen::Matrix3d p;
    for (int i = 0; i < 9; ++i) p(i / 3, i % 3) = u(rng);
    if (trial % 3 == 2) p = p.col(0) * p.row(1).eval(); // rank 1: no unique optimum
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(p, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d v = svd.matrixV();
    if ((v * svd.matrixU().transpose()).determinant() < 0) v.col(2) = -v.col(2);
    const Eigen::Matrix3d optimum = v * svd.matrixU().transpose();
    const double best = (optimum * p).trace();
    const double angle = trial % 2 ? 1e-3 : 0.2;
    const Eigen::Matrix3d near =
        optimum *
        Eigen::AngleAxisd(angle * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())
            .toRotationMatrix();
    const Eigen::Matrix3d saddle = optimum * svd.matrixU() *
                                   Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal() *
                                   svd.matrixU().transpose();
    const std::array<Eigen::Matrix3d, 3> starts{near, saddle, optimum};
    for (std::size_t which = 0; which < starts.size(); ++which) {
      const Eigen::Matrix3d& start = starts[which];
      const Eigen::Matrix3d r = best_rotation(p, start);
      EXPECT_NEAR((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
      EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
      EXPECT_GE((r * p).trace(), (start * p).trace() - 1e-12);
      if (trial % 3 != 2 && which != 1) {
        EXPECT_NEAR((r * p).trace(), best, 1e-12 * (1.0 + best)) << "start " << which;
      }
    }
    if (trial % 3 != 2) { // Newton alone, where it is sure: the optimum itself
      Eigen::Matrix3d r = near;
      const bool settled = rotation_detail::newton_rotation(p, r);
      if (angle < 0.01) {
        EXPECT_TRUE(settled);
      }
      if (settled) {
        EXPECT_NEAR((r - optimum).norm(), 0.0, 1e-10 / svd.singularValues()[2]);
      }
      Eigen::Matrix3d s = saddle;
      EXPECT_FALSE(rotation_detail::newton_rotation(p, s));
    }
  }
}

TEST(NonlinearDeformer, RefusesMismatchedInput) {
  const Mesh m = make_cylinder(4, 8, 1.0, 1.0);
  const Eigen::MatrixXd rest = positions_matrix(m);
  std::vector<int> labels(m.n_vertices(), Region::kFree);
  labels[0] = 0;
  const Eigen::MatrixXd weights = Eigen::MatrixXd::Zero(rest.rows(), 1);
  EXPECT_THROW(NonlinearDeformer(m, rest.topRows(3), labels, weights), InvalidArgument);
  EXPECT_THROW(NonlinearDeformer(m, rest, std::vector<int>(3, 0), weights), InvalidArgument);
  NonlinearDeformer d(m, rest, labels, weights);
  EXPECT_THROW(d.set_transforms({}), InvalidArgument);
  EXPECT_THROW(parse_nonlinear_energy("elastic"), InvalidArgument);
}

} // namespace
} // namespace remora
