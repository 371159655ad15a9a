// A client's frame (frame_export.h, steps 1 to 3) evaluated from the exported arrays: the code
// that the browser page runs, compiled to WebAssembly (web/wasm/kernel.cpp,
// scripts/build_web.sh), and that tests/test_frame.cpp checks against the editor's positions.
// Freestanding on purpose: no standard library, no Eigen, no allocation, only <stdint.h> and the
// compiler's square root, so that it builds for wasm32 without a C library. The arithmetic is
// phong_decode.h's, in double precision on the single-precision data.
//
// Step 1 for the energy blended-motions (the handles' screw motions blended per vertex) is not
// here: the page evaluates it in JavaScript (web/kernel.js) into `x` and then calls
// replay_normals() and replay_decode(); a linear frame is replay_blend() and
// replay_move_handles() first.
#pragma once

#include <stdint.h>

namespace remora {

/// The arrays of a FrameExport (same names, same shapes) and the frame's working memory. Every
/// field is 4 bytes on wasm32, in this order: web/kernel.js writes the struct as 25 words.
/// The caller's out array holds 3 (max record_slot + 1) floats; free_local and handle_local
/// name different vertices (a thread may move the handles while another blends rows).
struct FrameReplay {
  uint32_t handles = 0;        ///< h
  uint32_t rows = 0;           ///< basis rows (free base vertices)
  uint32_t columns = 0;        ///< 3 + 4 h
  uint32_t normal_count = 0;   ///< normal_vertices' length
  uint32_t record_count = 0;   ///< records
  uint32_t ring_faces = 0;     ///< faces 0 .. ring_faces − 1 are the ones ring refers to
  const float* rest = nullptr; ///< 6 per local vertex
  const uint32_t* free_local = nullptr;
  const float* basis = nullptr; ///< rows × columns
  const uint32_t* handle_begin = nullptr;
  const uint32_t* handle_local = nullptr;
  const uint32_t* faces = nullptr;
  const uint32_t* normal_vertices = nullptr;
  const uint32_t* ring_begin = nullptr;
  const uint32_t* ring = nullptr;
  const uint32_t* record_face = nullptr;
  const uint32_t* record_slot = nullptr;
  const float* record_bary = nullptr;
  const float* record_offset = nullptr;
  const int32_t* record_residual = nullptr;
  const float* residuals = nullptr;
  const float* offsets = nullptr; ///< 3 per record, or null
  /// Working rows, 6 per local vertex (position, then unit normal), in double precision. The
  /// caller fills them with `rest` once per region; a frame writes only the rows it moves, so
  /// the others keep their rest values.
  double* x = nullptr;
  double* cross = nullptr; ///< 3 per ring face: step 2's cross products
  /// 3 per basis row, added to step 1's blend: frame_base_offsets() of a `corrected` export
  /// (frame_export.h), or null.
  const float* row_offsets = nullptr;
};

/// Basis row `b` (3 + 4 handles floats) · C, C = [I; M_0ᵀ; t_0ᵀ; ...] from `transforms` (12
/// doubles per handle): the identity's three columns, then per handle w · [M_j | t_j] rows, summed
/// in the order of the columns. The client's step 1 and frame_base_offsets() both use it, so that
/// the offsets cancel the client's blend exactly.
inline void replay_blend_row(const float* b, uint32_t handles, const double* transforms,
                             double p[3]) {
  p[0] = b[0];
  p[1] = b[1];
  p[2] = b[2];
  for (uint32_t j = 0; j < handles; ++j) {
    const double* t = transforms + 12 * j;
    const float* w = b + 3 + 4 * j;
    for (uint32_t k = 0; k < 4; ++k) {
      const double wk = w[k];
      p[0] += wk * t[k];
      p[1] += wk * t[4 + k];
      p[2] += wk * t[8 + k];
    }
  }
}

/// Step 1, linear: x[free_local[i]] = basis row i · C (replay_blend_row()), plus row_offsets[i]
/// when there are row offsets; `transforms` holds 12 doubles per handle (the rows of [M_j | t_j]).
void replay_blend(const FrameReplay& f, const double* transforms);

/// Step 1, the handles' own vertices: x[v] = M_j rest[v] + t_j.
void replay_move_handles(const FrameReplay& f, const double* transforms);

/// Step 2: the unit normal of each of normal_vertices, the normalized sum of its ring faces'
/// (x1 − x0) × (x2 − x0); (0, 0, 0) where the sum vanishes.
void replay_normals(const FrameReplay& f);

/// Step 3: each record's Phong point (phong_decode.h's phong_point) plus its offset, as x, y, z
/// into out[3 record_slot[r] ..] (single precision).
void replay_decode(const FrameReplay& f, float* out);

/// The same steps over a range [begin, end), for callers that split a frame over threads (the
/// page: web/kernel.js). Each writes only its range's rows or records; the ranges of one step
/// may run at once, and a step must wait for the whole of the step before it (the vertex
/// normals read every face's cross product).
void replay_blend_rows(const FrameReplay& f, const double* transforms, uint32_t begin,
                       uint32_t end);
void replay_face_crosses(const FrameReplay& f, uint32_t begin, uint32_t end);
void replay_vertex_normals(const FrameReplay& f, uint32_t begin, uint32_t end);
void replay_decode_records(const FrameReplay& f, float* out, uint32_t begin, uint32_t end);

} // namespace remora
