// What the editor's page paints on: the mesh's faces at the positions the page shows (the edited
// shape, live transforms included), a ray caster over them and the brushes. Picking and brushes
// run here so that the page holds no second implementation of the library's geometry.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "remora/geometry/geodesic.h"
#include "remora/geometry/raycast.h"
#include "remora/mesh/mesh.h"

namespace remora::server {

enum class Brush {
  Geodesic, ///< distance on the surface from the hit point (fast marching, geometry/geodesic.h)
  Sphere,   ///< straight-line distance from the hit point
};
Brush parse_brush(const std::string& name); ///< "geodesic" or "sphere"; InvalidArgument else

/// A geodesic brush wider than this many mean edge lengths marches on a coarser level
/// (FastMarchingOptions::coarse_ratio): a pointer move then costs about the same at any radius.
constexpr double kBrushCoarseRatio = 64.0;

struct Pick {
  int face = -1;                    ///< the face met first, -1 when the ray met nothing
  Vec3 point{0, 0, 0};              ///< where
  int vertex = -1;                  ///< the corner of that face nearest to the point
  std::vector<std::uint32_t> brush; ///< the vertices within the radius of the point, by index
};

class Shape {
public:
  /// Copies the mesh (its faces and current positions) and builds the ray caster over it, and
  /// the geodesic brush's coarse levels (FastMarchingOptions::coarse_ratio; 0: none).
  /// Throws InvalidArgument for a corner that is not finite.
  explicit Shape(const Mesh& mesh, double coarse_ratio = kBrushCoarseRatio);

  /// Every vertex moves to the rows of `positions` (n_vertices × 3).
  void set_positions(const Eigen::MatrixXd& positions);
  /// Vertex ids[i] moves to row ids[i] of `positions` (the vertices a frame moved).
  void set_positions(const std::vector<int>& ids, const Eigen::MatrixXd& positions);

  /// The first face met by origin + t direction (t > 0) and the brush of `radius` around it.
  /// The ray caster is refitted first when the positions changed. With `stroke` >= 0, the brush
  /// holds only the vertices that no earlier pick of the same stroke (same number, brush and
  /// radius, no other pick and no move of the shape in between) answered; otherwise every vertex
  /// of the brush.
  /// Throws InvalidArgument for a non-finite or zero ray or a negative or non-finite radius.
  Pick pick(const Vec3& origin, const Vec3& direction, double radius, Brush brush,
            std::int64_t stroke = -1);

  const Mesh& mesh() const { return mesh_; }

private:
  Mesh mesh_;
  RayCaster caster_;
  bool stale_ = false;     // every vertex may have moved since the caster's last refit
  std::vector<int> moved_; // else these did (each once)
  std::vector<char> moved_flag_;
  FastMarching marching_;
  // The stroke being painted: its number (-1: none), brush and radius, and for the sphere brush
  // the vertices already answered (the geodesic brush's marcher keeps its own).
  std::int64_t stroke_ = -1;
  Brush stroke_brush_ = Brush::Geodesic;
  double stroke_radius_ = -1.0;
  std::vector<char> answered_;
  std::vector<std::uint32_t> answered_list_;
  void start_stroke(std::int64_t stroke, Brush brush, double radius);
};

} // namespace remora::server
