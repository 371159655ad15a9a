// Local closest-point search on a triangle mesh: from a face near the answer, walk over the mesh
// to the closest point in O(1) work per query instead of a global search. The remesher uses it to
// project vertices back onto the input surface and to carry the correspondence (paper §4).
// Both walks are greedy descents of the distance to q and end in a local minimum. It is the
// global one when q lies within a few edge lengths of the surface near `start` and away from the
// surface's medial axis. Otherwise the walk stays on the sheet it started on: on a thin part it
// does not jump to the other side, and near a concave crease, or inside a solid near a sharp
// edge, it may stop on the side it reached first (rare on smooth meshes, more frequent on CAD
// parts with sharp creases). Deleted faces (status deleted, or halfedges without a face) are
// never entered.
// Thread-safe for concurrent calls on the same const mesh; nothing is allocated.
#pragma once

#include <vector>

#include "remora/mesh/mesh.h"
#include "remora/mesh/surface_point.h"

namespace remora {

/// Steepest descent over faces. From f = start, each step evaluates the distance from q to every
/// face sharing a vertex with f (the union of the one-rings of f's corners, exact distances by
/// closest_point_on_triangle) and moves to the nearest one if it is closer than f by more than a
/// relative 1e-12 of the squared distance; it stops when no face is, or after max_steps moves.
/// Returns the closest point of the last face, as barycentrics w.r.t. face_vertices(face) (all
/// >= 0, summing to 1).
/// Throws InvalidArgument if start is not a face of mesh or is deleted, if q is not finite, or if
/// max_steps < 0.
SurfacePoint walk_to_closest(const Mesh& mesh, const Vec3& q, FaceHandle start, int max_steps = 64);

/// A point on a boundary edge: `point` lies on the face across `halfedge` (a boundary halfedge,
/// which has no face) with the barycentric weight of that face's third vertex exactly 0, and
/// evaluates to (1 - t) from_vertex(halfedge) + t to_vertex(halfedge), t in [0, 1].
struct BoundaryPoint {
  SurfacePoint point;
  HalfedgeHandle halfedge;
  double t = 0.0;
};

/// The closest point to q on the boundary loop through `start`: from h = start, each step moves to
/// the neighbouring boundary halfedge of the loop (next or prev) nearest to q if it is closer than
/// h by more than a relative 1e-12 of the squared distance; it stops when neither is, or after
/// max_steps moves. Throws InvalidArgument if start is not a halfedge of mesh, is deleted, is not
/// a boundary halfedge or has no face on its other side, if q is not finite, or if max_steps < 0.
BoundaryPoint walk_to_closest_on_boundary(const Mesh& mesh, const Vec3& q, HalfedgeHandle start,
                                          int max_steps = 64);

/// The closest point to q on the curve through `start`: a chain of the edges marked in
/// `on_curve` (indexed by edge idx(), of size n_edges(); boundary edges and feature lines, for
/// the remesher). A chain goes on through every vertex with exactly two marked edges and ends
/// at a vertex with one or more than two. From h = start, each step moves to the chain's next
/// or previous halfedge (oriented as h) nearest to q if it is closer than h by more than a
/// relative 1e-12 of the squared distance; it stops when neither is, or after max_steps moves.
/// The result's `point` lies on the face of `halfedge`, or on the face across it when
/// `halfedge` is a boundary halfedge, with the third vertex's weight exactly 0. Throws
/// InvalidArgument if on_curve has the wrong size, if start is not a live, marked halfedge of
/// mesh, if q is not finite, or if max_steps < 0.
BoundaryPoint walk_to_closest_on_curve(const Mesh& mesh, const Vec3& q, HalfedgeHandle start,
                                       const std::vector<char>& on_curve, int max_steps = 64);

} // namespace remora
