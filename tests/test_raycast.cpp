// The ray caster (geometry/raycast.h): the first face met agrees with a search over every face,
// the hit lies on the face where the barycentrics say, and the ray's interval, the skipped
// vertex and bad input behave as documented.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "remora/common/error.h"
#include "remora/geometry/raycast.h"
#include "remora/mesh/build.h"
#include "remora/mesh/primitives.h"
#include "remora/mesh/surface_point.h"

namespace remora {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The nearest t in (t_min, t_max] over every face, by the plane/inside test written out
/// independently (the plane through the face, then the signs of three sub-areas).
double brute_force(const Mesh& mesh, const Vec3& o, const Vec3& d, double t_min, double t_max) {
  double best = kInf;
  for (const FaceHandle f : mesh.faces()) {
    const auto fv = face_vertices(mesh, f);
    const Vec3 a = mesh.point(fv[0]), b = mesh.point(fv[1]), c = mesh.point(fv[2]);
    const Vec3 n = OpenMesh::cross(b - a, c - a);
    const double denominator = OpenMesh::dot(n, d);
    if (denominator == 0.0) continue;
    const double t = OpenMesh::dot(n, a - o) / denominator;
    if (!(t > t_min) || t > t_max) continue;
    const Vec3 p = o + t * d;
    const double s0 = OpenMesh::dot(OpenMesh::cross(b - a, p - a), n);
    const double s1 = OpenMesh::dot(OpenMesh::cross(c - b, p - b), n);
    const double s2 = OpenMesh::dot(OpenMesh::cross(a - c, p - c), n);
    if (s0 >= 0 && s1 >= 0 && s2 >= 0) best = std::min(best, t);
  }
  return best;
}

/// An icosphere with radial noise, and a cube inside it: rays meet several sheets.
Mesh two_shells() {
  Mesh outer = make_icosphere(3, 1.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> noise(-0.1, 0.1);
  for (const VertexHandle v : outer.vertices())
    outer.set_point(v, outer.point(v) * (1 + noise(rng)));
  const Mesh inner = make_cube(4, 0.8);
  std::vector<Vec3> points;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (const Mesh* m : {static_cast<const Mesh*>(&outer), &inner}) {
    const auto base = static_cast<std::uint32_t>(points.size());
    for (const VertexHandle v : m->vertices()) points.push_back(m->point(v));
    for (const FaceHandle f : m->faces()) {
      const auto fv = face_vertices(*m, f);
      triangles.push_back({base + static_cast<std::uint32_t>(fv[0].idx()),
                           base + static_cast<std::uint32_t>(fv[1].idx()),
                           base + static_cast<std::uint32_t>(fv[2].idx())});
    }
  }
  return build_mesh(points, triangles);
}

TEST(RayCaster, AgreesWithASearchOverEveryFace) {
  const Mesh mesh = two_shells();
  const RayCaster caster(mesh);
  EXPECT_EQ(caster.n_faces(), mesh.n_faces());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5), in(-0.6, 0.6);
  int met = 0;
  for (int i = 0; i < 2000; ++i) {
    // Half the rays start inside the outer shell (every one of those meets something).
    const Vec3 o = i % 2 == 0 ? Vec3(in(rng), in(rng), in(rng)) : Vec3(u(rng), u(rng), u(rng));
    Vec3 d(u(rng), u(rng), u(rng));
    if (i % 10 == 0) d = Vec3(0, 0, d[2] >= 0 ? 1 : -1); // axis-parallel rays too
    const double t_min = i % 3 == 0 ? 0.2 : 0.0, t_max = i % 4 == 0 ? 0.7 : kInf;
    const RayHit hit = caster.first_hit(o, d, t_min, t_max);
    const double expected = brute_force(mesh, o, d, t_min, t_max);
    if (std::isinf(expected)) {
      EXPECT_FALSE(hit.face.is_valid()) << "ray " << i;
      continue;
    }
    ASSERT_TRUE(hit.face.is_valid()) << "ray " << i;
    EXPECT_NEAR(hit.t, expected, 1e-9) << "ray " << i;
    // The hit evaluates to the point on the ray.
    const auto fv = face_vertices(mesh, hit.face);
    const Vec3 q = hit.bary[0] * mesh.point(fv[0]) + hit.bary[1] * mesh.point(fv[1]) +
                   hit.bary[2] * mesh.point(fv[2]);
    EXPECT_LT((q - (o + hit.t * d)).norm(), 1e-9);
    for (const double b : hit.bary) EXPECT_GE(b, -1e-9);
    ++met;
  }
  EXPECT_GT(met, 1000);
}

// Above 65,536 faces the tree's two halves are built on two threads and spliced.
TEST(RayCaster, ALargeMeshsTreeAgreesToo) {
  Mesh ball = make_icosphere(6, 1.0); // 81,920 faces
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> noise(-0.02, 0.02), u(-1, 1);
  for (const VertexHandle v : ball.vertices()) ball.set_point(v, ball.point(v) * (1 + noise(rng)));
  const RayCaster caster(ball);
  for (int i = 0; i < 300; ++i) {
    const Vec3 o(0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng)), d(u(rng), u(rng), u(rng));
    const RayHit hit = caster.first_hit(o, d, 0.0, kInf);
    ASSERT_TRUE(hit.face.is_valid()) << "ray " << i; // every ray from inside leaves the ball
    EXPECT_NEAR(hit.t, brute_force(ball, o, d, 0.0, kInf), 1e-9) << "ray " << i;
  }
}

