// §4's fine-tuning: tangential moves that equalize the vertices' mixed Voronoi areas, so that the
// Laplacian of Eq. 1 becomes symmetric once every area is replaced by their mean (§5). Two
// updates: the paper's (towards the area-weighted centroid of the one-ring) and a damped
// Gauss-Newton step on the area residuals (the default); each iteration ends with Delaunay
// flips (flip.cpp).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Dense>

#include "remora/common/parallel.h"
#include "remora/geometry/laplacian.h"
#include "remora/geometry/measures.h"

#include "remora/remesh/remesher.h"

namespace remora::remesh_detail {

namespace {

// A vertex's one-ring as the fine-tuning reads it: ring[j] = to(h_j) for its outgoing
// halfedges h_j, face j = (v, ring[j], ring[third[j]]) when face[j] is valid.
struct Ring {
  static constexpr int kMax = 64;
  VertexHandle ring[kMax];
  FaceHandle face[kMax];
  int third[kMax];
  int k = 0;
  bool boundary_band = false; // keep the edges to the ring's boundary vertices in the band
  bool near_boundary = false; // a vertex of the ring is on the boundary
  Vec3 centroid;              // of the ring's vertices
  Vec3 normal;                // unit, from the ring's faces
};

// The cosine of the smallest angle of the triangle (a, b, c); 1 when degenerate.
double smallest_angle_cos(const Vec3& a, const Vec3& b, const Vec3& c) {
  double s = (b - a).sqrnorm(), e1 = (c - b).sqrnorm(), e2 = (a - c).sqrnorm();
  if (e1 < s) std::swap(s, e1);
  if (e2 < s) std::swap(s, e2);
  const double denominator = 2 * std::sqrt(e1 * e2);
  return denominator > 0 ? std::min(1.0, (e1 + e2 - s) / denominator) : 1.0;
}

// Is the cosine of the smallest angle of every face of `r`, with its centre at q, at most
// `limit` (in [0, 1])? No square root: the cosine opposite the shortest side s,
// (e1 + e2 - s) / (2 sqrt(e1 e2)) in squared lengths, has a non-negative numerator.
bool ring_within(const Remesher& rm, const Ring& r, const Vec3& q, double limit) {
  const double limit2 = 4 * limit * limit;
  for (int j = 0; j < r.k; ++j) {
    if (!r.face[j].is_valid()) continue;
    const Vec3& a = rm.mesh.point(r.ring[j]);
    const Vec3& b = rm.mesh.point(r.ring[r.third[j]]);
    const double x = (a - q).sqrnorm(), y = (b - q).sqrnorm(), z = (a - b).sqrnorm();
    double s = x, e1 = y, e2 = z;
    if (e1 < s) std::swap(s, e1);
    if (e2 < s) std::swap(s, e2);
    const double numerator = e1 + e2 - s;
    if (numerator * numerator > limit2 * e1 * e2) return false;
  }
  return true;
}

// The sliver guard (equalize_guard_deg): places v at `goal`, or halfway back, twice at most,
// so that no face of its ring falls below the guard angle, nor below the ring's smallest angle
// where that is smaller already; else v stays. Tested after the placement on the input: on a
// part about four edges around, the projection, not the tangential step, is what squeezes an
// edge. Next to the boundary the same holds for
// the length of each edge to a boundary vertex: at most 4/3 l, or its length now if longer
// (equalize_boundary pulls these vertices inwards, to grow the boundary cells).
Placed guarded_place(Remesher& rm, VertexHandle v, Vec3 goal, const Ring& r,
                     const std::vector<std::array<double, 4>>& face_parts, Vec3& out) {
  const Vec3 p = rm.mesh.point(v);
  // The ring's smallest angle now (face_parts[f][3], from the iteration's face loop), how far v
  // may move before any angle of its ring can reach the limit: moving v by δ turns each angle
  // of a face (v, a, b) by at most 2|δ| / (r − |δ|), r the shorter of |va| and |vb|.
  double worst = -1, shortest2 = std::numeric_limits<double>::max();
  for (int j = 0; j < r.k; ++j) {
    shortest2 = std::min(shortest2, (rm.mesh.point(r.ring[j]) - p).sqrnorm());
    if (r.face[j].is_valid())
      worst = std::max(worst, face_parts[static_cast<std::size_t>(r.face[j].idx())][3]);
  }
  const double limit = std::max(worst, rm.cos_guard);
  const double margin = std::acos(std::clamp(worst, -1.0, 1.0)) - rm.guard_rad;
  const double safe = margin > 0 ? margin * std::sqrt(shortest2) / (2 + margin) : 0.0;
  // Next to the boundary: every edge of the ring stays in the band [4/5 l, 4/3 l], or no
  // further out of it than it is now.
  double reach2 = rm.hi2, short2 = rm.lo2;
  if (r.boundary_band)
    for (int j = 0; j < r.k; ++j) {
      const double d2 = (rm.mesh.point(r.ring[j]) - p).sqrnorm();
      reach2 = std::max(reach2, d2);
      short2 = std::min(short2, d2);
    }
  auto edges_within = [&](const Vec3& q) {
    if (!r.boundary_band) return true;
    for (int j = 0; j < r.k; ++j) {
      const double d2 = (rm.mesh.point(r.ring[j]) - q).sqrnorm();
      if (d2 > reach2 || d2 < short2) return false;
    }
    return true;
  };
  // A goal that would stretch an edge to a boundary vertex beyond the band is first pulled
  // back into it: alternating projections onto the balls of radius √reach2 around the ring's
  // boundary vertices, whose intersection is convex and holds p. The vertex then slides along
  // the band's limit, centring itself between its two boundary neighbours, instead of stopping
  // at the first edge that reaches it (halving the step, below).
  if (r.boundary_band) {
    const double reach = std::sqrt(reach2) * (1 - 1e-9);
    for (int pass = 0; pass < 4; ++pass)
      for (int j = 0; j < r.k; ++j) {
        if (!rm.mesh.is_boundary(r.ring[j])) continue;
        const Vec3& a = rm.mesh.point(r.ring[j]);
        const double d = (goal - a).norm();
        if (d > reach) goal = a + (goal - a) * (reach / d);
      }
  }
  const SurfacePoint before = rm.loc(v);
  for (int tries = 0; tries < 3; ++tries, goal = (p + goal) * 0.5) {
    out = relocate(rm, v, goal, v);
    if (!edges_within(out)) continue;
    if ((out - p).sqrnorm() <= safe * safe || ring_within(rm, r, out, limit))
      return tries == 0 ? Placed::Moved : Placed::Shortened;
  }
  rm.loc(v) = before;
  return Placed::Dropped;
}

// The ODT point of v's closed one-ring `r` (v at p): the circumcentres of its faces weighted
// by their areas, the vertex update of the optimal Delaunay triangulation energy (Chen & Xu
// 2004; Alliez et al. 2005). A face's weight × its circumcentre's offset from p is bounded
// (area × circumradius = the product of its sides / 4), so slivers do not throw it far;
// `fallback` (the centroid) when the faces have no area. `parts` holds each face's mixed-area
// parts at the current positions (Areas::face_parts): they sum to its area.
Vec3 odt_point(const Remesher& rm, const Vec3& p, const Ring& r, const Vec3& fallback,
               const std::vector<std::array<double, 4>>& parts) {
  Vec3 sum(0, 0, 0);
  double weight = 0;
  for (int j = 0; j < r.k; ++j) {
    if (!r.face[j].is_valid()) continue;
    const auto& part = parts[static_cast<std::size_t>(r.face[j].idx())];
    const double area = part[0] + part[1] + part[2];
    if (!(area > 0)) continue;
    const Vec3 a = rm.mesh.point(r.ring[j]) - p, b = rm.mesh.point(r.ring[r.third[j]]) - p;
    // Circumcentre offset: (|a|² b − |b|² a) × (a × b) / (2 |a × b|²), |a × b| = 2 area;
    // times the area.
    sum += OpenMesh::cross(b * a.sqrnorm() - a * b.sqrnorm(), OpenMesh::cross(a, b)) / (8 * area);
    weight += area;
  }
  return weight > 0 ? p + sum / weight : fallback;
}

// §4: p_i += λ (I − n nᵀ)(g_i − p_i), g_i the area-weighted centroid of the one-ring.
void equalize_areas_gravity(Remesher& rm) {
  const Eigen::VectorXd area = vertex_areas_mixed(rm.mesh);
  move_vertices(rm, [&](VertexHandle v, Vec3& goal) {
    if (rm.kind(v) == Kind::Curve) return false; // curve vertices keep their spacing
    Vec3 g(0, 0, 0);
    double w = 0;
    for (auto u : rm.mesh.vv_range(v)) {
      g += rm.mesh.point(u) * area[u.idx()];
      w += area[u.idx()];
    }
    if (!(w > 0)) return false;
    const Vec3 p = rm.mesh.point(v);
    Vec3 d = g / w - p;
    const Vec3 n = vertex_normal(rm, v);
    d -= n * OpenMesh::dot(n, d);
    goal = p + d * rm.options.lambda;
    return true;
  });
}

// The mixed-area parts of every face at the current positions (face_vertices order) with, for
// the guard, the cosine of its smallest angle (one cache line's worth for both readers); the
// vertex areas they sum to, and the target: the mean area of the interior vertices.
struct Areas {
  std::vector<std::array<double, 4>> face_parts;
  std::vector<double> vertex;
  double target = 0;
};

// Fills `areas`; false when the mesh has no interior vertex. A patch's locked vertices count
// their area outside it too, and a patch aims at the whole mesh's mean area (patch.cpp).
bool measure_areas(const Remesher& rm, bool guard, Areas& areas) {
  const std::size_t nf = rm.mesh.n_faces();
  std::vector<std::array<double, 4>>& face_parts = areas.face_parts;
  face_parts.resize(nf);
  parallel_for(nf, rm.options.threads, [&](std::size_t i) {
    const FaceHandle f(static_cast<int>(i));
    if (rm.mesh.status(f).deleted()) return;
    const auto fv = face_vertices(rm.mesh, f);
    const Vec3 &a = rm.mesh.point(fv[0]), &b = rm.mesh.point(fv[1]), &c = rm.mesh.point(fv[2]);
    const auto parts = triangle_mixed_areas(a, b, c);
    face_parts[i] = {parts[0], parts[1], parts[2], guard ? smallest_angle_cos(a, b, c) : 1.0};
  });
  std::vector<double>& area = areas.vertex;
  area.assign(rm.mesh.n_vertices(), 0.0);
  for (std::size_t i = 0; i < nf; ++i) {
    const FaceHandle f(static_cast<int>(i));
    if (rm.mesh.status(f).deleted()) continue;
    const auto fv = face_vertices(rm.mesh, f);
    for (int c = 0; c < 3; ++c) area[static_cast<std::size_t>(fv[c].idx())] += face_parts[i][c];
  }
  if (!rm.outside_area.empty())
    for (auto v : rm.mesh.vertices())
      if (rm.origin(v) >= 0)
        area[static_cast<std::size_t>(v.idx())] +=
            rm.outside_area[static_cast<std::size_t>(rm.origin(v))];
  if (rm.target_area > 0) {
    areas.target = rm.target_area;
    return true;
  }
  double sum = 0;
  std::size_t count = 0;
  for (auto v : rm.mesh.vertices())
    if (!rm.mesh.is_boundary(v) && !rm.mesh.is_isolated(v)) {
      sum += area[static_cast<std::size_t>(v.idx())];
      ++count;
    }
  if (count == 0) return false;
  areas.target = sum / static_cast<double>(count);
  return true;
}

// Reads v's one-ring (at most Ring::kMax, at least 3 vertices) with its centroid and unit
// normal; false where there is none.
bool read_ring(const Remesher& rm, VertexHandle v, Ring& r) {
  const Vec3 p = rm.mesh.point(v);
  int& k = r.k;
  k = 0;
  for (auto h : rm.mesh.voh_range(v)) {
    if (k == Ring::kMax) return false;
    r.ring[k] = rm.mesh.to_vertex_handle(h);
    r.face[k] = rm.mesh.face_handle(h);
    ++k;
  }
  if (k < 3) return false;
  // Next to the boundary (which does not move here) the vertex either takes the Newton step
  // on residuals that include the boundary vertices' (equalize_boundary; its placement then
  // keeps the edges to them in the band), or plain tangential smoothing.
  r.near_boundary = false;
  for (int j = 0; j < k; ++j) r.near_boundary |= rm.mesh.is_boundary(r.ring[j]);
  r.boundary_band = r.near_boundary && rm.options.equalize_boundary;
  // The circulator turns one way: the third corner of face j is ring[j + 1] or ring[j - 1].
  const HalfedgeHandle h0 = *rm.mesh.cvoh_begin(v);
  const VertexHandle c0 = rm.mesh.to_vertex_handle(rm.mesh.next_halfedge_handle(h0));
  const int turn = c0 == r.ring[1] ? 1 : k - 1;
  Vec3 centroid(0, 0, 0), normal(0, 0, 0);
  for (int j = 0; j < k; ++j) {
    r.third[j] = (j + turn) % k;
    centroid += rm.mesh.point(r.ring[j]);
    if (r.face[j].is_valid())
      normal +=
          OpenMesh::cross(rm.mesh.point(r.ring[j]) - p, rm.mesh.point(r.ring[r.third[j]]) - p);
  }
  centroid /= k;
  const double normal_length = normal.norm();
  if (!(normal_length > 0)) return false;
  r.centroid = centroid;
  r.normal = normal / normal_length;
  return true;
}

// ∂A_j/∂p along the tangents t1 and t2 (d1, d2), by forward differences of step eps, for v
// (index r.k) and each ring vertex j: only the parts of the faces around v depend on p.
void area_jacobian(const Remesher& rm, VertexHandle v, const Ring& r, const Areas& areas,
                   const Vec3& t1, const Vec3& t2, double eps, double* d1, double* d2) {
  constexpr int kMax = Ring::kMax;
  const int k = r.k;
  const Vec3 p = rm.mesh.point(v);
  double base[kMax + 1] = {}, moved[kMax + 1];
  for (int j = 0; j < k; ++j) {
    if (!r.face[j].is_valid()) continue;
    const auto fv = face_vertices(rm.mesh, r.face[j]);
    const auto& part = areas.face_parts[static_cast<std::size_t>(r.face[j].idx())];
    for (int c = 0; c < 3; ++c)
      base[fv[c] == v ? k : fv[c] == r.ring[j] ? j : r.third[j]] += part[c];
  }
  auto parts = [&](const Vec3& q, double* out) {
    for (int j = 0; j <= k; ++j) out[j] = 0;
    for (int j = 0; j < k; ++j) {
      if (!r.face[j].is_valid()) continue;
      const auto m =
          triangle_mixed_areas(q, rm.mesh.point(r.ring[j]), rm.mesh.point(r.ring[r.third[j]]));
      out[k] += m[0];
      out[j] += m[1];
      out[r.third[j]] += m[2];
    }
  };
  for (int axis = 0; axis < 2; ++axis) {
    const Vec3 t = axis == 0 ? t1 : t2;
    double* d = axis == 0 ? d1 : d2;
    parts(p + t * eps, moved);
    for (int j = 0; j <= k; ++j) d[j] = (moved[j] - base[j]) / eps;
  }
}

// What every vertex's Newton step reads in one iteration.
struct NewtonStep {
  const Remesher& rm;
  const Areas& areas;
  double eps;    // forward-difference step
  double beta;   // momentum
  bool momentum; // previous_points holds the last iteration's positions
};

// The Newton goal of interior vertex v (its ring in `r`); false where v does not move.
bool newton_goal(const NewtonStep& s, VertexHandle v, Vec3& goal, Ring& r) {
  const Remesher& rm = s.rm;
  if (rm.kind(v) != Kind::Interior || !read_ring(rm, v, r)) return false;
  const Vec3 p = rm.mesh.point(v);
  const Vec3& n = r.normal;
  if (r.near_boundary && !rm.options.equalize_boundary) {
    Vec3 u = r.centroid - p;
    u -= n * OpenMesh::dot(n, u);
    goal = p + u * rm.options.lambda;
    return true;
  }
  Vec3 t1 = OpenMesh::cross(n, std::abs(n[0]) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0));
  t1.normalize();
  const Vec3 t2 = OpenMesh::cross(n, t1);
  double d1[Ring::kMax + 1], d2[Ring::kMax + 1];
  area_jacobian(rm, v, r, s.areas, t1, t2, s.eps, d1, d2);
  // Residuals: v itself (index k) and the ring's interior vertices (on feature lines too), with
  // equalize_boundary its boundary vertices too, corners included (their cells are the
  // smallest).
  Eigen::Matrix2d jtj = Eigen::Matrix2d::Zero();
  Eigen::Vector2d jtr = Eigen::Vector2d::Zero();
  for (int j = 0; j <= r.k; ++j) {
    const VertexHandle w = j == r.k ? v : r.ring[j];
    if (rm.mesh.is_boundary(w) && !rm.options.equalize_boundary) continue;
    const Eigen::Vector2d row(d1[j], d2[j]);
    jtj += row * row.transpose();
    jtr += row * (s.areas.vertex[static_cast<std::size_t>(w.idx())] - s.areas.target);
  }
  const Vec3 off = p - (rm.options.smoothing_target == SmoothingTarget::Odt
                            ? odt_point(rm, p, r, r.centroid, s.areas.face_parts)
                            : r.centroid);
  const double mu = rm.options.equalize_smoothing * 0.5 * jtj.trace();
  jtj(0, 0) += mu;
  jtj(1, 1) += mu;
  jtr += mu * Eigen::Vector2d(OpenMesh::dot(off, t1), OpenMesh::dot(off, t2));
  if (!(jtj.determinant() > 0)) return false;
  const Eigen::Vector2d step = -jtj.inverse() * jtr * rm.options.lambda;
  Vec3 d = t1 * step[0] + t2 * step[1];
  if (s.momentum) { // β × the last move, in today's tangent plane
    Vec3 last = p - rm.previous_points[static_cast<std::size_t>(v.idx())];
    last -= n * OpenMesh::dot(n, last);
    d += last * s.beta;
  }
  // Never move by more than a fraction of the target length in one iteration.
  const double cap = 0.2 * rm.length;
  if (d.norm() > cap) d *= cap / d.norm();
  goal = p + d;
  return true;
}

// A regularized Gauss-Newton step per vertex on the residuals r_j = A_j − Ā (mixed areas) of
// the interior vertices of its closed one-ring, in the tangent plane:
//   δ_i = −λ (J_iᵀ J_i + μ I)⁻¹ (J_iᵀ r + μ (p_i − c_i)),
// J_i = ∂A_j/∂p_i by forward differences of the incident faces' mixed-area parts, c_i the
// one-ring's ODT point or centroid (smoothing_target); the μ term is the tangential smoothing
// of the cycles, which keeps triangles well shaped while the areas are pulled to their mean.
// Unlike the gravity update, whose fixed point is not an equal-area mesh, r = 0 is (up to μ)
// this iteration's fixed point. Jacobi-style (all vertices at once), hence the damping λ.
void equalize_areas_newton(Remesher& rm) {
  const bool guard = rm.options.equalize_guard_deg > 0;
  Areas areas;
  if (!measure_areas(rm, guard, areas)) return;
  // Heavy-ball momentum (equalize_momentum): the positions at the start of the previous
  // iteration give each vertex's last move. Vertices are neither added nor removed between
  // iterations (the Delaunay flips only reconnect them).
  const double beta = rm.options.equalize_momentum;
  const NewtonStep step{rm, areas, 1e-4 * rm.length, beta,
                        beta > 0 && rm.previous_points.size() == rm.mesh.n_vertices()};
  std::vector<Vec3> current;
  if (beta > 0) { // no copy when the momentum is off
    current.resize(rm.mesh.n_vertices());
    for (auto v : rm.mesh.vertices()) current[static_cast<std::size_t>(v.idx())] = rm.mesh.point(v);
  }
  move_vertices_placing(rm, [&](VertexHandle v, Vec3& out) {
    Ring r;
    Vec3 goal;
    if (!newton_goal(step, v, goal, r)) return Placed::No;
    if (!guard && !r.boundary_band) {
      out = relocate(rm, v, goal, v);
      return Placed::Moved;
    }
    return guarded_place(rm, v, goal, r, areas.face_parts, out);
  });
  rm.previous_points = std::move(current);
}

} // namespace

// One fine-tuning iteration; returns the number of Delaunay flips it made.
std::size_t equalize_areas(Remesher& rm) {
  if (rm.options.equalization == Equalization::Gravity)
    equalize_areas_gravity(rm);
  else
    equalize_areas_newton(rm);
  return rm.options.equalize_flips ? delaunay_flips(rm) : 0;
}

} // namespace remora::remesh_detail
