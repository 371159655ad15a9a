// Combinatorial topology of a Mesh: connected components, boundary loops, and per component the
// Euler characteristic and genus. Deleted elements (before garbage collection) are skipped; arrays
// are indexed by handle idx() and sized n_vertices() / n_faces(), with -1 for deleted elements.
#pragma once

#include <vector>

#include "remora/mesh/mesh.h"

namespace remora {

/// Components of the graph of vertices and edges; an isolated vertex is a component of its own.
/// Components are numbered 0..count-1 in the order of their smallest vertex index.
struct Components {
  std::vector<int> vertex_component; ///< by vertex idx(); -1 for deleted vertices
  std::vector<int> face_component;   ///< by face idx(); -1 for deleted faces
  int count = 0;
};

Components connected_components(const Mesh& mesh);

/// Every boundary loop as its boundary halfedges (the ones without a face) in next_halfedge order.
/// The mesh lies to the right of its boundary halfedges: seen from the side the faces' normals
/// point to, an outer boundary runs clockwise and a hole counter-clockwise. Loops are ordered by
/// their smallest halfedge index, and each starts at that halfedge.
/// Throws Error if the boundary's next pointers do not form cycles (corrupt connectivity).
std::vector<std::vector<HalfedgeHandle>> boundary_loops(const Mesh& mesh);

/// Counts of one connected component. euler = vertices - edges + faces. For a component with
/// faces, genus = (2 - euler - boundary_loops) / 2, exact for a connected orientable surface (with
/// boundary); a component whose vertices are pinched (non-manifold) has no meaningful genus and the
/// formula's value is truncated toward zero. An isolated vertex has euler = 1 and genus 0.
/// closed: at least one face and no boundary loop.
struct ComponentTopology {
  int vertices = 0;
  int edges = 0;
  int faces = 0;
  int boundary_loops = 0;
  int euler = 0;
  int genus = 0;
  bool closed = false;
};

/// One entry per component, in the numbering of connected_components().
std::vector<ComponentTopology> component_topology(const Mesh& mesh);

} // namespace remora