// The editor's page picks on the edited shape: a tree refitted after the vertices moved answers
// as a search over the moved faces, and the stale tree does not.
TEST(RayCaster, ARefittedTreeAgreesWithTheMovedMesh) {
  Mesh mesh = two_shells();
  RayCaster caster(mesh);
  // Twist about z by up to 60 degrees and stretch along x: every face moves.
  for (const VertexHandle v : mesh.vertices()) {
    const Vec3 p = mesh.point(v);
    const double a = 0.5 * p[2] + 0.3, c = std::cos(a), s = std::sin(a);
    mesh.set_point(v, Vec3(1.5 * (c * p[0] - s * p[1]), s * p[0] + c * p[1], p[2]));
  }
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.5, 1.5), in(-0.5, 0.5);
  int stale_wrong = 0;
  for (int i = 0; i < 500; ++i) {
    const Vec3 o(in(rng), in(rng), in(rng)), d(u(rng), u(rng), u(rng));
    const double expected = brute_force(mesh, o, d, 0.0, kInf);
    const RayHit stale = caster.first_hit(o, d, 0.0, kInf);
    stale_wrong += !stale.face.is_valid() || std::abs(stale.t - expected) > 1e-6;
  }
  EXPECT_GT(stale_wrong, 100);
  caster.refit(mesh);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 o(in(rng), in(rng), in(rng)), d(u(rng), u(rng), u(rng));
    const RayHit hit = caster.first_hit(o, d, 0.0, kInf);
    ASSERT_TRUE(hit.face.is_valid()) << "ray " << i;
    EXPECT_NEAR(hit.t, brute_force(mesh, o, d, 0.0, kInf), 1e-9) << "ray " << i;
  }
  EXPECT_THROW(caster.refit(make_icosphere(1, 1.0)), InvalidArgument);
}

// A drag moves a region: refitting only around the moved vertices answers as a full refit does.
TEST(RayCaster, APartialRefitAgreesWithAFullOne) {
  Mesh mesh = two_shells();
  RayCaster partial(mesh), full(mesh);
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.5, 1.5), in(-0.5, 0.5);
  for (int step = 0; step < 3; ++step) {
    std::vector<int> moved;
    for (const VertexHandle v : mesh.vertices()) {
      const Vec3 p = mesh.point(v);
      if (p[0] < 0.2 * step - 0.1) continue; // a cap of the outer shell, another each step
      mesh.set_point(v, p + Vec3(0.3, 0.1 * step, -0.2));
      moved.push_back(v.idx());
    }
    partial.refit(mesh, moved);
    full.refit(mesh);
    for (int i = 0; i < 500; ++i) {
      const Vec3 o(in(rng), in(rng), in(rng)), d(u(rng), u(rng), u(rng));
      const RayHit a = partial.first_hit(o, d, 0.0, kInf), b = full.first_hit(o, d, 0.0, kInf);
      ASSERT_EQ(a.face, b.face) << "step " << step << " ray " << i;
      EXPECT_EQ(a.t, b.t);
      if (a.face.is_valid()) {
        EXPECT_NEAR(a.t, brute_force(mesh, o, d, 0.0, kInf), 1e-9);
      }
    }
  }
  EXPECT_THROW(partial.refit(mesh, {-1}), InvalidArgument);
}

