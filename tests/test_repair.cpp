// The soup repair: every step on small hand-made soups, and its accounting invariants.
#include <algorithm>
#include <cmath>
#include <random>

#include <sstream>

#include <OpenMesh/Tools/Utils/MeshCheckerT.hh>
#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/mesh/repair.h"
#include "support.h"

namespace remora {
namespace {

using testing::expect_valid_halfedge_mesh;
using testing::signed_volume;

PolygonSoup soup_of(std::vector<Vec3> points,
                    const std::vector<std::vector<std::uint32_t>>& polys) {
  PolygonSoup s;
  s.points = std::move(points);
  for (const auto& p : polys) s.add_polygon(p.data(), p.size());
  return s;
}

// The invariants every repair must keep, whatever the input.
void expect_accounting(const RepairResult& r) {
  const RepairReport& rep = r.report;
  EXPECT_EQ(rep.triangles_in(), rep.faces_loaded + rep.faces_dropped());
  EXPECT_EQ(rep.vertices_in + rep.vertices_added_by_split,
            rep.unreferenced_vertices + rep.welded_vertices + rep.near_welded_vertices +
                rep.orphaned_vertices + rep.vertices_loaded);
  EXPECT_EQ(r.mesh.n_faces(), rep.faces_loaded);
  EXPECT_EQ(r.mesh.n_vertices(), rep.vertices_loaded);
  EXPECT_EQ(r.source_vertex.size(), r.mesh.n_vertices());
  expect_valid_halfedge_mesh(r.mesh);
  for (auto v : r.mesh.vertices()) EXPECT_FALSE(r.mesh.is_isolated(v)) << "vertex " << v.idx();
}

bool is_closed(const Mesh& m) {
  for (auto h : m.halfedges())
    if (m.is_boundary(h)) return false;
  return true;
}

// A unit cube as 12 triangles, every triangle with its own three vertices (like STL).
PolygonSoup stl_cube(const std::vector<int>& flipped = {}) {
  const Vec3 c[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                     {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const int tris[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                           {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  PolygonSoup s;
  for (int t = 0; t < 12; ++t) {
    const bool flip = std::find(flipped.begin(), flipped.end(), t) != flipped.end();
    const std::uint32_t base = static_cast<std::uint32_t>(s.points.size());
    for (int k = 0; k < 3; ++k) s.points.push_back(c[tris[t][k]]);
    if (flip)
      s.add_triangle(base, base + 2, base + 1);
    else
      s.add_triangle(base, base + 1, base + 2);
  }
  return s;
}

TEST(Repair, WeldsAnStlCubeIntoOneClosedOutwardComponent) {
  const RepairResult r = repair_soup(stl_cube());
  expect_accounting(r);
  EXPECT_EQ(r.report.welded_vertices, 36u - 8u);
  EXPECT_EQ(r.mesh.n_vertices(), 8u);
  EXPECT_EQ(r.mesh.n_faces(), 12u);
  EXPECT_TRUE(is_closed(r.mesh));
  EXPECT_NEAR(signed_volume(r.mesh), 1.0, 1e-12);
  EXPECT_EQ(r.report.flipped_faces, 0u);
}

// featuretype.STL's trap: CAD patches whose seam vertices sit at z = -2.7e-16 on one side and
// z = 0 on the other. Bit-identical welding leaves a crack along every seam.
TEST(Repair, WeldsVerticesWithinTheToleranceSoSeamsClose) {
  PolygonSoup soup = stl_cube();
  std::size_t moved = 0;
  for (std::size_t i = 0; i < soup.points.size(); i += 2) // every other facet corner
    if (soup.points[i][2] == 0) {
      soup.points[i][2] = -2.7e-16;
      ++moved;
    }
  ASSERT_GT(moved, 0u);
  const RepairResult r = repair_soup(soup);
  expect_accounting(r);
  EXPECT_EQ(r.mesh.n_vertices(), 8u);
  EXPECT_EQ(r.report.near_welded_vertices, 4u); // each bottom corner exists at both heights
  EXPECT_TRUE(is_closed(r.mesh));
  EXPECT_NEAR(signed_volume(r.mesh), 1.0, 1e-12);

  RepairOptions exact;
  exact.weld_tolerance = 0;
  const RepairResult cracked = repair_soup(soup, exact);
  expect_accounting(cracked);
  EXPECT_EQ(cracked.report.near_welded_vertices, 0u);
  EXPECT_GE(cracked.mesh.n_vertices(), 12u); // 8 + 4 copies, and pinch splits
  EXPECT_FALSE(is_closed(cracked.mesh));
}

// Pairs of triangles whose shared edge is doubled at 0.9 or 1.1 tolerances, at random places
// (about one pair in ten straddles a hash cell's face): exactly the close copies merge, into
// the vertex listed first, whose coordinates stay bit for bit.
TEST(Repair, NearWeldMergesExactlyTheCopiesWithinReach) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  auto random_unit = [&] {
    Vec3 d(uniform(rng), uniform(rng), uniform(rng));
    while (d.norm() < 0.1) d = Vec3(uniform(rng), uniform(rng), uniform(rng));
    return d.normalized();
  };
  PolygonSoup soup;
  // Two far corners fix the bounding box: diagonal 2 sqrt(3) x 10.
  soup.points = {{-10, -10, -10}, {-10, -9, -10}, {-9, -10, -10},
                 {10, 10, 10},    {10, 9, 10},    {9, 10, 10}};
  soup.add_triangle(0, 1, 2);
  soup.add_triangle(3, 4, 5);
  const double tol = RepairOptions{}.weld_tolerance * 20 * std::sqrt(3.0);
  const int pairs = 400;
  for (int k = 0; k < pairs; ++k) {
    const bool close = k % 2 == 0;
    const Vec3 p(5 * uniform(rng), 5 * uniform(rng), 5 * uniform(rng));
    const Vec3 q = p + Vec3(0.01, 0, 0), r = p + Vec3(0, 0.01, 0), s = p + Vec3(0, 0, -0.01);
    const double offset = (close ? 0.9 : 1.1) * tol;
    const auto base = static_cast<std::uint32_t>(soup.points.size());
    soup.points.insert(soup.points.end(),
                       {p, q, r, p + offset * random_unit(), q + offset * random_unit(), s});
    soup.add_triangle(base, base + 1, base + 2);
    soup.add_triangle(base + 4, base + 3, base + 5);
  }
  const RepairResult r = repair_soup(soup);
  expect_accounting(r);
  EXPECT_EQ(r.report.near_welded_vertices, static_cast<std::size_t>(pairs)); // 2 per close pair
  EXPECT_EQ(r.mesh.n_vertices(), 6u + 6u * pairs - pairs);
  // Every output vertex has the coordinates of the soup vertex it stems from, bit for bit, and
  // that vertex is the first of its copies.
  for (auto v : r.mesh.vertices()) {
    const std::uint32_t src = r.source_vertex[v.idx()];
    EXPECT_EQ(r.mesh.point(v), soup.points[src]);
    if (src >= 6 && (src - 6) / 6 % 2 == 0) { // a close pair: its copies 3 and 4 are gone
      EXPECT_TRUE((src - 6) % 6 != 3 && (src - 6) % 6 != 4) << "a later copy survived";
    }
  }
}

TEST(Repair, OrientsRandomlyWoundFacetsOutward) {
  const std::vector<int> flipped = {1, 4, 7, 8, 11};
  const RepairResult r = repair_soup(stl_cube(flipped));
  expect_accounting(r);
  EXPECT_EQ(r.report.flipped_faces, flipped.size());
  EXPECT_TRUE(is_closed(r.mesh));
  EXPECT_NEAR(signed_volume(r.mesh), 1.0, 1e-12);
}

TEST(Repair, TurnsAnInsideOutClosedSurfaceOutward) {
  std::vector<int> all(12);
  for (int i = 0; i < 12; ++i) all[i] = i;
  const RepairResult r = repair_soup(stl_cube(all));
  EXPECT_EQ(r.report.flipped_faces, 12u);
  EXPECT_NEAR(signed_volume(r.mesh), 1.0, 1e-12);
  RepairOptions keep;
  keep.outward = false;
  const RepairResult kept = repair_soup(stl_cube(all), keep);
  EXPECT_EQ(kept.report.flipped_faces, 0u);
  EXPECT_NEAR(signed_volume(kept.mesh), -1.0, 1e-12);
}

TEST(Repair, OpenSurfaceKeepsTheMajorityWinding) {
  // A 4x4 grid of quads split into triangles, 3 of 32 triangles wound the other way.
  PolygonSoup s;
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) s.points.push_back(Vec3(i, j, 0));
  int t = 0;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const std::uint32_t a = static_cast<std::uint32_t>(j * 5 + i), b = a + 1, c = a + 6,
                          d = a + 5;
      for (const auto& tri : {std::array<std::uint32_t, 3>{a, b, c}, {a, c, d}}) {
        if (t == 3 || t == 17 || t == 30)
          s.add_triangle(tri[0], tri[2], tri[1]);
        else
          s.add_triangle(tri[0], tri[1], tri[2]);
        ++t;
      }
    }
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.report.flipped_faces, 3u);
  for (auto f : r.mesh.faces()) EXPECT_GT(r.mesh.calc_face_normal(f)[2], 0.0);
}

TEST(Repair, CountsAndDropsUnreferencedVertices) {
  auto s = soup_of({{0, 0, 0}, {9, 9, 9}, {1, 0, 0}, {0, 1, 0}, {7, 7, 7}}, {{0, 2, 3}});
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.report.unreferenced_vertices, 2u);
  EXPECT_EQ(r.mesh.n_vertices(), 3u);
  EXPECT_EQ(r.source_vertex, (std::vector<std::uint32_t>{0, 2, 3}));
}

TEST(Repair, DropsRepeatedVertexAndDuplicateTriangles) {
  auto s = soup_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}},
                   {{0, 1, 2},
                    {1, 3, 2},
                    {0, 0, 1},   // repeated index
                    {0, 4, 1},   // repeated after welding (4 == 1)
                    {2, 0, 1},   // same triangle, rotated
                    {0, 2, 1},   // same triangle, reversed
                    {3, 2, 4}}); // the second triangle again, through the welded copy
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.report.dropped_repeated_vertex, 2u);
  EXPECT_EQ(r.report.dropped_duplicate, 3u);
  EXPECT_EQ(r.mesh.n_faces(), 2u);
}

