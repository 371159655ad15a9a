// The intrinsic Delaunay Laplacian (geometry/intrinsic.h) and the low-pass filter built on it
// (multires/base_surface.h).
#include <cmath>

#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/geometry/intrinsic.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/thickness.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/base_surface.h"

namespace remora {
namespace {

/// A grid with needles, caps and exactly zero-area faces: odd rows pushed almost onto the row
/// below and shifted sideways by 0.3 cells (corners near 180°: negative cotan weights), row 3
/// exactly onto row 2 (zero-area faces).
Mesh needle_grid() {
  const int n = 20;
  Mesh m = make_grid(n, n, 1.0, 1.0);
  const double cell = 1.0 / n;
  for (const VertexHandle v : m.vertices()) {
    Vec3 p = m.point(v);
    const int row = v.idx() / (n + 1), column = v.idx() % (n + 1);
    if (row % 2 == 1 && row < n && column > 0 && column < n) {
      p[1] -= row == 3 ? cell : 0.97 * cell;
      if (row != 3) p[0] += 0.3 * cell;
    }
    m.set_point(v, p);
  }
  return m;
}

// Mollification fattens zero-area faces to a height of about sqrt(ε × length), so the mass may
// exceed the surface area slightly (7e-5 on the needle grid).
void expect_laplacian_invariants(const IntrinsicLaplacian& lap, double surface) {
  const auto& w = lap.weights;
  EXPECT_LT((w * Eigen::VectorXd::Ones(w.rows())).cwiseAbs().maxCoeff(), 1e-9 * w.cwiseAbs().sum());
  EXPECT_LT((Eigen::SparseMatrix<double>(w.transpose()) - w).norm(), 1e-12 * w.norm());
  for (Eigen::Index c = 0; c < w.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(w, c); it; ++it) {
      if (it.row() != it.col()) {
        EXPECT_GE(it.value(), -1e-9) << it.row() << "," << it.col();
      }
    }
  EXPECT_TRUE(lap.mass.allFinite());
  EXPECT_GT(lap.mass.minCoeff(), 0.0);
  EXPECT_NEAR(lap.mass.sum(), surface, 1e-3 * surface);
}

TEST(Intrinsic, AgreesWithCotanWeightsOnADelaunayMesh) {
  const Mesh m = make_icosphere(3);
  const IntrinsicLaplacian lap = intrinsic_delaunay_laplacian(m);
  EXPECT_EQ(lap.flips, 0u);
  EXPECT_EQ(lap.negative_before, 0u);
  const Eigen::SparseMatrix<double> w = cotan_weights(m);
  EXPECT_LT((lap.weights - w).norm(), 1e-4 * w.norm()); // mollification only
  expect_laplacian_invariants(lap, surface_area(m));
}

TEST(Intrinsic, NeedlesAndZeroAreaFacesGetNonNegativeWeights) {
  const Mesh m = needle_grid();
  const Eigen::SparseMatrix<double> w = cotan_weights(m);
  int negative = 0;
  for (Eigen::Index c = 0; c < w.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(w, c); it; ++it)
      negative += it.row() != it.col() && it.value() < 0 ? 1 : 0;
  ASSERT_GT(negative, 10);
  const IntrinsicLaplacian lap = intrinsic_delaunay_laplacian(m);
  EXPECT_GT(lap.flips, 10u);
  EXPECT_GT(lap.epsilon, 0.0);
  EXPECT_EQ(lap.negative_after, 0u);
  expect_laplacian_invariants(lap, surface_area(m));
}

TEST(Intrinsic, RejectsBadOptions) {
  IntrinsicOptions o;
  o.mollify_factor = 0;
  EXPECT_THROW(intrinsic_delaunay_laplacian(make_icosphere(1), o), InvalidArgument);
}

TEST(LowPass, KeepsConstantsAndDampsShortWavelengthsMore) {
  Mesh m = make_grid(60, 60, 1.0, 1.0);
  const Eigen::MatrixXd p = positions_matrix(m);
  LowPassOptions options;
  options.smoothing = 2.0;
  LowPassFilter filter(m, options);
  const auto n = p.rows();
  Eigen::MatrixXd f(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    f(i, 0) = 1.0;
    f(i, 1) = std::cos(2 * M_PI * p(i, 0) / 0.5);  // long wavelength: 30 edges
    f(i, 2) = std::cos(2 * M_PI * p(i, 0) / 0.05); // short: 3 edges
  }
  const Eigen::MatrixXd g = filter.apply(f);
  EXPECT_LT((g.col(0).array() - 1.0).abs().maxCoeff(), 1e-8);
  // Rows away from the boundary (its loop is filtered as a curve, whose sides x = 0 and x = 1
  // see constants: a boundary layer about σ wide).
  double long_ratio = 0, short_ratio = 0;
  int count = 0;
  for (Eigen::Index i = 0; i < n; ++i)
    if (p(i, 0) > 0.2 && p(i, 0) < 0.8 && std::abs(f(i, 1)) > 0.9 && std::abs(f(i, 2)) > 0.9) {
      long_ratio += g(i, 1) / f(i, 1);
      short_ratio += g(i, 2) / f(i, 2);
      ++count;
    }
  ASSERT_GT(count, 10);
  long_ratio /= count;
  short_ratio /= count;
  // Continuum: 1 / (1 + (2πσ/λ)²), σ = 2 × the mean edge length (diagonals included, so
  // 1.14 / 60): 0.815 for λ = 0.5, 0.04 for λ = 0.05.
  const double sigma = filter.stats().sigma;
  EXPECT_NEAR(sigma, 2.0 * (2.0 + std::sqrt(2.0)) / 3.0 / 60.0, 1e-3);
  EXPECT_NEAR(long_ratio, 1.0 / (1.0 + std::pow(2 * M_PI * sigma / 0.5, 2)), 0.01);
  EXPECT_LT(short_ratio, 0.15);
  EXPECT_GT(filter.stats().sigma, 0.0);
  // Zero smoothing is the identity.
  options.smoothing = 0;
  LowPassFilter identity(m, options);
  EXPECT_EQ(identity.apply(f), f);
  EXPECT_THROW(identity.apply(Eigen::MatrixXd::Zero(3, 3)), InvalidArgument);
}

// A plane's boundary stays where it is: the loops are filtered as curves and the interior takes
// them as Dirichlet values (the surface operator's natural condition would move the sides inward
// by about σ). Noise along the boundary is damped as in the interior.
TEST(LowPass, KeepsAPlanesBoundaryAndSmoothsAlongIt) {
  Mesh m = make_grid(40, 40, 1.0, 1.0);
  Eigen::MatrixXd p = positions_matrix(m);
  const double wavelength = 3.0 / 40; // 3 edges
  Eigen::MatrixXd noisy = p;
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    noisy(i, 2) = 0.01 * std::cos(2 * M_PI * p(i, 0) / wavelength) *
                  std::cos(2 * M_PI * p(i, 1) / wavelength);
  LowPassFilter filter(m, {.smoothing = 2.0});
  const double sigma = filter.stats().sigma;
  // Flat input: every vertex away from the four corners stays put (linear precision inside,
  // straight evenly spaced sides on the boundary).
  const Eigen::MatrixXd flat = filter.apply(p);
  double side_shift = 0, inner_shift = 0, noise_in = 0, noise_out = 0;
  const Eigen::MatrixXd smoothed = filter.apply(noisy);
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const double x = p(i, 0), y = p(i, 1);
    const double corner = std::min(
        std::hypot(x, y),
        std::min(std::hypot(1 - x, y), std::min(std::hypot(x, 1 - y), std::hypot(1 - x, 1 - y))));
    if (corner < 8 * sigma) continue;
    const bool side = x == 0 || x == 1 || y == 0 || y == 1;
    const double shift = (flat.row(i) - p.row(i)).norm();
    (side ? side_shift : inner_shift) = std::max(side ? side_shift : inner_shift, shift);
    if (side) {
      noise_in = std::max(noise_in, std::abs(noisy(i, 2)));
      noise_out = std::max(noise_out, std::abs(smoothed(i, 2)));
    }
  }
  EXPECT_LT(side_shift, 1e-3 * sigma);
  EXPECT_LT(inner_shift, 1e-3 * sigma);
  ASSERT_GT(noise_in, 0.009);
  // The curve filter's factor for this wavelength, 1 / (1 + (2πσ/λ)²), is about 0.05.
  EXPECT_LT(noise_out, 0.15 * noise_in);
}

Eigen::MatrixXd points_of(const Mesh& m) {
  Eigen::MatrixXd x(static_cast<Eigen::Index>(m.n_vertices()), 3);
  for (const VertexHandle v : m.vertices())
    for (int k = 0; k < 3; ++k) x(v.idx(), k) = m.point(v)[k];
  return x;
}

// The tube of a thin torus is a circle mode of the filter: one step scales its radius r by
// 1 / (1 + c²) with c = σ / r, or with the cap c = min(σ / r, feature_cap). Uncapped (σ = 1.19 r)
// the tube keeps 42 % of its radius, capped at 1 half, at 0.5 four fifths.
TEST(LowPass, FeatureCapKeepsAThinTubeAtOneOverOnePlusCapSquared) {
  const double big = 2.0, small = 0.2;
  const Mesh torus = make_torus(120, 12, big, small);
  const Eigen::MatrixXd x = points_of(torus);
  for (const double cap : {0.0, 0.5, 1.0}) {
    LowPassFilter filter(torus, {.smoothing = 2.0, .feature_cap = cap});
    const double sigma = filter.stats().sigma;
    ASSERT_GT(sigma, small); // thinner than the filter: the cap has something to do
    const Eigen::MatrixXd y = filter.apply(x);
    double centre = 0, tube = 0;
    for (Eigen::Index i = 0; i < y.rows(); ++i) centre += std::hypot(y(i, 0), y(i, 1));
    centre /= static_cast<double>(y.rows());
    for (Eigen::Index i = 0; i < y.rows(); ++i)
      tube += std::hypot(std::hypot(y(i, 0), y(i, 1)) - centre, y(i, 2));
    tube /= static_cast<double>(y.rows());
    const double c = cap > 0 ? std::min(sigma / small, cap) : sigma / small;
    EXPECT_NEAR(tube / small, 1.0 / (1.0 + c * c), 0.03) << "cap " << cap;
    EXPECT_NEAR(centre, big, 0.03 * big) << "cap " << cap;
    if (cap > 0) {
      // Every vertex sees the tube's diameter (chords: within 1 %).
      EXPECT_EQ(filter.stats().capped, torus.n_vertices());
      EXPECT_NEAR(filter.stats().sigma_min, cap * small, 0.01 * cap * small);
    } else {
      EXPECT_EQ(filter.stats().capped, 0u);
      EXPECT_EQ(filter.stats().sigma_min, sigma);
    }
  }
}

// A boundary loop is capped by its own radius: the small hole of an annulus (radius 0.03, σ
// about 7 times that) all but closes without the cap and keeps 1 / (1 + cap²) of its radius
// with it; the outer rim (radius 1) is filtered as without the cap.
TEST(LowPass, FeatureCapKeepsASmallHoleOpen) {
  const double inner = 0.03;
  const int segments = 24, rings = 20;
  const Mesh annulus = make_annulus(rings, segments, inner, 1.0);
  const Eigen::MatrixXd x = points_of(annulus);
  Eigen::MatrixXd uncapped;
  for (const double cap : {0.0, 0.5, 1.0}) {
    LowPassFilter filter(annulus, {.smoothing = 2.0, .feature_cap = cap});
    const Eigen::MatrixXd y = filter.apply(x);
    double hole = 0;
    for (int s = 0; s < segments; ++s) hole += std::hypot(y(s, 0), y(s, 1)) / segments;
    const double c = cap > 0 ? cap : filter.stats().sigma / inner;
    EXPECT_NEAR(hole / inner, 1.0 / (1.0 + c * c), 0.03) << "cap " << cap;
    EXPECT_EQ(filter.stats().capped_loops, cap > 0 ? 1u : 0u); // the hole, not the rim
    if (cap == 0) {
      uncapped = y;
    } else {
      for (int s = 0; s < segments; ++s) {
        const Eigen::Index i = rings * segments + s; // the outer rim
        EXPECT_LT((y.row(i) - uncapped.row(i)).norm(), 1e-12);
      }
    }
  }
}

// A part thicker than 2σ / cap everywhere is filtered exactly as without the cap.
TEST(LowPass, FeatureCapLeavesAThickPartAlone) {
  for (const Mesh& m : {make_torus(96, 24, 1.0, 0.5), make_icosphere(3, 1.0)}) {
    const Eigen::MatrixXd x = points_of(m);
    LowPassFilter capped(m, {.smoothing = 2.0, .feature_cap = 1.0});
    LowPassFilter plain(m, {.smoothing = 2.0, .feature_cap = 0.0});
    EXPECT_EQ(capped.stats().capped, 0u);
    EXPECT_EQ(capped.apply(x), plain.apply(x));
  }
}

// The field: at most σ, at most cap × the half-width, and nowhere steeper than cap_slope along
// an edge; on a fat torus (hole radius 0.2) the cap bites around the hole only.
TEST(LowPass, SmoothingFieldIsCappedAndLipschitz) {
  const Mesh torus = make_torus(60, 48, 1.0, 0.8);
  const double sigma = 0.3;
  const Eigen::VectorXd half = vertex_half_widths(torus);
  for (const double slope : {0.5, 1.0, 4.0}) {
    const LowPassOptions options{.feature_cap = 1.0, .cap_slope = slope};
    const Eigen::VectorXd field = smoothing_field(torus, sigma, options);
    std::size_t capped = 0;
    for (const VertexHandle v : torus.vertices()) {
      const double f = field[v.idx()];
      EXPECT_LE(f, sigma);
      EXPECT_LE(f, half[v.idx()] * (1 + 1e-12));
      capped += f < sigma ? 1 : 0;
      for (const VertexHandle w : torus.vv_range(v))
        EXPECT_LE(std::abs(f - field[w.idx()]),
                  slope * (torus.point(v) - torus.point(w)).norm() * (1 + 1e-12));
    }
    EXPECT_NEAR(field.minCoeff(), 0.2, 0.002); // the hole's radius
    EXPECT_GT(capped, 0u);
    EXPECT_LT(capped, torus.n_vertices() / 2);
  }
  EXPECT_TRUE((smoothing_field(torus, sigma, {.feature_cap = 0.0}).array() == sigma).all());
  EXPECT_THROW(smoothing_field(torus, -1.0, {}), InvalidArgument);
  EXPECT_THROW(smoothing_field(torus, sigma, {.feature_cap = -1.0}), InvalidArgument);
  EXPECT_THROW(smoothing_field(torus, sigma, {.cap_slope = 0.0}), InvalidArgument);
  EXPECT_THROW(LowPassFilter(torus, {.feature_cap = std::nan("")}), InvalidArgument);
}

} // namespace
} // namespace remora
