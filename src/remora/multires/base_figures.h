// The base's figures in the editor's report (mesh_quality(), laplacian_symmetry_defect()) kept up
// to date by a local bake (multires/bake.h) in time proportional to what it changed: per base
// vertex the quantities those figures are sums over, and the figures' own sums and extremes.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "remora/geometry/quality.h"
#include "remora/mesh/mesh.h"

namespace remora {

/// Per base vertex (by idx()): its mixed and barycentric areas (vertex_areas_mixed(),
/// vertex_areas_barycentric()) and its row of the cotan Laplacian as the symmetry defect reads
/// it, Σ_j W_ij² + W_ii² (geometry/laplacian.h).
struct BaseStatistics {
  Eigen::VectorXd mixed_areas, barycentric_areas, rows;
};

BaseStatistics base_statistics(const Mesh& base);

/// A change of the base: faces (of the new base) whose corners moved or that are new, and faces
/// (of the old base) that went or whose corners moved; `vertex_map` gives each old vertex's
/// index in the new base (-1: gone; empty: the same numbering).
struct BaseChange {
  std::vector<int> old_faces, new_faces;
  std::vector<int> vertex_map;
};

/// The figures of `base` (the new base) from those of `old` (the old base, with `quality`,
/// `defect` and `statistics` its figures): the vertex statistics measured again on the vertices
/// of the new faces, the per-face and per-edge sums of mesh_quality() updated by the old and new
/// faces' terms, their extremes measured on the whole base only when the old extreme lay on an
/// old face of the change. The topological figures (components, boundary loops) are kept, the
/// counts are the new base's. Equal to mesh_quality(base) and laplacian_symmetry_defect(base)
/// up to the order of summation.
void update_base_figures(const Mesh& old, const MeshQuality& quality,
                         const BaseStatistics& statistics, const Mesh& base,
                         const BaseChange& change, MeshQuality& new_quality, double& new_defect,
                         BaseStatistics& new_statistics);

/// laplacian_symmetry_defect(base) from the statistics (all rows).
double symmetry_defect(const Mesh& base, const BaseStatistics& statistics);

} // namespace remora
