// Per-element geometric measures shared by the remesher, the Laplacian and the quality report.
// Angles are in radians, areas and lengths in the mesh's units. Points must be finite (the readers
// reject NaN and Inf); for finite points no function here returns NaN or Inf. Deleted elements are
// skipped; per-vertex vectors are indexed by vertex idx(), have size n_vertices(), and hold 0 for
// deleted and isolated vertices.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "remora/mesh/mesh.h"

namespace remora {

/// Area of the triangle (a, b, c): |(b - a) x (c - a)| / 2.
double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c);

/// Area of a triangle face of `mesh`.
double face_area(const Mesh& mesh, FaceHandle f);

/// Sum of the areas of all (non-deleted) faces.
double surface_area(const Mesh& mesh);

/// Inner angles at a, b, c, each atan2(|u x v|, u . v) of the corner's two edge vectors u, v (exact
/// to round-off for needles and for corners near 180 degrees alike); they sum to pi to round-off.
/// Degenerate triangles: an edge counts as zero-length when it is zero in double precision
/// relative to the triangle (shorter than roughly 1e-162 times its longest edge). If one edge has
/// zero length, the corner opposite it gets 0 and its two ends pi/2 each (the limit when one end
/// approaches the other perpendicularly to the remaining edge); if all three points coincide,
/// (0, 0, pi).
std::array<double, 3> triangle_angles(const Vec3& a, const Vec3& b, const Vec3& c);

/// The triangle's share of the mixed area of each corner a, b, c (Meyer, Desbrun, Schroeder, Barr
/// 2003, "Discrete differential-geometry operators for triangulated 2-manifolds", Fig. 4):
///  - no obtuse angle: the Voronoi part, for corner P with the others Q, R
///    (|PR|^2 cot Q + |PQ|^2 cot R) / 8;
///  - an obtuse angle: area/2 at the obtuse corner, area/4 at the two others.
/// The three parts sum to the triangle's area to round-off. A zero-area triangle gives (0, 0, 0);
/// each part is clamped to [0, area], where it lies mathematically, so needles stay finite.
std::array<double, 3> triangle_mixed_areas(const Vec3& a, const Vec3& b, const Vec3& c);

/// Barycentric vertex areas: one third of the area of every incident face.
Eigen::VectorXd vertex_areas_barycentric(const Mesh& mesh);

/// Mixed Voronoi vertex areas: the sum of triangle_mixed_areas() over the incident faces. Both
/// vertex-area vectors sum to surface_area() to round-off.
Eigen::VectorXd vertex_areas_mixed(const Mesh& mesh);
/// The one entry of vertex_areas_mixed() for v: the same sum, bit for bit (its faces in index
/// order).
double vertex_area_mixed(const Mesh& mesh, VertexHandle v);

/// Mean length of the mesh's edges (0 for a mesh without edges).
double mean_edge_length(const Mesh& mesh);

/// The feature (crease) edges: per edge idx(), 1 for an interior edge whose two faces' normals
/// differ by more than `angle_deg` degrees (its dihedral angle is sharper than 180 − angle_deg),
/// else 0. A face with zero area in double precision has no normal and makes no edge a feature;
/// boundary and deleted edges are 0. Throws InvalidArgument unless 0 <= angle_deg < 180 (at 0
/// every edge between two faces that are not coplanar and equally oriented is a feature).
std::vector<char> feature_edges(const Mesh& mesh, double angle_deg);

/// The mesh's length scale, from which remesh() derives its default target length and the
/// base-surface filter its σ: the mean edge length, unless needles inflate it. The edge length
/// of equilateral triangles with the mesh's area per (non-isolated) vertex, √(2A / (√3 V)), is
/// within about 15 % of the mean edge length on a well-shaped mesh; when it is below 3/4 of it
/// (a mesh of needles, whose long edges inflate the mean), it is used.
struct LengthScale {
  double length = 0.0;
  double mean_edge = 0.0;
  double from_area = 0.0;
  bool needles = false; ///< from_area was used
};
LengthScale length_scale(const Mesh& mesh);

/// Axis-aligned bounding box of all non-deleted vertices (isolated ones included). A mesh without
/// vertices gives min = max = (0, 0, 0).
struct BoundingBox {
  Vec3 min{0.0, 0.0, 0.0};
  Vec3 max{0.0, 0.0, 0.0};

  /// |max - min|
  double diagonal() const { return (max - min).norm(); }
};

BoundingBox bounding_box(const Mesh& mesh);

/// bounding_box(mesh).diagonal()
double bounding_box_diagonal(const Mesh& mesh);

/// A face area counts as zero when area <= kZeroAreaRelative (1e-12, mesh.h) * bbox_diagonal^2:
/// the convention of the test data's MANIFEST and of RepairReport::zero_area_faces.
bool is_zero_area(double area, double bbox_diagonal);

} // namespace remora
