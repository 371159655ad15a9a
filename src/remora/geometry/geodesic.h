// Geodesic distance on a triangle mesh by fast marching (Kimmel & Sethian, "Computing geodesic
// paths on manifolds", PNAS 1998): a front that grows from a source in order of distance and
// computes each vertex's distance from two known corners of a triangle, through the triangle,
// not along its edges. On a regular grid a ball of radius r is round, where edge paths give a
// diamond (up to 8 % longer along the diagonals of a square grid).
//
// The march is bounded: it stops at `radius`, so its cost is that of the ball, not of the mesh.
// Where the straight path through a triangle leaves it (obtuse triangles, the two corners'
// distances inconsistent), the distance falls back to the shorter of the two edge paths through
// the triangle, so the result is never below the straight-line distance of a flat region and never
// above the edge-path distance. Only the source's connected component is reached.
//
// A brush stroke paints the union of balls of one radius along the pointer's path. Marching each
// ball in full costs the ball's area per pointer move; a stroke (FastMarching::stroke_ball) marches
// from the new source only where it comes nearer than every earlier source of the stroke (plus a
// slack of two edge lengths, which the triangle updates need), and reports only the vertices no
// earlier ball reached: about half the ball's work for a small step, and an answer of the size of
// the new crescent. The union of what a stroke reports equals the union of the full balls.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "remora/mesh/mesh.h"
#include "remora/mesh/surface_point.h"

namespace remora {

/// Fast marching on one mesh's faces, for many balls (the page's brush marches on every pointer
/// move): keeps, for every vertex, the far edges of its faces, and the scratch memory. The
/// positions are read from the mesh at each call, so its vertices may move between calls; its
/// faces may not. Not thread-safe: one per thread.
class FastMarching {
public:
  explicit FastMarching(const Mesh& mesh);

  /// The vertices within geodesic distance `radius` of `source` (a point on a face: its three
  /// corners start at their straight-line distance from it), with their distances, in increasing
  /// order of distance. Throws InvalidArgument for an invalid or deleted face, barycentric
  /// coordinates that are not finite, a negative or non-finite radius, or a mesh whose numbers
  /// of vertices and faces differ from the constructor's.
  std::vector<std::pair<int, double>> ball(const Mesh& mesh, const SurfacePoint& source,
                                           double radius);
  /// The same from a vertex (distance 0 there); InvalidArgument for an invalid or deleted vertex.
  std::vector<std::pair<int, double>> ball(const Mesh& mesh, VertexHandle source, double radius);

  /// The next ball of a stroke: the vertices within `radius` of `source` that no earlier ball of
  /// the stroke reached, with their distance from `source`, in increasing order of distance. The
  /// first call after start_stroke(), after ball(), or with a radius other than the stroke's
  /// starts the stroke (and reports the whole ball). The positions must not change within a
  /// stroke: start a new one when they do. Throws as ball() does.
  std::vector<std::pair<int, double>> stroke_ball(const Mesh& mesh, const SurfacePoint& source,
                                                  double radius);
  /// Forgets the stroke: the next stroke_ball() reports its whole ball.
  void start_stroke();

private:
  std::vector<std::pair<int, double>>
  march(const Mesh& mesh, const std::vector<std::pair<int, double>>& seeds, double radius);
  std::vector<std::pair<int, double>> seeds_of(const Mesh& mesh, const SurfacePoint& source);
  std::size_t faces_ = 0;
  std::vector<std::uint32_t> ring_begin_; ///< vertex v's far edges: ring_[ring_begin_[v] ..
  std::vector<std::array<int, 2>>
      ring_;                        ///< .. ring_begin_[v + 1]), each (p, q) with (v, p, q) a face
  std::vector<double> distance_;    ///< +inf except where the last march wrote
  std::vector<std::uint8_t> state_; ///< far, trial, accepted
  std::vector<int> touched_;        ///< what to reset before the next march
  // The stroke: the distance from its nearest earlier source of every vertex a ball of it
  // reached (+inf elsewhere), which marks it reported; the radius, the slack, what to reset.
  std::vector<double> nearest_;
  std::vector<int> stroke_touched_;
  double stroke_radius_ = -1.0; ///< < 0: no stroke
  double slack_ = 0.0;
};

/// FastMarching(mesh).ball(mesh, source, radius): one ball.
std::vector<std::pair<int, double>> geodesic_ball(const Mesh& mesh, const SurfacePoint& source,
                                                  double radius);
std::vector<std::pair<int, double>> geodesic_ball(const Mesh& mesh, VertexHandle source,
                                                  double radius);

} // namespace remora
