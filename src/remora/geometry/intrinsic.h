// A Laplacian that stays well-behaved on needles, caps and zero-area faces: the cotan Laplacian
// of an intrinsic Delaunay triangulation of the mesh's own metric (Bobenko & Springborn 2007),
// after intrinsic mollification (Sharp & Crane 2020, "A Laplacian for Nonmanifold Triangle
// Meshes", §4.5). The vertices and the edge lengths of the input define a flat metric; edges are
// flipped intrinsically (lengths from the layout of the two triangles, no vertex moves) until
// every edge's cotan weight is >= 0. The result acts on the mesh's vertices like cotan_weights()
// (same sign conventions), with a lumped mass; the input mesh is not modified.
//
// Why (docs/editing.md): the base surface of the editor is a low-pass filter of the user's mesh,
// and scans and CAD tessellations carry needles whose cotan weights are huge or negative, which
// turns implicit fairing into an indefinite, badly conditioned system. On an intrinsic Delaunay
// triangulation every weight is >= 0, so (M + t L) is an M-matrix for every t > 0.
#pragma once

#include <cstddef>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "remora/mesh/mesh.h"

namespace remora {

struct IntrinsicOptions {
  /// Mollification: every edge length grows by the least ε for which each triangle satisfies the
  /// triangle inequality with margin δ = mollify_factor × the mean edge length.
  double mollify_factor = 1e-5;
  /// Give up flipping after this many flips per edge (never reached in practice; the flip
  /// algorithm terminates on its own).
  int max_flips_per_edge = 50;
};

struct IntrinsicLaplacian {
  /// n_vertices × n_vertices, symmetric: W_ij = (cot α_ij + cot β_ij) / 2 >= 0 summed over the
  /// intrinsic edges between i and j, W_ii = −Σ_j W_ij. Rows of deleted or isolated vertices are
  /// empty.
  Eigen::SparseMatrix<double> weights;
  /// Lumped (barycentric) vertex areas of the intrinsic triangles; > 0 for every vertex with a
  /// face after mollification.
  Eigen::VectorXd mass;
  double epsilon = 0.0;             ///< the mollification added to every edge length
  std::size_t flips = 0;            ///< intrinsic flips made
  std::size_t negative_before = 0;  ///< edges of the input with a cotan weight < 0
  std::size_t negative_after = 0;   ///< interior edges left with a weight < 0 (flip refused)
  std::size_t clamped_boundary = 0; ///< boundary edges whose negative weight was set to 0
};

/// Builds the intrinsic Delaunay Laplacian of `mesh`. An edge whose flip OpenMesh refuses (the
/// two opposite vertices already joined, which the intrinsic setting would allow) keeps its
/// weight and is counted in negative_after. A boundary edge cannot be flipped: a negative weight
/// there (an obtuse corner opposite it) is set to 0 and counted in clamped_boundary. Throws
/// InvalidArgument when options are not finite and positive.
IntrinsicLaplacian intrinsic_delaunay_laplacian(const Mesh& mesh,
                                                const IntrinsicOptions& options = {});

} // namespace remora
