#include "remora/multires/phong.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "remora/common/error.h"
#include "remora/common/parallel.h"
#include "remora/multires/phong_decode.h"

namespace remora {
namespace {

using V3 = Eigen::Vector3d;

constexpr double kInside = 1e-9; // barycentric tolerance of "inside the face"
// Beyond this the base point is not kept outside its face (a fallback instead).
constexpr double kExtrapolate = 0.1;

struct Corners {
  V3 x[3];
  V3 n[3];
};

template <class Points>
Corners corners(const TriangleTopology& t, const Points& positions, const Points& normals, int f) {
  Corners c;
  for (int k = 0; k < 3; ++k) {
    const int v = t.faces[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)];
    c.x[k] = positions.row(v).transpose();
    c.n[k] = normals.row(v).transpose();
  }
  return c;
}

bool face_frame(const Corners& c, V3& t1, V3& t2, V3& nf) {
  return phong_detail::face_frame(c.x, t1, t2, nf);
}

V3 decode(const Corners& c, const PhongDetail& d) {
  return phong_detail::phong_point(c.x, c.n, d.base.bary, d.offset,
                                   d.residual ? &d.frame : nullptr);
}

struct FaceSolution {
  bool ok = false;
  double u = 0.0, v = 0.0, offset = 0.0;
  double min_bary() const { return std::min({1.0 - u - v, u, v}); }
  int most_negative() const {
    const double a[3] = {1.0 - u - v, u, v};
    return a[0] <= a[1] && a[0] <= a[2] ? 0 : (a[1] <= a[2] ? 1 : 2);
  }
};

/// Newton's method on F(u, v, λ) = x(u, v) + λ ñ(u, v) − p = 0 with ñ the linearly interpolated
/// (unnormalized) normal; the offset along the unit normal is then λ |ñ|.
FaceSolution solve_in_face(const Corners& c, const V3& p) {
  FaceSolution s;
  const V3 e1 = c.x[1] - c.x[0], e2 = c.x[2] - c.x[0];
  const V3 f1 = c.n[1] - c.n[0], f2 = c.n[2] - c.n[0];
  const double scale = std::max({e1.norm(), e2.norm(), (c.x[2] - c.x[1]).norm()});
  if (!(scale > 0.0)) return s;
  // Start: the orthogonal projection onto the face's plane.
  const V3 d = p - c.x[0];
  const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
  const double det = g11 * g22 - g12 * g12;
  if (!(det > 1e-24 * g11 * g22)) return s;
  double u = (g22 * d.dot(e1) - g12 * d.dot(e2)) / det;
  double v = (g11 * d.dot(e2) - g12 * d.dot(e1)) / det;
  const V3 nf = e1.cross(e2).normalized();
  V3 n0 = c.n[0] + u * f1 + v * f2;
  double lambda = (d - u * e1 - v * e2).dot(nf) / std::max(n0.dot(nf), 1e-3);
  const double tol = 1e-13 * (scale + std::abs(lambda));
  for (int it = 0; it < 30; ++it) {
    const V3 n = c.n[0] + u * f1 + v * f2;
    const V3 residual = c.x[0] + u * e1 + v * e2 + lambda * n - p;
    if (residual.norm() <= tol) {
      const double len = n.norm();
      if (!(len > 1e-6)) return s; // opposite normals: no direction to offset along
      s.ok = true;
      s.u = u;
      s.v = v;
      s.offset = lambda * len;
      return s;
    }
    // The Jacobian's columns, and its solve by Cramer's rule (3 × 3, guarded against the
    // focal surface where it becomes singular).
    const V3 c0 = e1 + lambda * f1, c1 = e2 + lambda * f2, c2 = n;
    const V3 c12 = c1.cross(c2);
    const double jdet = c0.dot(c12);
    if (!(std::abs(jdet) > 1e-12 * c0.norm() * c1.norm() * c2.norm()))
      return s; // on the focal surface
    const V3 b = -residual;
    const V3 step(b.dot(c12) / jdet, c0.dot(b.cross(c2)) / jdet, c0.dot(c1.cross(b)) / jdet);
    u += step[0];
    v += step[1];
    lambda += step[2];
    if (!std::isfinite(u) || !std::isfinite(v) || !std::isfinite(lambda) || std::abs(u) > 1e3 ||
        std::abs(v) > 1e3)
      return s;
  }
  return s;
}

/// Store what decode() does not reproduce as a residual in the face frame.
void settle_residual(const Corners& c, const V3& p, PhongDetail& d) {
  d.residual = false;
  const V3 q = decode(c, d);
  const V3 r = p - q;
  const double scale = (c.x[1] - c.x[0]).norm() + (c.x[2] - c.x[0]).norm() + std::abs(d.offset);
  // Newton's own rounding (up to ~1e-12 of the scale for offsets of several edge lengths) is not
  // worth a residual.
  if (r.norm() <= 1e-10 * scale) return;
  d.residual = true;
  V3 t1, t2, nf;
  if (face_frame(c, t1, t2, nf))
    d.frame = {r.dot(t1), r.dot(t2), r.dot(nf)};
  else
    d.frame = {r[0], r[1], r[2]};
}

struct Outcome {
  PhongDetail detail;
  std::size_t steps = 0;
  bool extrapolated = false, fallback = false;
};

/// The face reached from `start` by walking towards p's orthogonal projection: across the edge of
/// the most negative barycentric coordinate (on the face's plane) until none is negative, the
/// boundary or the face just left is met, or `max_steps` moves were made. Cheap (no Newton), it
/// brings the Phong search close to its face when the base has moved far from where the start
/// face was found. `steps` counts the moves.
int approach(const TriangleTopology& t, const Eigen::MatrixXd& positions, const V3& p, int start,
             int max_steps, std::size_t& steps) {
  int face = start, previous = -1;
  for (int step = 0; step < max_steps; ++step) {
    const auto& f = t.faces[static_cast<std::size_t>(face)];
    const V3 a = positions.row(f[0]), e1 = V3(positions.row(f[1])) - a,
             e2 = V3(positions.row(f[2])) - a, d = p - a;
    const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
    const double det = g11 * g22 - g12 * g12;
    if (!(det > 1e-24 * g11 * g22)) break;
    const double u = (g22 * d.dot(e1) - g12 * d.dot(e2)) / det;
    const double v = (g11 * d.dot(e2) - g12 * d.dot(e1)) / det;
    const double bary[3] = {1.0 - u - v, u, v};
    const int k = bary[0] <= bary[1] && bary[0] <= bary[2] ? 0 : (bary[1] <= bary[2] ? 1 : 2);
    if (bary[k] >= -kInside) break;
    const int next = t.across[static_cast<std::size_t>(face)][static_cast<std::size_t>(k)];
    if (next < 0 || next == previous) break;
    previous = face;
    face = next;
    ++steps;
  }
  return face;
}

Outcome encode_one(const TriangleTopology& t, const Eigen::MatrixXd& positions,
                   const Eigen::MatrixXd& normals, const V3& p, int start,
                   const PhongOptions& options) {
  Outcome out;
  start = approach(t, positions, p, start, options.max_walk_steps, out.steps);
  int face = start;
  int best_face = -1;
  FaceSolution best;
  // The faces visited (a walk never returns to one); reused by the calls on this thread.
  thread_local std::vector<int> visited;
  visited.clear();
  bool accepted = false;
  // Newton may fail in the start face (p beyond its focal point) and succeed next door: try the
  // faces around the start before giving up.
  std::array<int, 4> seeds{start, -1, -1, -1};
  std::size_t seed_count = 1;
  for (const int g : t.across[static_cast<std::size_t>(start)])
    if (g >= 0) seeds[seed_count++] = g;
  std::size_t seed = 0;
  for (int step = 0; step <= options.max_walk_steps; ++step) {
    const Corners c = corners(t, positions, normals, face);
    const FaceSolution s = solve_in_face(c, p);
    if (!s.ok) {
      if (best_face >= 0 || ++seed >= seed_count) break;
      face = seeds[seed];
      continue;
    }
    visited.push_back(face);
    if (best_face < 0 || s.min_bary() > best.min_bary()) {
      best = s;
      best_face = face;
    }
    if (s.min_bary() >= -kInside) {
      accepted = true;
      break;
    }
    const int next =
        t.across[static_cast<std::size_t>(face)][static_cast<std::size_t>(s.most_negative())];
    if (next < 0 || std::find(visited.begin(), visited.end(), next) != visited.end()) break;
    face = next;
    ++out.steps;
  }
  if (best_face >= 0 && best.min_bary() >= -kExtrapolate) {
    out.extrapolated = !accepted || best.min_bary() < -kInside;
    out.detail.base.face = FaceHandle(best_face);
    out.detail.base.bary = {1.0 - best.u - best.v, best.u, best.v};
    out.detail.offset = best.offset;
  } else {
    // No face holds a Phong base point (p beyond the focal surface, or the solution far outside
    // the best face, where an extrapolated normal field would swing wildly under deformation):
    // the orthogonal projection onto the best (or start) face, clamped to it, the offset along
    // the normal there, and the rest as a residual in the face's frame.
    out.fallback = true;
    const int home = best_face >= 0 ? best_face : start;
    const Corners c = corners(t, positions, normals, home);
    const V3 e1 = c.x[1] - c.x[0], e2 = c.x[2] - c.x[0], d = p - c.x[0];
    const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
    const double det = g11 * g22 - g12 * g12;
    double u = 0.0, v = 0.0;
    if (det > 0.0) {
      u = std::clamp((g22 * d.dot(e1) - g12 * d.dot(e2)) / det, 0.0, 1.0);
      v = std::clamp((g11 * d.dot(e2) - g12 * d.dot(e1)) / det, 0.0, 1.0 - u);
    }
    out.detail.base.face = FaceHandle(home);
    out.detail.base.bary = {1.0 - u - v, u, v};
    const V3 n = (1.0 - u - v) * c.n[0] + u * c.n[1] + v * c.n[2];
    const V3 b = c.x[0] + u * e1 + v * e2;
    out.detail.offset = n.norm() > 0.0 ? (p - b).dot(n) / n.norm() : 0.0;
  }
  const Corners c = corners(t, positions, normals, out.detail.base.face.idx());
  settle_residual(c, p, out.detail);
  if (out.detail.residual) out.fallback = true;
  return out;
}

} // namespace

