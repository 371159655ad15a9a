// The mutual parameterization between input and output (paper §4), kept through every operation.
//
// Output -> input: every output vertex has a location on the input (Remesher::loc), set when the
// vertex starts as its input vertex and updated by every move (relocate), which walks from the
// old location to the new closest point.
//
// Input -> output: each input vertex i has a location track[i] (an output face and barycentrics), and each
// output face lists the input vertices located on it: a doubly linked list through next/prev
// whose head is a face property, so that it follows the faces through garbage collection and an
// operation finds the input vertices it displaces without a search. Every operation keeps each
// input vertex on a live face next to it: a split and a flip keep their faces (an input vertex
// stays on the half or the new triangle of its old face, at most one face from where it lies),
// a collapse puts the input vertices of its two deleted faces on the closest face around the
// survivor. After each pass of vertex moves (tangential smoothing, every equalization step)
// and before the end, each input vertex is projected again by a walk across the edges its
// projection falls beyond (reproject_points). At the very end one last walk makes each
// location the input vertex's closest point on the output.

#include <algorithm>
#include <array>
#include <limits>

#include "remora/common/parallel.h"
#include "remora/geometry/closest_point.h"
#include "remora/geometry/locate.h"

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

namespace {

// Twice the area vector of input face f.
Vec3 input_face_cross(const Remesher& rm, FaceHandle f) {
  const auto fv = face_vertices(rm.input, f);
  const Vec3& a = rm.input.point(fv[0]);
  return OpenMesh::cross(rm.input.point(fv[1]) - a, rm.input.point(fv[2]) - a);
}

// Is the closest point of face f to p strictly inside f and within l/100 of p? `out` gets it
// either way.
bool close_inside(const Remesher& rm, const Vec3& p, FaceHandle f, SurfacePoint& out,
                  double& distance2) {
  const auto fv = face_vertices(rm.input, f);
  const Vec3 &a = rm.input.point(fv[0]), &b = rm.input.point(fv[1]), &c3 = rm.input.point(fv[2]);
  constexpr double inside = 1e-6;
  // Most moves end above the interior of a face: there the closest point is the foot of the
  // perpendicular, a few dot products instead of the full region test.
  std::array<double, 3> w{};
  if (plane_barycentrics(p, a, b, c3, w) && w[0] > inside && w[1] > inside && w[2] > inside) {
    out = SurfacePoint{f, w};
    distance2 = (p - (a * w[0] + b * w[1] + c3 * w[2])).sqrnorm();
    return distance2 <= 1e-4 * rm.length * rm.length;
  }
  const TriangleClosest c = closest_point_on_triangle(p, a, b, c3);
  out = SurfacePoint{f, c.bary};
  distance2 = c.distance2;
  return c.bary[0] > inside && c.bary[1] > inside && c.bary[2] > inside &&
         c.distance2 <= 1e-4 * rm.length * rm.length;
}

// Where the closest point `sp` of p on face f left it: across an edge (one weight vanished),
// the face on the other side; at a corner (two vanished), the face around that corner closest
// to p. Invalid at the input boundary or when no face of the fan is closer.
FaceHandle next_face_towards(const Remesher& rm, const Vec3& p, FaceHandle f,
                             const SurfacePoint& sp) {
  int zero = -1, zeros = 0, kept = -1;
  for (int k = 0; k < 3; ++k) {
    if (sp.bary[k] <= 0.0) {
      zero = k;
      ++zeros;
    } else {
      kept = k;
    }
  }
  if (zeros == 1) {
    // halfedge_handle(f) runs v0 -> v1, opposite v2; then v1 -> v2 (opposite v0), v2 -> v0.
    HalfedgeHandle h = rm.input.halfedge_handle(f);
    if (zero == 0) h = rm.input.next_halfedge_handle(h);
    if (zero == 1) h = rm.input.prev_halfedge_handle(h);
    return rm.input.face_handle(rm.input.opposite_halfedge_handle(h));
  }
  if (zeros != 2) return FaceHandle();
  const VertexHandle corner = face_vertices(rm.input, f)[static_cast<std::size_t>(kept)];
  double best = (p - evaluate(rm.input, sp)).sqrnorm();
  FaceHandle best_face;
  for (auto h : rm.input.voh_range(corner)) {
    const FaceHandle g = rm.input.face_handle(h);
    if (!g.is_valid() || g == f) continue;
    const Vec3 q = rm.input.point(rm.input.to_vertex_handle(h));
    const Vec3 r = rm.input.point(rm.input.to_vertex_handle(rm.input.next_halfedge_handle(h)));
    const double d2 = closest_point_on_triangle(p, rm.input.point(corner), q, r).distance2;
    if (d2 < best) {
      best = d2;
      best_face = g;
    }
  }
  return best_face;
}

void link_point(Remesher& rm, int i, FaceHandle f) {
  PointList& list = rm.points(f);
  const auto u = static_cast<std::size_t>(i);
  rm.prev[u] = -1;
  rm.next[u] = list.head;
  if (list.head >= 0) rm.prev[static_cast<std::size_t>(list.head)] = i;
  list.head = i;
  rm.track[u].face = f;
}

void unlink_point(Remesher& rm, int i) {
  const auto u = static_cast<std::size_t>(i);
  if (rm.prev[u] >= 0)
    rm.next[static_cast<std::size_t>(rm.prev[u])] = rm.next[u];
  else
    rm.points(rm.track[u].face).head = rm.next[u];
  if (rm.next[u] >= 0) rm.prev[static_cast<std::size_t>(rm.next[u])] = rm.prev[u];
}

} // namespace

