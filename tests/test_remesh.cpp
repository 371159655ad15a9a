// The area-equalizing remesher (paper §4): edge lengths in band, area spread shrinking, no
// flipped or degenerate output triangles, boundaries kept, output on the input, the
// correspondence in both directions, determinism.
#include <cmath>
#include <filesystem>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <type_traits>

#include <gtest/gtest.h>

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

// Fraction of edges with length in [4/5, 4/3] l.
double fraction_in_band(const Mesh& m, double l) {
  std::size_t in = 0, all = 0;
  for (auto e : m.edges()) {
    const double len = m.calc_edge_length(e);
    in += (len >= 0.8 * l - 1e-12 && len <= 4.0 / 3.0 * l + 1e-12) ? 1 : 0;
    ++all;
  }
  return static_cast<double>(in) / static_cast<double>(all);
}

Vec3 face_normal(const Mesh& m, FaceHandle f) {
  const auto v = face_vertices(m, f);
  return OpenMesh::cross(m.point(v[1]) - m.point(v[0]), m.point(v[2]) - m.point(v[0]));
}

// Brute-force distance from p to the surface of m.
double distance_to(const Mesh& m, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (auto f : m.faces()) {
    const auto v = face_vertices(m, f);
    best = std::min(
        best, closest_point_on_triangle(p, m.point(v[0]), m.point(v[1]), m.point(v[2])).distance2);
  }
  return std::sqrt(best);
}

// A flat grid whose columns are squeezed towards x = 0: needles everywhere on the left.
Mesh needle_grid() {
  Mesh m = make_grid(40, 20, 4.0, 2.0);
  for (auto v : m.vertices()) {
    Vec3 p = m.point(v);
    p[0] = 4.0 * std::pow(p[0] / 4.0, 3.0);
    m.set_point(v, p);
  }
  return m;
}

void expect_sound_output(const RemeshResult& r, const Mesh& input) {
  const Mesh& m = r.mesh;
  ASSERT_GT(m.n_faces(), 0u);
  for (auto v : m.vertices()) {
    const Vec3 p = m.point(v);
    ASSERT_TRUE(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]));
    EXPECT_TRUE(m.is_manifold(v));
  }
  const double diag = bounding_box_diagonal(input);
  for (auto f : m.faces())
    EXPECT_GT(face_area(m, f), 1e-10 * diag * diag) << "degenerate output face " << f.idx();
  ASSERT_EQ(r.output_on_input.size(), m.n_vertices());
  ASSERT_EQ(r.input_on_output.size(), input.n_vertices());
  // Each location evaluates to its point.
  for (auto v : m.vertices())
    EXPECT_LT((evaluate(input, r.output_on_input[v.idx()]) - m.point(v)).norm(), 1e-9 * diag);
  for (auto v : input.vertices()) {
    const SurfacePoint& sp = r.input_on_output[v.idx()];
    ASSERT_TRUE(sp.face.is_valid());
    double sum = 0;
    for (double b : sp.bary) {
      EXPECT_GE(b, -1e-12);
      sum += b;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
  }
}

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
// long spokes were cut while its rim edges (3 l here) were still whole: each cut joined a
// spoke's midpoint to a far rim vertex, an edge nearly as long, whose own cuts fanned out again.
// A disc of radius 32 l needs about 3,700 vertices; in index order its first cycle split 29,800
// edges, left 32,000 faces, four of them turned over, and the whole remesh ended with 97.1 % of
// its edges in the band and a mean |θ−60°| of 8.3°; in classes, 8,800 splits and 8,400 faces.
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

TEST(Remesh, KeepsTheBoundaryAndItsCorners) {
  const Mesh input = make_grid(30, 30, 3.0, 3.0);
  RemeshOptions opt;
  opt.target_length = 0.13;
  const RemeshResult r = remesh(input, opt);
  expect_sound_output(r, input);
  EXPECT_EQ(boundary_loops(r.mesh).size(), 1u);
  EXPECT_NEAR(surface_area(r.mesh), 9.0, 1e-9);
  int corners = 0;
  for (auto v : r.mesh.vertices()) {
    const Vec3 p = r.mesh.point(v);
    if (!r.mesh.is_boundary(v)) continue;
    // On the square's boundary.
    const double d =
        std::min({std::abs(p[0]), std::abs(p[0] - 3), std::abs(p[1]), std::abs(p[1] - 3)});
    EXPECT_LT(d, 1e-12);
    if ((std::abs(p[0]) < 1e-12 || std::abs(p[0] - 3) < 1e-12) &&
        (std::abs(p[1]) < 1e-12 || std::abs(p[1] - 3) < 1e-12))
      ++corners;
  }
  EXPECT_EQ(corners, 4);
}

