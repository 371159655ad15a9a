// §4 step 1 of a cycle: split every edge longer than 4/3 l.

#include <algorithm>

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

// Splits every edge longer than 4/3 l at its midpoint, in passes until none is left (a pass
// visits the edges that existed when it began), the longest first: while edges longer than
// twice 4/3 l remain, a pass splits only those longer than half the longest of the last pass
// (length classes, after Rivara's longest-edge bisection). Split in index order, a CAD fan's
// long spokes are cut while its rim edges are still whole: each cut joins a spoke's midpoint to
// a far rim vertex by an edge nearly as long, whose own cuts fan out again
// (Remesh.SplitsLongEdgesLongestFirst). An input without edges longer than 8/3 l is split in
// index order.
//
// New vertices, like the survivors of collapses, stay where the operation put them, at the
// midpoint of a chord, and take the location of an endpoint as a start: the cycle's smoothing
// moves every vertex and projects it onto the input, walking from there. That is the paper's
// order (it projects only the smoothing's updates) and CGAL's. Projecting each new vertex at
// once costs a walk per split and collapse that the smoothing redoes, and does not improve the
// output's quality (docs/remesh.md, "Design notes").
std::size_t split_long_edges(Remesher& rm) {
  std::size_t count = 0;
  double longest2 = 0; // of the last pass's edges
  for (auto e : rm.mesh.edges()) longest2 = std::max(longest2, rm.mesh.calc_edge_sqr_length(e));
  // Passes at 4/3 l: at most 10 (bounded work whatever the geometry); the classes above it
  // halve the length each pass, at most 64 of them (a factor of 2^64).
  for (int pass = 0, final_passes = 0; pass < 64 && final_passes < 10; ++pass) {
    const double t2 = std::max(rm.hi2, longest2 / 4);
    final_passes += t2 <= rm.hi2 ? 1 : 0;
    longest2 = 0;
    std::size_t made = 0;
    const std::size_t n = rm.mesh.n_edges();
    for (std::size_t i = 0; i < n && rm.live_faces < rm.max_faces; ++i) {
      const EdgeHandle e(static_cast<int>(i));
      if (rm.mesh.status(e).deleted()) continue;
      const HalfedgeHandle h = rm.mesh.halfedge_handle(e, 0);
      const VertexHandle a = rm.mesh.from_vertex_handle(h), b = rm.mesh.to_vertex_handle(h);
      const Vec3 pa = rm.mesh.point(a), pb = rm.mesh.point(b);
      const double length2 = (pa - pb).sqrnorm();
      if (length2 <= t2) {
        longest2 = std::max(longest2, length2);
        continue;
      }
      const bool on_boundary = rm.mesh.is_boundary(e);
      if (on_boundary && rm.locked_boundary) continue; // a patch's border stays as it is
      const bool on_feature = rm.feature(e);
      const VertexHandle v = rm.mesh.split(e, (pa + pb) * 0.5);
      rm.live_faces += on_boundary ? 1 : 2;
      for (auto w : rm.mesh.vv_range(v)) // the halves and the edges to the opposite corners
        longest2 = std::max(longest2, (rm.mesh.point(w) - rm.mesh.point(v)).sqrnorm());
      rm.kind(v) = on_boundary || on_feature ? Kind::Curve : Kind::Interior;
      // On a curve, start from an endpoint that slides along it; between two corners, from
      // the curve edge of the input at a that is closest to the midpoint. With feature lines
      // this matters on the boundary too: the walk along a curve stops where lines meet, and
      // from the corner's own boundary halfedge, which may leave it the other way, the new
      // vertex would stay on the corner and leave a zero-length edge.
      const bool lines = rm.feature_count > 0 && (on_feature || on_boundary);
      const VertexHandle near = lines && rm.kind(a) == Kind::Corner ? b : a;
      rm.loc(v) = rm.loc(near);
      rm.curve_loc(v) = rm.curve_loc(near);
      if (lines && rm.kind(near) == Kind::Corner)
        rm.curve_loc(v) = curve_start(rm, near, (pa + pb) * 0.5);
      if (on_feature) {
        for (auto g : rm.mesh.voh_range(v)) {
          const VertexHandle w = rm.mesh.to_vertex_handle(g);
          rm.feature(rm.mesh.edge_handle(g)) = w == a || w == b;
        }
      } else if (rm.feature_count > 0) {
        for (auto g : rm.mesh.voh_range(v)) rm.feature(rm.mesh.edge_handle(g)) = 0;
      }
      ++made;
    }
    count += made;
    if ((made == 0 && t2 <= rm.hi2) || rm.live_faces >= rm.max_faces) break;
  }
  return count;
}

} // namespace remora::remesh_detail
