// Phong detail encoding (Kobbelt, Vorsatz, Seidel 1999; paper §3): a point p is stored against a
// base triangle mesh as a base point b (a face and barycentric coordinates α, not restricted to
// vertices) and an offset λ along the normal n(b) interpolated from the base's vertex normals,
//   p = b + λ n̂(b),  b = Σ α_i x_i,  n̂(b) = normalize(Σ α_i n_i).
// Decoding on a deformed base (same connectivity, moved vertices) puts p' = b' + λ n̂'(b'): the
// detail follows the base's translation and rotation, and keeps its size.
//
// The base point is found by Newton's method on (α, λ) within a face, starting at a given face
// and walking across the edge of the most negative barycentric coordinate until the coordinates
// are all >= -1e-9 (a containing face). Where the walk meets the mesh boundary, cycles or runs
// out of steps, the best face visited is kept with coordinates slightly outside it (down to
// -0.1: extrapolated). When Newton fails in the start face and its neighbours (a point beyond the
// focal surface of the base) or the best solution lies farther outside, the detail is the clamped
// orthogonal projection onto the best face, the offset along the normal there, and the rest as a
// vector in the face's frame (a fallback). Both cases are counted, and decode(encode(p)) on the
// undeformed base returns p to round-off in every case.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "remora/mesh/mesh.h"
#include "remora/mesh/surface_point.h"

namespace remora {

/// A triangle mesh as plain arrays, for the tight loops of encoding and decoding.
/// n × 3 points or vectors stored a vertex's row at a time: x, y, z together in memory.
using RowPoints = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct TriangleTopology {
  std::vector<std::array<int, 3>> faces;  ///< by face idx(), in face_vertices() order
  std::vector<std::array<int, 3>> across; ///< face across the edge opposite corner k, or -1
  /// The incident faces of every vertex: vertex_faces[vertex_offsets[v] .. vertex_offsets[v+1]).
  std::vector<int> vertex_offsets, vertex_faces;
};

/// Throws InvalidArgument if `mesh` has deleted faces (garbage-collect first).
TriangleTopology triangle_topology(const Mesh& mesh);
/// Face i's corners and the faces across its edges, read from `mesh` into t.faces[i] and
/// t.across[i] (sized by the caller), as triangle_topology() reads them. Throws InvalidArgument
/// if face i is deleted.
void read_face_topology(const Mesh& mesh, std::size_t i, TriangleTopology& t);
/// t.vertex_offsets and t.vertex_faces for `vertices` vertices, from t.faces.
void build_vertex_faces(TriangleTopology& t, std::size_t vertices);

/// Unit vertex normals (n_vertices × 3): the sum of the incident faces' cross products (area
/// weighted), normalized; (0, 0, 0) for a vertex whose faces all have zero area.
Eigen::MatrixXd vertex_normals(const TriangleTopology& topology, const Eigen::MatrixXd& positions);
/// The rows `vertices` of normals (n_vertices × 3) made what vertex_normals() gives for them, bit
/// for bit; the other rows are left alone. Parallel with `threads` threads (0 = all). Throws
/// InvalidArgument for wrong shapes.
void update_vertex_normals(const TriangleTopology& topology, const Eigen::MatrixXd& positions,
                           const std::vector<int>& vertices, Eigen::MatrixXd& normals,
                           int threads = 0);

struct PhongDetail {
  SurfacePoint base;     ///< on the base mesh; coordinates may be slightly outside the face
  double offset = 0.0;   ///< λ along the interpolated unit normal
  bool residual = false; ///< a fallback: `frame` holds what the normal offset does not reach
  std::array<double, 3> frame{0.0, 0.0,
                              0.0}; ///< in the face's frame (edge 0-1, normal × it, normal)
};

struct PhongStats {
  std::size_t encoded = 0;
  std::size_t walk_steps = 0;   ///< face-to-face moves, summed
  std::size_t extrapolated = 0; ///< base point outside its face (boundary, cycle, step limit)
  std::size_t fallbacks = 0;    ///< stored with a residual vector
  double max_abs_offset = 0.0;
};

struct PhongOptions {
  int max_walk_steps = 64;
};

/// Encodes point i (row i of `points`) starting at face start_faces[i] of the base
/// (`topology`, `positions`, `normals` = vertex_normals(topology, positions)). Parallel over the
/// points with `threads` threads (0 = all). Throws InvalidArgument for mismatched sizes, a start
/// face out of range, or a non-finite point.
std::vector<PhongDetail> encode_phong(const TriangleTopology& topology,
                                      const Eigen::MatrixXd& positions,
                                      const Eigen::MatrixXd& normals, const Eigen::MatrixXd& points,
                                      const std::vector<int>& start_faces,
                                      const PhongOptions& options = {}, PhongStats* stats = nullptr,
                                      int threads = 0);

/// The point a detail stands for on the base (positions, normals).
Eigen::Vector3d decode_phong(const TriangleTopology& topology, const Eigen::MatrixXd& positions,
                             const Eigen::MatrixXd& normals, const PhongDetail& detail);
/// The same on positions and normals stored a vertex's row at a time (the editor's frame).
Eigen::Vector3d decode_phong(const TriangleTopology& topology, const RowPoints& positions,
                             const RowPoints& normals, const PhongDetail& detail);

} // namespace remora
