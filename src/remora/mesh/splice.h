// Replacing a part of a triangle mesh in place: a set of faces gives way to another triangulation
// with the same border, and the rest of the mesh keeps its elements and their numbers (the
// editor's local bake puts a remeshed patch back into its base this way, multires/bake.h).
#pragma once

#include <vector>

#include "remora/mesh/mesh.h"

namespace remora {

/// Where splice() put the elements: the new index of every old vertex and face (-1: removed)
/// and of every patch vertex and face.
struct SpliceMap {
  std::vector<int> vertices, faces;             ///< old index -> new index, -1 removed
  std::vector<int> patch_vertices, patch_faces; ///< patch index -> new index
};

/// Replaces the faces of `mesh` flagged in `removed` (one flag per face) by the faces of `patch`.
/// `origin` gives, per patch vertex, the vertex of `mesh` a boundary vertex of the patch stands
/// for, and -1 for every other patch vertex (a new one). The patch's boundary edges must be
/// exactly the edges of removed faces whose other side is a kept face or the mesh boundary, with
/// the removed faces on the patch's side. Vertices of `mesh` that only removed faces use, and
/// that are no origin, go; the patch's new vertices, edges and faces take the places of removed
/// ones first. Where fewer are needed, the last elements of the mesh move into the free places;
/// nothing else is renumbered and no kept point changes, so the work is proportional to the
/// patch, besides a pass over the face flags. Throws InvalidArgument, before changing anything,
/// when the sizes disagree, the mesh has deleted elements or an origin is out of range, a vertex
/// of a removed face that is no origin has kept faces too, or the borders do not match.
SpliceMap splice(Mesh& mesh, const std::vector<char>& removed, const Mesh& patch,
                 const std::vector<int>& origin);

} // namespace remora
