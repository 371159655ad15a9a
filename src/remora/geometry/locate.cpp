#include "remora/geometry/locate.h"

#include <array>
#include <cmath>
#include <string>

#include "remora/common/error.h"
#include "remora/geometry/closest_point.h"

namespace remora {
namespace {

// A move must shorten the squared distance by more than this fraction: rounding cannot make the
// walk step between faces that touch at the closest point, and each move is a real improvement,
// so the walk cannot cycle.
constexpr double kImprovement = 1e-12;

bool improves(double candidate, double current) {
  return candidate < current - kImprovement * current;
}

void require_query(const char* function, const Vec3& q, int max_steps) {
  if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2])) {
    throw InvalidArgument(std::string(function) + ": the query point is not finite");
  }
  if (max_steps < 0) {
    throw InvalidArgument(std::string(function) + ": max_steps = " + std::to_string(max_steps) +
                          " is negative");
  }
}

bool is_live(const Mesh& mesh, FaceHandle f) {
  return f.is_valid() && !mesh.status(f).deleted();
}

double distance2_to_face(const Mesh& mesh, const Vec3& q, FaceHandle f) {
  const std::array<VertexHandle, 3> v = face_vertices(mesh, f);
  return closest_point_on_triangle(q, mesh.point(v[0]), mesh.point(v[1]), mesh.point(v[2]))
      .distance2;
}

} // namespace

SurfacePoint walk_to_closest(const Mesh& mesh, const Vec3& q, FaceHandle start, int max_steps) {
  require_query("walk_to_closest", q, max_steps);
  if (!start.is_valid() || start.idx() >= static_cast<int>(mesh.n_faces()) ||
      mesh.status(start).deleted()) {
    throw InvalidArgument("walk_to_closest: start face " + std::to_string(start.idx()) +
                          " is not a live face of the mesh; pass a non-deleted face");
  }
  FaceHandle f = start;
  double current = distance2_to_face(mesh, q, f);
  for (int step = 0; step < max_steps; ++step) {
    const std::array<VertexHandle, 3> corners = face_vertices(mesh, f);
    FaceHandle best_face = f;
    double best = current;
    for (std::size_t i = 0; i < 3; ++i) {
      const Vec3& pv = mesh.point(corners[i]);
      // Outgoing halfedges of corner i, clockwise. A face that also holds an earlier corner was
      // already evaluated from that corner, so every face of the neighbourhood is evaluated once.
      const HalfedgeHandle first = mesh.halfedge_handle(corners[i]);
      HalfedgeHandle h = first;
      do {
        const FaceHandle g = mesh.face_handle(h);
        if (g != f && is_live(mesh, g)) {
          const VertexHandle v1 = mesh.to_vertex_handle(h);
          const VertexHandle v2 = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
          bool seen = false;
          for (std::size_t j = 0; j < i; ++j) seen = seen || v1 == corners[j] || v2 == corners[j];
          if (!seen) {
            const double d2 =
                closest_point_on_triangle(q, pv, mesh.point(v1), mesh.point(v2)).distance2;
            if (d2 < best) {
              best = d2;
              best_face = g;
            }
          }
        }
        h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
      } while (h != first);
    }
    if (best_face == f || !improves(best, current)) break;
    f = best_face;
    current = best;
  }
  const std::array<VertexHandle, 3> v = face_vertices(mesh, f);
  const TriangleClosest closest =
      closest_point_on_triangle(q, mesh.point(v[0]), mesh.point(v[1]), mesh.point(v[2]));
  return {f, closest.bary};
}

