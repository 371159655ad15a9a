// The remesher on the real meshes of ../shared/data (skipped when absent): the paper's area
// figures, the goals, sound output on ugly CAD parts and scans.
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

std::string shared_mesh(const std::string& rel) {
  if (const char* env = std::getenv("REMORA_DATA")) return std::string(env) + "/" + rel;
  return std::string(REMORA_SHARED_DATA) + "/" + rel;
}

// A test name from a mesh path: every character that is not a letter or digit becomes '_'.
std::string mesh_label(const ::testing::TestParamInfo<const char*>& param) {
  std::string label = param.param;
  for (char& c : label)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return label;
}

// The paper's area figures (rel MAD, variance reduction, symmetry defect) and the edge band; the
// defect over all rows or, on an open mesh, over the interior rows (laplacian.h says why).
void expect_papers_area_figures(const RemeshResult& r, SymmetryRows rows) {
  const RemeshReport& rep = r.report;
  EXPECT_LT(rep.after_equalization.mixed_area.rel_mad, 0.05);
  const double variance_ratio = std::pow(
      rep.after_cycles.mixed_area.rel_std / rep.after_equalization.mixed_area.rel_std, 2.0);
  EXPECT_GT(variance_ratio, 5.0);
  EXPECT_LT(rows == SymmetryRows::All ? rep.symmetry_defect_output
                                      : rep.symmetry_defect_output_interior,
            0.06);
  EXPECT_GT(fraction_in_band(r.mesh, rep.target_length), 0.95);
  // The tracked input -> output locations are (all but) the closest points already. The largest
  // gap is one vertex's: on camelhead's flap (two sheets about 0.36 l apart) the closest point
  // of a few input vertices lies on the other sheet.
  EXPECT_LT(rep.tracked_excess_mean, 1e-3);
  EXPECT_LT(rep.tracked_excess_max, 0.5);
}

// Every goal of docs/remesh.md's table: the paper's area figures with the defect over all rows,
// the smallest and the mean angle, 99 % of the edges in the band.
void expect_every_goal(const RemeshResult& r) {
  const RemeshReport& rep = r.report;
  EXPECT_LT(rep.after_equalization.mixed_area.rel_mad, 0.05);
  EXPECT_GT(
      std::pow(rep.after_cycles.mixed_area.rel_std / rep.after_equalization.mixed_area.rel_std,
               2.0),
      5.0);
  EXPECT_LT(rep.symmetry_defect_output, 0.06);
  EXPECT_GE(rep.after_equalization.angles.min_deg, 25.0);
  EXPECT_LT(rep.after_equalization.angles.mean_abs_deviation_from_60_deg, 7.0);
  EXPECT_GE(fraction_in_band(r.mesh, rep.target_length), 0.99);
}

// The paper's claims on real closed meshes of ../shared/data (skipped when absent).
class RemeshData : public ::testing::TestWithParam<const char*> {};

TEST_P(RemeshData, MeetsThePapersAreaFigures) {
  const std::string path = shared_mesh(GetParam());
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  const Mesh input = read_mesh(path).mesh;
  const RemeshResult r = remesh(input);
  expect_sound_output(r, input);
  expect_papers_area_figures(r, SymmetryRows::All);
  const RemeshReport& rep = r.report;
  EXPECT_GT(rep.after_equalization.angles.min_deg, 25.0);
  EXPECT_LT(rep.after_equalization.angles.mean_abs_deviation_from_60_deg, 7.0);
  for (auto f : r.mesh.faces()) {
    // No flipped face: the output normal agrees with the input's normal where at least one of
    // its corners lies (on a sharp crease of fandisk the other corners may see a normal at 90°).
    const auto v = face_vertices(r.mesh, f);
    double best = -1;
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = face_normal(r.mesh, f).normalized();
      const Vec3 b = face_normal(input, r.output_on_input[v[k].idx()].face).normalized();
      best = std::max(best, OpenMesh::dot(a, b));
    }
    EXPECT_GT(best, 0.0) << "face " << f.idx();
  }
}

