// Anderson acceleration (linalg/anderson.h): on an affine contraction with a history as deep as
// the dimension it is GMRES and reaches the fixed point in dimension + 1 steps, where the plain
// iteration has barely started; its result does not depend on the number of threads; clear() and
// restart() forget what they say.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Dense>

#include "remora/common/error.h"
#include "remora/linalg/anderson.h"

namespace remora {
namespace {

/// u ← A u + b with A = Q diag(0.9 … 0.5) Qᵀ + a skew part, spectral radius below 1.
struct Affine {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  Eigen::VectorXd fixed_point() const {
    return (Eigen::MatrixXd::Identity(a.rows(), a.cols()) - a).lu().solve(b);
  }
};

Affine contraction(int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd m(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) m(i, j) = u(rng);
  const Eigen::MatrixXd q = m.householderQr().householderQ();
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) d[i] = 0.9 - 0.4 * i / (n - 1);
  Affine f;
  f.a = q * d.asDiagonal() * q.transpose() + 0.05 * (m - m.transpose()) / n;
  f.b.resize(n);
  for (int i = 0; i < n; ++i) f.b[i] = u(rng);
  return f;
}

TEST(Anderson, ADeepHistoryReachesTheFixedPointOfAnAffineMapInDimensionPlusOneSteps) {
  const int n = 6;
  const Affine f = contraction(n);
  const Eigen::VectorXd target = f.fixed_point();
  AndersonAcceleration anderson(n);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), plain = u;
  for (int k = 0; k <= n + 1; ++k) {
    const Eigen::VectorXd g = f.a * u + f.b;
    u = anderson.extrapolate(g, g - u);
    plain = f.a * plain + f.b;
  }
  EXPECT_EQ(anderson.history(), n);
  EXPECT_LE((u - target).norm(), 1e-8 * target.norm());
  EXPECT_GT((plain - target).norm(), 0.1 * target.norm()); // the plain iteration is far from it
}

TEST(Anderson, TheResultDoesNotDependOnTheThreads) {
  // A diagonal contraction long enough for several blocks of the vectors.
  const int n = 50000;
  Eigen::VectorXd d(n), b(n);
  for (int i = 0; i < n; ++i) {
    d[i] = 0.95 * (i % 97) / 96.0;
    b[i] = std::sin(0.001 * i);
  }
  Eigen::VectorXd results[2];
  for (const int threads : {1, 2}) {
    AndersonAcceleration anderson(5, threads);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
    for (int k = 0; k < 12; ++k) {
      const Eigen::VectorXd g = d.cwiseProduct(u) + b;
      u = anderson.extrapolate(g, g - u);
    }
    results[threads - 1] = u;
  }
  EXPECT_EQ(results[0], results[1]); // bit for bit
  const Eigen::VectorXd target = b.cwiseQuotient(Eigen::VectorXd::Ones(n) - d);
  // Twelve plain steps leave 0.95¹² ≈ 0.54 of the slowest component; the extrapolation far less.
  EXPECT_LE((results[0] - target).norm(), 0.1 * target.norm());
}

TEST(Anderson, ClearAndRestartForgetTheHistory) {
  const Affine f = contraction(4);
  AndersonAcceleration anderson(3);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(4);
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd g = f.a * u + f.b;
    u = anderson.extrapolate(g, g - u);
  }
  EXPECT_EQ(anderson.history(), 3);
  anderson.restart(); // the newest pair stays: the next call holds one difference
  EXPECT_EQ(anderson.history(), 0);
  Eigen::VectorXd g = f.a * u + f.b;
  EXPECT_NE(anderson.extrapolate(g, g - u), g);
  EXPECT_EQ(anderson.history(), 1);
  anderson.clear(); // nothing stays: the next call has no difference and returns g
  g = f.a * u + f.b;
  EXPECT_EQ(anderson.extrapolate(g, g - u), g);
  EXPECT_EQ(anderson.history(), 0);
  // A new length starts a new history.
  const Eigen::VectorXd longer = Eigen::VectorXd::Ones(7);
  EXPECT_EQ(anderson.extrapolate(longer, longer), longer);
  EXPECT_THROW(anderson.extrapolate(longer, g), InvalidArgument);
  EXPECT_THROW(AndersonAcceleration(0), InvalidArgument);
}

} // namespace
} // namespace remora
