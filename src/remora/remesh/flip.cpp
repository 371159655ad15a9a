// §4 step 3 of a cycle: flips towards valence 6 (4 on the boundary); and the fine-tuning's
// intrinsic Delaunay flips. No flip touches a curve edge, turns a face over or makes one flat.

#include <vector>

#include "remora/common/parallel.h"

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

namespace {

// Do the two angles opposite interior edge e sum to more than π?
bool violates_delaunay(const Remesher& rm, EdgeHandle e) {
  const HalfedgeHandle h0 = rm.mesh.halfedge_handle(e, 0), h1 = rm.mesh.halfedge_handle(e, 1);
  const Vec3& a = rm.mesh.point(rm.mesh.to_vertex_handle(h0));
  const Vec3& b = rm.mesh.point(rm.mesh.to_vertex_handle(h1));
  const Vec3& c = rm.mesh.point(rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h0)));
  const Vec3& d = rm.mesh.point(rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h1)));
  // cot of the angle at c (between c->a and c->b) and at d; their sum is negative exactly when
  // the angles sum to more than π.
  const Vec3 ca = a - c, cb = b - c, da = a - d, db = b - d;
  const double dc = OpenMesh::dot(ca, cb), dd = OpenMesh::dot(da, db);
  if (dc >= 0 && dd >= 0) return false; // two angles of at most 90 degrees: most edges
  const double sc = OpenMesh::cross(ca, cb).norm(), sd = OpenMesh::cross(da, db).norm();
  if (!(sc > 0) || !(sd > 0)) return false; // degenerate: the repair's business
  return dc * sd + dd * sc < 0;
}

} // namespace

// One pass of valence-improving flips over all edges. Valences and targets (6 inside, 4 on
// the boundary, a patch's locked vertices less their edges outside it) are cached per vertex and
// updated by each flip.
std::size_t equalize_valences(Remesher& rm) {
  const std::size_t nv = rm.mesh.n_vertices();
  std::vector<int> excess(nv, 0); // valence minus target valence
  parallel_for(nv, rm.options.threads, [&](std::size_t i) {
    const VertexHandle v(static_cast<int>(i));
    if (rm.mesh.status(v).deleted()) return;
    // A patch's locked vertex has edges outside the patch too (patch.cpp).
    const int origin = rm.origin(v);
    const int target = origin >= 0 && !rm.valence_target.empty()
                           ? rm.valence_target[static_cast<std::size_t>(origin)]
                           : (rm.mesh.is_boundary(v) ? 4 : 6);
    excess[i] = static_cast<int>(rm.mesh.valence(v)) - target;
  });
  std::size_t count = 0;
  const std::size_t n = rm.mesh.n_edges();
  for (std::size_t i = 0; i < n; ++i) {
    const EdgeHandle e(static_cast<int>(i));
    if (rm.mesh.status(e).deleted() || rm.on_curve(e)) continue;
    const HalfedgeHandle h0 = rm.mesh.halfedge_handle(e, 0), h1 = rm.mesh.halfedge_handle(e, 1);
    const VertexHandle a = rm.mesh.to_vertex_handle(h0), b = rm.mesh.to_vertex_handle(h1);
    const VertexHandle c = rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h0));
    const VertexHandle d = rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h1));
    if (c == d) continue;
    int& xa = excess[static_cast<std::size_t>(a.idx())];
    int& xb = excess[static_cast<std::size_t>(b.idx())];
    int& xc = excess[static_cast<std::size_t>(c.idx())];
    int& xd = excess[static_cast<std::size_t>(d.idx())];
    auto sq = [](int x) { return x * x; };
    const int before = sq(xa) + sq(xb) + sq(xc) + sq(xd);
    const int after = sq(xa - 1) + sq(xb - 1) + sq(xc + 1) + sq(xd + 1);
    if (after >= before || !rm.mesh.is_flip_ok(e)) continue;
    if (!flip_keeps_orientation(rm, a, b, c, d)) continue;
    rm.mesh.flip(e);
    --xa;
    --xb;
    ++xc;
    ++xd;
    ++count;
  }
  return count;
}

// Flips every interior edge whose opposite angles sum to more than π (cot α + cot β < 0),
// where the flip keeps the mesh manifold and the faces' orientation. The test runs on all
// edges at once, data-parallel; the flips of the marked edges follow in edge order, each
// tested again on the mesh as the earlier flips left it.
std::size_t delaunay_flips(Remesher& rm) {
  const std::size_t n = rm.mesh.n_edges();
  std::vector<char> marked(n, 0);
  parallel_for(n, rm.options.threads, [&](std::size_t i) {
    const EdgeHandle e(static_cast<int>(i));
    if (rm.mesh.status(e).deleted() || rm.on_curve(e)) return;
    marked[i] = violates_delaunay(rm, e) ? 1 : 0;
  });
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!marked[i]) continue;
    const EdgeHandle e(static_cast<int>(i));
    if (!violates_delaunay(rm, e) || !rm.mesh.is_flip_ok(e)) continue;
    const HalfedgeHandle h0 = rm.mesh.halfedge_handle(e, 0), h1 = rm.mesh.halfedge_handle(e, 1);
    const VertexHandle a = rm.mesh.to_vertex_handle(h0), b = rm.mesh.to_vertex_handle(h1);
    const VertexHandle c = rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h0));
    const VertexHandle d = rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h1));
    if (!flip_keeps_orientation(rm, a, b, c, d)) continue;
    rm.mesh.flip(e);
    ++count;
  }
  return count;
}

// The triangles (b, a, c) and (a, b, d) around edge ab become (a, c, d) and (c, b, d): both must
// face the way the pair did, and neither may be degenerate. Neither may span a feature line
// at a or b either (spans_line).
bool flip_keeps_orientation(const Remesher& rm, VertexHandle a, VertexHandle b, VertexHandle c,
                            VertexHandle d) {
  if (rm.feature_count > 0 && (spans_line(rm, a, c, d) || spans_line(rm, b, c, d))) return false;
  const Vec3 pa = rm.mesh.point(a), pb = rm.mesh.point(b), pc = rm.mesh.point(c),
             pd = rm.mesh.point(d);
  const Vec3 n_old = OpenMesh::cross(pa - pb, pc - pb) + OpenMesh::cross(pb - pa, pd - pa);
  const Vec3 n1 = OpenMesh::cross(pc - pa, pd - pa);
  const Vec3 n2 = OpenMesh::cross(pb - pc, pd - pc);
  // No new face flat by the repair's measure (flat_cross): where boundary vertices of a
  // thinned input coincide to 1e-4 l, a flip would make a face whose corners all sit there.
  if (n1.norm() <= rm.flat_cross || n2.norm() <= rm.flat_cross) return false;
  return OpenMesh::dot(n1, n_old) > 0 && OpenMesh::dot(n2, n_old) > 0 &&
         OpenMesh::dot(n1, n2) > 0.5 * n1.norm() * n2.norm();
}

} // namespace remora::remesh_detail