// The paper's area figures on real open meshes. Their boundary vertices span half a turn, so
// their cells end at the boundary and stay below the mean area (about 0.7 Ā within the edge
// band); the fine-tuning grows them (equalize_boundary) and, with its momentum, carries their
// deficit far enough inwards that the full symmetry defect meets the figure too (AcrossRiver
// 0.063 -> 0.059 with the momentum and 9 iterations, camelhead 0.057 -> 0.052).
class RemeshOpenData : public ::testing::TestWithParam<const char*> {};

TEST_P(RemeshOpenData, MeetsThePapersAreaFiguresWithTheBoundaryRows) {
  const std::string path = shared_mesh(GetParam());
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  const Mesh input = read_mesh(path).mesh;
  const RemeshResult r = remesh(input);
  expect_sound_output(r, input);
  expect_papers_area_figures(r, SymmetryRows::All);
  EXPECT_LT(r.report.symmetry_defect_output_interior, r.report.symmetry_defect_output);
}

INSTANTIATE_TEST_SUITE_P(OpenMeshes, RemeshOpenData,
                         ::testing::Values("open/camelhead.off", "heightfield/AcrossRiver.stl"),
                         mesh_label);

// Needles, zero-area faces, sharp creases, holes, several bodies: a sound mesh, no NaN, no stall.
class RemeshUglyData : public ::testing::TestWithParam<const char*> {};

TEST_P(RemeshUglyData, GivesASoundMesh) {
  const std::string path = shared_mesh(GetParam());
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  const Mesh input = read_mesh(path).mesh;
  const RemeshResult r = remesh(input);
  expect_sound_output(r, input);
  EXPECT_EQ(connected_components(r.mesh).count, connected_components(input).count);
  EXPECT_EQ(boundary_loops(r.mesh).size(), boundary_loops(input).size());
  EXPECT_LT(r.report.after_equalization.mixed_area.rel_mad,
            r.report.after_cycles.mixed_area.rel_mad);
  EXPECT_LT(r.report.tracked_excess_mean, 0.01);
}

// With feature lines (45 degrees) on CAD parts, scans and open meshes: still a sound mesh (no
// degenerate faces where lines meet at sliver angles or fold back, as on scanned hole rims),
// with the input's components and boundary loops, and a chord error no larger than without
// lines; half or less on the CAD parts, whose creases the lines keep.
TEST_P(RemeshUglyData, WithFeatureLinesGivesASoundMeshCloserToTheInput) {
  const std::string path = shared_mesh(GetParam());
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  const Mesh input = read_mesh(path).mesh;
  RemeshOptions options;
  options.feature_angle_deg = 45;
  const RemeshResult r = remesh(input, options);
  expect_sound_output(r, input);
  EXPECT_GT(r.report.feature_edges, 0u);
  EXPECT_EQ(connected_components(r.mesh).count, connected_components(input).count);
  EXPECT_EQ(boundary_loops(r.mesh).size(), boundary_loops(input).size());
  EXPECT_EQ(r.report.after_equalization.zero_area_faces, 0u);
  const RemeshResult plain = remesh(input);
  const double factor = std::string(GetParam()).starts_with("cad/") ? 0.5 : 1.0;
  EXPECT_LE(r.report.centroid_distance_mean, factor * plain.report.centroid_distance_mean);
}

// Every repair (a flip or a collapse) must raise the smallest angle of the faces it touches. With
// the survivor left where the collapse put it (no projection) and no equalization afterwards,
// the repaired mesh's smallest angle can then only be larger than the unrepaired one's. Collapses
// that only kept orientations and lengths lowered it (gears at 40°: 27.9° to 26.7°).
TEST_P(RemeshUglyData, RepairsNeverLowerTheSmallestAngle) {
  const std::string path = shared_mesh(GetParam());
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  const Mesh input = read_mesh(path).mesh;
  RemeshOptions options;
  options.target_length = 0.9 * mean_edge_length(input); // the paper's l, needles or not
  options.project = false;
  options.equalize_iterations = 0;
  options.repair_angle_deg = 0.0;
  const RemeshResult plain = remesh(input, options);
  options.repair_angle_deg = 40.0; // far more repairs than the default 25°: a sharper test
  const RemeshResult repaired = remesh(input, options);
  EXPECT_EQ(plain.report.repairs, 0u);
  const double before = plain.report.after_cycles.angles.min_deg;
  if (before < 40.0) {
    EXPECT_GT(repaired.report.repairs, 0u) << "smallest angle " << before;
  }
  EXPECT_GE(repaired.report.after_cycles.angles.min_deg, before);
}

