// Step 7 of the editor, one frame (Botsch & Kobbelt 2004 §6; editor.h): the blend of the basis
// functions into the base's free vertices, and the base's normals where they can change. Both
// run once per handle move, so they are written for memory traffic: the basis is read once, row
// by row, and each face's normal is computed once.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "remora/multires/phong.h"

namespace remora {

/// The basis functions, one row per free base vertex (n_free × (3 + 4h)), row-major so that a
/// vertex's coefficients lie together.
using BasisRows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// positions.row(free_vertices[i]) = basis.row(i) · coefficients for every i: the blend
/// X_free = Φ C of editor.h. coefficients: (3 + 4h) × 3. Parallel over the rows with `threads`
/// threads (0 = all). Sizes are the caller's contract (checked in debug builds only).
void blend_basis(const BasisRows& basis, const Eigen::MatrixXd& coefficients,
                 const std::vector<int>& free_vertices, RowPoints& positions, int threads);

/// What a frame's normals need, built once per region: `vertices`, whose normals can change;
/// `faces`, every face around one of them; `ring`, for vertices[i] the positions in `faces` of its
/// faces, ring[ring_begin[i] .. ring_begin[i + 1]), in the order of topology.vertex_faces.
struct NormalPlan {
  std::vector<int> vertices, faces, ring_begin, ring;
};

/// The plan for the normals of `vertices` (base vertex ids).
NormalPlan plan_normals(const TriangleTopology& topology, const std::vector<int>& vertices);

/// normals.row(v) for every v of plan.vertices, as vertex_normals() computes them (the same sums
/// in the same order, so bit for bit the same): the normalized sum of the faces' cross products,
/// (0, 0, 0) where it vanishes. `scratch` holds the faces' cross products between calls.
void update_normals(const TriangleTopology& topology, const RowPoints& positions,
                    const NormalPlan& plan, RowPoints& normals, std::vector<double>& scratch,
                    int threads);

} // namespace remora
