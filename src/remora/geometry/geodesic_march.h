// The fast-marching front itself (Kimmel & Sethian 1998), on any set of triangles given as each
// vertex's far edges: the fine mesh's (geometry/geodesic.h) or a coarser level's
// (geometry/geodesic_levels.h). It keeps the scratch memory between marches and the state of a
// stroke: per vertex, the distance from the nearest earlier source of the stroke.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "remora/mesh/mesh.h"

namespace remora {

/// Every vertex's far edges: vertex v's are ring[begin[v] .. begin[v + 1]), each (p, q) with
/// (v, p, q) a triangle; (p, p) stands for an edge v–p on no triangle (a coarse level's).
struct MarchRings {
  std::vector<std::uint32_t> begin; ///< size n + 1
  std::vector<std::array<int, 2>> ring;
};

/// The rings of a triangle list (corner indices in 0 .. n - 1), and of edges on no triangle.
MarchRings march_rings(std::size_t n, const std::vector<std::array<int, 3>>& triangles,
                       const std::vector<std::array<int, 2>>& lone_edges = {});

/// One vertex the front accepted: its distance, and whether no earlier march of the stroke had
/// accepted it.
struct Accepted {
  int vertex = -1;
  double distance = 0.0;
  bool fresh = false;
};

/// Marches on one set of rings; not thread-safe.
class Marcher {
public:
  Marcher() = default; ///< on no vertices
  explicit Marcher(MarchRings rings);
  std::size_t size() const { return distance_.size(); }
  const MarchRings& rings() const { return rings_; }

  /// The vertices within `radius` of the seeds (vertex, starting distance), in increasing order
  /// of distance, through the triangles around the points `points[0 .. size())`. In a stroke
  /// (after the first march since start_stroke()) the front goes on only where it comes nearer
  /// than the stroke's earlier sources plus the slack: twice the mean edge length the first march
  /// crossed, plus `extra_slack`.
  std::vector<Accepted> march(const Vec3* points, const std::vector<std::pair<int, double>>& seeds,
                              double radius, double extra_slack);
  /// Forgets the stroke's earlier sources.
  void start_stroke();

private:
  MarchRings rings_;
  std::vector<double> distance_;    ///< +inf except where the last march wrote
  std::vector<std::uint8_t> state_; ///< far, trial, accepted
  std::vector<int> touched_;        ///< what to reset before the next march
  std::vector<double> nearest_;     ///< the stroke's: +inf where no march of it accepted
  std::vector<int> stroke_touched_;
  double slack_ = 0.0;
};

} // namespace remora
