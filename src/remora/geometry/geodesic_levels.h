// A coarser level of a mesh for the geodesic balls of large brushes (geometry/geodesic.h).
//
// The fine mesh's vertices are clustered: a cluster is a set of vertices in one cell of a cubic
// grid that the mesh's edges inside the cell connect (two sheets of a thin part that share a cell
// stay apart). Two clusters are adjacent where an edge joins them, and every three pairwise
// adjacent clusters are a coarse triangle (where four meet, both diagonals of their
// quadrilateral); an adjacency on no triangle is a lone edge. The front starts at the clusters
// of the source's face and their neighbours, at their straight-line distance from the source,
// and marches on the clusters' mean points; a fine vertex v of a cluster C at coarse distance
// d(C) then gets
//   d(v) = d(C) + |P(v − s)| − |P(c − s)|   (s the source, c the mean point of C, P the
//   projection on C's tangent plane),
// the coarse distance carried to v to first order: the projected direction from s is the
// front's on a sphere, and on a plane the formula is exact. A ball of radius r costs the
// clusters it covers plus one pass over their vertices: with cells of r/64 … r/32, about ten
// thousand clusters, whatever the number of vertices.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "remora/geometry/geodesic_march.h"
#include "remora/mesh/mesh.h"

namespace remora {

class CoarseLevel {
public:
  /// Clusters `mesh`'s vertices in cells of edge `cell` (> 0) from the corner of its bounding box;
  /// `faces` are its faces' corners (shared by the levels of one mesh).
  CoarseLevel(const Mesh& mesh, std::shared_ptr<const std::vector<std::array<int, 3>>> faces,
              double cell);

  double cell() const { return cell_; }
  std::size_t clusters() const { return marcher_.size(); }

  /// `vertices` moved or have a neighbour that did (or every vertex moved): their clusters'
  /// points, spreads and normals are read again at the next stroke's start (a cluster whose
  /// vertices spread beyond twice the cell from their mean: the level clusters the moved mesh
  /// again).
  void positions_changed(const std::vector<int>& vertices);
  void positions_changed();
  /// Whether the next stroke reads every cluster again anyway.
  bool reads_all() const { return all_dirty_; }

  /// As FastMarching::stroke_ball, from the point `source` on the face with corners `corners`:
  /// the fine vertices within `radius` that no earlier ball of the stroke reported, with their
  /// distances, in increasing order. The first call after start_stroke() reads the positions of
  /// the clusters that changed.
  std::vector<std::pair<int, double>> stroke_ball(const Mesh& mesh, const Vec3& source,
                                                  const std::array<int, 3>& corners, double radius);
  void start_stroke();

private:
  void read_positions(const Mesh& mesh);
  void read_cluster(const Vec3* points, std::size_t c);
  double cell_;
  std::shared_ptr<const std::vector<std::array<int, 3>>> faces_; ///< the fine faces' corners
  std::vector<int> cluster_of_;                                  ///< fine vertex -> cluster
  std::vector<std::uint32_t> member_begin_; ///< cluster c's vertices: members_[member_begin_[c] ..
  std::vector<int> members_;                ///< .. member_begin_[c + 1])
  std::vector<std::uint32_t> face_begin_;   ///< the faces with a corner in cluster c:
  std::vector<int> cluster_faces_; ///< cluster_faces_[face_begin_[c] .. face_begin_[c + 1])
  Marcher marcher_;
  std::vector<Vec3> points_;       ///< the clusters' mean points, read at a stroke's start
  std::vector<Vec3> normals_;      ///< their unit normals (0 where the faces cancel)
  std::vector<double> deviations_; ///< the largest distance of a vertex from its cluster's point
  double deviation_ = 0.0;         ///< the largest of them
  bool all_dirty_ = true;          ///< every cluster to read again
  std::vector<int> dirty_;         ///< the clusters to read again
  std::vector<std::uint8_t> dirty_flag_;
  bool stroke_started_ = false;
  std::vector<std::uint8_t> reported_; ///< fine vertices the stroke reported
  std::vector<int> reported_list_;
  std::vector<std::uint32_t> unreported_; ///< per cluster, its vertices the stroke did not report
};

} // namespace remora