// Every output vertex starts as its input vertex: at a corner of an incident face, and on a
// curve at an outgoing halfedge of it (on the boundary its outgoing boundary halfedge).
void init_locations(Remesher& rm) {
  for (auto v : rm.mesh.vertices()) {
    rm.kind(v) = Kind::Interior;
    if (rm.mesh.is_isolated(v)) {
      rm.kind(v) = Kind::Corner;
      continue;
    }
    // The same handles index the copy and the input.
    const FaceHandle f = *rm.input.cvf_begin(v);
    SurfacePoint sp;
    sp.face = f;
    const auto fv = face_vertices(rm.input, f);
    sp.bary = {fv[0] == v ? 1.0 : 0.0, fv[1] == v ? 1.0 : 0.0, fv[2] == v ? 1.0 : 0.0};
    rm.loc(v) = sp;
    if (rm.mesh.is_boundary(v)) {
      rm.kind(v) = Kind::Curve;
      rm.curve_loc(v) = boundary_out(rm.input, v);
    } else if (rm.feature_count > 0) {
      for (auto h : rm.input.voh_range(v))
        if (rm.input_curve[static_cast<std::size_t>(h.idx() / 2)]) {
          rm.kind(v) = Kind::Curve;
          rm.curve_loc(v) = h;
          break;
        }
    }
  }
}

// Finds where `p` lies on the input, starting from the location of `near`, and returns the
// point to place the vertex at (the projection when projecting).
Vec3 relocate(Remesher& rm, VertexHandle v, const Vec3& p, VertexHandle near) {
  if (rm.kind(near) != Kind::Interior && rm.kind(v) != Kind::Interior) {
    const BoundaryPoint bp =
        walk_to_closest_on_curve(rm.input, p, rm.curve_loc(near), rm.input_curve);
    rm.loc(v) = bp.point;
    rm.curve_loc(v) = bp.halfedge;
  } else {
    // Most moves stay close above the face the vertex was on, or cross a few faces: a directed
    // walk follows the closest point across the edge or around the corner it leaves by, only
    // downhill. Its answer is taken when it ends strictly inside a face and within l/100 (then
    // only a sheet of the surface passing closer than that could be closer), or within l/20
    // when no face of the walk turned more than 18 degrees from the first (a smooth sheet, no
    // crease crossed: on curved organic parts the smoothing's goals sit l/100 to l/20 above
    // the surface, and a full walk for each is costly). Otherwise the full walk runs from the
    // start: a walk from wherever a wrong turn led (across a crease, or the fold of a thin
    // plate) can end in a local minimum far from p; taken at l/20 without the turn test, such
    // answers leave flat faces on CAD parts.
    const FaceHandle start = rm.loc(near).face;
    FaceHandle f = start;
    SurfacePoint quick;
    double d2 = 0;
    bool found = close_inside(rm, p, f, quick, d2);
    const Vec3 start_normal = input_face_cross(rm, start);
    bool smooth_walk = true; // every face so far within 18 degrees of the start face
    for (int step = 0; step < 8 && !found; ++step) {
      const FaceHandle g = next_face_towards(rm, p, f, quick);
      if (!g.is_valid()) break;
      SurfacePoint there;
      double there_d2 = 0;
      found = close_inside(rm, p, g, there, there_d2);
      if (!(there_d2 < d2)) {
        found = false;
        break;
      }
      f = g;
      quick = there;
      d2 = there_d2;
      if (smooth_walk) {
        const Vec3 n = input_face_cross(rm, g);
        smooth_walk = OpenMesh::dot(n, start_normal) >= 0.95 * n.norm() * start_normal.norm();
      }
    }
    constexpr double inside = 1e-6; // as in close_inside
    if (!found && smooth_walk && quick.bary[0] > inside && quick.bary[1] > inside &&
        quick.bary[2] > inside && d2 <= rm.length * rm.length / 400.0)
      found = true;
    rm.loc(v) = found ? quick : walk_to_closest(rm.input, p, start);
  }
  return rm.options.project ? evaluate(rm.input, rm.loc(v)) : p;
}