// A scanned hole's rim zigzags: sharp at the scale of its own edges, straight at the scale of
// the mesh. A rectangle (4 x 2, cells of 0.1) whose long sides zigzag by ±0.04 turns by 44
// degrees at every tip, measured l/2 = 0.1 away, but not 2 l away: its tips are not corners and
// slide along the rim like any boundary vertex (a few still end on one: the closest point of the
// rim to anything outside a tip is the tip), while the rectangle's own corners stay. With the
// turn measured at l/2 only, 10 of the 40 tips were corners; now 3 end on a tip.
TEST(Remesh, ZigzagRimsAreNoCorners) {
  Mesh input = make_grid(40, 20, 4.0, 2.0);
  std::vector<Vec3> tips;
  for (auto v : input.vertices()) {
    Vec3 p = input.point(v);
    const long i = std::lround(p[0] / 0.1);
    const bool long_side = p[1] < 1e-9 || p[1] > 2 - 1e-9;
    if (!long_side || i == 0 || i == 40 || i % 2 == 0) continue;
    p[1] += p[1] < 1 ? -0.04 : 0.04; // outwards
    input.set_point(v, p);
    tips.push_back(p);
  }
  RemeshOptions opt;
  opt.target_length = 0.2;
  const RemeshResult r = remesh(input, opt);
  expect_sound_output(r, input);
  int corners = 0, tips_kept = 0;
  for (auto v : r.mesh.vertices()) {
    if (!r.mesh.is_boundary(v)) continue;
    const Vec3 p = r.mesh.point(v);
    for (const Vec3& t : tips) tips_kept += (p - t).norm() < 1e-9 ? 1 : 0;
    for (double x : {0.0, 4.0})
      for (double y : {0.0, 2.0}) corners += (p - Vec3(x, y, 0)).norm() < 1e-12 ? 1 : 0;
  }
  EXPECT_EQ(corners, 4);
  EXPECT_LE(tips_kept, 5) << "of " << tips.size() << " zigzag tips";
}

// Mean mixed area of the boundary vertices that are not corners (valence > 2) over the interior
// vertices' mean.
double boundary_area_ratio(const Mesh& m) {
  const Eigen::VectorXd area = vertex_areas_mixed(m);
  double inner = 0, outer = 0;
  int n_inner = 0, n_outer = 0;
  for (auto v : m.vertices()) {
    if (!m.is_boundary(v)) {
      inner += area[v.idx()];
      ++n_inner;
    } else if (m.valence(v) > 2) {
      outer += area[v.idx()];
      ++n_outer;
    }
  }
  return (outer / n_outer) / (inner / n_inner);
}

// How many edges with an endpoint on the boundary are longer than 4/3 l.
int long_boundary_edges(const Mesh& m, double l) {
  int count = 0;
  for (auto e : m.edges()) {
    const auto h = m.halfedge_handle(e, 0);
    if ((m.is_boundary(m.from_vertex_handle(h)) || m.is_boundary(m.to_vertex_handle(h))) &&
        m.calc_edge_length(e) > 4.0 / 3.0 * l * (1 + 1e-9))
      ++count;
  }
  return count;
}

