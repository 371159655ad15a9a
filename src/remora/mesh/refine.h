// Longest-edge bisection of a region of a triangle mesh: the refinement `remora edit
// --refine-support` offers for a support whose own triangles are much longer than the editor's
// base (docs/editing.md, "A support of long triangles"). Only the input's vertices move in an
// edit, so a long triangle stays flat between its corners; split, it bends with the base.
//
// Every edge with both ends in `region` and longer than `max_length` is split at its midpoint,
// the longest first, pass after pass, until none is; each new vertex joins the region. A midpoint
// lies on its edge, so the surface does not change (creases and corners stay where they are).
// Faces with no edge inside the region are untouched; the old vertices keep their ids and
// positions, the new ones are numbered after them. Throws InvalidArgument for an id out of
// range, a max_length that is not > 0, or a refinement that would pass `max_vertices` vertices
// (then the mesh is left as it was).
#pragma once

#include <cstddef>
#include <vector>

#include "remora/mesh/mesh.h"

namespace remora {

struct RefineResult {
  std::size_t added = 0;   ///< new vertices
  std::vector<int> region; ///< the region's vertices after the refinement, sorted
};

RefineResult refine_region(Mesh& mesh, const std::vector<int>& region, double max_length,
                           std::size_t max_vertices);

} // namespace remora