// Every input vertex starts at its own output vertex (the working mesh is a copy of the input).
void init_points(Remesher& rm) {
  const std::size_t n = rm.input.n_vertices();
  rm.track.assign(n, SurfacePoint());
  rm.next.assign(n, -1);
  rm.prev.assign(n, -1);
  for (auto v : rm.input.vertices()) {
    if (rm.input.is_isolated(v)) continue;
    const FaceHandle f = *rm.mesh.cvf_begin(v);
    const auto fv = face_vertices(rm.mesh, f);
    link_point(rm, v.idx(), f);
    rm.track[static_cast<std::size_t>(v.idx())].bary = {
        fv[0] == v ? 1.0 : 0.0, fv[1] == v ? 1.0 : 0.0, fv[2] == v ? 1.0 : 0.0};
  }
}

// Input vertex i starts at located[i] on the working mesh, or is not tracked (invalid face).
void init_points(Remesher& rm, const std::vector<SurfacePoint>& located) {
  const std::size_t n = located.size();
  rm.track.assign(n, SurfacePoint());
  rm.next.assign(n, -1);
  rm.prev.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (!located[i].face.is_valid()) continue;
    link_point(rm, static_cast<int>(i), located[i].face);
    rm.track[i].bary = located[i].bary;
  }
}

// Takes every input vertex off face f and appends it to `out`.
void take_points(Remesher& rm, FaceHandle f, std::vector<int>& out) {
  PointList& list = rm.points(f);
  for (int i = list.head; i >= 0; i = rm.next[static_cast<std::size_t>(i)]) out.push_back(i);
  list.head = -1;
}

// Puts every input vertex of `taken` on the closest of the faces around v, and clears `taken`.
void place_points_around(Remesher& rm, VertexHandle v, std::vector<int>& taken) {
  if (taken.empty()) return;
  FaceHandle faces[64];
  std::array<Vec3, 3> corners[64];
  int n = 0;
  for (auto f : rm.mesh.vf_range(v)) {
    if (n == 64) break;
    const auto fv = face_vertices(rm.mesh, f);
    faces[n] = f;
    corners[n] = {rm.mesh.point(fv[0]), rm.mesh.point(fv[1]), rm.mesh.point(fv[2])};
    ++n;
  }
  for (int i : taken) {
    const Vec3 q = rm.input.point(VertexHandle(i));
    double best = std::numeric_limits<double>::infinity();
    int best_k = 0;
    std::array<double, 3> bary{1.0, 0.0, 0.0};
    for (int k = 0; k < n; ++k) {
      const TriangleClosest c =
          closest_point_on_triangle(q, corners[k][0], corners[k][1], corners[k][2]);
      if (c.distance2 < best) {
        best = c.distance2;
        best_k = k;
        bary = c.bary;
      }
    }
    link_point(rm, i, faces[best_k]);
    rm.track[static_cast<std::size_t>(i)].bary = bary;
  }
  taken.clear();
}