TEST(Repair, ARepeatedFaceThatClosesASurfaceKeepsOneCopy) {
  PolygonSoup s = stl_cube();
  s.add_triangle(s.indices[0], s.indices[1], s.indices[2]);
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.report.dropped_duplicate, 1u);
  EXPECT_EQ(r.report.dropped_flap, 0u);
  EXPECT_TRUE(is_closed(r.mesh));
}

TEST(Repair, ADoubledFlapHingedOnOneEdgeIsRemovedEntirely) {
  // A cube with a zero-thickness flap (one triangle listed twice, opposite windings) hinged on
  // its edge (0,0,0)-(1,0,0), as in cad/conrod.stl.
  PolygonSoup s = stl_cube();
  const std::uint32_t a = static_cast<std::uint32_t>(s.points.size());
  s.points.push_back({0, 0, 0});
  s.points.push_back({1, 0, 0});
  s.points.push_back({0.5, -1, -1});
  s.add_triangle(a, a + 1, a + 2);
  s.add_triangle(a, a + 2, a + 1);
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.report.dropped_flap, 2u);
  EXPECT_EQ(r.report.orphaned_vertices, 1u);
  EXPECT_EQ(r.report.nonmanifold_edges, 0u);
  EXPECT_TRUE(is_closed(r.mesh));
  EXPECT_EQ(r.mesh.n_faces(), 12u);
}

