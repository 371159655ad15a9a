// A nonlinear, rotation-invariant deformation of the editor's hidden base (docs/nonlinear.md).
// The linear method of Botsch & Kobbelt 2004 blends the handles' affine maps
// linearly, so a rotated handle shears and shrinks the support (Botsch & Sorkine 2008, §4). This
// deformer minimizes an energy that is invariant under rotations of the rest shape's local
// pieces instead, by alternating a local step (one 3×3 rotation per vertex, Procrustes) and a
// global step (one sparse solve with a matrix factored once per region):
//
//   E(x, R) = Σ_m [ a ‖(W x)_m − R_m S_m δ_m‖² + β Σ_{j~m} w_mj ‖x_m − x_j − R_m S_m e⁰_mj‖² ]
//
// over the vertices m that are free or next to a free one, with W the cotan matrix of the base B
// (geometry/laplacian.h; w_mj its off-diagonal entries), x⁰ the rest shape (B0: the linear fill
// with the handles at rest, against which the details are encoded), δ = W x⁰ its Laplacian
// coordinates, e⁰_mj = x⁰_m − x⁰_j, and S_m the stretch of the handles' maps blended by the
// handles' scalar k-harmonic weights (identity for rotations and translations).
//   Energy::Arap            a = 0: as-rigid-as-possible (Sorkine & Alexa 2007), a membrane;
//                           global matrix −2βW.
//   Energy::RotatedLaplacian a = 1: rotated Laplacian coordinates (the thin plate's W², as the
//                           k = 2 system) plus the ARAP term that fixes the rotations; global
//                           matrix W² − 2βW.
//   Energy::PropagatedRotations a = 1, β = 0, and no local step: R_m is the handles' rotations
//                           (polar parts of their maps) blended by the handles' weights, the
//                           identity taking the rest (multires/rotation_blend.h; Zayer et al.
//                           2005, Lipman et al. 2004); x is one solve of the W² system for those
//                           rotations, so a frame is one back-substitution and no iteration.
//   Energy::BlendedMotions  no energy and no system: the handles' whole rigid motions (screws)
//                           blended by the same weights and applied to x⁰ in closed form
//                           (multires/motion_blend.h); a twisted or bent tube keeps its
//                           cross-sections, which no energy above does with the ends held.
// For the iterative energies (Arap, RotatedLaplacian) each local step minimizes E over R exactly
// and each global step over x exactly (the matrix is positive definite), so E never increases. Anderson acceleration (Peng et al. 2018) extrapolates
// from the last iterates and keeps an extrapolated step only when it lowers E.
//
// Exact cases: all transforms identity -> x⁰ bit for bit (no iteration); one rigid motion of
// every constraint -> that motion of x⁰ (E = 0 there, and the minimizer is unique).
//
// Shapes: positions are n_vertices × 3 rows (row = vertex idx); only the free rows change.
// Labels as linalg/kharmonic.h's Region. Throws InvalidArgument for mismatched sizes and
// NumericalError when the global matrix cannot be factored.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "remora/linalg/kharmonic.h"
#include "remora/linalg/solver.h"
#include "remora/mesh/mesh.h"
#include "remora/multires/phong.h"

