// Internal to the soup repair (repair*.cpp): the steps that stand on their own, one file each.
// Not part of the public API; repair.h states what the repair as a whole promises.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "remora/mesh/mesh.h"
#include "remora/mesh/repair.h"
#include "remora/mesh/soup.h"

namespace remora::repair_detail {

using Tri = std::array<std::uint32_t, 3>;

/// "No vertex": an unreferenced soup vertex, an empty cell, the end of a list.
inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

/// Steps 1 and 2 (repair_weld.cpp): the soup's referenced vertices, welded.
struct Welded {
  std::vector<std::uint32_t> vertex_of; ///< soup vertex -> welded vertex (kNone: unreferenced)
  std::vector<Vec3> points;             ///< the welded vertices, in the order first met
  std::vector<std::uint32_t> source;    ///< per welded vertex, the soup vertex it came from
  std::size_t unreferenced = 0;         ///< soup vertices no polygon uses
  std::size_t welded = 0;               ///< merged into a bit-identical earlier vertex
  std::size_t near_welded = 0;          ///< merged into an earlier one within the tolerance
};

/// Drops the vertices no polygon references; with options.weld merges bit-identical ones
/// (-0 == +0) into the first of them, then, with options.weld_tolerance > 0, every vertex within
/// weld_tolerance × the bounding-box diagonal of an earlier survivor into the first such
/// survivor (file order; the result does not depend on hashing). A soup with a non-finite point
/// gets no near weld. Indices must be in range (the caller checks).
Welded weld_vertices(const PolygonSoup& soup, const RepairOptions& options);

/// Step 3 (repair_triangulate.cpp): ear clipping of the polygon `poly` (ids into `pts`, at least
/// three) in its best-fit (Newell) plane, appending n − 2 triangles to `out` with the polygon's
/// winding. Falls back to clipping the flattest corner when no proper ear exists
/// (self-overlapping or degenerate input), so it always produces n − 2 triangles.
void triangulate_polygon(const std::vector<Vec3>& pts, const std::vector<std::uint32_t>& poly,
                         std::vector<Tri>& out);

} // namespace remora::repair_detail
