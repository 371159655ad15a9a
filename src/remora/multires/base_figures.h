// The base's figures in the editor's report (mesh_quality(), laplacian_symmetry_defect()) kept up
// to date by a local bake (multires/bake.h) in time proportional to what it changed: per base
// vertex the quantities those figures are sums over, and the figures' own sums and extremes.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "remora/geometry/quality.h"
#include "remora/linalg/kharmonic.h"
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

/// The figures of `base` (the new base) from those of `old` (the old base, `quality` its
/// figures), all but those over the vertex statistics (mixed_area, barycentric_area): the
/// vertex counts and valences less the old faces' vertices and plus the new faces', the per-face
/// and per-edge sums of mesh_quality() updated by the old and new faces' terms, their extremes
/// measured on the whole base only when the old extreme lay on an old face of the change. The
/// topological figures (components, boundary loops) are kept, the counts are the new base's.
/// Equal to mesh_quality(base) up to the order of summation.
void update_mesh_figures(const Mesh& old, const MeshQuality& quality, const Mesh& base,
                         const BaseChange& change, MeshQuality& new_quality);

/// The figures of mesh_quality() and laplacian_symmetry_defect() over the vertex statistics.
struct VertexFigures {
  VertexAreaFigures mixed_area, barycentric_area;
  double symmetry_defect = 0;
};

/// The vertex statistics of `base` and the figures over them: the mixed areas and the rows of −W
/// are those of `assembler` (built for `base`, or carried over to it), the barycentric areas are
/// carried over from `statistics` (the old base's) and measured again on the vertices of the new
/// faces. Equal to base_statistics(base), mesh_quality(base) and laplacian_symmetry_defect(base)
/// up to the order of summation. `threads`: 0 = all. Throws InvalidArgument when the assembler
/// is not of `base`'s size.
VertexFigures update_vertex_figures(const BaseStatistics& statistics, const Mesh& base,
                                    const BaseChange& change, const KHarmonicAssembler& assembler,
                                    BaseStatistics& new_statistics, int threads = 0);

/// laplacian_symmetry_defect(base) from the statistics (all rows).
double symmetry_defect(const Mesh& base, const BaseStatistics& statistics);

} // namespace remora