// After garbage collection or renumbering the faces have new handles; the lists moved with
// them, so each input vertex takes its face from the list it is on.
void rebind_points(Remesher& rm) {
  for (auto f : rm.mesh.faces())
    for (int i = rm.points(f).head; i >= 0; i = rm.next[static_cast<std::size_t>(i)])
      rm.track[static_cast<std::size_t>(i)].face = f;
}

// Projects every input vertex onto its face again after vertices moved or faces changed: a
// visibility walk that steps across the edge its projection falls beyond until the projection
// lies in the face (almost always at once, or after one step). Where that stops at the
// boundary, or turns in a circle on a strongly curved part, a short closest-point walk takes
// over. Data-parallel, then the lists are updated in input order.
void reproject_points(Remesher& rm) {
  const std::size_t n = rm.track.size();
  std::vector<SurfacePoint> moved(n);
  parallel_for(n, rm.options.threads, [&](std::size_t i) {
    if (!rm.track[i].face.is_valid()) return;
    const Vec3 q = rm.input.point(VertexHandle(static_cast<int>(i)));
    FaceHandle f = rm.track[i].face;
    for (int step = 0; step < 8; ++step) {
      const HalfedgeHandle h0 = rm.mesh.halfedge_handle(f);
      const HalfedgeHandle h1 = rm.mesh.next_halfedge_handle(h0);
      const HalfedgeHandle h2 = rm.mesh.next_halfedge_handle(h1);
      std::array<double, 3> w{};
      if (!plane_barycentrics(q, rm.mesh.point(rm.mesh.from_vertex_handle(h0)),
                              rm.mesh.point(rm.mesh.to_vertex_handle(h0)),
                              rm.mesh.point(rm.mesh.to_vertex_handle(h1)), w))
        break;
      const int k = static_cast<int>(std::min_element(w.begin(), w.end()) - w.begin());
      if (w[static_cast<std::size_t>(k)] >= 0) {
        moved[i] = SurfacePoint{f, w};
        return;
      }
      // The edge opposite corner k: h1 for corner 0, h2 for corner 1, h0 for corner 2.
      const HalfedgeHandle exit = k == 0 ? h1 : k == 1 ? h2 : h0;
      const FaceHandle g = rm.mesh.face_handle(rm.mesh.opposite_halfedge_handle(exit));
      if (!g.is_valid()) break;
      f = g;
    }
    moved[i] = walk_to_closest(rm.mesh, q, f, 8);
  });
  for (std::size_t i = 0; i < n; ++i) {
    if (!rm.track[i].face.is_valid()) continue;
    if (moved[i].face != rm.track[i].face) {
      unlink_point(rm, static_cast<int>(i));
      link_point(rm, static_cast<int>(i), moved[i].face);
    }
    rm.track[i].bary = moved[i].bary;
  }
}

// The tracked locations made exact: each input vertex's closest point on the output, by a
// local walk from its tracked face. The report gets how far the walk had to go.
std::vector<SurfacePoint> closest_input_locations(const Remesher& rm, RemeshReport& report) {
  const std::size_t n = rm.track.size();
  std::vector<SurfacePoint> out(n);
  std::vector<double> excess(n, 0.0);
  parallel_for(n, rm.options.threads, [&](std::size_t i) {
    if (!rm.track[i].face.is_valid()) return;
    const Vec3 q = rm.input.point(VertexHandle(static_cast<int>(i)));
    out[i] = walk_to_closest(rm.mesh, q, rm.track[i].face, 256);
    excess[i] =
        (q - evaluate(rm.mesh, rm.track[i])).norm() - (q - evaluate(rm.mesh, out[i])).norm();
  });
  std::size_t located = 0, same = 0;
  double sum = 0, worst = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!rm.track[i].face.is_valid()) continue;
    ++located;
    same += out[i].face == rm.track[i].face ? 1 : 0;
    sum += excess[i];
    worst = std::max(worst, excess[i]);
  }
  const double count = static_cast<double>(std::max<std::size_t>(located, 1));
  report.tracked_same_face = located > 0 ? static_cast<double>(same) / count : 1.0;
  report.tracked_excess_mean = sum / count / rm.length;
  report.tracked_excess_max = worst / rm.length;
  return out;
}

} // namespace remora::remesh_detail