TEST(Repair, CountsTheFilesComponentsBeforeSplittingPinchVertices) {
  // Two triangles sharing only a vertex: one component in the file, two once split.
  auto s =
      soup_of({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}}, {{0, 1, 2}, {0, 3, 4}});
  EXPECT_EQ(repair_soup(s).report.components_in, 1u);
}

TEST(Repair, DropsPolygonsWithFewerThanThreeCorners) {
  auto s = soup_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1}, {0, 1, 2}});
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.report.dropped_degenerate_polygon, 1u);
  EXPECT_EQ(r.mesh.n_faces(), 1u);
}

double total_area(const Mesh& m) {
  double a = 0;
  for (auto f : m.faces()) {
    auto h = m.halfedge_handle(f);
    const Vec3& p = m.point(m.from_vertex_handle(h));
    const Vec3& q = m.point(m.to_vertex_handle(h));
    const Vec3& r = m.point(m.to_vertex_handle(m.next_halfedge_handle(h)));
    a += 0.5 * OpenMesh::cross(q - p, r - p).norm();
  }
  return a;
}

TEST(Repair, TriangulatesANonConvexPolygonWithoutOverlap) {
  // An L-shaped hexagon (area 3) in a tilted plane, and a quad.
  const double c = std::cos(0.3), s = std::sin(0.3);
  auto tilt = [&](double x, double y) { return Vec3(x, c * y, s * y); };
  auto soup = soup_of({tilt(0, 0), tilt(2, 0), tilt(2, 1), tilt(1, 1), tilt(1, 2), tilt(0, 2)},
                      {{0, 1, 2, 3, 4, 5}});
  const RepairResult r = repair_soup(soup);
  expect_accounting(r);
  EXPECT_EQ(r.report.polygons_triangulated, 1u);
  EXPECT_EQ(r.report.triangles_added_by_triangulation, 3u);
  EXPECT_EQ(r.mesh.n_faces(), 4u);
  // No overlap and no gap: the triangles' areas add up to the polygon's, all wound like it.
  EXPECT_NEAR(total_area(r.mesh), 3.0, 1e-12);
  const Vec3 normal(0, -s, c);
  for (auto f : r.mesh.faces()) EXPECT_GT(OpenMesh::dot(r.mesh.calc_face_normal(f), normal), 0.99);
}

