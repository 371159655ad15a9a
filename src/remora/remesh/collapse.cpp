// §4 step 2 of a cycle: collapse every edge shorter than 4/5 l into its midpoint, and the rules
// every collapse obeys (the cycles', the boundary spacing's and the repairs').

#include <algorithm>
#include <vector>

#include "remora/geometry/measures.h"

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

namespace {

// Repairs come after the last smoothing and may leave longer edges than the cycles' collapses.
bool is_repair(Collapse purpose) {
  return purpose == Collapse::Repair || purpose == Collapse::Flat ||
         purpose == Collapse::Degenerate;
}

// Does collapsing h (its source into its target) keep the mesh a manifold? The link condition
// (the only common neighbours of the endpoints are the tips of the edge's faces), no face with
// two boundary edges, no interior edge between two boundary vertices, and no collapse of a
// closed tetrahedron. OpenMesh's is_collapse_ok tests the same with vertex tags; this one
// keeps the first ring in a small array, which is faster.
bool collapse_keeps_manifold(const Remesher& rm, HalfedgeHandle h) {
  const HalfedgeHandle o = rm.mesh.opposite_halfedge_handle(h);
  const VertexHandle a = rm.mesh.from_vertex_handle(h), b = rm.mesh.to_vertex_handle(h);
  if (rm.mesh.status(a).deleted() || rm.mesh.status(b).deleted()) return false;
  VertexHandle tips[2];
  int n_tips = 0;
  for (HalfedgeHandle side : {h, o}) {
    if (rm.mesh.is_boundary(side)) continue;
    const HalfedgeHandle n1 = rm.mesh.next_halfedge_handle(side);
    const HalfedgeHandle n2 = rm.mesh.next_halfedge_handle(n1);
    if (rm.mesh.is_boundary(rm.mesh.opposite_halfedge_handle(n1)) &&
        rm.mesh.is_boundary(rm.mesh.opposite_halfedge_handle(n2)))
      return false;
    tips[n_tips++] = rm.mesh.to_vertex_handle(n1);
  }
  if (n_tips == 2 && tips[0] == tips[1]) return false;
  if (n_tips == 2 && rm.mesh.is_boundary(a) && rm.mesh.is_boundary(b)) return false;
  constexpr int kMax = 64;
  VertexHandle ring[kMax];
  int k = 0;
  for (auto w : rm.mesh.vv_range(a)) {
    if (k == kMax) return false;
    ring[k++] = w;
  }
  int valence_b = 0;
  for (auto w : rm.mesh.vv_range(b)) {
    ++valence_b;
    bool tip = false;
    for (int t = 0; t < n_tips; ++t) tip |= w == tips[t];
    if (tip) continue;
    for (int i = 0; i < k; ++i)
      if (ring[i] == w) return false;
  }
  // A tetrahedron would fold onto one double-sided triangle. Where b is on the boundary, the
  // face opposite a is missing: the three faces around a are an island (or the tip of a
  // strip) and become one triangle (on a thinned mesh: an interior vertex of valence 3 pressed
  // onto the line of two boundary vertices, a flat face nothing else mends).
  return !(n_tips == 2 && k == 3 && valence_b == 3 && !rm.mesh.is_boundary(b));
}

// Would merging a and b at p leave every edge of the survivor within √max_length2 (4/3 l in
// the cycles)? Where b stays where it is (p is b's point), only a's edges are new: b's own
// may be longer already (a corner of a coarse, jagged boundary) without barring the collapse.
bool neighbours_within(const Remesher& rm, VertexHandle a, VertexHandle b, const Vec3& p,
                       double max_length2) {
  const bool b_stays = p == rm.mesh.point(b);
  for (VertexHandle v : {a, b}) {
    if (v == b && b_stays) continue;
    for (auto w : rm.mesh.vv_range(v))
      if (w != a && w != b && (rm.mesh.point(w) - p).sqrnorm() > max_length2) return false;
  }
  return true;
}

// Would moving `keep` to `p` (after removing `gone`) keep every remaining face's orientation
// (within 60 degrees) and a non-trivial area?
bool collapse_keeps_orientation(const Remesher& rm, HalfedgeHandle h, const Vec3& p) {
  const VertexHandle gone = rm.mesh.from_vertex_handle(h), keep = rm.mesh.to_vertex_handle(h);
  const FaceHandle fl = rm.mesh.face_handle(h),
                   fr = rm.mesh.face_handle(rm.mesh.opposite_halfedge_handle(h));
  for (VertexHandle v : {gone, keep}) {
    for (auto f : rm.mesh.vf_range(v)) {
      if (f == fl || f == fr) continue;
      auto fv = face_vertices(rm.mesh, f);
      Vec3 q[3];
      for (int k = 0; k < 3; ++k) q[k] = rm.mesh.point(fv[k]);
      const Vec3 n_before = OpenMesh::cross(q[1] - q[0], q[2] - q[0]);
      for (int k = 0; k < 3; ++k)
        if (fv[k] == gone || fv[k] == keep) q[k] = p;
      const Vec3 n_after = OpenMesh::cross(q[1] - q[0], q[2] - q[0]);
      // The new face must keep its orientation (within 60 degrees) and a non-trivial area.
      const double before = n_before.norm(), after = n_after.norm();
      if (after <= 1e-12 * rm.hi2) return false;
      if (before > 0 && OpenMesh::dot(n_before, n_after) < 0.5 * before * after) return false;
    }
  }
  return true;
}

// Is the smallest angle of the faces around h's endpoints larger after collapsing h into p
// than before?
bool collapse_raises_min_angle(const Remesher& rm, HalfedgeHandle h, const Vec3& p) {
  const VertexHandle gone = rm.mesh.from_vertex_handle(h), keep = rm.mesh.to_vertex_handle(h);
  const FaceHandle fl = rm.mesh.face_handle(h),
                   fr = rm.mesh.face_handle(rm.mesh.opposite_halfedge_handle(h));
  double before = M_PI, after = M_PI;
  auto smallest = [](const Vec3& a, const Vec3& b, const Vec3& c) {
    const auto t = triangle_angles(a, b, c);
    return std::min({t[0], t[1], t[2]});
  };
  for (VertexHandle v : {gone, keep})
    for (auto f : rm.mesh.vf_range(v)) {
      const auto fv = face_vertices(rm.mesh, f);
      Vec3 q[3];
      for (int k = 0; k < 3; ++k) q[k] = rm.mesh.point(fv[k]);
      before = std::min(before, smallest(q[0], q[1], q[2]));
      if (f == fl || f == fr) continue;
      for (int k = 0; k < 3; ++k)
        if (fv[k] == gone || fv[k] == keep) q[k] = p;
      after = std::min(after, smallest(q[0], q[1], q[2]));
    }
  return after > before;
}

// The rules of try_collapse() beyond the kinds, for collapsing h (a into b) with the survivor
// at `target`: the manifold rule, and unless a and b are at one point the geometric ones.
// Where the first choice fails, a collapse the other way (and for a repair into either
// endpoint) may be taken instead, which updates h, a, b, target and midpoint.
bool collapse_allowed(const Remesher& rm, Collapse purpose, HalfedgeHandle& h, VertexHandle& a,
                      VertexHandle& b, Vec3& target, bool& midpoint) {
  if ((rm.mesh.point(a) - rm.mesh.point(b)).sqrnorm() <= 1e-12 * rm.hi2) {
    // Two vertices at one point (the smoothing, moving all vertices at once, placed both on
    // the same input vertex or crack tip): merging them changes no remaining face, it only
    // removes the two flat ones; so only the kinds and the manifold rule hold here. With the
    // geometric rules a cluster of such vertices never goes: each collapse leaves a flat face.
    bool ok = collapse_keeps_manifold(rm, h);
    if (!ok && midpoint) {
      h = rm.mesh.opposite_halfedge_handle(h);
      std::swap(a, b);
      ok = collapse_keeps_manifold(rm, h);
    }
    target = rm.mesh.point(b);
    midpoint = false;
    return ok;
  }
  // A repair may leave an edge up to √1.4 × 4/3 l ≈ 1.58 l long (one long edge costs the
  // Laplacian less than a sliver), and must raise the smallest angle around it. The length
  // test comes first: it is the cheapest and the one that fails most (two thirds of the short
  // edges of a cycle cannot go without leaving an edge longer than 4/3 l).
  const bool repair = is_repair(purpose);
  const double reach2 = purpose == Collapse::Short                                 ? rm.hi2
                        : purpose == Collapse::Repair || purpose == Collapse::Flat ? 1.4 * rm.hi2
                                                                                   : 4 * rm.hi2;
  bool ok = neighbours_within(rm, a, b, target, reach2);
  if (ok && !collapse_keeps_manifold(rm, h)) {
    if (!midpoint) return false;
    h = rm.mesh.opposite_halfedge_handle(h);
    std::swap(a, b);
    ok = collapse_keeps_manifold(rm, h);
    if (!ok && purpose != Collapse::Repair) return false;
  }
  ok = ok && collapse_keeps_orientation(rm, h, target) &&
       (!repair || collapse_raises_min_angle(rm, h, target));
  if (!ok) {
    // A repair of an interior edge may also collapse it into either endpoint, which stays
    // where it is, on the input: on a sharp crease the midpoint can be the
    // only position that lowers an angle around it.
    if (!midpoint || purpose != Collapse::Repair) return false;
    midpoint = false;
    for (int side = 0; side < 2 && !ok; ++side) {
      h = rm.mesh.opposite_halfedge_handle(h); // remove the other endpoint
      std::swap(a, b);
      target = rm.mesh.point(b);
      ok = neighbours_within(rm, a, b, target, reach2) && collapse_keeps_manifold(rm, h) &&
           collapse_keeps_orientation(rm, h, target) && collapse_raises_min_angle(rm, h, target);
    }
    if (!ok) return false;
  }
  return true;
}

} // namespace