void read_face_topology(const Mesh& mesh, std::size_t i, TriangleTopology& t) {
  const FaceHandle f(static_cast<int>(i));
  if (mesh.status(f).deleted())
    throw InvalidArgument("triangle_topology: the mesh has deleted faces; call "
                          "garbage_collection() first");
  // Corner k = from(h0), to(h0), to(next(h0)); the edge opposite corner 0 is next(h0), opposite
  // corner 1 is next(next(h0)), opposite corner 2 is h0.
  const HalfedgeHandle h0 = mesh.halfedge_handle(f), h1 = mesh.next_halfedge_handle(h0),
                       h2 = mesh.next_halfedge_handle(h1);
  t.faces[i] = {mesh.from_vertex_handle(h0).idx(), mesh.to_vertex_handle(h0).idx(),
                mesh.to_vertex_handle(h1).idx()};
  const HalfedgeHandle opposite[3] = {h1, h2, h0};
  for (int k = 0; k < 3; ++k) {
    const FaceHandle g = mesh.face_handle(mesh.opposite_halfedge_handle(opposite[k]));
    t.across[i][static_cast<std::size_t>(k)] = g.is_valid() ? g.idx() : -1;
  }
}

void build_vertex_faces(TriangleTopology& t, std::size_t nv) {
  t.vertex_offsets.assign(nv + 1, 0);
  for (const auto& f : t.faces)
    for (int v : f) ++t.vertex_offsets[static_cast<std::size_t>(v) + 1];
  for (std::size_t v = 0; v < nv; ++v) t.vertex_offsets[v + 1] += t.vertex_offsets[v];
  t.vertex_faces.resize(static_cast<std::size_t>(t.vertex_offsets[nv]));
  std::vector<int> fill(t.vertex_offsets.begin(), t.vertex_offsets.end() - 1);
  for (std::size_t i = 0; i < t.faces.size(); ++i)
    for (int v : t.faces[i])
      t.vertex_faces[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] =
          static_cast<int>(i);
}

