// Rotations of the handles' maps and their blend by the handles' scalar weights, for the
// nonlinear method's propagated rotations (multires/nonlinear.h; Zayer, Rössl, Karni & Seidel
// 2005, "Harmonic guidance for surface deformation"; Lipman et al. 2004).
//
// A handle's map M = R S (polar decomposition) contributes its rotation R as the unit
// quaternion q with non-negative real part (the shorter way from the identity, an angle in
// [0, π]). A vertex with weights w_j (k-harmonic: 1 on handle j, 0 on the fixed vertices) gets
//   R = exp(Σ_j w_j log q_j),
// the identity taking the remaining weight 1 − Σ_j w_j (log 1 = 0). For one handle this is the
// slerp from the identity by w; when the weights sum to 1 and every handle has the same
// rotation it is that rotation (to round-off).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace remora {

/// The rotation R of the polar decomposition M = R S (the nearest rotation to M; for det M < 0
/// the nearest rotation, which then is not M's polar factor).
Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& m);

/// The symmetric factor S = V Σ Vᵀ of M = U Σ Vᵀ (M = R S when det M > 0).
Eigen::Matrix3d polar_stretch(const Eigen::Matrix3d& m);

/// log q for the unit quaternion of `r` with non-negative real part: the rotation vector
/// (axis × angle, angle in [0, π]).
Eigen::Vector3d rotation_log(const Eigen::Matrix3d& r);

/// exp of a rotation vector: the rotation by |v| about v / |v|.
Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& v);

/// exp(Σ_j weights[j] logs[j]): the blend above, with logs[j] = rotation_log(R_j).
Eigen::Matrix3d blend_rotations(const std::vector<Eigen::Vector3d>& logs,
                                const Eigen::Ref<const Eigen::RowVectorXd>& weights);

} // namespace remora