// Collapses every edge shorter than 4/5 l that the rules allow (try_collapse), sequentially.
std::size_t collapse_short_edges(Remesher& rm) {
  std::size_t count = 0;
  const std::size_t n = rm.mesh.n_edges();
  for (std::size_t i = 0; i < n; ++i) {
    const EdgeHandle e(static_cast<int>(i));
    if (rm.mesh.status(e).deleted()) continue;
    if (rm.mesh.calc_edge_sqr_length(e) >= rm.lo2) continue;
    count += try_collapse(rm, e, Collapse::Short) ? 1 : 0;
  }
  return count;
}

// Collapses e if the rules allow it: corners never go, an interior vertex goes onto a curve
// vertex (which stays put), two curve vertices merge along a curve edge only (a Flat repair
// excepted: it merges them into the corner if one is, else into either), and the
// survivor's edges stay short, the mesh stays manifold and no face turns over (two vertices at
// one point need only the kinds and the manifold rule). Otherwise the survivor moves to the
// midpoint: in the cycles it stays there until the smoothing projects it (split.cpp says why);
// a repair, which comes after the last smoothing, projects it at once.
bool try_collapse(Remesher& rm, EdgeHandle e, Collapse purpose) {
  HalfedgeHandle h = rm.mesh.halfedge_handle(e, 0);
  VertexHandle a = rm.mesh.from_vertex_handle(h), b = rm.mesh.to_vertex_handle(h);
  const Kind ka = rm.kind(a), kb = rm.kind(b);
  // Which endpoint goes, and where the survivor ends up.
  bool midpoint = true;
  if (ka == Kind::Corner && kb == Kind::Corner) return false;
  if (ka != Kind::Interior && kb != Kind::Interior && !rm.on_curve(e)) {
    if (purpose != Collapse::Flat) return false;
    if (kb != Kind::Corner) { // keep the corner if one is
      h = rm.mesh.opposite_halfedge_handle(h);
      std::swap(a, b);
    }
    midpoint = false;
  } else if (ka == Kind::Corner || (ka == Kind::Curve && kb == Kind::Interior)) {
    h = rm.mesh.opposite_halfedge_handle(h); // remove b, keep a where it is
    std::swap(a, b);
    midpoint = false;
  } else if (kb == Kind::Corner || (kb == Kind::Curve && ka == Kind::Interior)) {
    midpoint = false; // remove a, keep b where it is
  }
  Vec3 target = midpoint ? (rm.mesh.point(a) + rm.mesh.point(b)) * 0.5 : rm.mesh.point(b);
  if (!collapse_allowed(rm, purpose, h, a, b, target, midpoint)) return false;
  rm.live_faces -= rm.mesh.is_boundary(e) ? 1 : 2;
  // The two faces of the edge go: their input vertices move to the survivor's faces. In each,
  // the edges from a and b to the tip merge; the merged edge is a feature if either was.
  std::vector<int> displaced; // the input vertices on the two faces that go
  VertexHandle tips[2];
  char merged[2] = {0, 0};
  int n_tips = 0;
  for (auto side : {h, rm.mesh.opposite_halfedge_handle(h)}) {
    if (rm.mesh.is_boundary(side)) continue;
    take_points(rm, rm.mesh.face_handle(side), displaced);
    if (rm.feature_count == 0) continue;
    const HalfedgeHandle n1 = rm.mesh.next_halfedge_handle(side);
    tips[n_tips] = rm.mesh.to_vertex_handle(n1);
    merged[n_tips++] = rm.feature(rm.mesh.edge_handle(n1)) ||
                       rm.feature(rm.mesh.edge_handle(rm.mesh.next_halfedge_handle(n1)));
  }
  rm.mesh.collapse(h);
  for (int t = 0; t < n_tips; ++t) {
    const HalfedgeHandle kept = rm.mesh.find_halfedge(b, tips[t]);
    if (kept.is_valid()) rm.feature(rm.mesh.edge_handle(kept)) = merged[t];
  }
  // A repair comes after the last smoothing: its survivor is placed on the input at once.
  if (midpoint) rm.mesh.set_point(b, is_repair(purpose) ? relocate(rm, b, target, b) : target);
  place_points_around(rm, b, displaced);
  return true;
}

} // namespace remora::remesh_detail