namespace remora {

/// An affine map x -> M x + t as the 3×4 matrix [M | t] (also multires/editor.h's Transform).
using AffineMap = Eigen::Matrix<double, 3, 4>;

/// How the editor deforms the base under the handles' maps (multires/editor.h).
enum class EditMethod {
  Linear,    ///< the blend of the k-harmonic basis functions (the paper; exact for affine maps)
  Nonlinear, ///< this file's deformation from B0, warm-started by the blend (large rotations)
};
std::string to_string(EditMethod method);
EditMethod parse_edit_method(const std::string& name); ///< "linear", "nonlinear"

/// The energies above; PropagatedRotations is one solve, BlendedMotions a closed form, the others
/// local/global iterations.
enum class NonlinearEnergy { Arap, RotatedLaplacian, PropagatedRotations, BlendedMotions };

struct NonlinearOptions {
  NonlinearEnergy energy = NonlinearEnergy::RotatedLaplacian;
  /// RotatedLaplacian: the ARAP term's weight β = rigidity / (number of free vertices), i.e.
  /// rigidity × mean vertex area / support area, so that the balance of the two terms does not
  /// change when the base is refined or the shape scaled. Arap: β = 1. PropagatedRotations: β = 0
  /// (unused).
  double rigidity = 100.0;
  int max_iterations = 200; ///< since the last set_transforms()
  /// Converged when the largest move of a free vertex in an iteration is below this times the
  /// base's mean edge length, or when E fell by less than energy_tolerance × E per iteration over
  /// the last three.
  double tolerance = 1e-4;
  double energy_tolerance = 1e-4;
  int anderson = 5;     ///< Anderson history length; 0 = plain local/global iterations
  SolverOptions solver; ///< the global step's factorization (empty name: the default)
  /// The editor: a support of more than twice this many free base vertices is previewed while
  /// dragging on a coarse remesh of the base with about this many (multires/nonlinear_region.h);
  /// 0 = never. Not for PropagatedRotations (one solve per frame).
  int preview_vertices = 4000;
  int threads = 0; ///< 0 = all
};

struct NonlinearStats {
  int iterations = 0;         ///< in the last solve() call
  int total_iterations = 0;   ///< since the last set_transforms()
  std::vector<double> energy; ///< E after each accepted iterate of the last call, start first
  int accelerated = 0;        ///< iterates of the last call taken from Anderson's extrapolation
  bool converged = false;
  bool exhausted = false; ///< max_iterations reached before converging
  bool finished() const { return converged || exhausted; }
  double last_move = 0.0; ///< largest free-vertex move of the last iteration / edge length
};

class NonlinearDeformer {
public:
  /// `base`: B at rest (its cotan weights and connectivity); `rest`: x⁰, n × 3 (equal to B on
  /// the constrained vertices); `labels`: per vertex kFree, kFixed or a handle index;
  /// `handle_weights`: n × h, the handles' scalar k-harmonic weights (1 on the handle's own
  /// vertices, 0 on the fixed ones). Factors the global matrix.
  NonlinearDeformer(const Mesh& base, const Eigen::MatrixXd& rest, const std::vector<int>& labels,
                    const Eigen::MatrixXd& handle_weights, const NonlinearOptions& options = {});
  ~NonlinearDeformer();
  NonlinearDeformer(NonlinearDeformer&&) noexcept;
  NonlinearDeformer& operator=(NonlinearDeformer&&) noexcept;

  /// New handle maps (one per handle). `guess` (n × 3, or nullptr), e.g. the linear result, is a
  /// start for the free vertices: the iteration starts from whichever of it and the current
  /// positions moved as the guess moved since the last call has the lower energy (without a
  /// guess: the current positions). Resets the iteration's history.
  void set_transforms(const std::vector<AffineMap>& transforms, const RowPoints* guess = nullptr);
  /// Iterates until converged, max_iterations (counted since set_transforms()) or `budget_ms` of
  /// wall time: at least one iteration unless finished, and another only when it would end within
  /// the budget, were it as slow as the slowest of this call, and `interrupt` (when given) returns
  /// false (a caller with other work waiting). Returns the stats of this call.
  const NonlinearStats& solve(double budget_ms = 1e300,
                              const std::function<bool()>& interrupt = {});
  /// Every base vertex: the free rows as solved, the constrained ones at their values.
  const RowPoints& positions() const;
  const std::vector<int>& free_vertices() const;
  const NonlinearStats& stats() const;
  /// E at the current positions with the best rotations (PropagatedRotations: the propagated
  /// ones).
  double energy() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

std::string to_string(NonlinearEnergy energy);
/// "arap", "rotated-laplacian", "propagated", "blended-motions"
NonlinearEnergy parse_nonlinear_energy(const std::string& name);
/// The names parse_nonlinear_energy() takes, the default first.
const std::vector<std::string>& nonlinear_energy_names();

} // namespace remora
