// splice() (mesh/splice.h): a set of faces replaced in place by another triangulation of the same
// border; checked against the same triangles built from scratch. And the Laplacian assembler
// carried over a splice (linalg/kharmonic.h) against one built afresh.
#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "remora/common/error.h"
#include "remora/linalg/kharmonic.h"
#include "remora/mesh/build.h"
#include "remora/mesh/primitives.h"
#include "remora/mesh/splice.h"
#include "support.h"

namespace remora {
namespace {

using Triangle = std::array<std::array<double, 3>, 3>;

// The faces as point triples, each rotated to start at its smallest point: a numbering-free
// picture of the mesh.
std::multiset<Triangle> triangles(const Mesh& m) {
  std::multiset<Triangle> out;
  for (const FaceHandle f : m.faces()) {
    Triangle t;
    int k = 0;
    for (const VertexHandle v : m.fv_range(f))
      t[static_cast<std::size_t>(k++)] = {m.point(v)[0], m.point(v)[1], m.point(v)[2]};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    out.insert(t);
  }
  return out;
}

// The faces of `m` within `radius` of `center` (by centroid), flagged.
std::vector<char> faces_near(const Mesh& m, const Vec3& center, double radius) {
  std::vector<char> in(m.n_faces(), 0);
  for (const FaceHandle f : m.faces()) {
    Vec3 c(0, 0, 0);
    for (const VertexHandle v : m.fv_range(f)) c += m.point(v) / 3.0;
    in[static_cast<std::size_t>(f.idx())] = (c - center).norm() < radius;
  }
  return in;
}

// The flagged faces as a mesh of their own, and per patch vertex its vertex in `m`.
Mesh cut_out(const Mesh& m, const std::vector<char>& in, std::vector<int>& origin) {
  std::vector<int> local(m.n_vertices(), -1);
  std::vector<Vec3> points;
  std::vector<std::array<std::uint32_t, 3>> tris;
  for (const FaceHandle f : m.faces()) {
    if (!in[static_cast<std::size_t>(f.idx())]) continue;
    std::array<std::uint32_t, 3> t{};
    int k = 0;
    for (const VertexHandle v : m.fv_range(f)) {
      int& l = local[static_cast<std::size_t>(v.idx())];
      if (l < 0) {
        l = static_cast<int>(points.size());
        points.push_back(m.point(v));
        origin.push_back(v.idx());
      }
      t[static_cast<std::size_t>(k++)] = static_cast<std::uint32_t>(l);
    }
    tris.push_back(t);
  }
  return build_mesh(points, tris);
}

// Splices `patch` (cut from `mesh` at `removed` and changed) back in and compares with the
// expected triangles: those kept plus the patch's.
void expect_splice(Mesh mesh, const std::vector<char>& removed, const Mesh& patch,
                   const std::vector<int>& origin) {
  std::multiset<Triangle> expected = triangles(patch);
  for (const FaceHandle f : mesh.faces())
    if (!removed[static_cast<std::size_t>(f.idx())]) {
      Mesh one;
      std::vector<VertexHandle> vs;
      for (const VertexHandle v : mesh.fv_range(f)) vs.push_back(one.add_vertex(mesh.point(v)));
      one.add_face(vs);
      expected.insert(*triangles(one).begin());
    }
  const Mesh before = mesh;
  const SpliceMap map = splice(mesh, removed, patch, origin);
  testing::expect_valid_halfedge_mesh(mesh);
  EXPECT_EQ(triangles(mesh), expected);
  // Kept vertices keep their points; the maps lead to the right places.
  for (std::size_t v = 0; v < map.vertices.size(); ++v) {
    if (map.vertices[v] < 0) continue;
    EXPECT_EQ(mesh.point(VertexHandle(map.vertices[v])),
              before.point(VertexHandle(static_cast<int>(v))));
  }
  for (std::size_t v = 0; v < map.patch_vertices.size(); ++v)
    EXPECT_EQ(mesh.point(VertexHandle(map.patch_vertices[v])),
              patch.point(VertexHandle(static_cast<int>(v))));
  for (std::size_t f = 0; f < map.patch_faces.size(); ++f) {
    std::vector<Vec3> a, b;
    for (const VertexHandle v : patch.fv_range(FaceHandle(static_cast<int>(f))))
      a.push_back(patch.point(v));
    for (const VertexHandle v : mesh.fv_range(FaceHandle(map.patch_faces[f])))
      b.push_back(mesh.point(v));
    EXPECT_EQ(a, b) << "patch face " << f;
  }
}

TEST(Splice, TheSameFacesPutBackGiveTheSameMesh) {
  Mesh mesh = make_icosphere(3);
  const auto removed = faces_near(mesh, Vec3(0, 0, 1), 0.5);
  std::vector<int> origin;
  Mesh patch = cut_out(mesh, removed, origin);
  for (const VertexHandle v : patch.vertices())
    if (!patch.is_boundary(v)) origin[static_cast<std::size_t>(v.idx())] = -1;
  expect_splice(mesh, removed, patch, origin);
}

// The faces of `mesh` near `center` cut out and changed inside: three splits (`more`) or three
// collapses, so that the last elements of the mesh move into the places left over when spliced
// back. `origin` as splice() takes it.
Mesh changed_patch(const Mesh& mesh, const std::vector<char>& removed, bool more,
                   std::vector<int>& origin) {
  Mesh patch = cut_out(mesh, removed, origin);
  int changes = 0;
  for (const EdgeHandle e : patch.edges()) {
    if (changes == 3) break;
    if (patch.status(e).deleted() || patch.is_boundary(e)) continue;
    const HalfedgeHandle h = patch.halfedge_handle(e, 0);
    if (patch.is_boundary(patch.from_vertex_handle(h)) ||
        patch.is_boundary(patch.to_vertex_handle(h)))
      continue;
    if (more) {
      patch.split(e, patch.calc_edge_midpoint(e));
      ++changes;
    } else if (patch.is_collapse_ok(h)) {
      patch.collapse(h);
      ++changes;
    }
  }
  EXPECT_EQ(changes, 3);
  patch.garbage_collection();
  origin.resize(patch.n_vertices(), -1);
  for (const VertexHandle v : patch.vertices())
    if (!patch.is_boundary(v)) origin[static_cast<std::size_t>(v.idx())] = -1;
  return patch;
}

// More vertices and faces than removed: splits inside the patch; fewer: collapses.
TEST(Splice, MoreOrFewerElementsThanRemoved) {
  for (const bool more : {true, false}) {
    Mesh mesh = make_icosphere(3);
    const auto removed = faces_near(mesh, Vec3(1, 0, 0), 0.6);
    std::vector<int> origin;
    const Mesh patch = changed_patch(mesh, removed, more, origin);
    expect_splice(mesh, removed, patch, origin);
  }
}

// The Laplacian assembler carried over a splice and moved points (linalg/kharmonic.h) against one
// built afresh: the same −W (its copied diagonal entries to round-off), and the same systems.
TEST(Splice, TheAssemblerCarriedOverASpliceMatchesOneBuiltAfresh) {
  for (const bool more : {true, false}) {
    Mesh mesh = make_icosphere(4);
    const KHarmonicAssembler before(mesh);
    const auto removed = faces_near(mesh, Vec3(1, 0, 0), 0.5);
    std::vector<int> origin;
    const Mesh patch = changed_patch(mesh, removed, more, origin);
    const SpliceMap map = splice(mesh, removed, patch, origin);
    const std::size_t n = mesh.n_vertices();
    std::vector<int> previous_of(n, -1);
    std::vector<char> changed(n, 1);
    for (std::size_t o = 0; o < map.vertices.size(); ++o)
      if (map.vertices[o] >= 0) {
        previous_of[static_cast<std::size_t>(map.vertices[o])] = static_cast<int>(o);
        changed[static_cast<std::size_t>(map.vertices[o])] = 0;
      }
    for (const int v : map.patch_vertices) changed[static_cast<std::size_t>(v)] = 1;
    // Kept vertices near (0, 1, 0) pushed out: their points change, their faces do not.
    int moved = 0;
    for (const VertexHandle v : mesh.vertices())
      if (!changed[static_cast<std::size_t>(v.idx())] && mesh.point(v)[1] > 0.8) {
        mesh.set_point(v, mesh.point(v) * 1.1);
        changed[static_cast<std::size_t>(v.idx())] = 1;
        ++moved;
      }
    ASSERT_GT(moved, 10);
    const KHarmonicAssembler updated(mesh, before, previous_of, changed), fresh(mesh);
    const SparseMatrix& a = updated.minus_w();
    const SparseMatrix& b = fresh.minus_w();
    ASSERT_EQ(a.nonZeros(), b.nonZeros());
    for (Eigen::Index c = 0; c < b.outerSize(); ++c) {
      ASSERT_EQ(a.outerIndexPtr()[c + 1], b.outerIndexPtr()[c + 1]) << "column " << c;
      for (SparseMatrix::InnerIterator ia(a, c), ib(b, c); ib; ++ia, ++ib) {
        ASSERT_EQ(ia.row(), ib.row()) << "column " << c;
        if (ib.row() == c)
          EXPECT_NEAR(ia.value(), ib.value(), 1e-14 * std::abs(ib.value())) << c;
        else
          EXPECT_EQ(ia.value(), ib.value()) << "entry " << ib.row() << ", " << c;
      }
    }
    // The systems use the areas, the one-rings and the components as well.
    Region region = Region::all_fixed(n);
    for (const VertexHandle v : mesh.vertices()) {
      const Vec3& p = mesh.point(v);
      if (p[0] > 0.97)
        region.label[static_cast<std::size_t>(v.idx())] = 0;
      else if (p[0] > 0.0)
        region.label[static_cast<std::size_t>(v.idx())] = Region::kFree;
    }
    for (const AreaWeights areas : {AreaWeights::Mixed, AreaWeights::MixedSymmetric}) {
      const KHarmonicOptions options{2, areas};
      const KHarmonicSystem x = updated.assemble(region, options),
                            y = fresh.assemble(region, options);
      EXPECT_EQ(x.free_vertices, y.free_vertices);
      EXPECT_EQ(x.constrained_vertices, y.constrained_vertices);
      EXPECT_LE((x.matrix - y.matrix).norm(), 1e-13 * y.matrix.norm());
      EXPECT_LE((x.coupling - y.coupling).norm(), 1e-13 * y.coupling.norm());
    }
    // A kept vertex said to be unchanged needs its earlier vertex.
    std::vector<int> lost = previous_of;
    const auto kept =
        static_cast<std::size_t>(std::find(changed.begin(), changed.end(), 0) - changed.begin());
    lost[kept] = -1;
    EXPECT_THROW(KHarmonicAssembler(mesh, before, lost, changed), InvalidArgument);
  }
}

// On an open mesh the patch may hold part of the mesh boundary.
TEST(Splice, APatchOnTheMeshBoundary) {
  Mesh mesh = make_grid(12, 12, 1.0, 1.0);
  const auto removed = faces_near(mesh, Vec3(0, 0.5, 0), 0.3);
  std::vector<int> origin;
  Mesh patch = cut_out(mesh, removed, origin);
  for (const VertexHandle v : patch.vertices())
    if (!patch.is_boundary(v)) origin[static_cast<std::size_t>(v.idx())] = -1;
  for (const EdgeHandle e : patch.edges())
    if (!patch.is_boundary(e) && patch.is_flip_ok(e)) {
      patch.flip(e);
      break;
    }
  expect_splice(mesh, removed, patch, origin);
}

TEST(Splice, AMismatchedBorderIsRefusedAndChangesNothing) {
  Mesh mesh = make_icosphere(2);
  const auto removed = faces_near(mesh, Vec3(0, 0, 1), 0.5);
  std::vector<int> origin;
  const Mesh patch = cut_out(mesh, removed, origin);
  const auto fewer = faces_near(mesh, Vec3(0, 0, 1), 0.3);
  const Mesh before = mesh;
  EXPECT_THROW(splice(mesh, fewer, patch, origin), InvalidArgument);
  EXPECT_EQ(triangles(mesh), triangles(before));
  EXPECT_THROW(splice(mesh, removed, patch, std::vector<int>(3, -1)), InvalidArgument);
}

} // namespace
} // namespace remora
