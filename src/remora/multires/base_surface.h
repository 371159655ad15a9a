// The base surface S of the editor (paper §3, Fig. 3): a low-pass filtered copy of the user's
// mesh with the same connectivity, by one or more steps of implicit fairing (Desbrun, Meyer,
// Schröder, Barr 1999), (M − t W) S = M X, with W and M the Laplacian and lumped mass of the
// mesh's intrinsic Delaunay triangulation (geometry/intrinsic.h). That operator is robust on
// needles and zero-area faces, where the mesh's own cotan weights are huge or negative and would
// make the system indefinite; docs/editing.md says why this choice and what it measured.
//
// Boundaries: a boundary loop is filtered as a curve, by the same step with the curve's own
// operator (edge weights 1/length, mass half the adjacent boundary lengths), and the interior then
// takes the filtered loops as Dirichlet values, so a straight, evenly sampled boundary of a plane
// stays where it is. The surface operator's natural condition instead would pull every boundary
// vertex inward in the tangent plane, by about σ, and fold the first rows of triangles
// (docs/editing.md).
//
// Strength: t = σ², σ = smoothing × the mesh's length scale (its mean edge length unless needles
// inflate it: geometry/measures.h, length_scale()). A Laplacian eigenfunction of
// wavelength λ is scaled by 1 / (1 + (2πσ/λ)²) per step: wavelengths below 2πσ lose at least half.
// The filter is set up once and applied to any positions (Jacobi-preconditioned CG solves).
//
// Locality: the filter's kernel (M − t W)⁻¹ M is a screened Poisson kernel, which decays like
// exp(−d/σ) with the distance d along the surface. apply_local() solves the same system on a
// vertex set only, the values outside taken as zero: for values that vanish outside a region, the
// result on the region grown by a band of a few σ matches apply() up to that decay (the editor's
// local bake, multires/bake.h, uses it for the change of an edit).
//
// Feature cap: a tube or a hole of radius r is such a short wavelength; one step scales its
// radius by about 1 / (1 + σ²/r²), so a hole smaller than σ closes into a neck and an arm
// thinner than σ shrinks to a thread, which the remesher cannot line with triangles of the
// target size and over which the Phong offsets (larger than the base's curvature radius) cross.
// So σ varies per vertex: σ_i = min(σ, feature_cap × the vertex's half-width), the half-width
// measured by rays across the part (geometry/thickness.h), then relaxed to the largest field
// below that which changes by at most cap_slope per unit length along edges; an edge's weight
// is scaled by σ_i σ_j instead of σ². A boundary loop's σ is at most feature_cap × its radius
// (perimeter / 2π). A part thicker than 2σ/feature_cap everywhere, with loops longer than
// 2πσ/feature_cap, is filtered exactly as without the cap. docs/editing.md has what it measured.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "remora/geometry/intrinsic.h"
#include "remora/mesh/mesh.h"

namespace remora {

struct LowPassOptions {
  /// σ in units of length_scale() (the mean edge length on a mesh without needles); 0 turns the
  /// filter into the identity.
  double smoothing = 2.0;
  /// σ_i <= feature_cap × half-width (above); 0 turns the cap off (one σ everywhere). At 1 a
  /// tube or hole keeps about half its radius.
  double feature_cap = 1.0;
  /// How fast σ may grow again away from a capped vertex (per unit length; > 0).
  double cap_slope = 1.0;
  int threads = 0; ///< for the half-widths; 0 = all hardware threads
  /// Implicit steps with the same operator (a steeper cut-off).
  int steps = 1;
  /// Relative residual of every CG solve.
  double tolerance = 1e-10;
};

struct LowPassStats {
  double sigma = 0.0;                 ///< absolute σ
  double sigma_min = 0.0;             ///< the smallest σ_i (σ when no vertex is capped)
  std::size_t capped = 0;             ///< vertices whose σ_i < σ
  std::size_t capped_loops = 0;       ///< boundary loops filtered with a σ below σ
  IntrinsicLaplacian laplacian_stats; ///< flips, clamps (weights and mass are not kept here)
};

/// The filter's σ per vertex (by idx()) for an absolute σ `sigma`: the cap and its relaxation
/// above. Without the cap, or on a part thick enough, every entry is `sigma`. Isolated vertices
/// keep `sigma`. Throws InvalidArgument for a negative or non-finite sigma, feature_cap or a
/// cap_slope that is not > 0.
Eigen::VectorXd smoothing_field(const Mesh& mesh, double sigma, const LowPassOptions& options);

class LowPassFilter {
public:
  /// Builds the operator of `mesh` (its points define the metric). Throws InvalidArgument for a
  /// negative or non-finite smoothing or feature_cap, a cap_slope that is not > 0, or steps < 1.
  LowPassFilter(const Mesh& mesh, const LowPassOptions& options = {});
  LowPassFilter(LowPassFilter&&) noexcept;
  LowPassFilter& operator=(LowPassFilter&&) noexcept;
  ~LowPassFilter();

  /// The filtered values of `values` (n_vertices × any number of columns, e.g. positions).
  /// Isolated vertices keep their values. Throws InvalidArgument for a wrong row count and
  /// NumericalError if CG does not converge. Const and thread-safe: the filter may be shared.
  Eigen::MatrixXd apply(const Eigen::MatrixXd& values) const;
  /// The same system solved on the vertices `region` only (distinct ids; row r of `values` and
  /// of the result belong to vertex region[r]), with every value outside the region taken as 0:
  /// the boundary loops' curve system on the region's boundary vertices, then the interior one
  /// on its interior vertices. For values that are 0 outside a set X, the result differs from
  /// apply()'s on the region by about exp(−d/σ) × the values' size, d the distance from X to
  /// the region's border. Throws InvalidArgument for an id out of range or a wrong row count,
  /// NumericalError if CG does not converge.
  Eigen::MatrixXd apply_local(const std::vector<int>& region, const Eigen::MatrixXd& values) const;

  const LowPassStats& stats() const { return stats_; }

private:
  Eigen::Index n_ = 0;
  // Interior vertices (all of them on a closed mesh), then boundary vertices: their row indices,
  // and per vertex its row in its own block.
  std::vector<Eigen::Index> interior_, boundary_;
  std::vector<Eigen::Index> place_;
  std::vector<char> on_boundary_;
  Eigen::VectorXd mass_, boundary_mass_;
  Eigen::SparseMatrix<double> system_;   // (M − t W) on the interior rows and columns
  Eigen::SparseMatrix<double> coupling_; // t W restricted to interior rows, boundary columns
  Eigen::SparseMatrix<double> loops_;    // the loops' curve system on the boundary block
  double tolerance_ = 1e-10;
  bool solved_ = false; // false: smoothing == 0, the identity
  int steps_ = 1;
  LowPassStats stats_;
};

} // namespace remora