TriangleTopology triangle_topology(const Mesh& mesh) {
  TriangleTopology t;
  const std::size_t nf = mesh.n_faces();
  t.faces.resize(nf);
  t.across.resize(nf);
  for (std::size_t i = 0; i < nf; ++i) read_face_topology(mesh, i, t);
  build_vertex_faces(t, mesh.n_vertices());
  return t;
}

namespace {

/// The normal of vertex v: the normalized sum of its faces' cross products, (0, 0, 0) where it
/// vanishes.
Eigen::RowVector3d vertex_normal(const TriangleTopology& t, const Eigen::MatrixXd& positions,
                                 std::size_t v) {
  V3 sum = V3::Zero();
  for (int k = t.vertex_offsets[v]; k < t.vertex_offsets[v + 1]; ++k) {
    const auto& f = t.faces[static_cast<std::size_t>(t.vertex_faces[static_cast<std::size_t>(k)])];
    const V3 a = positions.row(f[0]), b = positions.row(f[1]), c = positions.row(f[2]);
    sum += (b - a).cross(c - a);
  }
  const double len = sum.norm();
  return len > 0.0 ? Eigen::RowVector3d((sum / len).transpose()) : Eigen::RowVector3d::Zero();
}

} // namespace

Eigen::MatrixXd vertex_normals(const TriangleTopology& t, const Eigen::MatrixXd& positions) {
  const auto nv = static_cast<Eigen::Index>(t.vertex_offsets.size()) - 1;
  if (positions.rows() != nv || positions.cols() != 3)
    throw InvalidArgument(fmt::format("vertex_normals: positions are {}×{}, expected {}×3",
                                      positions.rows(), positions.cols(), nv));
  Eigen::MatrixXd normals(nv, 3);
  parallel_for(static_cast<std::size_t>(nv), 0, [&](std::size_t v) {
    normals.row(static_cast<Eigen::Index>(v)) = vertex_normal(t, positions, v);
  });
  return normals;
}