namespace {

// The point (1 - t) from(h) + t to(h) on the face of h, or on the face across h when h is a
// boundary halfedge.
BoundaryPoint point_on_halfedge(const Mesh& mesh, HalfedgeHandle h, double t) {
  BoundaryPoint result;
  result.halfedge = h;
  result.t = t;
  result.point.face = mesh.is_boundary(h) ? mesh.face_handle(mesh.opposite_halfedge_handle(h))
                                          : mesh.face_handle(h);
  const VertexHandle from = mesh.from_vertex_handle(h);
  const VertexHandle to = mesh.to_vertex_handle(h);
  const std::array<VertexHandle, 3> corners = face_vertices(mesh, result.point.face);
  for (std::size_t k = 0; k < 3; ++k) {
    result.point.bary[k] = corners[k] == from ? 1.0 - t : corners[k] == to ? t : 0.0;
  }
  return result;
}

// The greedy descent of both walks along a chain of halfedges: from h = start, each step moves
// to whichever of neighbours(h) (two halfedges; invalid ones are skipped) is nearest to q, if it
// is closer than h by more than a relative 1e-12; at most max_steps moves.
template <class Neighbours>
BoundaryPoint descend_along(const Mesh& mesh, const Vec3& q, HalfedgeHandle start, int max_steps,
                            Neighbours&& neighbours) {
  const auto closest = [&mesh, &q](HalfedgeHandle h) {
    return closest_point_on_segment(q, mesh.point(mesh.from_vertex_handle(h)),
                                    mesh.point(mesh.to_vertex_handle(h)));
  };
  HalfedgeHandle h = start;
  SegmentClosest current = closest(h);
  for (int step = 0; step < max_steps; ++step) {
    HalfedgeHandle best_halfedge = h;
    SegmentClosest best = current;
    for (const HalfedgeHandle n : neighbours(h)) {
      if (!n.is_valid()) continue;
      const SegmentClosest candidate = closest(n);
      if (candidate.distance2 < best.distance2) {
        best = candidate;
        best_halfedge = n;
      }
    }
    if (best_halfedge == h || !improves(best.distance2, current.distance2)) break;
    h = best_halfedge;
    current = best;
  }
  return point_on_halfedge(mesh, h, current.t);
}

} // namespace

BoundaryPoint walk_to_closest_on_boundary(const Mesh& mesh, const Vec3& q, HalfedgeHandle start,
                                          int max_steps) {
  require_query("walk_to_closest_on_boundary", q, max_steps);
  // A usable boundary halfedge: live, without a face, with a live face on the other side.
  const auto usable = [&mesh](HalfedgeHandle h) {
    return !mesh.status(h).deleted() && mesh.is_boundary(h) &&
           is_live(mesh, mesh.face_handle(mesh.opposite_halfedge_handle(h)));
  };
  if (!start.is_valid() || start.idx() >= static_cast<int>(mesh.n_halfedges()) || !usable(start)) {
    throw InvalidArgument("walk_to_closest_on_boundary: halfedge " + std::to_string(start.idx()) +
                          " is not a live boundary halfedge with a face on its other side; pass "
                          "a halfedge h with mesh.is_boundary(h)");
  }
  return descend_along(mesh, q, start, max_steps, [&](HalfedgeHandle h) {
    std::array<HalfedgeHandle, 2> n{mesh.next_halfedge_handle(h), mesh.prev_halfedge_handle(h)};
    for (HalfedgeHandle& g : n)
      if (g == h || !usable(g)) g = HalfedgeHandle();
    return n;
  });
}

BoundaryPoint walk_to_closest_on_curve(const Mesh& mesh, const Vec3& q, HalfedgeHandle start,
                                       const std::vector<char>& on_curve, int max_steps) {
  require_query("walk_to_closest_on_curve", q, max_steps);
  if (on_curve.size() != mesh.n_edges())
    throw InvalidArgument("walk_to_closest_on_curve: on_curve has " +
                          std::to_string(on_curve.size()) + " entries for " +
                          std::to_string(mesh.n_edges()) + " edges; pass one per edge");
  const auto marked = [&](HalfedgeHandle h) {
    return on_curve[static_cast<std::size_t>(h.idx() / 2)] != 0 && !mesh.status(h).deleted();
  };
  if (!start.is_valid() || start.idx() >= static_cast<int>(mesh.n_halfedges()) || !marked(start))
    throw InvalidArgument("walk_to_closest_on_curve: halfedge " + std::to_string(start.idx()) +
                          " is not a live halfedge of an edge marked in on_curve");
  // The chain's other marked halfedge at v, leaving v (`out`) or reaching it; invalid where the
  // chain ends (v has one marked edge, or more than two).
  const auto other = [&](VertexHandle v, HalfedgeHandle not_this, bool out) {
    HalfedgeHandle found;
    int count = 0;
    for (auto g : mesh.voh_range(v)) {
      if (!marked(g)) continue;
      ++count;
      if (mesh.edge_handle(g) != mesh.edge_handle(not_this)) found = g;
    }
    if (count != 2) return HalfedgeHandle();
    return out ? found : mesh.opposite_halfedge_handle(found);
  };
  return descend_along(mesh, q, start, max_steps, [&](HalfedgeHandle h) {
    return std::array<HalfedgeHandle, 2>{other(mesh.to_vertex_handle(h), h, true),
                                         other(mesh.from_vertex_handle(h), h, false)};
  });
}

} // namespace remora
