// Building a half-edge Mesh directly from oriented triangles, without OpenMesh's incremental
// add_face() (which may reject a face depending on the order faces arrive in).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "remora/mesh/mesh.h"

namespace remora {

/// Every point becomes a vertex (in order; isolated if no triangle uses it) and every triangle a
/// face (in order). Precondition, as repair_soup() guarantees: no directed edge is used by two
/// triangles, no triangle repeats a vertex, and the triangles around each vertex form one fan.
/// Throws InvalidArgument when an index is out of range or the precondition is violated.
Mesh build_mesh(const std::vector<Vec3>& points,
                const std::vector<std::array<std::uint32_t, 3>>& triangles);

} // namespace remora
