// Detail retention of an edit: how much of the input's fine detail the result still carries, the
// figure `remora edit --report` prints. The editor's promise (paper §3, Fig. 3) is that details
// ride on the deformed base surface instead of being smoothed away with it.
//
// With D(X) = X − low_pass(X) the details of positions X (n_vertices × 3, a row per vertex),
//   retention = sqrt( Σ_{v in vertices} |D(result)_v|² / Σ_{v in vertices} |D(input)_v|² ),
// the RMS length of the result's details over the input's, on the given vertices. For a low-pass
// filter that is linear, the same for every column, and keeps constants (the editor's does:
// W 1 = 0), so that D(X M + 1 tᵀ) = D(X) M:
//   result = input (an identity edit)                  → 1,
//   result = input moved rigidly (translated, rotated) → 1,
//   result = input scaled by s about any point        → |s|,
//   result = its own low-pass (no detail left)        → 0.
// A vertex set on which the input has no detail (an empty set included) gives 1: there was
// nothing to lose.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "remora/multires/editor.h"

namespace remora {

/// A low-pass filter of per-vertex values (n_vertices × any number of columns, same shape out).
using LowPassFunction = std::function<Eigen::MatrixXd(const Eigen::MatrixXd&)>;

/// The retention above for `input` and `result` (same shape) on `vertices` (row indices).
/// Throws InvalidArgument when the shapes differ, the filter returns another shape, or a vertex
/// is out of range.
double detail_retention(const Eigen::MatrixXd& input, const Eigen::MatrixXd& result,
                        const std::vector<int>& vertices, const LowPassFunction& low_pass);

/// The editor's figure: its input O against positions() under the current transforms, through
/// the editor's own low_pass() (the filter that made the base surface), on `vertices` of O
/// (usually the support). Throws as above.
double detail_retention(Editor& editor, const std::vector<int>& vertices);

} // namespace remora