TEST(Repair, SplitsANonManifoldEdgeShownByThreePages) {
  // Three triangles hinged on the edge (0,1): a "book" with three pages.
  auto s = soup_of({{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {-0.5, 0.8, 0}, {-0.5, -0.8, 0}},
                   {{0, 1, 2}, {1, 0, 3}, {1, 0, 4}});
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.report.nonmanifold_edges, 1u);
  EXPECT_EQ(r.mesh.n_faces(), 3u);
  EXPECT_EQ(r.report.faces_detached, 0u);
  EXPECT_GT(r.report.vertices_added_by_split, 0u);
}

TEST(Repair, SplitsABowTieVertex) {
  auto s =
      soup_of({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}}, {{0, 1, 2}, {0, 3, 4}});
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.report.split_vertices, 1u);
  EXPECT_EQ(r.report.vertices_added_by_split, 1u);
  EXPECT_EQ(r.mesh.n_vertices(), 6u);
  EXPECT_EQ(r.source_vertex[5], 0u);
}

TEST(Repair, TwoClosedCubesSharingAnEdgeStayClosed) {
  PolygonSoup a = stl_cube();
  PolygonSoup b = stl_cube({0, 3, 6});
  // Second cube shifted by (1,1,0): it touches the first along the edge x=1, y=1.
  const std::uint32_t base = static_cast<std::uint32_t>(a.points.size());
  for (Vec3 p : b.points) a.points.push_back(p + Vec3(1, 1, 0));
  for (std::size_t f = 0; f < b.num_polygons(); ++f)
    a.add_triangle(base + b.indices[3 * f], base + b.indices[3 * f + 1],
                   base + b.indices[3 * f + 2]);
  const RepairResult r = repair_soup(a);
  expect_accounting(r);
  EXPECT_EQ(r.report.nonmanifold_edges, 1u);
  EXPECT_EQ(r.mesh.n_faces(), 24u);
  EXPECT_EQ(r.report.faces_detached, 0u);
  EXPECT_TRUE(is_closed(r.mesh));
  EXPECT_NEAR(signed_volume(r.mesh), 2.0, 1e-12);
}