// The smoothed fertility's arm is about four edges around when the filter's σ is not capped by
// the arm's width (the base filter's cap keeps it thicker: then even the unguarded remesh keeps
// 34 degrees). There the fine-tuning, placing its moves on the input, squeezed an edge from
// 0.58 l to 0.31 l, and the link condition keeps the repair from collapsing it: a 13.5 degree
// triangle. The guard shortens such moves.
TEST(RemeshFertility, TheSliverGuardKeepsTheSmoothedArmAbove25Degrees) {
  const std::string path = shared_mesh("genus/fertility.off");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  Mesh input = read_mesh(path).mesh;
  LowPassFilter filter(input, {.smoothing = 2.0, .feature_cap = 0.0});
  Eigen::MatrixXd x(input.n_vertices(), 3);
  for (auto v : input.vertices())
    for (int k = 0; k < 3; ++k) x(v.idx(), k) = input.point(v)[k];
  const Eigen::MatrixXd smoothed = filter.apply(x);
  for (auto v : input.vertices())
    input.set_point(v, Vec3(smoothed(v.idx(), 0), smoothed(v.idx(), 1), smoothed(v.idx(), 2)));
  RemeshOptions options;
  const RemeshResult guarded = remesh(input, options);
  EXPECT_GT(guarded.report.guarded_moves, 0u);
  EXPECT_GE(guarded.report.after_equalization.angles.min_deg, 25.0);
  EXPECT_LT(guarded.report.symmetry_defect_output, 0.06);
  options.equalize_guard_deg = 0;
  const RemeshResult unguarded = remesh(input, options);
  EXPECT_EQ(unguarded.report.guarded_moves, 0u);
  EXPECT_LT(unguarded.report.after_equalization.angles.min_deg, 20.0);
  // The guard costs the areas nothing worth counting.
  EXPECT_LT(guarded.report.after_equalization.mixed_area.rel_mad,
            unguarded.report.after_equalization.mixed_area.rel_mad + 0.002);
}

// The sharp creases of gears.stl can put three output vertices on one line. At 0.6 of the
// default length that left four flat faces, whose shortest edge could not go: the repair then
// tries the face's other edges too.
TEST(RemeshGears, NoFlatFacesAtAnotherLength) {
  const std::string path = shared_mesh("cad/gears.stl");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  const Mesh input = read_mesh(path).mesh;
  RemeshOptions options;
  options.length_factor = 0.6;
  options.compute_report = false;
  const RemeshResult r = remesh(input, options);
  expect_sound_output(r, input);
  // Here the sliver guard leaves a 0.32 l edge across a 91 degree crease whose midpoint collapse
  // would lower an angle: the repair collapses it into an endpoint instead (11.8 degrees
  // without that).
  EXPECT_GE(mesh_quality(r.mesh).angles.min_deg, 25.0);
}

// blade.off's rim curls up from its plate. At 10 cycles the smoothing left an interior vertex on
// the rim, in line with two boundary vertices: two flat faces that no flip or collapse mends,
// because relocate()'s walk from the rim stops on the rim. The repair moves the vertex to its
// ring's centroid, found on the plate by a search around it.
TEST(RemeshBlade, NoFlatFacesAfterTenCycles) {
  const std::string path = shared_mesh("cad/blade.off");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  const Mesh input = read_mesh(path).mesh;
  RemeshOptions options;
  options.cycles = 10;
  options.compute_report = false;
  const RemeshResult r = remesh(input, options);
  expect_sound_output(r, input);
  EXPECT_GE(mesh_quality(r.mesh).angles.min_deg, 25.0);
}

