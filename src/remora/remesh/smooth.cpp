// §4 step 4 of a cycle: tangential smoothing. Also the vertex moves every step uses: all targets
// computed from the same positions, data-parallel, each placed on the input by a walk.

#include <functional>
#include <vector>

#include "remora/common/parallel.h"

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

namespace {

// Where a curve vertex goes: the midpoint of its two neighbours along the curve, relaxed by
// `weight`.
bool curve_target(const Remesher& rm, VertexHandle v, double weight, Vec3& goal) {
  VertexHandle next, prev;
  const HalfedgeHandle out = boundary_out(rm.mesh, v);
  if (out.is_valid()) {
    next = rm.mesh.to_vertex_handle(out);
    prev = rm.mesh.from_vertex_handle(rm.mesh.prev_halfedge_handle(out));
    // An ear (v's only face is (prev, v, next)) would flatten that face by moving towards the
    // midpoint of its other corners (a thinned input's island, collapsed to one triangle). It
    // stays.
    if (rm.mesh.valence(v) == 2) {
      goal = rm.mesh.point(v);
      return true;
    }
  } else {
    int n = 0;
    for (auto h : rm.mesh.voh_range(v))
      if (rm.feature(rm.mesh.edge_handle(h)))
        (n++ == 0 ? next : prev) = rm.mesh.to_vertex_handle(h);
    // Where the line is not a simple path through v (a repair merged two lines), or a face
    // (prev, v, next) would go flat on a straight line (spans_line), v stays where it is; it
    // is still placed on its line: a split may have left it at a chord's midpoint.
    bool stays = n != 2;
    for (auto h : rm.mesh.voh_range(v))
      stays = stays || (!rm.mesh.is_boundary(h) &&
                        spans_line(rm, v, rm.mesh.to_vertex_handle(h),
                                   rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h))));
    if (stays) {
      goal = rm.mesh.point(v);
      return true;
    }
  }
  const Vec3 mid = (rm.mesh.point(next) + rm.mesh.point(prev)) * 0.5;
  goal = rm.mesh.point(v) + (mid - rm.mesh.point(v)) * weight;
  return true;
}

} // namespace

// Interior vertices move to their one-ring centroid in the tangent plane, curve vertices halfway
// to the midpoint of their curve neighbours.
void tangential_smoothing(Remesher& rm) {
  move_vertices(rm, [&](VertexHandle v, Vec3& goal) {
    if (rm.kind(v) == Kind::Curve) return curve_target(rm, v, 0.5, goal);
    return centroid_target(rm, v, goal);
  });
}

// v's one-ring centroid, the move to it projected into v's tangent plane; false for an
// isolated vertex.
bool centroid_target(const Remesher& rm, VertexHandle v, Vec3& goal) {
  Vec3 centroid(0, 0, 0);
  int k = 0;
  for (auto w : rm.mesh.vv_range(v)) {
    centroid += rm.mesh.point(w);
    ++k;
  }
  if (k == 0) return false;
  const Vec3 p = rm.mesh.point(v);
  Vec3 u = centroid / k - p;
  const Vec3 n = vertex_normal(rm, v);
  u -= n * OpenMesh::dot(n, u);
  goal = p + u;
  return true;
}

// Area-weighted vertex normal (zero for a vertex whose faces all have zero area).
Vec3 vertex_normal(const Remesher& rm, VertexHandle v) {
  Vec3 n(0, 0, 0);
  for (auto h : rm.mesh.voh_range(v)) {
    if (rm.mesh.is_boundary(h)) continue;
    const Vec3 p = rm.mesh.point(v);
    const Vec3 q = rm.mesh.point(rm.mesh.to_vertex_handle(h));
    const Vec3 r = rm.mesh.point(rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h)));
    n += OpenMesh::cross(q - p, r - p);
  }
  const double len = n.norm();
  return len > 0 ? n / len : Vec3(0, 0, 0);
}

// Moves every vertex for which target(v, goal) holds (tangentially for interior vertices, along
// their curve for curve vertices), then back onto the input. One data-parallel loop computes
// each target from the current positions and places it on the input (a relocation reads and
// writes only its own vertex's location); the new positions are applied after it.
void move_vertices(Remesher& rm, const std::function<bool(VertexHandle, Vec3&)>& target) {
  move_vertices_placing(rm, [&](VertexHandle v, Vec3& out) {
    Vec3 g;
    if (!target(v, g)) return Placed::No;
    if (rm.kind(v) != Kind::Curve) {
      out = relocate(rm, v, g, v);
      return Placed::Moved;
    }
    // A curve vertex slides along its curve, which may run back along itself: the two sides
    // of a crack in the input, which meet at a pinched vertex the loader split. Slid onto
    // the other side, its faces would span the crack and go flat. It stays where a face of its
    // ring would go flat or turn over; placed on its curve there (a split or a collapse may
    // have left it at a chord's midpoint, for the smoothing to place).
    const SurfacePoint before = rm.loc(v);
    const HalfedgeHandle before_curve = rm.curve_loc(v);
    out = relocate(rm, v, g, v);
    if (ring_keeps_faces(rm, v, out)) return Placed::Moved;
    rm.loc(v) = before;
    rm.curve_loc(v) = before_curve;
    out = relocate(rm, v, rm.mesh.point(v), v);
    return Placed::Moved;
  });
}

// The same loop for a target that places its vertex on the input itself (`out`), so that it
// can test the placed position (the fine-tuning's sliver guard). Corners and isolated vertices
// never move; the input vertices are projected again afterwards.
void move_vertices_placing(Remesher& rm, const std::function<Placed(VertexHandle, Vec3&)>& place) {
  const std::size_t n = rm.mesh.n_vertices();
  std::vector<Vec3> placed(n);
  std::vector<Placed> moves(n, Placed::No);
  parallel_for(n, rm.options.threads, [&](std::size_t i) {
    const VertexHandle v(static_cast<int>(i));
    if (rm.mesh.status(v).deleted() || rm.kind(v) == Kind::Corner || rm.mesh.is_isolated(v)) return;
    moves[i] = place(v, placed[i]);
  });
  for (std::size_t i = 0; i < n; ++i) {
    if (moves[i] == Placed::Moved || moves[i] == Placed::Shortened)
      rm.mesh.set_point(VertexHandle(static_cast<int>(i)), placed[i]);
    rm.guarded += moves[i] == Placed::Shortened || moves[i] == Placed::Dropped ? 1 : 0;
  }
  reproject_points(rm);
}

// Would moving v to q keep each face around it from going flat or turning over (against its
// normal now, where it has one)?
bool ring_keeps_faces(const Remesher& rm, VertexHandle v, const Vec3& q) {
  const Vec3 p = rm.mesh.point(v);
  const double tiny = 1e-12 * rm.hi2;
  for (auto h : rm.mesh.voh_range(v)) {
    if (rm.mesh.is_boundary(h)) continue;
    const Vec3& a = rm.mesh.point(rm.mesh.to_vertex_handle(h));
    const Vec3& b = rm.mesh.point(rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h)));
    const Vec3 n_new = OpenMesh::cross(a - q, b - q);
    if (n_new.norm() <= tiny) return false;
    const Vec3 n_old = OpenMesh::cross(a - p, b - p);
    if (n_old.norm() > tiny && !(OpenMesh::dot(n_new, n_old) > 0)) return false;
  }
  return true;
}

} // namespace remora::remesh_detail
