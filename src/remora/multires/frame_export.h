// The current region's frame (frame.h: blend, normals, Phong decode) as data, for a client that
// evaluates a drag's frames itself: the browser page does, so that a drag needs no round trip
// (web/kernel.js; docs/server.md, `GET /api/region/kernel`). Single precision, in a local
// numbering of the base: only the base vertices and faces a frame reads.
//
// A client's frame, for transforms T_j = [M_j | t_j] (j < handles), with C the (3 + 4h) × 3
// matrix [I; M_0ᵀ; t_0ᵀ; ...] of editor.h:
//  1. x = rest positions; x[free_local[i]] = basis row i · C; x[v] = M_j rest[v] + t_j for the
//     vertices of handle j (handle_local[handle_begin[j] .. handle_begin[j + 1])). With
//     `blended` (method nonlinear, energy blended-motions) the free rows are instead the blend
//     of motion_blend.h, the weights w_j being the basis rows' columns 3 + 4j + 3 and the pivots
//     o_j the centroids of the handles' rest positions. With `corrected` (method nonlinear, an
//     energy that iterates) each free row adds the row offsets of frame_base_offsets(), which
//     the server computes with its frames: under the transforms of those offsets the client's
//     base is the server's nonlinear base, and under others it is that base plus the linear
//     blend's change since, off by the difference of the nonlinear and the linear responses to
//     that change.
//  2. n = rest normals; for normal_vertices[i]: the normalized sum over its faces
//     ring[ring_begin[i] .. ring_begin[i + 1]) of (x1 − x0) × (x2 − x0), (0, 0, 0) where it
//     vanishes.
//  3. output slot[r] (an index into Editor::movable_vertices()) = phong_point() of record r on
//     its face (phong_decode.h), plus offsets[r] when there are offsets.
// Its results differ from Editor::positions() by the single-precision round-off of the data.
#pragma once

#include <cstdint>
#include <vector>

namespace remora {

class Editor;

struct FrameExport {
  int handles = 0;
  bool blended = false;   ///< step 1 blends the handles' motions (motion_blend.h)
  bool corrected = false; ///< step 1 adds the server's row offsets (frame_base_offsets())
  /// n_local × 6: B0's position and unit normal (that of normal_vertices is step 2's to compute)
  std::vector<float> rest;
  std::vector<std::uint32_t> free_local;   ///< per basis row, its local vertex
  std::vector<float> basis;                ///< n_free × (3 + 4 handles), row-major
  std::vector<std::uint32_t> handle_begin; ///< handles + 1 offsets into handle_local
  std::vector<std::uint32_t> handle_local; ///< the handles' local vertices
  std::vector<std::uint32_t> faces;        ///< n_faces × 3 local vertices
  std::vector<std::uint32_t> normal_vertices, ring_begin, ring; ///< step 2 (ring: local faces)
  std::vector<std::uint32_t> record_face, record_slot;          ///< per record
  std::vector<float> record_bary;            ///< per record, 3 barycentric coordinates
  std::vector<float> record_offset;          ///< per record, the offset along the normal
  std::vector<std::int32_t> record_residual; ///< per record, an index into residuals, or −1
  std::vector<float> residuals;              ///< 3 per residual, in the face's frame
  std::vector<float> offsets;                ///< 3 per record, or empty
};

/// The editor's current region as a FrameExport (`corrected` for method nonlinear with an
/// energy that iterates). Throws InvalidArgument without a region.
FrameExport frame_export(const Editor& editor);

/// Per basis row of frame_export() (free base vertex), x, y, z: its base position in the
/// editor's last frame (Editor::positions(), with or without a budget) minus step 1's blend of
/// the single-precision basis under the current transforms (replay_blend_row() of
/// frame_replay.h: a client's blend plus these offsets gives the last frame's base to the
/// rounding of the offsets). Zero to round-off for method linear. Throws InvalidArgument without
/// a region, for the energy blended-motions (whose step 1 is no blend of the basis), or when a
/// transform was set after the last positions() call.
std::vector<float> frame_base_offsets(const Editor& editor);

} // namespace remora
