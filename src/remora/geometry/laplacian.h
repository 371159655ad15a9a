// The discrete Laplace-Beltrami operator of the paper's Eq. 1: cotangent weights over mixed
// Voronoi areas (Meyer, Desbrun, Schroeder, Barr 2003). For a function f on the vertices,
//
//   (Delta f)_i = (1 / A_i) sum_{j in N(i)} W_ij (f_j - f_i) = (A^-1 W f)_i,
//   W_ij = (cot alpha_ij + cot beta_ij) / 2,   W_ii = -sum_j W_ij,
//
// with A = diag(vertex_areas_mixed(mesh)) and alpha_ij, beta_ij the angles opposite the edge ij.
// Normalization: Delta (x^2 + y^2) = 4 on a plane, and on a surface Delta x = -2 H n with H the
// mean curvature and n the outward normal (a sphere of radius r: -2 x / r^2). The paper writes
// 2 (cot alpha + cot beta) / A(p_i), 4 times this operator; a constant factor does not change the
// solutions of Delta^k p = 0 (Eq. 3). Sign: Delta is negative semi-definite like the smooth one
// (f^T W f = -sum_edges W_ij (f_i - f_j)^2 <= 0 whenever every W_ij >= 0, e.g. on Delaunay meshes).
// Vertices are indexed by idx(); deleted faces are ignored.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "remora/mesh/mesh.h"

namespace remora {

/// The symmetric n_vertices() x n_vertices() matrix W above. Structure: an entry for both
/// directions of every live edge and a diagonal entry for every vertex with an edge (values may
/// be 0); rows of deleted and isolated vertices are empty. Each face contributes cot(corner) / 2
/// to the edge opposite each corner, so a boundary edge has one term. A face whose doubled area is
/// at most 1e-12 times its longest squared edge (collinear or coincident corners, to round-off)
/// contributes nothing; every other face's cotangent is dot / |cross| of the corner's edge vectors,
/// whose magnitude that threshold bounds by 1e12. No entry is NaN or Inf. W 1 = 0 to round-off.
Eigen::SparseMatrix<double> cotan_weights(const Mesh& mesh);

/// W_ij of the one edge e = (i, j), the same value as cotan_weights()'s entry.
double cotan_weight(const Mesh& mesh, EdgeHandle e);
/// The same at the positions `points` (a row per vertex idx(), 3 columns) instead of the mesh's
/// own: what cotan_weights() gives for the mesh moved to them.
double cotan_weight(const Mesh& mesh, const Eigen::MatrixXd& points, EdgeHandle e);

/// W_ij of every edge, by edge idx() (0 for deleted edges): cotan_weights()'s off-diagonal
/// entries without the matrix.
std::vector<double> cotan_edge_weights(const Mesh& mesh);

/// The symmetric n_vertices() x n_vertices() matrix of any edge weights, assembled like W above:
/// W_ij = W_ji = weights[e.idx()] for every live edge e = (i, j), W_ii = -sum_j W_ij (summed in
/// edge order), with cotan_weights()'s structure. Throws InvalidArgument unless `weights` has
/// n_edges() entries, and Error for two edges joining the same two vertices (which a half-edge
/// mesh built by add_face() does not have).
Eigen::SparseMatrix<double> weights_matrix(const Mesh& mesh, const std::vector<double>& weights);

/// How far the Laplacian is from its symmetric approximation of paper §5 (every A_i replaced by
/// the mean area A_bar over the non-deleted, non-isolated vertices):
///   || A^-1 W - A_bar^-1 W ||_F / || A^-1 W ||_F,
/// W including its diagonal. Computed in O(V + E) without forming either matrix. Scale-invariant;
/// 0 when all mixed areas are equal. Rows of vertices with zero mixed area (all their faces have
/// zero area) are left out, since A^-1 W is undefined there; returns 0 when nothing is left.
///
/// `SymmetryRows::Interior` leaves out the rows of mesh-boundary vertices, from the mean too. On an
/// open mesh those rows cannot match: a boundary vertex of a well-shaped mesh has about half an
/// interior vertex's area (its triangles span π, not 2π), so they alone put the full defect near
/// 0.08–0.15 however equal the interior is. The interior figure is what a support away from the
/// mesh boundary sees (docs/remesh.md).
enum class SymmetryRows { All, Interior };
double laplacian_symmetry_defect(const Mesh& mesh, SymmetryRows rows = SymmetryRows::All);

} // namespace remora