void update_vertex_normals(const TriangleTopology& t, const Eigen::MatrixXd& positions,
                           const std::vector<int>& vertices, Eigen::MatrixXd& normals,
                           int threads) {
  const auto nv = static_cast<Eigen::Index>(t.vertex_offsets.size()) - 1;
  if (positions.rows() != nv || positions.cols() != 3 || normals.rows() != nv ||
      normals.cols() != 3)
    throw InvalidArgument(fmt::format("update_vertex_normals: positions are {}×{} and normals "
                                      "{}×{}, expected {}×3",
                                      positions.rows(), positions.cols(), normals.rows(),
                                      normals.cols(), nv));
  parallel_for(vertices.size(), threads, [&](std::size_t i) {
    const auto v = static_cast<std::size_t>(vertices[i]);
    normals.row(static_cast<Eigen::Index>(v)) = vertex_normal(t, positions, v);
  });
}

std::vector<PhongDetail> encode_phong(const TriangleTopology& topology,
                                      const Eigen::MatrixXd& positions,
                                      const Eigen::MatrixXd& normals, const Eigen::MatrixXd& points,
                                      const std::vector<int>& start_faces,
                                      const PhongOptions& options, PhongStats* stats, int threads) {
  const auto nv = static_cast<Eigen::Index>(topology.vertex_offsets.size()) - 1;
  if (positions.rows() != nv || normals.rows() != nv || positions.cols() != 3 ||
      normals.cols() != 3 || points.cols() != 3 ||
      static_cast<std::size_t>(points.rows()) != start_faces.size())
    throw InvalidArgument("encode_phong: positions, normals, points or start faces have the "
                          "wrong shape");
  if (options.max_walk_steps < 0)
    throw InvalidArgument("encode_phong: max_walk_steps must be >= 0");
  const auto nf = static_cast<int>(topology.faces.size());
  for (std::size_t i = 0; i < start_faces.size(); ++i) {
    if (start_faces[i] < 0 || start_faces[i] >= nf)
      throw InvalidArgument(fmt::format("encode_phong: start face {} of point {} is out of range "
                                        "(the base has {} faces)",
                                        start_faces[i], i, nf));
    if (!points.row(static_cast<Eigen::Index>(i)).allFinite())
      throw InvalidArgument(fmt::format("encode_phong: point {} is not finite", i));
  }
  std::vector<Outcome> outcomes(start_faces.size());
  parallel_for(start_faces.size(), threads, [&](std::size_t i) {
    outcomes[i] =
        encode_one(topology, positions, normals,
                   points.row(static_cast<Eigen::Index>(i)).transpose(), start_faces[i], options);
  });
  std::vector<PhongDetail> details(outcomes.size());
  PhongStats s;
  for (std::size_t i = 0; i < outcomes.size(); ++i) {
    details[i] = outcomes[i].detail;
    s.walk_steps += outcomes[i].steps;
    s.extrapolated += outcomes[i].extrapolated ? 1 : 0;
    s.fallbacks += outcomes[i].fallback ? 1 : 0;
    s.max_abs_offset = std::max(s.max_abs_offset, std::abs(details[i].offset));
  }
  s.encoded = details.size();
  if (stats) *stats = s;
  return details;
}

Eigen::Vector3d decode_phong(const TriangleTopology& topology, const Eigen::MatrixXd& positions,
                             const Eigen::MatrixXd& normals, const PhongDetail& detail) {
  return decode(corners(topology, positions, normals, detail.base.face.idx()), detail);
}

Eigen::Vector3d decode_phong(const TriangleTopology& topology, const RowPoints& positions,
                             const RowPoints& normals, const PhongDetail& detail) {
  return decode(corners(topology, positions, normals, detail.base.face.idx()), detail);
}

} // namespace remora
