// The repair of bad triangles, after the cycles and after the fine-tuning: triangles with an
// angle below repair_angle_deg get their longest edge flipped or their shortest collapsed; flat
// faces and slivers between curves have further ways out.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_set>
#include <vector>

#include "remora/geometry/closest_point.h"
#include "remora/geometry/measures.h"

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

namespace {

// Slivers below this angle (5 degrees) between two curves may merge two curve vertices
// (repair_pass).
constexpr double kFlatRepairRad = 5.0 * M_PI / 180.0;

// The smallest angle (radians) of the triangle (x, y, z) at the current positions.
double min_angle(const Remesher& rm, VertexHandle x, VertexHandle y, VertexHandle z) {
  const auto a = triangle_angles(rm.mesh.point(x), rm.mesh.point(y), rm.mesh.point(z));
  return std::min({a[0], a[1], a[2]});
}

// Twice the area vector of face f at the current positions.
Vec3 face_cross(const Remesher& rm, FaceHandle f) {
  const auto fv = face_vertices(rm.mesh, f);
  const Vec3& p = rm.mesh.point(fv[0]);
  return OpenMesh::cross(rm.mesh.point(fv[1]) - p, rm.mesh.point(fv[2]) - p);
}

// The smallest angle (radians) of the faces around v, with v at q.
double ring_min_angle(const Remesher& rm, VertexHandle v, const Vec3& q) {
  double smallest = M_PI;
  for (auto h : rm.mesh.voh_range(v)) {
    if (rm.mesh.is_boundary(h)) continue;
    const Vec3& a = rm.mesh.point(rm.mesh.to_vertex_handle(h));
    const Vec3& b = rm.mesh.point(rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h)));
    const auto t = triangle_angles(q, a, b);
    smallest = std::min({smallest, t[0], t[1], t[2]});
  }
  return smallest;
}

// The closest point to q on the input faces within `radius` of `from` (a point on face
// `start`): a breadth-first search across the input's edges, at most 4096 faces. Unlike
// relocate()'s walks it finds the closest point where the surface curls back between `from`
// and q; the repairs' rare moves can pay for it.
SurfacePoint closest_around(const Remesher& rm, const Vec3& q, const Vec3& from, FaceHandle start,
                            double radius) {
  const double radius2 = radius * radius;
  std::vector<FaceHandle> queue{start};
  std::unordered_set<int> seen{start.idx()};
  SurfacePoint best;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < queue.size() && queue.size() < 4096; ++i) {
    const FaceHandle f = queue[i];
    const auto fv = face_vertices(rm.input, f);
    const Vec3 &a = rm.input.point(fv[0]), &b = rm.input.point(fv[1]), &c = rm.input.point(fv[2]);
    const TriangleClosest to_q = closest_point_on_triangle(q, a, b, c);
    if (to_q.distance2 < best_d2) {
      best_d2 = to_q.distance2;
      best = SurfacePoint{f, to_q.bary};
    }
    for (auto h : rm.input.fh_range(f)) {
      const FaceHandle g = rm.input.opposite_face_handle(h);
      if (!g.is_valid() || seen.count(g.idx())) continue;
      seen.insert(g.idx());
      const auto gv = face_vertices(rm.input, g);
      if (closest_point_on_triangle(from, rm.input.point(gv[0]), rm.input.point(gv[1]),
                                    rm.input.point(gv[2]))
              .distance2 <= radius2)
        queue.push_back(g);
    }
  }
  return best;
}

// Flips e where the rules allow it (not on a curve, a manifold result, both new faces facing
// the old pair's way) and the smaller angle of its two faces grows.
bool try_repair_flip(Remesher& rm, EdgeHandle e) {
  if (rm.on_curve(e) || !rm.mesh.is_flip_ok(e)) return false;
  const HalfedgeHandle h0 = rm.mesh.halfedge_handle(e, 0), h1 = rm.mesh.halfedge_handle(e, 1);
  const VertexHandle a = rm.mesh.to_vertex_handle(h0), b = rm.mesh.to_vertex_handle(h1);
  const VertexHandle c = rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h0));
  const VertexHandle d = rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h1));
  const double before = std::min(min_angle(rm, b, a, c), min_angle(rm, a, b, d));
  const double after = std::min(min_angle(rm, a, c, d), min_angle(rm, c, b, d));
  if (!(after > before) || !flip_keeps_orientation(rm, a, b, c, d)) return false;
  rm.mesh.flip(e);
  return true;
}

// Moves interior vertex v to its one-ring centroid (the move in its tangent plane, then onto
// the input) where no face of its ring goes flat or turns over and the ring's smallest angle
// grows. The repair of a flat face that no flip or collapse mends: an interior vertex that the
// smoothing left on a boundary edge of the input, in line with two boundary vertices (where a
// rim curls up from a plate, the goal's closest point lies on the plate, but relocate()'s walk
// from the rim stops on the rim).
bool try_repair_move(Remesher& rm, VertexHandle v) {
  Vec3 goal;
  if (rm.kind(v) != Kind::Interior || rm.mesh.is_boundary(v) || !centroid_target(rm, v, goal))
    return false;
  const Vec3 p = rm.mesh.point(v);
  const SurfacePoint there = closest_around(rm, goal, p, rm.loc(v).face, 2 * rm.length);
  const Vec3 q = rm.options.project ? evaluate(rm.input, there) : goal;
  if (!ring_keeps_faces(rm, v, q) || !(ring_min_angle(rm, v, q) > ring_min_angle(rm, v, p)))
    return false;
  rm.loc(v) = there;
  rm.mesh.set_point(v, q);
  return true;
}

