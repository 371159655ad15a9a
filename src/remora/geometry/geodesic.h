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
// A large ball may be marched on a coarser level (FastMarchingOptions::coarse_ratio, off by
// default; geometry/geodesic_levels.h): its cost is then bounded whatever its radius, and its
// distances lose a little accuracy: 0.1–0.8 % of the radius on a plane and a sphere with the
// browser editor's ratio of 64, and the tests bound it at 2 % with ratios of 16 and 32. Near the
// source they are the level's too: the source's own distance is not exactly 0 there.
//
// A brush stroke paints the union of balls of one radius along the pointer's path. Marching each
// ball in full costs the ball's area per pointer move; a stroke (FastMarching::stroke_ball) marches
// from the new source only where it comes nearer than every earlier source of the stroke (plus a
// slack of two edge lengths, which the triangle updates need; on a coarse level two of its edge
// lengths plus twice its clusters' spread), and reports only the vertices no
// earlier ball reached: about half the ball's work for a small step, and an answer of the size of
// the new crescent. The union of what a stroke reports equals the union of the full balls.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "remora/geometry/geodesic_levels.h"
#include "remora/geometry/geodesic_march.h"
#include "remora/mesh/mesh.h"
#include "remora/mesh/surface_point.h"

namespace remora {

struct FastMarchingOptions {
  /// 0: every ball is marched on the mesh itself. Otherwise a ball whose radius exceeds
  /// `coarse_ratio` mean edge lengths is marched on the coarser level whose cells are between
  /// radius / coarse_ratio and twice that (edges of 2^k mean edge lengths, k >= 1), built the
  /// first time a ball needs it; the last level's cells span the faces' bounding box, and larger
  /// balls use it. The mean edge length is the constructor's. Must be 0 or >= 1 (else
  /// InvalidArgument). The browser editor's brush uses 64.
  double coarse_ratio = 0.0;
};

/// Fast marching on one mesh's faces, for many balls (the page's brush marches on every pointer
/// move): keeps, for every vertex, the far edges of its faces, and the scratch memory. The
/// positions are read from the mesh at each call, so its vertices may move between strokes; its
/// faces may not. A coarse level keeps its clusters' points: tell it, with positions_changed(),
/// which vertices moved. Not thread-safe: one per thread.
class FastMarching {
public:
  explicit FastMarching(const Mesh& mesh, const FastMarchingOptions& options = {});
  ~FastMarching();
  FastMarching(FastMarching&&) noexcept;
  FastMarching& operator=(FastMarching&&) noexcept;

  /// The vertices within geodesic distance `radius` of `source` (a point on a face: its three
  /// corners start at their straight-line distance from it), with their distances, in increasing
  /// order of distance. Throws InvalidArgument for an invalid or deleted face, barycentric
  /// coordinates that are not finite, a negative or non-finite radius, or a mesh whose numbers
  /// of vertices and faces differ from the constructor's.
  std::vector<std::pair<int, double>> ball(const Mesh& mesh, const SurfacePoint& source,
                                           double radius);
  /// The same from a vertex (distance 0 there, on the mesh itself; a coarse level marches from a
  /// face at the vertex); InvalidArgument for an invalid or deleted vertex.
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

  /// Builds now the coarse levels that balls of radius up to `radius` need (otherwise each is
  /// built by the first ball that needs it: 0.1–0.3 s on a million triangles).
  void prepare(const Mesh& mesh, double radius);
  /// The diagonal of the bounding box of the faces' finite corners at construction (with
  /// coarse levels; 0 without).
  double faces_diagonal() const { return diagonal_; }

  /// `vertices` of `mesh` (or all of them) moved: the coarse levels read their clusters again
  /// at the next stroke's start. Not needed for balls on the mesh itself.
  void positions_changed(const Mesh& mesh, const std::vector<int>& vertices);
  void positions_changed();

  /// The level the last ball was marched on: 0 the mesh itself, k >= 1 cells of 2^k mean edge
  /// lengths; and that level's cell size (0 for the mesh).
  int last_level() const { return last_level_; }
  double last_cell() const;

private:
  void check_mesh(const Mesh& mesh) const;
  int level_for(double radius) const;
  CoarseLevel& level(const Mesh& mesh, int k);
  std::vector<std::pair<int, double>>
  fine(const Mesh& mesh, const std::vector<std::pair<int, double>>& seeds, double radius);
  std::size_t faces_ = 0;
  FastMarchingOptions options_;
  double mean_edge_ = 0.0;
  Marcher marcher_;
  std::shared_ptr<const std::vector<std::array<int, 3>>> corners_; ///< the faces', for the levels
  std::vector<std::unique_ptr<CoarseLevel>> levels_; ///< levels_[k - 1], built when first used
  double stroke_radius_ = -1.0;                      ///< < 0: no stroke
  double diagonal_ = 0.0;
  int top_level_ = 0;            ///< the coarsest level (0: none)
  std::vector<char> near_moved_; ///< positions_changed()'s scratch
  int last_level_ = 0;
};

/// FastMarching(mesh).ball(mesh, source, radius): one ball, on the mesh itself.
std::vector<std::pair<int, double>> geodesic_ball(const Mesh& mesh, const SurfacePoint& source,
                                                  double radius);
std::vector<std::pair<int, double>> geodesic_ball(const Mesh& mesh, VertexHandle source,
                                                  double radius);

} // namespace remora