// A boundary vertex's Voronoi cell ends at the boundary: at a uniform l it has about half the
// mean area. With equalize_boundary its area joins the fine-tuning's residuals and the vertices
// next to it move inwards, as far as the edge band lets them: the cells grow, the full symmetry
// defect drops, and no edge to the boundary leaves the band.
TEST(Remesh, FineTuningGrowsTheBoundaryCellsWithinTheBand) {
  const Mesh input = make_annulus(40, 256, 0.5, 1.5);
  RemeshOptions opt;
  opt.target_length = 0.05;
  opt.equalize_boundary = false;
  const RemeshResult off = remesh(input, opt);
  opt.equalize_boundary = true;
  const RemeshResult on = remesh(input, opt);
  expect_sound_output(on, input);
  const double ratio_off = boundary_area_ratio(off.mesh), ratio_on = boundary_area_ratio(on.mesh);
  EXPECT_LT(ratio_off, 0.6);
  EXPECT_GT(ratio_on, ratio_off + 0.07);
  EXPECT_LT(on.report.symmetry_defect_output, 0.85 * off.report.symmetry_defect_output);
  // Inside, and for the edge band and the angles, no worse.
  EXPECT_LT(on.report.symmetry_defect_output_interior,
            1.05 * off.report.symmetry_defect_output_interior);
  EXPECT_GE(on.report.after_equalization.angles.min_deg, 25.0);
  EXPECT_GE(fraction_in_band(on.mesh, opt.target_length), 0.99);
  // The fine-tuning keeps the edges to the boundary within 4/3 l, or no longer than they were;
  // the Delaunay flips between its iterations and the last repair may leave one or two longer
  // ones, as they do without equalize_boundary.
  EXPECT_LE(long_boundary_edges(on.mesh, opt.target_length),
            long_boundary_edges(off.mesh, opt.target_length) + 2);
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

// Islands and holes a few target lengths around keep three corners spread around them. A
// single triangle, a hexagon and a round 48-gon, 2.5 to 6 l around, used to be smoothed and
// collapsed into flat or tiny triangles (a raw scan's specks: lato000.ply).
TEST(Remesh, SmallIslandsKeepTheirArea) {
  const std::vector<Vec3> points = {{0, 0, 0}, {1.36, 0, 0}, {0.9, 0.7, 0}};
  const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}};
  const Mesh triangle = build_mesh(points, triangles);
  for (const Mesh& input : {triangle, make_disc(1, 6, 1.0), make_disc(2, 48, 1.0)}) {
    double perimeter = 0;
    for (const auto& loop : boundary_loops(input))
      for (auto h : loop) perimeter += input.calc_edge_length(h);
    for (double around : {2.5, 3.5, 4.5, 6.0}) {
      RemeshOptions opt;
      opt.target_length = perimeter / around;
      const RemeshResult r = remesh(input, opt);
      SCOPED_TRACE(std::to_string(input.n_vertices()) + " vertices, " + std::to_string(around) +
                   " l around");
      expect_sound_output(r, input);
      // Three corners a third of the way round a circle from each other span 0.41 of its area.
      EXPECT_GT(surface_area(r.mesh), 0.4 * surface_area(input));
      EXPECT_EQ(boundary_loops(r.mesh).size(), 1u);
    }
  }
}

// A portable linear congruential generator, in [0, 1): the fuzz tests below draw the same
// meshes on every platform.
struct Lcg {
  std::uint64_t state;
  double operator()() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  }
};

// The faces of `base` kept with probability `keep` each (one draw per face, in face order), as a
// soup over `points`, through the loader's repair (islands, strips, holes, cracks whose pinches
// it splits).
Mesh thinned(const Mesh& base, const std::vector<Vec3>& points, double keep, Lcg& next) {
  PolygonSoup soup;
  soup.points = points;
  for (auto f : base.faces()) {
    const auto fv = face_vertices(base, f);
    if (next() < keep)
      soup.add_triangle(static_cast<std::uint32_t>(fv[0].idx()),
                        static_cast<std::uint32_t>(fv[1].idx()),
                        static_cast<std::uint32_t>(fv[2].idx()));
  }
  return repair_soup(soup).mesh;
}