// A flat face (three corners on a line, as on a sharp crease) is worth any collapse of its edges
// that the rules allow, the other two included; then a move of a corner to its ring's centroid;
// last, a collapse that may leave edges up to 8/3 l. A face across a crack of the input (two
// boundary vertices on one side, one on the other, all on the crack's line, next to its tip) has
// no other way out: there a curve vertex goes into the tip. `hs` are the face's halfedges
// (opposite its corners), `fv` its vertices. True when one of them was done.
bool repair_flat_face(Remesher& rm, const HalfedgeHandle (&hs)[3], int shortest,
                      const std::array<VertexHandle, 3>& fv) {
  for (int k : {(shortest + 1) % 3, (shortest + 2) % 3})
    if (try_collapse(rm, rm.mesh.edge_handle(hs[k]), Collapse::Repair)) return true;
  for (int k = 0; k < 3; ++k)
    if (try_repair_move(rm, fv[k])) return true;
  for (int k = 0; k < 3; ++k)
    if (try_collapse(rm, rm.mesh.edge_handle(hs[k]), Collapse::Degenerate)) return true;
  return false;
}

// One sweep of repair_bad_triangles().
std::size_t repair_pass(Remesher& rm, double min_deg) {
  const double min_rad = min_deg * M_PI / 180.0;
  const double cos_min = std::cos(min_rad);
  std::size_t count = 0;
  const std::size_t n = rm.mesh.n_faces();
  for (std::size_t i = 0; i < n; ++i) {
    const FaceHandle f(static_cast<int>(i));
    if (rm.mesh.status(f).deleted()) continue;
    // The face's halfedges, opposite its three corners.
    HalfedgeHandle hs[3];
    hs[0] = rm.mesh.halfedge_handle(f);
    hs[1] = rm.mesh.next_halfedge_handle(hs[0]);
    hs[2] = rm.mesh.next_halfedge_handle(hs[1]);
    double len[3];
    for (int k = 0; k < 3; ++k) len[k] = rm.mesh.calc_edge_sqr_length(hs[k]);
    const int shortest = static_cast<int>(std::min_element(len, len + 3) - len);
    // The smallest angle is the one opposite the shortest edge: a cosine clearly below the
    // limit's settles almost every face without the exact angles.
    {
      const HalfedgeHandle a = hs[(shortest + 1) % 3], b = hs[(shortest + 2) % 3];
      const Vec3 u =
          rm.mesh.point(rm.mesh.to_vertex_handle(a)) - rm.mesh.point(rm.mesh.from_vertex_handle(a));
      const Vec3 w =
          rm.mesh.point(rm.mesh.from_vertex_handle(b)) - rm.mesh.point(rm.mesh.to_vertex_handle(b));
      const double lengths = std::sqrt(u.sqrnorm() * w.sqrnorm());
      if (lengths > 0 && OpenMesh::dot(u, w) < (cos_min - 1e-9) * lengths) continue;
    }
    const auto fv = face_vertices(rm.mesh, f);
    if (min_angle(rm, fv[0], fv[1], fv[2]) >= min_rad) continue;
    const int longest = static_cast<int>(std::max_element(len, len + 3) - len);
    const EdgeHandle el = rm.mesh.edge_handle(hs[longest]);
    if (try_repair_flip(rm, el)) {
      ++count;
      continue;
    }
    if (try_collapse(rm, rm.mesh.edge_handle(hs[shortest]), Collapse::Repair)) {
      ++count;
      continue;
    }
    if (face_cross(rm, f).norm() <= rm.flat_cross && repair_flat_face(rm, hs, shortest, fv)) {
      ++count;
      continue;
    }
    // With feature lines, a sliver between two curves that no legal operation fixes (two
    // lines that leave a corner 0.5 degrees apart, a line folded back on itself: scan noise
    // at 45 degrees) is worth merging two of its curve vertices, the corner kept if one is.
    if (rm.feature_count > 0 && min_angle(rm, fv[0], fv[1], fv[2]) < kFlatRepairRad)
      for (int k : {shortest, (shortest + 1) % 3, (shortest + 2) % 3})
        if (try_collapse(rm, rm.mesh.edge_handle(hs[k]), Collapse::Flat)) {
          ++count;
          break;
        }
  }
  return count;
}

} // namespace

// Triangles whose smallest angle is below `min_deg` (folds and slivers the cycles leave, a
// handful per 100k faces): flip their longest edge when that raises the smallest angle of
// the pair, else collapse their shortest edge when the collapse rules allow. Sequential, in face
// order; the deleted elements stay until remove_deleted().
std::size_t repair_bad_triangles(Remesher& rm, double min_deg) {
  // Every repair raises the smallest angle of the faces it touches (up to the projection of a
  // moved survivor), so passes do not undo each other; a pass that repairs nothing ends the
  // loop, and three bound the work.
  std::size_t total = 0;
  for (int pass = 0; pass < 3; ++pass) {
    const std::size_t c = repair_pass(rm, min_deg);
    total += c;
    if (c == 0) break;
  }
  return total;
}

} // namespace remora::remesh_detail