TEST(RayCaster, FromAVertexSkipsItsOwnFacesAndMeetsTheFarSide) {
  const Mesh cube = make_cube(3, 2.0);
  const RayCaster caster(cube);
  for (const VertexHandle v : cube.vertices()) {
    const Vec3 p = cube.point(v);
    if (std::abs(p[2] - 1.0) > 1e-12 || std::abs(p[0]) > 0.9 || std::abs(p[1]) > 0.9) continue;
    // An inner vertex of the top side: straight down meets the bottom side at 2.
    const RayHit down = caster.first_hit(p, Vec3(0, 0, -1), 0.0, kInf, v);
    ASSERT_TRUE(down.face.is_valid());
    EXPECT_NEAR(down.t, 2.0, 1e-12);
    // Up: nothing. Down but stopping short of the far side: nothing.
    EXPECT_FALSE(caster.first_hit(p, Vec3(0, 0, 1), 0.0, kInf, v).face.is_valid());
    EXPECT_FALSE(caster.first_hit(p, Vec3(0, 0, -1), 0.0, 1.9, v).face.is_valid());
    // Without skipping, the vertex's own faces are met at t = 0, which t_min = 0 leaves out;
    // a negative t_min lets them in.
    const RayHit own = caster.first_hit(p, Vec3(0, 0, -1), -1.0, kInf);
    ASSERT_TRUE(own.face.is_valid());
    EXPECT_NEAR(own.t, 0.0, 1e-12);
  }
}

TEST(RayCaster, ZeroAreaFacesAndEmptyMeshesAreNeverMet) {
  // Two triangles: a proper one, and a needle of zero area across the ray's path.
  const Mesh mesh = build_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 2}, {0, 0, 3}},
                               {{0, 1, 2}, {3, 4, 5}});
  const RayCaster caster(mesh);
  EXPECT_EQ(caster.n_faces(), 1u);
  const RayHit hit = caster.first_hit(Vec3(0.2, 0.2, 5), Vec3(0, 0, -1), 0.0, kInf);
  ASSERT_TRUE(hit.face.is_valid());
  EXPECT_EQ(hit.face.idx(), 0);
  EXPECT_NEAR(hit.t, 5.0, 1e-12);
  const RayCaster empty{Mesh()};
  EXPECT_FALSE(empty.first_hit(Vec3(0, 0, 0), Vec3(1, 0, 0), 0.0, kInf).face.is_valid());
}

TEST(RayCaster, RejectsBadRaysAndCorners) {
  const RayCaster caster(make_icosphere(1));
  const double nan = std::nan("");
  EXPECT_THROW(caster.first_hit(Vec3(nan, 0, 0), Vec3(1, 0, 0), 0, 1), InvalidArgument);
  EXPECT_THROW(caster.first_hit(Vec3(0, 0, 0), Vec3(0, kInf, 0), 0, 1), InvalidArgument);
  EXPECT_THROW(caster.first_hit(Vec3(0, 0, 0), Vec3(0, 0, 0), 0, 1), InvalidArgument);
  EXPECT_THROW(caster.first_hit(Vec3(0, 0, 0), Vec3(1, 0, 0), 2, 1), InvalidArgument);
  Mesh broken = make_icosphere(1);
  broken.set_point(VertexHandle(3), Vec3(nan, 0, 0));
  EXPECT_THROW(RayCaster{broken}, InvalidArgument);
}

} // namespace
} // namespace remora