// Remeshes `trials` random thinnings and checks every output: no flat face, every location on
// its point. Trial t thins make(t) = {mesh, cells across}, its points moved by move(p) (drawn
// first), each face kept with probability keep_min + (1 - keep_min) × a draw, after the
// loader's repair (islands, strips, holes, and cracks whose pinches it splits); the target
// length is (0.3 + length_span × a draw) / cells, and every features_every-th trial keeps
// feature lines at 30 degrees.
template <class Make, class Move>
void expect_sound_thinnings(Lcg& next, int trials, Make make, Move move, double keep_min,
                            double length_span, int features_every) {
  for (int trial = 0; trial < trials; ++trial) {
    const auto [base, cells] = make(trial);
    std::vector<Vec3> points;
    for (auto v : base.vertices()) points.push_back(move(base.point(v)));
    const Mesh input = thinned(base, points, keep_min + (1 - keep_min) * next(), next);
    RemeshOptions opt;
    opt.target_length = (0.3 + length_span * next()) / cells;
    opt.feature_angle_deg = trial % features_every == 0 ? 30 : 0;
    if (input.n_faces() == 0) continue;
    SCOPED_TRACE("trial " + std::to_string(trial));
    expect_sound_output(remesh(input, opt), input);
  }
}

// Random thinnings of a wavy grid: islands, strips one triangle wide, holes, and cracks whose two
// sides meet at vertices the loader splits (pinches). A boundary vertex sliding along such a
// crack used to reach its other side, and the faces between the two sides went flat (15 of 300
// thinnings). Every output is sound: no flat face, every location on its point.
TEST(Remesh, ThinnedGridsWithCracksGiveNoFlatFaces) {
  Lcg next{12345};
  expect_sound_thinnings(
      next, 60,
      [](int trial) {
        const int n = 6 + trial % 15;
        return std::pair{make_grid(n, n, 1.0, 1.0), n};
      },
      [&next](Vec3 p) {
        p[2] = 0.1 * std::sin(7 * p[0]) * std::cos(5 * p[1]) + 0.02 * next();
        return p;
      },
      0.3, 3.0, 3);
}

// Noisy cubes with random faces removed: cracks, pinches split by the loader, feature lines on
// every other one. The smoothing moves every vertex at once, so two of them can land on the same
// input vertex or crack tip; each collapse of such a cluster used to leave a flat face behind
// and so was refused. And an island of three faces around an interior vertex pressed onto the
// line of two boundary vertices could not collapse into one triangle (the tetrahedron rule).
// 32 of 6,000 such cubes kept flat faces, 1 now; the first 150 below, 3 (trials 4, 24, 148; the
// first rule alone mended 4 and 148).
TEST(Remesh, ThinnedCubesGiveNoFlatFaces) {
  Lcg next{24};
  expect_sound_thinnings(
      next, 150,
      [](int trial) {
        const int n = 3 + trial % 5;
        return std::pair{make_cube(n, 1.0), n};
      },
      [&next](Vec3 p) {
        for (int k = 0; k < 3; ++k) p[k] += 0.003 * (next() - 0.5);
        return p;
      },
      0.4, 2.5, 2);
}

// Thinned noisy grids, spheres and cubes (the fuzz run of docs/remesh.md, "Bad-triangle
// repair"): with the extra cycles 19 of its 3,000 outputs kept flat faces, 1 at 7 cycles. A flip
// (the repair's, a Delaunay or a valence flip) made a face whose three corners, boundary
// vertices of the thinned input, sat within 1e-4 l of each other; and the curve smoothing moved
// the corners of a one-triangle island (ears) towards each other's midpoints until it lay flat.
// Flips now refuse faces flat by the repair's measure, and ears stay. These are the trials that
// failed; the others are drawn (the generator's state must match) but not remeshed.
TEST(Remesh, ThinnedMeshesGiveNoFlatFacesAfterTheExtraCycles) {
  Lcg next{987654321};
  const std::set<int> failed = {49, 349, 353, 441, 837};
  for (int trial = 0; trial <= *failed.rbegin(); ++trial) {
    const int type = trial % 3;
    const Mesh base = type == 0   ? make_grid(8 + trial % 13, 8 + trial % 11, 1.0, 1.0)
                      : type == 1 ? make_icosphere(2 + trial % 2, 1.0)
                                  : make_cube(3 + trial % 5, 1.0);
    const double noise = 0.03 * next();
    std::vector<Vec3> points;
    for (auto v : base.vertices()) {
      Vec3 p = base.point(v);
      if (type == 0) p[2] = 0.1 * std::sin(7 * p[0]) * std::cos(5 * p[1]);
      for (int k = 0; k < 3; ++k) p[k] += noise * (next() - 0.5) * 0.1;
      points.push_back(p);
    }
    const Mesh input = thinned(base, points, 0.4 + 0.6 * next(), next);
    if (input.n_faces() == 0) continue; // no length drawn then
    RemeshOptions opt;
    opt.target_length = mean_edge_length(input) * (0.3 + 2.5 * next());
    opt.feature_angle_deg = type == 2 ? 30 : 0;
    if (!failed.count(trial)) continue;
    SCOPED_TRACE("trial " + std::to_string(trial));
    expect_sound_output(remesh(input, opt), input);
  }
}

