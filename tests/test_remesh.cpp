// The area-equalizing remesher (paper §4): the cycles and the fine-tuning. Edge lengths in band,
// area spread shrinking, no flipped or degenerate output triangles, output on the input,
// determinism, options. Curves, the correspondence, robustness and the real meshes have files of
// their own (test_remesh_*.cpp).
#include <cmath>
#include <filesystem>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <type_traits>

#include <gtest/gtest.h>

#include "remesh_support.h"

#include "remora/common/error.h"
#include "remora/geometry/closest_point.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/locate.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/quality.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/build.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "remora/mesh/repair.h"
#include "remora/mesh/soup.h"
#include "remora/mesh/topology.h"
#include "remora/multires/base_surface.h"
#include "remora/remesh/remesh.h"

namespace remora {
namespace {

using namespace remesh_testing;

TEST(Remesh, FlatGridWithNeedlesBecomesIsotropic) {
  const Mesh input = needle_grid();
  RemeshOptions opt;
  opt.target_length = 0.1;
  const RemeshResult r = remesh(input, opt);
  expect_sound_output(r, input);
  EXPECT_GT(fraction_in_band(r.mesh, 0.1), 0.95);
  for (auto f : r.mesh.faces()) EXPECT_GT(face_normal(r.mesh, f)[2], 0.0) << "flipped face";
  // Flat: every output vertex stays in the plane, inside the rectangle.
  for (auto v : r.mesh.vertices()) {
    const Vec3 p = r.mesh.point(v);
    EXPECT_NEAR(p[2], 0.0, 1e-12);
    EXPECT_GE(p[0], -1e-12);
    EXPECT_LE(p[0], 4.0 + 1e-12);
  }
  EXPECT_GT(r.report.input.angles.percent_below_10, 5.0);
  EXPECT_EQ(r.report.after_equalization.angles.percent_below_10, 0.0);
  // No needle is left (the rectangle's four fixed right-angle corners bound the best angle).
  EXPECT_GT(r.report.after_equalization.angles.min_deg, 15.0);
  EXPECT_LT(r.report.after_equalization.angles.percent_below_30, 1.0);
}

// A flat disc as a CAD tessellation makes it: `segments` vertices on its rim, one at its centre
// and a fan of needles between them.
Mesh fan_disc(int segments, double radius) {
  std::vector<Vec3> points;
  for (int i = 0; i < segments; ++i) {
    const double t = 2 * M_PI * i / segments;
    points.emplace_back(radius * std::cos(t), radius * std::sin(t), 0.0);
  }
  points.emplace_back(0.0, 0.0, 0.0);
  std::vector<std::array<std::uint32_t, 3>> triangles;
  const auto n = static_cast<std::uint32_t>(segments);
  for (std::uint32_t i = 0; i < n; ++i) triangles.push_back({n, i, (i + 1) % n});
  return build_mesh(points, triangles);
}

// The split pass takes the longest edges first (length classes). Split in index order, a fan's
// long spokes are cut while its rim edges (3 l here) are still whole: each cut joins a spoke's
// midpoint to a far rim vertex, an edge nearly as long, whose own cuts fan out again. A disc of
// radius 32 l needs about 3,700 vertices; in index order its first cycle splits 29,800 edges and
// leaves 32,000 faces, some turned over; in classes, 8,800 splits and 8,400 faces.
TEST(Remesh, SplitsLongEdgesLongestFirst) {
  const Mesh input = fan_disc(64, 32.0);
  const double ideal_vertices = M_PI * 32.0 * 32.0 / (std::sqrt(3.0) / 2.0);
  RemeshOptions opt;
  opt.target_length = 1.0;
  opt.cycles = opt.max_cycles = 1;
  opt.equalize_iterations = 0;
  opt.compute_report = false;
  const RemeshResult first = remesh(input, opt);
  EXPECT_LT(static_cast<double>(first.report.splits), 3.0 * ideal_vertices);
  EXPECT_LT(static_cast<double>(first.mesh.n_faces()), 1.5 * 2.0 * ideal_vertices);
  for (auto f : first.mesh.faces()) EXPECT_GT(face_normal(first.mesh, f)[2], 0.0);

  opt = RemeshOptions{};
  opt.target_length = 1.0;
  const RemeshResult full = remesh(input, opt);
  expect_sound_output(full, input);
  EXPECT_GT(fraction_in_band(full.mesh, 1.0), 0.99);
  EXPECT_LT(full.report.after_equalization.angles.mean_abs_deviation_from_60_deg, 7.0);
}

TEST(Remesh, DefaultLengthFollowsTheAreaOnNeedles) {
  // An equilateral grid squeezed 8x across: every triangle a needle.
  Mesh needles = make_equilateral_grid(20, 20, 0.3);
  for (auto v : needles.vertices()) {
    Vec3 p = needles.point(v);
    p[1] /= 8.0;
    needles.set_point(v, p);
  }
  const LengthScale scale = length_scale(needles);
  ASSERT_TRUE(scale.needles);
  RemeshOptions opt;
  opt.equalize_iterations = 0;
  RemeshResult r = remesh(needles, opt);
  EXPECT_TRUE(r.report.length_from_area);
  EXPECT_DOUBLE_EQ(r.report.target_length, 0.9 * scale.from_area);
  opt.target_length = 0.05; // an explicit length is taken as given
  r = remesh(needles, opt);
  EXPECT_FALSE(r.report.length_from_area);
  EXPECT_EQ(r.report.target_length, 0.05);
  const Mesh sphere = make_icosphere(3);
  r = remesh(sphere, RemeshOptions{});
  EXPECT_FALSE(r.report.length_from_area);
  EXPECT_DOUBLE_EQ(r.report.target_length, 0.9 * mean_edge_length(sphere));
}

// The heavy-ball momentum of the fine-tuning (equalize_momentum) speeds up its convergence: in
// the same 6 iterations the area spread and the full symmetry defect (the boundary cells'
// deficit has to travel several rings inwards) end lower than without, and the triangles keep
// their shape.
TEST(Remesh, MomentumSpeedsUpTheFineTuning) {
  const Mesh input = make_annulus(40, 256, 0.5, 1.5);
  RemeshOptions opt;
  opt.target_length = 0.05;
  opt.equalize_iterations = 6;
  opt.equalize_momentum = 0;
  const RemeshReport off = remesh(input, opt).report;
  opt.equalize_momentum = 0.5;
  const RemeshResult on = remesh(input, opt);
  expect_sound_output(on, input);
  const RemeshReport& rep = on.report;
  EXPECT_LT(rep.symmetry_defect_output, 0.95 * off.symmetry_defect_output);
  EXPECT_LT(rep.after_equalization.mixed_area.rel_std,
            0.95 * off.after_equalization.mixed_area.rel_std);
  EXPECT_GE(rep.after_equalization.angles.min_deg, 25.0);
  EXPECT_LT(rep.after_equalization.angles.mean_abs_deviation_from_60_deg,
            off.after_equalization.angles.mean_abs_deviation_from_60_deg + 0.5);
  EXPECT_GE(fraction_in_band(on.mesh, opt.target_length), 0.99);
}

// The cycles run at least `cycles` times, then again while the last one still split, collapsed
// or flipped more than settle_fraction × the faces, up to max_cycles. A cube of 4 × 4 quads per
// side keeps reconnecting around its creases at the default l.
TEST(Remesh, ExtraCyclesRunWhileTheMeshStillChanges) {
  const Mesh input = make_cube(4, 1.0);
  RemeshOptions opt;
  int reported = 0;
  opt.progress = [&](std::string_view phase, int, int) { reported += phase == "remesh"; };
  const RemeshResult adaptive = remesh(input, opt);
  expect_sound_output(adaptive, input);
  EXPECT_GT(adaptive.report.cycles, opt.cycles);
  EXPECT_LE(adaptive.report.cycles, opt.max_cycles);
  EXPECT_EQ(reported, adaptive.report.cycles);
  opt.progress = nullptr;
  opt.compute_report = false;
  opt.settle_fraction = 1; // never an extra cycle
  EXPECT_EQ(remesh(input, opt).report.cycles, opt.cycles);
  opt.settle_fraction = 0.03;
  opt.cycles = 5;
  opt.max_cycles = 3; // below `cycles`: exactly `cycles`
  EXPECT_EQ(remesh(input, opt).report.cycles, 5);
  opt.cycles = opt.max_cycles = 0;
  EXPECT_EQ(remesh(input, opt).report.cycles, 0);
  // A first cycle on needles may change more than all the faces (a disc cut into 200 needles
  // around its centre: splits and collapses many times its output faces); settle_fraction 1
  // still stops (it ran 3 cycles when it only compared the changes with the faces).
  std::vector<Vec3> points = {{0, 0, 0}};
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (std::uint32_t i = 0; i < 200; ++i) {
    const double angle = 2 * M_PI * i / 200;
    points.push_back({std::cos(angle), std::sin(angle), 0});
    triangles.push_back({0, 1 + i, 1 + (i + 1) % 200});
  }
  const Mesh needles = build_mesh(points, triangles);
  opt.cycles = 1;
  opt.max_cycles = 12;
  opt.settle_fraction = 1;
  EXPECT_EQ(remesh(needles, opt).report.cycles, 1);
}

TEST(Remesh, SphereStaysOnTheInputAndEqualizesAreas) {
  const Mesh input = make_icosphere(4);
  RemeshOptions opt;
  opt.target_length = 0.1;
  const RemeshResult r = remesh(input, opt);
  expect_sound_output(r, input);
  const auto& rep = r.report;
  EXPECT_GT(fraction_in_band(r.mesh, 0.1), 0.97);
  // Outward and on the input polyhedron.
  for (auto f : r.mesh.faces()) {
    const auto v = face_vertices(r.mesh, f);
    EXPECT_GT(OpenMesh::dot(face_normal(r.mesh, f), r.mesh.point(v[0])), 0.0);
  }
  for (int i = 0; i < 200; ++i) {
    const VertexHandle v(static_cast<int>(i * r.mesh.n_vertices() / 200));
    EXPECT_LT(distance_to(input, r.mesh.point(v)), 1e-10);
  }
  EXPECT_EQ(component_topology(r.mesh)[0].genus, 0);
  // The paper's figures: relative mean area error below 5 %, area variance down about 5x.
  EXPECT_LT(rep.after_equalization.mixed_area.rel_mad, 0.05);
  EXPECT_LT(rep.after_equalization.mixed_area.rel_std * 2.2,
            rep.after_cycles.mixed_area.rel_std); // variance ratio > 4.8
  EXPECT_LT(rep.symmetry_defect_output, 0.06);
  EXPECT_GT(rep.after_equalization.angles.min_deg, 25.0);
}

TEST(Remesh, PaperGravityUpdateAlsoShrinksTheAreaSpread) {
  const Mesh input = make_icosphere(4);
  RemeshOptions opt;
  opt.target_length = 0.1;
  opt.equalization = Equalization::Gravity;
  const RemeshReport rep = remesh(input, opt).report;
  EXPECT_LT(rep.after_equalization.mixed_area.rel_mad, rep.after_cycles.mixed_area.rel_mad);
  EXPECT_LT(rep.symmetry_defect_output, rep.symmetry_defect_cycles);
}

TEST(Remesh, IsDeterministicWhateverTheThreadCount) {
  const Mesh input = needle_grid();
  RemeshOptions one;
  one.threads = 1;
  RemeshOptions two;
  two.threads = 2;
  const RemeshResult a = remesh(input, one), b = remesh(input, two), c = remesh(input, two);
  ASSERT_EQ(a.mesh.n_vertices(), b.mesh.n_vertices());
  ASSERT_EQ(b.mesh.n_vertices(), c.mesh.n_vertices());
  for (auto v : a.mesh.vertices()) {
    EXPECT_EQ(a.mesh.point(v), b.mesh.point(v));
    EXPECT_EQ(b.mesh.point(v), c.mesh.point(v));
  }
}

TEST(Remesh, WithoutProjectionVerticesStayNearTheInput) {
  const Mesh input = make_icosphere(4);
  RemeshOptions opt;
  opt.target_length = 0.1;
  opt.project = false;
  const RemeshResult r = remesh(input, opt);
  const RemeshReport& rep = r.report;
  EXPECT_GT(rep.vertex_distance_max, 0.0); // off the polyhedron: tangent-plane moves only
  EXPECT_LT(rep.vertex_distance_max, 4e-3);
  EXPECT_LT(rep.vertex_distance_mean, 1e-3);
  // The tracked locations are the vertices' closest points on the input.
  for (int i = 0; i < 100; ++i) {
    const VertexHandle v(static_cast<int>(i * r.mesh.n_vertices() / 100));
    EXPECT_NEAR((evaluate(input, r.output_on_input[v.idx()]) - r.mesh.point(v)).norm(),
                distance_to(input, r.mesh.point(v)), 1e-12);
  }
  opt.project = true;
  EXPECT_EQ(remesh(input, opt).report.vertex_distance_max, 0.0);
  // Split vertices and collapse survivors wait at chord midpoints for the cycle's smoothing to
  // project them: without any fine-tuning, every vertex must still end on the input, and every
  // location must evaluate to its vertex.
  opt.equalize_iterations = 0;
  const RemeshResult cycles_only = remesh(input, opt);
  EXPECT_GT(cycles_only.report.splits + cycles_only.report.collapses, 0u);
  EXPECT_EQ(cycles_only.report.vertex_distance_max, 0.0);
  expect_sound_output(cycles_only, input);
}

TEST(Remesh, WithoutTheReportTheMeshIsTheSame) {
  const Mesh input = needle_grid();
  RemeshOptions quiet;
  quiet.compute_report = false;
  const RemeshResult a = remesh(input), b = remesh(input, quiet);
  ASSERT_EQ(a.mesh.n_vertices(), b.mesh.n_vertices());
  for (auto v : a.mesh.vertices()) EXPECT_EQ(a.mesh.point(v), b.mesh.point(v));
  EXPECT_EQ(b.report.after_equalization.faces, 0u); // not computed
  EXPECT_EQ(b.report.splits, a.report.splits);
  EXPECT_GT(a.report.after_equalization.faces, 0u);
}

// Interior edges whose two opposite angles sum to more than π (+ a rounding margin).
std::size_t non_delaunay_edges(const Mesh& m) {
  auto angle = [&m](VertexHandle at, VertexHandle x, VertexHandle y) {
    const Vec3 u = m.point(x) - m.point(at), w = m.point(y) - m.point(at);
    return std::atan2(OpenMesh::cross(u, w).norm(), OpenMesh::dot(u, w));
  };
  std::size_t count = 0;
  for (auto e : m.edges()) {
    if (m.is_boundary(e)) continue;
    const HalfedgeHandle h0 = m.halfedge_handle(e, 0), h1 = m.halfedge_handle(e, 1);
    const VertexHandle a = m.to_vertex_handle(h0), b = m.to_vertex_handle(h1);
    const VertexHandle c = m.to_vertex_handle(m.next_halfedge_handle(h0));
    const VertexHandle d = m.to_vertex_handle(m.next_halfedge_handle(h1));
    count += angle(c, a, b) + angle(d, a, b) > M_PI + 1e-9 ? 1 : 0;
  }
  return count;
}

TEST(Remesh, FineTuningFlipsLeaveADelaunayMesh) {
  // The bundled scan: the fine-tuning's moves open up some angles beyond 90 degrees; its flips
  // (equalize_flips) turn every such edge whose flip is allowed, and here all are.
  const Mesh input = read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh;
  RemeshOptions opt;
  opt.compute_report = false;
  const RemeshResult flipped = remesh(input, opt);
  EXPECT_EQ(non_delaunay_edges(flipped.mesh), 0u);
  EXPECT_GT(flipped.report.delaunay_flips, 0u);
  opt.equalize_flips = false;
  const RemeshResult unflipped = remesh(input, opt);
  EXPECT_GT(non_delaunay_edges(unflipped.mesh), 20u); // what the flips remove
  EXPECT_EQ(unflipped.report.delaunay_flips, 0u);
}

TEST(Remesh, RejectsBadOptions) {
  const Mesh input = make_icosphere(1);
  // Each value of a field, the other options at their defaults, must be refused.
  auto rejects = [&input](auto RemeshOptions::*field, std::initializer_list<double> values) {
    for (double value : values) {
      RemeshOptions opt;
      opt.*field = static_cast<std::remove_reference_t<decltype(opt.*field)>>(value);
      EXPECT_THROW(remesh(input, opt), InvalidArgument) << value;
    }
  };
  const double nan = std::nan("");
  rejects(&RemeshOptions::lambda, {0.0, 1.5, nan});
  rejects(&RemeshOptions::target_length, {nan});
  rejects(&RemeshOptions::cycles, {-1});
  rejects(&RemeshOptions::max_cycles, {-1});
  rejects(&RemeshOptions::settle_fraction, {-0.1, 1.5, nan});
  rejects(&RemeshOptions::equalize_guard_deg, {60.0, nan});
  rejects(&RemeshOptions::boundary_spacing, {1.5, nan});
  rejects(&RemeshOptions::feature_angle_deg, {-1.0, 180.0, nan});
  rejects(&RemeshOptions::equalize_smoothing, {-1.0, nan, HUGE_VAL});
  rejects(&RemeshOptions::equalize_momentum, {-0.1, 1.0, 2.0, nan});
  rejects(&RemeshOptions::corner_angle_deg, {-1.0, 181.0, nan});
  EXPECT_THROW(remesh(Mesh()), InvalidArgument);
}

} // namespace
} // namespace remora
