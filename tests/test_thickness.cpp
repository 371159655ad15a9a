// Half-widths (geometry/thickness.h) against the analytic ones: a ball's radius, a torus's tube
// radius and, across its hole, the hole's radius; a plate's half thickness; nothing on an open
// sheet; the ray length limit.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "remora/common/error.h"
#include "remora/geometry/thickness.h"
#include "remora/mesh/primitives.h"

namespace remora {
namespace {

TEST(HalfWidths, ABallsIsItsRadius) {
  const double radius = 1.5;
  const Mesh ball = make_icosphere(4, radius);
  const Eigen::VectorXd half = vertex_half_widths(ball);
  ASSERT_EQ(half.size(), static_cast<Eigen::Index>(ball.n_vertices()));
  // The ray through the centre meets the antipode's faces, whose chords lie inside the sphere.
  EXPECT_LE(half.maxCoeff(), radius * (1 + 1e-12));
  EXPECT_GE(half.minCoeff(), 0.995 * radius);
  // Rays stopping short of the far side see nothing.
  const Eigen::VectorXd limited = vertex_half_widths(ball, {.max_distance = 1.9 * radius});
  EXPECT_TRUE(limited.array().isInf().all());
}

TEST(HalfWidths, ATorusHasItsTubeRadiusAndAcrossTheHoleTheHolesRadius) {
  // A fat torus: tube radius 0.7, hole radius R - r = 0.3. Inside the material every vertex
  // sees the tube's diameter; vertices on the inner equator see across the hole, 2 (R - r),
  // which is smaller.
  const double big = 1.0, small = 0.7;
  const int around = 96, tube = 48;
  const Mesh torus = make_torus(around, tube, big, small);
  const Eigen::VectorXd half = vertex_half_widths(torus);
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < tube; ++j) {
      const double h = half[i * tube + j];
      const double v = 2 * std::numbers::pi * j / tube;
      if (j == tube / 2) { // v = pi: the inner equator, facing the axis
        EXPECT_NEAR(h, big - small, 0.01 * (big - small)) << i << ", " << j;
      } else {
        EXPECT_LE(h, small * (1 + 1e-9)) << i << ", " << j;
        // Near the inner equator the ray across the hole is shorter than the tube; elsewhere
        // the tube's chord through its centre.
        if (std::cos(v) > -0.5) {
          EXPECT_GE(h, 0.99 * small) << i << ", " << j;
        }
      }
    }
}

TEST(HalfWidths, APlateHasHalfItsThicknessAndAnOpenSheetNone) {
  // A flattened cube: 4 x 4 x 0.2.
  Mesh plate = make_cube(20, 1.0);
  for (const VertexHandle v : plate.vertices()) {
    const Vec3 p = plate.point(v);
    plate.set_point(v, Vec3(4 * p[0], 4 * p[1], 0.2 * p[2]));
  }
  const Eigen::VectorXd half = vertex_half_widths(plate);
  int checked = 0;
  for (const VertexHandle v : plate.vertices()) {
    const Vec3 p = plate.point(v);
    if (std::abs(std::abs(p[2]) - 0.1) < 1e-12 && std::abs(p[0]) < 1.5 && std::abs(p[1]) < 1.5) {
      EXPECT_NEAR(half[v.idx()], 0.1, 1e-12);
      ++checked;
    }
  }
  EXPECT_GT(checked, 300);
  const Mesh sheet = make_grid(10, 10, 1.0, 1.0);
  EXPECT_TRUE(vertex_half_widths(sheet).array().isInf().all());
}

TEST(HalfWidths, RejectsBadOptions) {
  const Mesh ball = make_icosphere(1);
  EXPECT_THROW(vertex_half_widths(ball, {.min_distance = -1}), InvalidArgument);
  EXPECT_THROW(vertex_half_widths(ball, {.min_distance = std::nan("")}), InvalidArgument);
  EXPECT_THROW(vertex_half_widths(ball, {.min_distance = 1, .max_distance = 1}), InvalidArgument);
}

} // namespace
} // namespace remora
