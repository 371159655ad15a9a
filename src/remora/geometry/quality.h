// The mesh quality figures, defined once for the remesher's report, the benchmarks and the web
// editor; docs/quality.md gives every definition. Angles are in degrees, lengths and areas in the
// mesh's units, percentages in [0, 100]. Deleted elements are skipped. A figure over an empty set
// (no face, no edge, no interior vertex) is 0, and the matching count (faces, edges,
// interior_vertices) says so; no figure is ever NaN or Inf for finite points.
#pragma once

#include <cstddef>
#include <map>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "remora/geometry/measures.h"
#include "remora/mesh/mesh.h"
#include "remora/mesh/topology.h"

namespace remora {

/// Angle thresholds are compared with this tolerance (degrees): "below t" is theta < t - tol,
/// "above t" is theta > t + tol, so right angles are not obtuse by round-off or float coordinates.
inline constexpr double kAngleThresholdToleranceDeg = 1e-3;

/// Inner angles of all faces (triangle_angles()). The percent_* figures are over all 3F angles,
/// except percent_faces_min_below_10, which is over the F faces (their smallest angle).
struct AngleFigures {
  double min_deg = 0.0;
  double max_deg = 0.0;
  double mean_abs_deviation_from_60_deg = 0.0; ///< mean |theta - 60|; the mean theta is always 60
  double percent_below_10 = 0.0;
  double percent_below_30 = 0.0;
  double percent_above_90 = 0.0;
  double percent_above_150 = 0.0;
  double percent_faces_min_below_10 = 0.0;
};

/// Valence (number of incident edges) histograms, valence -> vertex count, interior and boundary
/// vertices separately (isolated vertices are in neither).
struct ValenceFigures {
  std::map<int, std::size_t> interior;
  std::map<int, std::size_t> boundary;
  double percent_interior_6 = 0.0; ///< of the interior vertices
  double percent_boundary_4 = 0.0; ///< of the boundary vertices
};

/// Over all edges; cv = population standard deviation / mean (0 when the mean is 0).
struct EdgeLengthFigures {
  double mean = 0.0;
  double cv = 0.0;
  double min = 0.0;
  double max = 0.0;
};

/// Vertex areas over the interior vertices only: mean A, rel_std = population std / mean, and
/// rel_mad = mean |A_i - mean| / mean (the relative figures are 0 when the mean is 0).
struct VertexAreaFigures {
  double mean = 0.0;
  double rel_std = 0.0;
  double rel_mad = 0.0;
};

struct MeshQuality {
  std::size_t vertices = 0; ///< non-deleted, isolated ones included
  std::size_t faces = 0;
  std::size_t edges = 0;
  std::size_t boundary_loops = 0;
  std::size_t components = 0;
  std::size_t interior_vertices = 0; ///< not isolated, not on the boundary
  std::size_t boundary_vertices = 0;
  std::size_t isolated_vertices = 0;
  std::vector<ComponentTopology> component_topology; ///< genus and closed flag per component
  AngleFigures angles;
  ValenceFigures valence;
  EdgeLengthFigures edge_length;
  VertexAreaFigures barycentric_area; ///< vertex_areas_barycentric()
  VertexAreaFigures mixed_area;       ///< vertex_areas_mixed()
  std::size_t zero_area_faces = 0;    ///< is_zero_area(face_area, bounding_box.diagonal())
  BoundingBox bounding_box;
  double bounding_box_diagonal = 0.0;
};

struct QualityOptions {
  /// The topological figures (boundary_loops, components, component_topology); off, they stay
  /// 0 and empty (a caller that knows them from elsewhere saves their cost).
  bool topology = true;
};

/// Every figure above. The per-face and per-edge values are computed on all hardware threads and
/// added up in element order: the figures do not depend on the number of threads.
MeshQuality mesh_quality(const Mesh& mesh, const QualityOptions& options = {});

/// mesh_quality()'s vertex counts and valences into `q`; `interior` gets the interior vertices.
void vertex_figures(const Mesh& mesh, MeshQuality& q, std::vector<VertexHandle>& interior);

/// mesh_quality()'s figures of per-vertex `areas` over the vertices `interior`.
VertexAreaFigures vertex_area_figures(const Eigen::VectorXd& areas,
                                      const std::vector<VertexHandle>& interior);

/// Percentage of the (live) edges whose length lies in [lo, hi]: the remesher's band is
/// [4/5 l, 4/3 l] (§4). 0 for a mesh without edges.
double percent_edges_within(const Mesh& mesh, double lo, double hi);

/// Stable snake_case keys mirroring the struct; valence histograms are arrays of
/// {"valence": v, "count": n} in increasing valence, bounding-box corners are [x, y, z].
nlohmann::json to_json(const MeshQuality& quality);

} // namespace remora
