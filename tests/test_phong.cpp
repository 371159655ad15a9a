// Phong detail encoding (multires/phong.h): round trips, equivariance, the walk, the fallbacks.
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/phong.h"

namespace remora {
namespace {

struct Scene {
  TriangleTopology topology;
  Eigen::MatrixXd positions, normals, points;
  std::vector<int> starts;
};

/// Points at random offsets (up to `offset`) off random spots of `mesh`, each started `shift`
/// faces away from its spot's face.
Scene make_scene(const Mesh& mesh, double offset, int count, unsigned seed = 1) {
  Scene s;
  s.topology = triangle_topology(mesh);
  s.positions = positions_matrix(mesh);
  s.normals = vertex_normals(s.topology, s.positions);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  s.points.resize(count, 3);
  for (int i = 0; i < count; ++i) {
    const int f = static_cast<int>(u(rng) * double(s.topology.faces.size()));
    double a = u(rng), b = u(rng);
    if (a + b > 1) {
      a = 1 - a;
      b = 1 - b;
    }
    const auto& face = s.topology.faces[static_cast<std::size_t>(f)];
    const Eigen::RowVector3d p = (1 - a - b) * s.positions.row(face[0]) +
                                 a * s.positions.row(face[1]) + b * s.positions.row(face[2]);
    const Eigen::RowVector3d n = ((1 - a - b) * s.normals.row(face[0]) +
                                  a * s.normals.row(face[1]) + b * s.normals.row(face[2]))
                                     .normalized();
    s.points.row(i) = p + offset * (2 * u(rng) - 1) * n;
    // Start a couple of faces away.
    int g = f;
    for (int k = 0; k < 2; ++k) {
      const int across =
          s.topology.across[static_cast<std::size_t>(g)][static_cast<std::size_t>(k)];
      if (across >= 0) g = across;
    }
    s.starts.push_back(g);
  }
  return s;
}

TEST(Phong, RoundTripOnTheUndeformedBase) {
  const Mesh sphere = make_icosphere(3, 1.0);
  Scene s = make_scene(sphere, 0.05, 2000);
  PhongStats stats;
  const auto details =
      encode_phong(s.topology, s.positions, s.normals, s.points, s.starts, {}, &stats);
  EXPECT_EQ(stats.encoded, 2000u);
  EXPECT_EQ(stats.fallbacks, 0u);
  EXPECT_EQ(stats.extrapolated, 0u); // closed surface: every point has a containing face
  EXPECT_GT(stats.walk_steps, 0u);
  for (std::size_t i = 0; i < details.size(); ++i) {
    const Eigen::Vector3d q = decode_phong(s.topology, s.positions, s.normals, details[i]);
    EXPECT_LT((q - s.points.row(static_cast<Eigen::Index>(i)).transpose()).norm(), 1e-12);
    for (const double a : details[i].base.bary) EXPECT_GE(a, -1e-9);
    EXPECT_LE(std::abs(details[i].offset), 0.05 + 1e-12);
  }
}

TEST(Phong, DetailsFollowARigidMotionOfTheBase) {
  const Mesh sphere = make_icosphere(3, 1.0);
  Scene s = make_scene(sphere, 0.08, 500, 7);
  const auto details = encode_phong(s.topology, s.positions, s.normals, s.points, s.starts);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(0.3, -4, 2);
  const Eigen::MatrixXd moved = (s.positions * r.transpose()).rowwise() + t;
  const Eigen::MatrixXd normals = vertex_normals(s.topology, moved);
  for (std::size_t i = 0; i < details.size(); ++i) {
    const Eigen::Vector3d q = decode_phong(s.topology, moved, normals, details[i]);
    const Eigen::Vector3d expected =
        r * s.points.row(static_cast<Eigen::Index>(i)).transpose() + t.transpose();
    EXPECT_LT((q - expected).norm(), 1e-12);
  }
}

TEST(Phong, BeyondTheBoundaryAndTheFocalSurfaceStillRoundTrips) {
  // A flat disc: points beside its rim have no containing face (extrapolated or fallback), and
  // points far from a strongly curved sphere lie beyond its focal surface on the inside.
  const Mesh disc = make_disc(6, 6, 1.0);
  Scene s = make_scene(disc, 0.1, 50);
  s.points.row(0) << 1.05, 0.0, 0.02; // just beyond the rim
  s.points.row(1) << 3.0, 0.0, 0.5;   // far beyond it
  PhongStats stats;
  auto details = encode_phong(s.topology, s.positions, s.normals, s.points, s.starts, {}, &stats);
  EXPECT_GE(stats.extrapolated + stats.fallbacks, 2u);
  for (std::size_t i = 0; i < details.size(); ++i) {
    const Eigen::Vector3d q = decode_phong(s.topology, s.positions, s.normals, details[i]);
    EXPECT_LT((q - s.points.row(static_cast<Eigen::Index>(i)).transpose()).norm(), 1e-10) << i;
  }
  const Mesh sphere = make_icosphere(2, 1.0);
  Scene t = make_scene(sphere, 0.0, 20);
  t.points.row(0) << 0.0, 0.0, 0.0; // the center: every normal line passes through it
  t.points.row(1) << 0.01, -0.02, 0.03;
  details = encode_phong(t.topology, t.positions, t.normals, t.points, t.starts, {}, &stats);
  for (std::size_t i = 0; i < details.size(); ++i) {
    const Eigen::Vector3d q = decode_phong(t.topology, t.positions, t.normals, details[i]);
    EXPECT_TRUE(q.allFinite());
    EXPECT_LT((q - t.points.row(static_cast<Eigen::Index>(i)).transpose()).norm(), 1e-10) << i;
  }
}

TEST(Phong, RejectsBadInput) {
  const Mesh sphere = make_icosphere(1, 1.0);
  Scene s = make_scene(sphere, 0.0, 3);
  s.starts[1] = 9999;
  EXPECT_THROW(encode_phong(s.topology, s.positions, s.normals, s.points, s.starts),
               InvalidArgument);
  s.starts[1] = 0;
  s.points(2, 1) = std::nan("");
  EXPECT_THROW(encode_phong(s.topology, s.positions, s.normals, s.points, s.starts),
               InvalidArgument);
  EXPECT_THROW(vertex_normals(s.topology, Eigen::MatrixXd::Zero(2, 3)), InvalidArgument);
}

} // namespace
} // namespace remora
