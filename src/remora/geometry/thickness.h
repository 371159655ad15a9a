// The local half-width of a part at each vertex: half the distance to the surface across it,
// along the vertex normal, on both sides. Inside the material that is half the wall's thickness
// (a plate's, a tube's diameter); outside, half the gap (a hole's diameter, the slot between two
// fingers). The base-surface filter (multires/base_surface.h) caps its σ with it so that a tube
// or hole thinner than the filter does not collapse into a neck.
//
// Rays (geometry/raycast.h) leave each vertex along its angle-weighted normal n (Thürmer &
// Wüthrich 1998), once along +n and once along -n, and the first face met counts only when it
// faces the right way: a ray through air (+n) must meet a face turned towards it, a ray through
// material (-n) one turned away. A face met the wrong way (an open mesh's back side, a
// self-intersection) or no face at all leaves that side unbounded. The mesh should be
// consistently oriented with outward normals (mesh/repair.h orients closed parts so).
#pragma once

#include <limits>

#include <Eigen/Core>

#include "remora/mesh/mesh.h"

namespace remora {

struct HalfWidthOptions {
  /// Faces met closer than this (absolute, >= 0) are passed over: they are the vertex's own
  /// neighbourhood folded over (a needle, a zero-area fan), not the other side of the part.
  double min_distance = 0.0;
  /// Rays stop here (absolute, > min_distance; +inf = no limit): a vertex whose part is wider
  /// than this on both sides gets +inf. The filter asks only up to 2σ / feature_cap, which keeps
  /// the rays short on thick parts.
  double max_distance = std::numeric_limits<double>::infinity();
  int threads = 0; ///< 0 = all hardware threads
};

/// Per vertex (n_vertices() rows, by idx()): half the distance to the nearest face met along the
/// vertex's normal on either side, +inf when neither side meets one the right way, and for
/// isolated vertices and vertices whose normal vanishes (a flat fold). Throws InvalidArgument if
/// min_distance is negative or not finite, max_distance is not above it, or a corner is not
/// finite.
Eigen::VectorXd vertex_half_widths(const Mesh& mesh, const HalfWidthOptions& options = {});

} // namespace remora
