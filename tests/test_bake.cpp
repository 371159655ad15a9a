// The local bake (multires/bake.h) against a full preprocess of the same edited shape, on a
// procedural sphere and the bundled bunny: the final surfaces after the same next edit, the
// bases' area figures, the report's figures, the base outside the change kept bit for bit, both
// correspondences, and the exactness the editor promises (an identity edit reproduces the baked
// shape).
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_set>
#include <vector>

#include <gtest/gtest.h>

#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"
#include "remora/geometry/quality.h"
#include "remora/geometry/selection.h"
#include "remora/linalg/nested_dissection.h"
#include "remora/mesh/io.h"
#include "remora/mesh/primitives.h"
#include "remora/multires/bake.h"
#include "remora/multires/base_figures.h"
#include "support.h"

namespace remora {
namespace {

using testing::max_row_distance;

EditorOptions two_threads() {
  EditorOptions o;
  o.threads = 2;
  return o;
}

/// A unit sphere of 10,242 vertices with radial bumps.
Mesh bumpy_fine_sphere() {
  Mesh m = make_icosphere(5, 1.0);
  for (const VertexHandle v : m.vertices()) {
    const Vec3 p = m.point(v);
    m.set_point(v,
                p * (1.0 + 0.01 * std::sin(15 * p[0]) * std::sin(15 * p[1]) * std::sin(15 * p[2])));
  }
  return m;
}

/// The support (geodesic, `count` vertices around `seed`) and its innermost 5 % as the handle.
struct BakeRegion {
  std::vector<int> support, handle;
};
BakeRegion region(const Mesh& mesh, VertexHandle seed, std::size_t count) {
  BakeRegion r;
  r.support = geodesic_order(mesh, seed, count);
  r.handle.assign(r.support.begin(), r.support.begin() + static_cast<long>(count / 20 + 1));
  std::sort(r.support.begin(), r.support.end());
  return r;
}

/// The handle lifted along the seed's normal by `amount` and turned by 0.3 rad.
Transform lift(const Editor& editor, VertexHandle seed, double amount) {
  Mesh m = editor.input();
  m.request_face_normals();
  m.request_vertex_normals();
  m.update_normals();
  const Eigen::Vector3d n(m.normal(seed)[0], m.normal(seed)[1], m.normal(seed)[2]);
  return compose(translation(amount * n),
                 rotation(n.unitOrthogonal(), 0.3, editor.handle_center(0)));
}

struct Case {
  std::string name;
  Mesh mesh;
  VertexHandle seed;
  std::size_t support;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  Mesh sphere = bumpy_fine_sphere();
  const VertexHandle top = nearest_vertex(sphere, Vec3(0, 0, 1));
  out.push_back({"sphere", std::move(sphere), top, 1500});
  Mesh bunny = read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh;
  // The back, away from the holes underneath.
  const VertexHandle back = nearest_vertex(bunny, Vec3(-0.03, 0.12, -0.03));
  out.push_back({"bunny", std::move(bunny), back, 3000});
  return out;
}

/// Every point of the base, for bit-for-bit lookups.
struct PointHash {
  std::size_t operator()(const Vec3& p) const {
    return std::hash<double>()(p[0]) ^ (std::hash<double>()(p[1]) * 31) ^
           (std::hash<double>()(p[2]) * 97);
  }
};

/// Every base vertex lies where its location on the input says (on S'), and every input vertex
/// is located on the base, near its point of S'.
void expect_correspondences(const EditorPartsView& p, double diagonal) {
  const double l = p.report.base_target_length;
  for (const VertexHandle v : p.base.vertices()) {
    const SurfacePoint& sp = p.base_on_input[static_cast<std::size_t>(v.idx())];
    ASSERT_TRUE(sp.face.is_valid() && sp.face.idx() < static_cast<int>(p.input.n_faces()));
    const auto& f = p.input_topology.faces[static_cast<std::size_t>(sp.face.idx())];
    Eigen::RowVector3d q = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k)
      q += sp.bary[static_cast<std::size_t>(k)] * p.smooth.row(f[static_cast<std::size_t>(k)]);
    ASSERT_LT((q - p.base_rest.row(v.idx())).norm(), 1e-9 * diagonal) << "base vertex " << v.idx();
  }
  for (std::size_t i = 0; i < p.input_on_base.size(); ++i) {
    const SurfacePoint& sp = p.input_on_base[i];
    ASSERT_TRUE(sp.face.is_valid() && sp.face.idx() < static_cast<int>(p.base.n_faces())) << i;
    const Vec3 q = evaluate(p.base, sp);
    const Eigen::RowVector3d at(q[0], q[1], q[2]);
    ASSERT_LT((at - p.smooth.row(static_cast<Eigen::Index>(i))).norm(), l) << "input vertex " << i;
  }
}

TEST(Bake, MatchesAFullPreprocessAndKeepsTheRestBitForBit) {
  for (Case& c : cases()) {
    SCOPED_TRACE(c.name);
    Editor editor(c.mesh, two_threads());
    const double diagonal = bounding_box_diagonal(c.mesh);
    const BakeRegion r = region(c.mesh, c.seed, c.support);
    editor.set_region(r.support, {r.handle});
    editor.set_transform(0, lift(editor, c.seed, 0.04 * diagonal));
    const Eigen::MatrixXd edited = editor.positions();
    BakeResult local = bake(editor);
    ASSERT_TRUE(local.report.local) << local.report.fallback;
    EXPECT_GT(local.report.patch_faces, 0u);
    expect_correspondences(local.editor.parts(), diagonal);
    BakeOptions full_options;
    full_options.force_full = true;
    BakeResult full = bake(editor, full_options);
    EXPECT_FALSE(full.report.local);

    // The same next edit on both: a support twice as large, lifted the other way. The local
    // bake's editor edits the baked shape: before the move, its positions are O'.
    const BakeRegion next = region(c.mesh, c.seed, 2 * c.support);
    EXPECT_EQ(local.editor.parts().input_positions, edited);
    Eigen::MatrixXd after[2];
    Editor* editors[2] = {&local.editor, &full.editor};
    for (int e = 0; e < 2; ++e) {
      editors[e]->set_region(next.support, {next.handle});
      if (e == 0) {
        EXPECT_LT(max_row_distance(editors[e]->positions(), edited), 1e-10 * diagonal);
      }
      editors[e]->set_transform(0, lift(*editors[e], c.seed, -0.03 * diagonal));
      after[e] = editors[e]->positions();
    }
    const Eigen::VectorXd d = (after[0] - after[1]).rowwise().norm() / diagonal;
    EXPECT_LT(d.mean(), 5e-4);
    EXPECT_LT(d.maxCoeff(), 6e-3);

    // The bases' area figures: as good as the full remesh's.
    const MeshQuality ql = mesh_quality(local.editor.base()), qf = mesh_quality(full.editor.base());
    const double l = editor.report().base_target_length;
    EXPECT_LT(ql.mixed_area.rel_mad, qf.mixed_area.rel_mad + 0.005);
    EXPECT_LT(ql.angles.mean_abs_deviation_from_60_deg,
              qf.angles.mean_abs_deviation_from_60_deg + 0.5);
    EXPECT_GT(percent_edges_within(local.editor.base(), 0.8 * l, 4.0 / 3.0 * l), 99.0);
    EXPECT_LT(laplacian_symmetry_defect(local.editor.base()),
              laplacian_symmetry_defect(full.editor.base()) + 0.005);
    EXPECT_GT(ql.angles.min_deg, 25.0);
    // The report's figures, updated where the bake changed the base, are the base's.
    const EditReport& report = local.editor.report();
    const MeshQuality& qr = report.base_quality;
    auto near = [](double a, double b) {
      return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(b));
    };
    EXPECT_TRUE(near(qr.mixed_area.rel_mad, ql.mixed_area.rel_mad));
    EXPECT_TRUE(near(qr.mixed_area.rel_std, ql.mixed_area.rel_std));
    EXPECT_TRUE(near(qr.barycentric_area.rel_mad, ql.barycentric_area.rel_mad));
    EXPECT_TRUE(
        near(qr.angles.mean_abs_deviation_from_60_deg, ql.angles.mean_abs_deviation_from_60_deg));
    EXPECT_TRUE(near(qr.angles.percent_below_30, ql.angles.percent_below_30));
    EXPECT_EQ(qr.angles.min_deg, ql.angles.min_deg);
    EXPECT_EQ(qr.angles.max_deg, ql.angles.max_deg);
    EXPECT_TRUE(near(qr.edge_length.mean, ql.edge_length.mean));
    EXPECT_TRUE(near(qr.edge_length.cv, ql.edge_length.cv));
    EXPECT_EQ(qr.edge_length.max, ql.edge_length.max);
    EXPECT_EQ(qr.valence.interior, ql.valence.interior);
    EXPECT_EQ(qr.valence.boundary, ql.valence.boundary);
    EXPECT_EQ(qr.valence.percent_interior_6, ql.valence.percent_interior_6);
    EXPECT_EQ(qr.interior_vertices, ql.interior_vertices);
    EXPECT_EQ(qr.boundary_vertices, ql.boundary_vertices);
    EXPECT_TRUE(near(qr.barycentric_area.rel_std, ql.barycentric_area.rel_std));
    EXPECT_EQ(qr.components, ql.components);
    EXPECT_EQ(qr.vertices, ql.vertices);
    EXPECT_TRUE(near(report.base_symmetry_defect, laplacian_symmetry_defect(local.editor.base())));
    // The statistics those figures sum, per vertex, against the base's measured afresh.
    const BaseStatistics fresh_statistics = base_statistics(local.editor.base());
    const BaseStatistics& carried_statistics = local.editor.parts().statistics;
    for (const auto member : {&BaseStatistics::mixed_areas, &BaseStatistics::barycentric_areas,
                              &BaseStatistics::rows}) {
      const Eigen::VectorXd& expected = fresh_statistics.*member;
      EXPECT_LE((carried_statistics.*member - expected).cwiseAbs().maxCoeff(),
                1e-12 * expected.cwiseAbs().maxCoeff());
    }
    // The base's normals, carried over where no face around them changed: vertex_normals()'s bits.
    const EditorPartsView lp = local.editor.parts();
    EXPECT_EQ(lp.base_normals, vertex_normals(lp.topology, lp.base_rest));
    // The base's topology, carried over through the splice: the base's own.
    const TriangleTopology fresh_topology = triangle_topology(lp.base);
    EXPECT_EQ(lp.topology.faces, fresh_topology.faces);
    EXPECT_EQ(lp.topology.across, fresh_topology.across);
    EXPECT_EQ(lp.topology.vertex_offsets, fresh_topology.vertex_offsets);
    EXPECT_EQ(lp.topology.vertex_faces, fresh_topology.vertex_faces);
    // The Laplacian assembler, carried over from the old editor where the base did not change,
    // is the new base's: −W to round-off in the diagonal, the same systems.
    const KHarmonicAssembler fresh(local.editor.base());
    const SparseMatrix& carried = local.editor.parts().assembler.minus_w();
    EXPECT_LE((carried - fresh.minus_w()).norm(), 1e-14 * fresh.minus_w().norm());
    const KHarmonicOptions mixed{2, AreaWeights::MixedSymmetric};
    const Mesh& nb = local.editor.base();
    Region labels = Region::all_fixed(nb.n_vertices());
    const Vec3 at = c.mesh.point(c.seed);
    double reach0 = 0;
    for (const int v : r.support)
      reach0 = std::max(reach0, (c.mesh.point(VertexHandle(v)) - at).norm());
    for (const VertexHandle v : nb.vertices()) {
      const double from = (nb.point(v) - at).norm();
      if (from < reach0)
        labels.label[static_cast<std::size_t>(v.idx())] = from < 0.3 * reach0 ? 0 : Region::kFree;
    }
    const KHarmonicSystem x = local.editor.parts().assembler.assemble(labels, mixed),
                          y = fresh.assemble(labels, mixed);
    EXPECT_LE((x.matrix - y.matrix).norm(), 1e-13 * y.matrix.norm());

    // Far from the edit (beyond the band, 8 σ, and a few edges more) S and the base are the old
    // ones, bit for bit.
    const EditorPartsView before = editor.parts(), baked = local.editor.parts();
    // Euclidean distances bound the band's edge paths from below.
    const Vec3 seed = c.mesh.point(c.seed);
    double radius = 0;
    for (const int v : r.support)
      radius = std::max(radius, (c.mesh.point(VertexHandle(v)) - seed).norm());
    const double reach = radius + 8.5 * before.filter->stats().sigma + 4 * l;
    std::vector<char> far(c.mesh.n_vertices(), 0);
    for (const VertexHandle w : c.mesh.vertices())
      far[static_cast<std::size_t>(w.idx())] = (c.mesh.point(w) - seed).norm() > reach;
    std::size_t far_count = 0;
    for (std::size_t i = 0; i < far.size(); ++i) {
      if (!far[i]) continue;
      ++far_count;
      ASSERT_EQ(baked.smooth.row(static_cast<Eigen::Index>(i)),
                before.smooth.row(static_cast<Eigen::Index>(i)));
    }
    EXPECT_GT(far_count, c.mesh.n_vertices() / 4);
    std::unordered_set<Vec3, PointHash> points;
    for (const VertexHandle v : baked.base.vertices()) points.insert(baked.base.point(v));
    std::size_t kept = 0;
    for (const VertexHandle v : before.base.vertices()) {
      const auto& f = before.input_topology.faces[static_cast<std::size_t>(
          before.base_on_input[static_cast<std::size_t>(v.idx())].face.idx())];
      if (!far[static_cast<std::size_t>(f[0])] || !far[static_cast<std::size_t>(f[1])] ||
          !far[static_cast<std::size_t>(f[2])])
        continue;
      ++kept;
      EXPECT_TRUE(points.count(before.base.point(v))) << "base vertex " << v.idx();
    }
    EXPECT_GT(kept, before.base.n_vertices() / 4);
  }
}