TEST(Repair, CutsAMoebiusStripWhereItsOrientationConflicts) {
  // A Moebius band of 12 quads (24 triangles).
  const int n = 12;
  PolygonSoup s;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n, half = t / 2;
    for (double w : {-0.3, 0.3})
      s.points.push_back(Vec3((1 + w * std::cos(half)) * std::cos(t),
                              (1 + w * std::cos(half)) * std::sin(t), w * std::sin(half)));
  }
  for (int i = 0; i < n; ++i) {
    const std::uint32_t a = static_cast<std::uint32_t>(2 * i), b = a + 1;
    std::uint32_t c = static_cast<std::uint32_t>(2 * ((i + 1) % n)), d = c + 1;
    if (i == n - 1) std::swap(c, d); // the half twist
    s.add_triangle(a, c, b);
    s.add_triangle(b, c, d);
  }
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.mesh.n_faces(), 24u);
  EXPECT_EQ(r.report.orientation_cuts, 1u);
  EXPECT_EQ(r.report.faces_detached, 0u);
}

TEST(Repair, RandomSoupsNeverBreakTheInvariants) {
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 1000; ++trial) {
    std::uniform_int_distribution<int> nv_dist(3, 12);
    const int nv = nv_dist(rng);
    PolygonSoup s;
    std::uniform_real_distribution<double> coord(-1, 1);
    for (int i = 0; i < nv; ++i) s.points.push_back(Vec3(coord(rng), coord(rng), coord(rng)));
    std::uniform_int_distribution<std::uint32_t> id(0, static_cast<std::uint32_t>(nv - 1));
    std::uniform_int_distribution<int> size(2, 5);
    const int nf = std::uniform_int_distribution<int>(1, 30)(rng);
    for (int f = 0; f < nf; ++f) {
      std::vector<std::uint32_t> p(static_cast<std::size_t>(size(rng)));
      for (auto& i : p) i = id(rng);
      s.add_polygon(p.data(), p.size());
    }
    const RepairResult r = repair_soup(s);
    SCOPED_TRACE("trial " + std::to_string(trial));
    expect_accounting(r);
  }
}

TEST(Repair, RejectsOutOfRangeIndices) {
  auto s = soup_of({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 3}});
  EXPECT_THROW(repair_soup(s), InvalidArgument);
}

TEST(Repair, CountsZeroAreaFacesAndKeepsThem) {
  // A sliver whose apex lies on its base edge, next to a proper triangle.
  auto s = soup_of({{0, 0, 0}, {2, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 2, 1}, {0, 1, 3}});
  const RepairResult r = repair_soup(s);
  expect_accounting(r);
  EXPECT_EQ(r.report.zero_area_faces, 1u);
  EXPECT_EQ(r.mesh.n_faces(), 2u);
}

TEST(Repair, DescribeListsOnlyWhatChanged) {
  EXPECT_TRUE(describe(repair_soup(stl_cube()).report).size() == 1u); // the weld
  const auto lines = describe(repair_soup(stl_cube({2})).report);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "28 coincident vertices welded");
  EXPECT_EQ(lines[1], "1 faces flipped to orient their component consistently");
}

} // namespace
} // namespace remora
