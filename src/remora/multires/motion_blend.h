// The nonlinear method's blended motions (NonlinearEnergy::BlendedMotions, multires/nonlinear.h):
// the handles' rigid motions blended per vertex by the handles' scalar k-harmonic weights and
// applied to the rest shape, in closed form (no system, no iteration). Skinning with the
// editor's own weights (Jacobson et al. 2011 use biharmonic weights the same way) and with the
// motions interpolated as screws, so that a twisted or bent tube keeps its cross-sections
// (Kavan et al. 2008 blend dual quaternions for the same reason).
//
// Handle j's map M_j = R_j S_j (polar decomposition: rotation R_j, symmetric stretch S_j,
// multires/rotation_blend.h) is split at the handle's pivot o_j into the stretch about o_j and
// the rigid motion G_j(y) = R_j y + t_j + R_j (S_j − I) o_j, so that M_j p = G_j(o_j + S_j(p − o_j)).
// A vertex p with weights w_j (1 on handle j's vertices, 0 on the fixed ones) goes to
//
//   x = G(p + Σ_j w_j (S_j − I)(p − o_j)),   G = exp(Σ_j w_j log G_j),
//
// log G_j the twist of G_j's screw motion (se(3); the rotation's angle in [0, π], as
// rotation_log()), the identity taking the weight 1 − Σ_j w_j. Hence:
//   - a handle's own vertices go to M_j p, the fixed ones stay;
//   - one handle: G is the screw interpolation of the identity and G_j, so every set of
//     vertices of equal weight (a cylinder's rings, for a handle at one end) moves rigidly;
//   - translations only: x = p + Σ_j w_j t_j, the linear method's result for translations;
//   - weights summing to 1 and one rigid map of every handle: x = that map of p.
// Rotations differ from the linear method at first order: the linear method moves a vertex by
// its weight times the handle's own displacement (a lever at the handle), this by the blended
// motion of the vertex itself (docs/nonlinear.md).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "remora/multires/phong.h"

namespace remora {

/// A rigid motion's twist (ω, v): R = exp(ω) (rotation vector, angle |ω| in [0, π]) and
/// t = V(ω) v, V the left Jacobian of SO(3).
struct ScrewTwist {
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
};

/// log of the rigid motion y -> r y + t (r a rotation).
ScrewTwist screw_log(const Eigen::Matrix3d& r, const Eigen::Vector3d& t);

/// exp of a twist: the rotation `r` and translation `t` of the motion y -> r y + t.
void screw_exp(const ScrewTwist& twist, Eigen::Matrix3d& r, Eigen::Vector3d& t);

/// exp(twist) applied to the point y: r y + t of screw_exp(), without forming r.
Eigen::Vector3d screw_apply(const ScrewTwist& twist, const Eigen::Vector3d& y);

/// The handles' maps prepared for blending: their twists, stretches and pivots.
struct HandleMotions {
  std::vector<ScrewTwist> twist;
  std::vector<Eigen::Matrix3d> stretch; ///< S_j
  std::vector<Eigen::Vector3d> pivot;   ///< o_j
  bool stretched = false;               ///< some S_j is not the identity
};

/// `maps` are the handles' 3×4 maps [M | t] (det M > 0), `pivots` their rest pivots (one each).
/// Throws InvalidArgument when the counts differ.
HandleMotions handle_motions(const std::vector<Eigen::Matrix<double, 3, 4>>& maps,
                             const std::vector<Eigen::Vector3d>& pivots);

/// x.row(v) for every v of `vertices`: the blend above of rest.row(v) with weights.row(v)
/// (n × h, h the number of handles). Other rows of x are left as they are. Parallel over the
/// vertices (`threads`, 0 = all).
void blend_motions(const RowPoints& rest, const Eigen::MatrixXd& weights,
                   const std::vector<int>& vertices, const HandleMotions& motions, RowPoints& x,
                   int threads = 0);

} // namespace remora
