// Rays against a triangle mesh: a bounding volume hierarchy over its faces (median splits of the
// face centroids along the widest axis, four faces a leaf) and the first face a ray meets. The
// base-surface filter measures the local width of a part with it (geometry/thickness.h).
// The tree copies the faces' corners when it is built: later changes to the mesh are not seen.
// Queries are thread-safe (const, nothing allocated on the heap).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "remora/mesh/mesh.h"

namespace remora {

/// The first face met: origin + t direction lies on `face` (invalid when nothing was met, with
/// t = +inf). bary are the weights of face_vertices(face) at that point (each >= about -1e-12).
struct RayHit {
  FaceHandle face;
  double t = std::numeric_limits<double>::infinity();
  std::array<double, 3> bary{0.0, 0.0, 0.0};
};

class RayCaster {
public:
  /// Indexes the non-deleted faces of `mesh`. Throws InvalidArgument if a corner of one of them
  /// is not finite.
  explicit RayCaster(const Mesh& mesh);

  /// The face met first by origin + t direction, t in (t_min, t_max], skipping the faces around
  /// `skip` (pass an invalid handle to skip none): a ray cast from a vertex does not hit the
  /// faces it starts on. A face met exactly on an edge or corner counts (Möller–Trumbore with a
  /// relative 1e-12 tolerance on the barycentrics); faces of zero area are never met. direction
  /// need not be unit length; t is in its units. Throws InvalidArgument if origin or direction
  /// is not finite, direction is zero, or t_min > t_max.
  RayHit first_hit(const Vec3& origin, const Vec3& direction, double t_min, double t_max,
                   VertexHandle skip = VertexHandle()) const;

  /// Takes the corners of the same faces from `mesh` after its vertices moved (the editor's page
  /// picks on the edited shape): the bounds are recomputed, the tree's shape is kept, so queries
  /// stay exact and slow down only after large motions. O(faces), much cheaper than a rebuild.
  /// The faces left out at construction (zero area) stay out. Throws InvalidArgument if `mesh`
  /// has another number of vertices or a corner that is not finite.
  void refit(const Mesh& mesh);
  /// The same when only the vertices `moved` (ids) moved: only the leaves holding one of their
  /// faces and those leaves' ancestors are recomputed, so a drag of a small region costs what the
  /// region holds. The first call indexes the faces by vertex (twelve bytes per face kept).
  /// Throws InvalidArgument as refit(mesh) does, or for an id out of range.
  void refit(const Mesh& mesh, const std::vector<int>& moved);

  std::size_t n_faces() const { return faces_.size(); }

private:
  struct Node {
    float lo[3], hi[3]; // bounds, rounded outwards to float
    std::int32_t first; // leaf: first index into faces_; inner node: the right child
    std::int32_t count; // leaf: number of faces (> 0); inner node: 0 (the left child is next)
  };
  struct Face {
    std::int32_t v[3]; // corners, by vertex idx() into points_
    std::int32_t face;
  };
  void refit_node(std::size_t i); // bounds from its faces (leaf) or its children (inner)
  void index_for_partial_refit(); // parent_, slot_leaf_, vertex_slots_
  void build(std::vector<Node>& nodes, std::vector<std::int32_t>& order,
             const std::vector<Vec3>& centroids, std::int32_t begin, std::int32_t end,
             bool split) const;
  std::vector<Vec3> points_; // the mesh's vertices
  std::vector<Node> nodes_;
  std::vector<Face> faces_; // in the order of the leaves
  // For refit(mesh, moved), built on its first call: each node's parent (-1 at the root), each
  // face slot's leaf, and the face slots around each vertex (CSR).
  std::vector<std::int32_t> parent_, slot_leaf_, vertex_slots_begin_, vertex_slots_;
};

} // namespace remora