// boundary_spacing: after the first cycle each boundary run is thinned to about 1.2 l and spaced
// evenly; the cells of its vertices grow with it. On an annulus (two loops without corners) the
// boundary edges come out about 1.2 l long, still in the band and on the input's circles.
TEST(Remesh, BoundaryRunsAreThinnedToTheirSpacing) {
  const Mesh input = make_annulus(40, 256, 0.5, 1.5);
  RemeshOptions opt;
  opt.target_length = 0.05;
  opt.boundary_spacing = 1.0;
  const RemeshResult as_cycled = remesh(input, opt);
  opt.boundary_spacing = 1.2;
  const RemeshResult spaced = remesh(input, opt);
  expect_sound_output(spaced, input);
  auto boundary_edges = [&](const Mesh& m) {
    double sum = 0, longest = 0;
    int n = 0;
    for (auto e : m.edges())
      if (m.is_boundary(e)) {
        const double len = m.calc_edge_length(e);
        sum += len;
        longest = std::max(longest, len);
        ++n;
      }
    return std::pair{sum / n / opt.target_length, longest / opt.target_length};
  };
  const auto [mean_before, longest_before] = boundary_edges(as_cycled.mesh);
  const auto [mean_after, longest_after] = boundary_edges(spaced.mesh);
  EXPECT_LT(mean_before, 1.1);
  EXPECT_GT(mean_after, 1.15);
  EXPECT_LE(longest_after, 4.0 / 3.0);
  // Boundary cells relative to the interior ones: 0.635 -> 0.664 (0.650 -> 0.684 with the
  // fine-tuning's centroid target, session 12's default).
  EXPECT_GT(boundary_area_ratio(spaced.mesh), boundary_area_ratio(as_cycled.mesh) + 0.02);
  EXPECT_LT(spaced.report.symmetry_defect_output, 0.9 * as_cycled.report.symmetry_defect_output);
  EXPECT_GE(spaced.report.after_equalization.angles.min_deg, 25.0);
  EXPECT_GE(fraction_in_band(spaced.mesh, opt.target_length), 0.99);
  EXPECT_EQ(boundary_loops(spaced.mesh).size(), 2u);
  for (auto v : spaced.mesh.vertices())
    if (spaced.mesh.is_boundary(v)) {
      const double rad = spaced.mesh.point(v).norm();
      EXPECT_TRUE(rad <= 1.5 + 1e-12 && rad >= 0.5 * std::cos(M_PI / 256) - 1e-12) << rad;
    }
}