#ifdef REMORA_WITH_GPL_SOLVERS
// Editor::prepare_regions: regions' systems come from the kept rows and their factors are cut at
// the top of the base's nested dissection, thinner than an unprepared editor's, with its results;
// a bake prepares the new editor, carrying the order over, and the next regions follow it.
TEST(Bake, CarriesTheBasesOrderAndTheRegionsFollowIt) {
  const Mesh bunny = read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh;
  const VertexHandle back = nearest_vertex(bunny, Vec3(-0.03, 0.12, -0.03));
  const double diagonal = bounding_box_diagonal(bunny);
  Editor ordered(bunny, two_threads()), plain(bunny, two_threads());
  ordered.prepare_regions();
  const EditorPartsView p = ordered.parts();
  ASSERT_EQ(p.base_order.size(), ordered.base().n_vertices());
  EXPECT_EQ(p.base_order_k, 2);
  std::vector<int> sorted = p.base_order;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], static_cast<int>(k));
  EXPECT_TRUE(plain.parts().base_order.empty());
  EXPECT_GT(p.assembler.kept_row_bytes(), 0u);
  EXPECT_EQ(plain.parts().assembler.kept_row_bytes(), 0u);
  const BakeRegion large = region(bunny, back, 20000);
  Eigen::MatrixXd moved[2];
  Editor* editors[2] = {&ordered, &plain};
  for (int e = 0; e < 2; ++e) {
    editors[e]->set_region(large.support, {large.handle});
    const SolverStats& stats = editors[e]->report().solver_stats;
    EXPECT_EQ(stats.keyed_order, e == 0);
    EXPECT_EQ(stats.tree_cut, e == 0);
    EXPECT_GT(stats.separator_rows, 0);
    editors[e]->set_transform(0, lift(*editors[e], back, 0.04 * diagonal));
    moved[e] = editors[e]->positions();
  }
  EXPECT_LT(max_row_distance(moved[0], moved[1]), 1e-9 * diagonal);
  const int unprepared_separator = plain.report().solver_stats.separator_rows;
  EXPECT_LT(ordered.report().solver_stats.separator_rows, unprepared_separator);

  // A move of a small region, baked locally: the order is carried over.
  const BakeRegion small = region(bunny, back, 3000);
  ordered.set_region(small.support, {small.handle});
  ordered.set_transform(0, lift(ordered, back, 0.04 * diagonal));
  BakeResult baked = bake(ordered);
  ASSERT_TRUE(baked.report.local) << baked.report.fallback;
  const EditorPartsView q = baked.editor.parts();
  ASSERT_EQ(q.base_order.size(), baked.editor.base().n_vertices());
  EXPECT_EQ(q.base_order_k, 2);
  EXPECT_GT(q.assembler.kept_row_bytes(), 0u); // prepared as the old editor was
  for (const int key : q.base_order) ASSERT_TRUE(key >= 0 && key < static_cast<int>(sorted.size()));
  // The old vertices keep distinct keys; only the patch's new vertices share theirs.
  std::vector<int> distinct = q.base_order;
  std::sort(distinct.begin(), distinct.end());
  const auto unique = std::unique(distinct.begin(), distinct.end()) - distinct.begin();
  EXPECT_GE(static_cast<double>(unique), 0.9 * static_cast<double>(q.base_order.size()));
  // The rows that bridge a separator where the patch crossed it are raised into it: every
  // coupled pair of the new base's rows lies on one root path of the order's tree, and a region
  // across the patch is cut at the top of its tree, thinner than without the order.
  ASSERT_EQ(q.base_order_tree, p.base_order_tree);
  const SparseMatrix pattern = ring_pattern(q.assembler.minus_w(), 2);
  for (int j = 0; j < pattern.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(pattern, j); it; ++it) {
      int lower = q.base_order[static_cast<std::size_t>(j)],
          upper = q.base_order[static_cast<std::size_t>(it.row())];
      if (lower > upper) std::swap(lower, upper);
      while (lower >= 0 && lower < upper)
        lower = q.base_order_tree[static_cast<std::size_t>(lower)];
      ASSERT_EQ(lower, upper) << "rows " << j << " and " << it.row() << " off one root path";
    }
  baked.editor.set_region(large.support, {large.handle});
  const SolverStats& after = baked.editor.report().solver_stats;
  EXPECT_TRUE(after.keyed_order);
  EXPECT_TRUE(after.tree_cut);
  EXPECT_GT(after.separator_rows, 0);
  EXPECT_LT(after.separator_rows, unprepared_separator);
  // A full re-preprocess orders its base afresh.
  BakeOptions full_options;
  full_options.force_full = true;
  BakeResult full = bake(ordered, full_options);
  ASSERT_FALSE(full.report.local);
  EXPECT_EQ(full.editor.parts().base_order.size(), full.editor.base().n_vertices());
}
#endif

