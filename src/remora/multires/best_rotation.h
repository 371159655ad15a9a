// The local step of as-rigid-as-possible iterations (Sorkine & Alexa 2007, Eq. 6): the rotation
// that best turns a vertex's rest cell into its current one. Used by NonlinearDeformer
// (multires/nonlinear.h).
#pragma once

#include <Eigen/Core>

namespace remora {

/// The local step's rotation: R maximizing tr(R P) (orthogonal Procrustes), improved from
/// `start` by power iterations on Horn's quaternion matrix (1987): never worse than `start`, the
/// best rotation to round-off unless P is nearly degenerate (then it is still no worse).
Eigen::Matrix3d best_rotation(const Eigen::Matrix3d& p, const Eigen::Matrix3d& start);

} // namespace remora