// featuretype.STL, a coarse CAD tessellation (3,476 faces, 74 % needles, a third of its edges
// creases sharper than 30 degrees), meets every goal of docs/remesh.md's table. Its cycles keep
// reconnecting around the creases: the extra cycles (10 here) take its mean |θ−60°| under 7°
// (7.07° at 7 cycles), and the fine-tuning's pull towards the ODT point keeps 99 % of its edges
// in the band (99.1 %; 98.6 % with the centroid at its μ of 1.5, the same cycles).
TEST(RemeshFeaturetype, MeetsEveryGoalWithTheExtraCyclesAndTheOdtTarget) {
  const std::string path = shared_mesh("cad/featuretype.STL");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  const Mesh input = read_mesh(path).mesh;
  const RemeshResult r = remesh(input);
  expect_sound_output(r, input);
  const RemeshReport& rep = r.report;
  expect_every_goal(r);
  // The tracked locations are 3e-3 l farther than the closest points here, as on the other CAD
  // parts.
  EXPECT_LT(rep.tracked_excess_mean, 0.01);
  EXPECT_GT(rep.cycles, RemeshOptions{}.cycles);
  const double in_band = fraction_in_band(r.mesh, rep.target_length);

  RemeshOptions seven;
  seven.max_cycles = seven.cycles;
  seven.compute_report = false;
  const RemeshResult fewer = remesh(input, seven);
  EXPECT_GT(mesh_quality(fewer.mesh).angles.mean_abs_deviation_from_60_deg,
            rep.after_equalization.angles.mean_abs_deviation_from_60_deg);
  RemeshOptions centroid;
  centroid.smoothing_target = SmoothingTarget::Centroid;
  centroid.equalize_smoothing = 1.5;
  centroid.compute_report = false;
  const RemeshResult pulled = remesh(input, centroid);
  EXPECT_LT(fraction_in_band(pulled.mesh, rep.target_length), in_band);
}

// The smoothed featuretype, the editor's base surface at its defaults (σ = 2 length scales):
// the part's holes (radius 0.175, about 0.9 σ) and walls are thinner than the filter. Without
// the base filter's feature cap the holes closed into necks about 2 l round, folded at the
// scale of l, and 83 of 5,793 edges stayed out of the band (98.6 %); the cap keeps every goal.
TEST(RemeshFeaturetype, TheSmoothedPartMeetsEveryGoalWithTheFeatureCap) {
  const std::string path = shared_mesh("cad/featuretype.STL");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  const Mesh input = read_mesh(path).mesh;
  auto smoothed = [&](double cap) {
    Mesh s = input;
    LowPassFilter filter(s, {.smoothing = 2.0, .feature_cap = cap});
    set_positions(s, filter.apply(positions_matrix(s)));
    return s;
  };
  const Mesh base = smoothed(LowPassOptions{}.feature_cap);
  const RemeshResult r = remesh(base);
  expect_sound_output(r, base);
  expect_every_goal(r);

  RemeshOptions quick;
  quick.compute_report = false;
  const Mesh necks = smoothed(0.0);
  const RemeshResult pinched = remesh(necks, quick);
  EXPECT_LT(fraction_in_band(pinched.mesh, pinched.report.target_length), 0.99);
}

INSTANTIATE_TEST_SUITE_P(CiMeshes, RemeshUglyData,
                         ::testing::Values("cad/conrod.stl", "cad/featuretype.STL", "cad/gears.stl",
                                           "open/camelhead.off", "heightfield/AcrossRiver.stl",
                                           "scans/bunny.ply"),
                         mesh_label);

INSTANTIATE_TEST_SUITE_P(ClosedMeshes, RemeshData,
                         ::testing::Values("cad/fandisk.obj", "genus/fertility.off"), mesh_label);

} // namespace
} // namespace remora