TEST(Bake, TheReportFollowsTheBaseThroughBakesOfBakesAtABoundary) {
  // Three bakes in a row, each of the last one's editor, around a hole of the bunny, on one
  // thread: the valences and counts updated where faces changed are the base's own, boundary
  // ones included, and so are the figures over the statistics.
  Mesh bunny = read_mesh(std::string(REMORA_REPO_DATA) + "/bunny.ply").mesh;
  VertexHandle rim;
  for (const VertexHandle v : bunny.vertices())
    if (bunny.is_boundary(v)) {
      rim = v;
      break;
    }
  ASSERT_TRUE(rim.is_valid());
  EditorOptions options;
  options.threads = 1;
  std::vector<BakeResult> bakes;
  bakes.reserve(3);
  Editor first(bunny, options);
  Editor* editor = &first;
  for (int round = 0; round < 3; ++round) {
    SCOPED_TRACE(round);
    const BakeRegion r = region(editor->input(), rim, 2500);
    editor->set_region(r.support, {r.handle});
    editor->set_transform(0, translation({0.0, round % 2 ? -0.004 : 0.004, 0.003}));
    bakes.push_back(bake(*editor));
    const BakeResult& b = bakes.back();
    ASSERT_TRUE(b.report.local) << b.report.fallback;
    const MeshQuality& qr = b.editor.report().base_quality;
    const MeshQuality q = mesh_quality(b.editor.base());
    EXPECT_GT(q.boundary_vertices, 0u);
    EXPECT_EQ(qr.valence.interior, q.valence.interior);
    EXPECT_EQ(qr.valence.boundary, q.valence.boundary);
    EXPECT_EQ(qr.interior_vertices, q.interior_vertices);
    EXPECT_EQ(qr.boundary_vertices, q.boundary_vertices);
    EXPECT_EQ(qr.isolated_vertices, q.isolated_vertices);
    EXPECT_EQ(qr.valence.percent_boundary_4, q.valence.percent_boundary_4);
    const auto near = [](double a, double c) {
      return std::abs(a - c) <= 1e-9 * std::max(1.0, std::abs(c));
    };
    EXPECT_TRUE(near(qr.mixed_area.rel_mad, q.mixed_area.rel_mad));
    EXPECT_TRUE(near(qr.barycentric_area.rel_mad, q.barycentric_area.rel_mad));
    EXPECT_TRUE(
        near(b.editor.report().base_symmetry_defect, laplacian_symmetry_defect(b.editor.base())));
    editor = &bakes.back().editor;
  }
}

TEST(Bake, FallsBackToTheFullPreprocessWithAReason) {
  const Mesh mesh = bumpy_fine_sphere();
  Editor editor(mesh, two_threads());
  std::vector<int> all(mesh.n_vertices());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const BakeRegion r = region(mesh, VertexHandle(0), 100);
  editor.set_region(all, {r.handle});
  editor.set_transform(0, translation({0.0, 0.0, 0.2}));
  const BakeResult b = bake(editor);
  EXPECT_FALSE(b.report.local);
  EXPECT_NE(b.report.fallback.find("band"), std::string::npos) << b.report.fallback;
  EXPECT_EQ(b.editor.parts().input_positions, editor.positions());
}

} // namespace
} // namespace remora