TEST(Remesh, AnnulusKeepsBothLoops) {
  const Mesh input = make_annulus(12, 64, 0.5, 1.5);
  const RemeshResult r = remesh(input);
  expect_sound_output(r, input);
  EXPECT_EQ(boundary_loops(r.mesh).size(), 2u);
  EXPECT_EQ(component_topology(r.mesh)[0].genus, 0);
  for (auto v : r.mesh.vertices())
    if (r.mesh.is_boundary(v)) {
      const double rad = r.mesh.point(v).norm();
      // On the input's boundary polygons (chords of the circles).
      EXPECT_TRUE(rad <= 1.5 + 1e-12 && rad >= 0.5 * std::cos(M_PI / 64) - 1e-12) << rad;
    }
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

TEST(Remesh, CorrespondenceRoundTripOnAFlatMesh) {
  const Mesh input = needle_grid();
  RemeshOptions opt;
  opt.target_length = 0.12;
  const RemeshResult r = remesh(input, opt);
  const double diag = bounding_box_diagonal(input);
  for (auto v : input.vertices()) {
    // input vertex -> location on the output -> back onto the input.
    const SurfacePoint& on_out = r.input_on_output[v.idx()];
    const Vec3 q = evaluate(r.mesh, on_out);
    const VertexHandle w = face_vertices(r.mesh, on_out.face)[0];
    const SurfacePoint back = walk_to_closest(input, q, r.output_on_input[w.idx()].face);
    EXPECT_LT((evaluate(input, back) - input.point(v)).norm(), 1e-6 * diag);
  }
}

TEST(Remesh, InputVerticesFindTheirClosestOutputPoint) {
  const Mesh input = make_icosphere(3);
  RemeshOptions opt;
  opt.target_length = 0.15;
  const RemeshResult r = remesh(input, opt);
  for (int i = 0; i < 100; ++i) {
    const VertexHandle v(static_cast<int>(i * input.n_vertices() / 100));
    const Vec3 q = evaluate(r.mesh, r.input_on_output[v.idx()]);
    EXPECT_NEAR((q - input.point(v)).norm(), distance_to(r.mesh, input.point(v)), 1e-12);
  }
}

// The input -> output locations are carried through every split, collapse, flip and move (not
// searched for at the end): the final walk that makes each one the input vertex's closest point
// on the output finds them all but exact already. Dropping the update after the moves, or the
// redistribution after a split or collapse, leaves them far behind.
TEST(Remesh, TracksInputVerticesThroughEveryOperation) {
  for (int shape = 0; shape < 2; ++shape) {
    const Mesh input = shape == 0 ? make_icosphere(4) : needle_grid();
    RemeshOptions opt;
    opt.target_length = shape == 0 ? 0.15 : 0.12;
    const RemeshReport rep = remesh(input, opt).report;
    EXPECT_GT(rep.tracked_same_face, 0.97) << "shape " << shape;
    EXPECT_LT(rep.tracked_excess_mean, 1e-4) << "shape " << shape;
    EXPECT_LT(rep.tracked_excess_max, 0.05) << "shape " << shape;
  }
}

// A large input is remeshed in a spatial order of its own; the correspondence must come back
// in the caller's numbering. The grid's vertices and faces are shuffled (no spatial order left)
// and it is flat, so every input vertex lies exactly on the output.
TEST(Remesh, LargeShuffledInputGetsItsCorrespondenceInItsOwnNumbering) {
  const Mesh grid = make_grid(130, 130, 1.0, 1.0); // 33,800 faces: above the spatial threshold
  std::mt19937 rng(7);
  std::vector<int> vorder(grid.n_vertices());
  std::iota(vorder.begin(), vorder.end(), 0);
  std::shuffle(vorder.begin(), vorder.end(), rng);
  std::vector<int> where(vorder.size());
  Mesh input;
  for (std::size_t i = 0; i < vorder.size(); ++i) {
    where[static_cast<std::size_t>(vorder[i])] = static_cast<int>(i);
    input.add_vertex(grid.point(VertexHandle(vorder[i])));
  }
  std::vector<FaceHandle> faces(grid.faces().begin(), grid.faces().end());
  std::shuffle(faces.begin(), faces.end(), rng);
  for (FaceHandle f : faces) {
    const auto fv = face_vertices(grid, f);
    input.add_face(VertexHandle(where[fv[0].idx()]), VertexHandle(where[fv[1].idx()]),
                   VertexHandle(where[fv[2].idx()]));
  }
  ASSERT_GT(input.n_faces(), 32768u);
  RemeshOptions opt;
  opt.target_length = 0.02;
  const RemeshResult r = remesh(input, opt);
  expect_sound_output(r, input);
  for (auto v : input.vertices())
    ASSERT_LT((evaluate(r.mesh, r.input_on_output[v.idx()]) - input.point(v)).norm(), 1e-9)
        << "input vertex " << v.idx();
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

// With feature lines on, a cube keeps its 12 edges and 8 corners exactly: every output triangle
// lies in a side, so the chord error is zero (without, the output cuts the edges off), and the
// output edges on the cube's edges cover them.
TEST(Remesh, KeepsTheCubesFeatureLinesAndCorners) {
  const Mesh cube = make_cube(12, 1.0);
  RemeshOptions options;
  options.feature_angle_deg = 45;
  const RemeshResult r = remesh(cube, options);
  expect_sound_output(r, cube);
  const Mesh& m = r.mesh;
  EXPECT_EQ(r.report.feature_edges, 144u);
  auto at_half = [](double x) { return std::abs(std::abs(x) - 0.5) < 1e-12; };
  auto halves = [&](const Vec3& p) { return at_half(p[0]) + at_half(p[1]) + at_half(p[2]); };
  int corners = 0;
  for (auto v : m.vertices()) corners += halves(m.point(v)) == 3;
  EXPECT_EQ(corners, 8);
  double along_edges = 0;
  for (auto e : m.edges()) {
    const HalfedgeHandle h = m.halfedge_handle(e, 0);
    const Vec3 a = m.point(m.from_vertex_handle(h)), b = m.point(m.to_vertex_handle(h));
    int shared = 0;
    for (int d = 0; d < 3; ++d) shared += at_half(a[d]) && std::abs(a[d] - b[d]) < 1e-12;
    if (shared == 2) along_edges += (a - b).norm();
  }
  EXPECT_NEAR(along_edges, 12.0, 1e-9);
  for (auto f : m.faces()) {
    const auto fv = face_vertices(m, f);
    const Vec3 c = (m.point(fv[0]) + m.point(fv[1]) + m.point(fv[2])) / 3.0;
    ASSERT_GE(halves(c), 1) << "face " << f.idx() << " cuts through the cube";
  }
  EXPECT_LT(r.report.centroid_distance_max, 1e-12);
  EXPECT_GE(r.report.after_equalization.angles.min_deg, 25.0);
  EXPECT_GT(fraction_in_band(m, r.report.target_length), 0.95);
  // Without feature lines the remesh rounds the cube's edges off.
  const RemeshResult plain = remesh(cube);
  EXPECT_EQ(plain.report.feature_edges, 0u);
  EXPECT_GT(plain.report.centroid_distance_max, 1e-3);
  // Deterministic whatever the thread count, with feature lines too.
  options.threads = 1;
  const RemeshResult serial = remesh(cube, options);
  ASSERT_EQ(serial.mesh.n_vertices(), m.n_vertices());
  for (auto v : m.vertices()) EXPECT_EQ(serial.mesh.point(v), m.point(v));
}

// Feature lines shorter than the target length are dropped: with l above the cube's side no
// line is kept; the boundary is never dropped.
TEST(Remesh, FeatureLinesShorterThanTheTargetLengthAreDropped) {
  RemeshOptions options;
  options.feature_angle_deg = 45;
  options.target_length = 1.2;
  options.cycles = 1;
  options.equalize_iterations = 0;
  EXPECT_EQ(remesh(make_cube(4, 1.0), options).report.feature_edges, 0u);
  options.target_length = 0.3;
  EXPECT_EQ(remesh(make_cube(4, 1.0), options).report.feature_edges, 48u);
  // An open box (the cube without its top side): its four vertical lines meet the boundary
  // loop, which stays; its corners stay too.
  Mesh box = make_cube(6, 1.0);
  for (auto f : box.faces()) {
    const auto fv = face_vertices(box, f);
    bool top = true;
    for (auto v : fv) top = top && box.point(v)[2] == 0.5;
    if (top) box.delete_face(f, true);
  }
  box.garbage_collection();
  options.target_length = 0.15;
  options.cycles = 7;
  options.equalize_iterations = 6;
  const RemeshResult r = remesh(box, options);
  expect_sound_output(r, box);
  EXPECT_EQ(r.report.feature_edges, 8u * 6u);
  int corners = 0;
  for (auto v : r.mesh.vertices()) {
    const Vec3 p = r.mesh.point(v);
    corners += std::abs(std::abs(p[0]) - 0.5) < 1e-12 && std::abs(std::abs(p[1]) - 0.5) < 1e-12 &&
               std::abs(std::abs(p[2]) - 0.5) < 1e-12;
  }
  EXPECT_EQ(corners, 8);
  EXPECT_LT(r.report.centroid_distance_max, 1e-12);
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

namespace remora {
namespace {

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
