// The base surface S of the editor (paper §3, Fig. 3): a low-pass filtered copy of the user's
// mesh with the same connectivity, by one or more steps of implicit fairing (Desbrun, Meyer,
// Schröder, Barr 1999), (M − t W) S = M X, with W and M the Laplacian and lumped mass of the
// mesh's intrinsic Delaunay triangulation (geometry/intrinsic.h). That operator is robust on
// needles and zero-area faces, where the mesh's own cotan weights are huge or negative and would
// make the system indefinite; docs/editing.md says why this choice and what it measured.
//
// Boundaries: a boundary loop is filtered as a curve, by the same step with the curve's own
// operator (edge weights 1/length, mass half the adjacent boundary lengths), and the interior then
// takes the filtered loops as Dirichlet values. With the surface operator's natural condition
// instead, the cotan Laplacian pulls every boundary vertex inward in the tangent plane: by 2 mean
// edge lengths on heightfield/AcrossRiver.stl at σ = 2, where the first rows of triangles folded
// (docs/editing.md). A straight, evenly sampled boundary of a plane now stays where it is.
//
// Strength: t = σ², σ = smoothing × the mesh's length scale (its mean edge length unless needles
// inflate it: geometry/measures.h, length_scale()). A Laplacian eigenfunction of
// wavelength λ is scaled by 1 / (1 + (2πσ/λ)²) per step: wavelengths below 2πσ lose at least half.
// The filter is factored once (a Jacobi-preconditioned CG set-up) and applied to any positions.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "remora/geometry/intrinsic.h"
#include "remora/linalg/solver.h"
#include "remora/mesh/mesh.h"

namespace remora {

struct LowPassOptions {
  /// σ in units of length_scale() (the mean edge length on a mesh without needles); 0 turns the
  /// filter into the identity.
  double smoothing = 2.0;
  /// Implicit steps with the same operator (a steeper cut-off).
  int steps = 1;
  /// Relative residual of every CG solve.
  double tolerance = 1e-10;
};

struct LowPassStats {
  double sigma = 0.0;                 ///< absolute σ
  IntrinsicLaplacian laplacian_stats; ///< flips, clamps (weights and mass are not kept here)
  int iterations = 0; ///< CG iterations of the last apply(), the most over the columns
};

class LowPassFilter {
public:
  /// Builds the operator of `mesh` (its points define the metric). Throws InvalidArgument for a
  /// negative or non-finite smoothing, or steps < 1.
  LowPassFilter(const Mesh& mesh, const LowPassOptions& options = {});
  LowPassFilter(LowPassFilter&&) noexcept;
  LowPassFilter& operator=(LowPassFilter&&) noexcept;
  ~LowPassFilter();

  /// The filtered values of `values` (n_vertices × any number of columns, e.g. positions).
  /// Isolated vertices keep their values. Throws InvalidArgument for a wrong row count and
  /// NumericalError if CG does not converge.
  Eigen::MatrixXd apply(const Eigen::MatrixXd& values);

  const LowPassStats& stats() const { return stats_; }

private:
  Eigen::Index n_ = 0;
  // Interior vertices (all of them on a closed mesh), then boundary vertices: their row indices.
  std::vector<Eigen::Index> interior_, boundary_;
  Eigen::VectorXd mass_, boundary_mass_;
  Eigen::SparseMatrix<double> coupling_; // t W restricted to interior rows, boundary columns
  // The interior system; null when smoothing == 0 or when no vertex is interior.
  std::unique_ptr<Solver> solver_;
  std::unique_ptr<Solver> boundary_solver_; // the loops' curve system; null without boundary
  bool solved_ = false;                     // false: smoothing == 0, the identity
  int steps_ = 1;
  LowPassStats stats_;
};

} // namespace remora
