// The page's frame in WebAssembly: the library's client replay (src/remora/multires/
// frame_replay.h) behind a C interface that web/kernel.js calls, and the drawn mesh's normals
// around the moved vertices that web/normals.js asks for. Built by scripts/build_web.sh with
// clang for wasm32 (no C library: each instance's memory is laid out by the JavaScript).
#include "remora/multires/frame_replay.h"

static_assert(sizeof(remora::FrameReplay) == 24 * 4,
              "web/kernel.js writes FrameReplay as 24 words");

extern "C" {

/// Part `part` of `parts` of one step of a linear frame, for a frame split over threads
/// (web/kernel.js): step 0 the blend (part 0 also moves the handles' vertices), 1 the faces'
/// cross products, 2 the vertex normals, 3 the decode (a blended-motions frame, whose step 0 is
/// the caller's, runs 1 to 3). Every part of a step must end before any part of the next begins.
__attribute__((export_name("frame_part"))) void frame_part(const remora::FrameReplay* f,
                                                           const double* transforms, float* out,
                                                           uint32_t step, uint32_t part,
                                                           uint32_t parts) {
  const auto range = [&](uint32_t n, uint32_t& begin, uint32_t& end) {
    begin = uint32_t(uint64_t(n) * part / parts);
    end = uint32_t(uint64_t(n) * (part + 1) / parts);
  };
  uint32_t begin = 0, end = 0;
  switch (step) {
  case 0:
    range(f->rows, begin, end);
    remora::replay_blend_rows(*f, transforms, begin, end);
    if (part == 0) remora::replay_move_handles(*f, transforms);
    break;
  case 1:
    range(f->ring_faces, begin, end);
    remora::replay_face_crosses(*f, begin, end);
    break;
  case 2:
    range(f->normal_count, begin, end);
    remora::replay_vertex_normals(*f, begin, end);
    break;
  case 3:
    range(f->record_count, begin, end);
    remora::replay_decode_records(*f, out, begin, end);
    break;
  default:
    break;
  }
}

/// The drawn mesh's vertex normals that a drag changes, with three.js's formula (web/normals.js,
/// updateNormals(): the sum over a vertex's faces of (c − b) × (a − b), normalized; a zero sum
/// gives (0, 0, 0)). Every field is 4 bytes: web/normals.js writes the struct as 7 words.
struct DisplayNormals {
  uint32_t faces;         ///< faces of the plan
  uint32_t vertices;      ///< vertices whose normal is computed
  const uint32_t* corner; ///< 3 per face: the corners' indices into positions (3 floats each)
  const int32_t* target;  ///< 3 per face: the corners' indices into normals, or −1
  const float* positions; ///< x, y, z per index
  double* sums;           ///< 3 per vertex: working memory
  float* normals;         ///< 3 per vertex: the result
};
static_assert(sizeof(DisplayNormals) == 7 * 4, "web/normals.js writes DisplayNormals as 7 words");

__attribute__((export_name("display_normals"))) void display_normals(const DisplayNormals* d) {
  for (uint32_t i = 0; i < 3 * d->vertices; ++i) d->sums[i] = 0.0;
  const float* p = d->positions;
  for (uint32_t f = 0; f < d->faces; ++f) {
    const uint32_t* c = d->corner + 3 * f;
    const float* a = p + 3 * c[0];
    const float* b = p + 3 * c[1];
    const float* e = p + 3 * c[2];
    const double bx = b[0], by = b[1], bz = b[2];
    const double cbx = e[0] - bx, cby = e[1] - by, cbz = e[2] - bz;
    const double abx = a[0] - bx, aby = a[1] - by, abz = a[2] - bz;
    const double n[3] = {cby * abz - cbz * aby, cbz * abx - cbx * abz, cbx * aby - cby * abx};
    for (int k = 0; k < 3; ++k) {
      const int32_t t = d->target[3 * f + k];
      if (t < 0) continue;
      double* s = d->sums + 3 * t;
      s[0] += n[0];
      s[1] += n[1];
      s[2] += n[2];
    }
  }
  for (uint32_t v = 0; v < d->vertices; ++v) {
    const double* s = d->sums + 3 * v;
    double length = __builtin_sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (!(length > 0.0)) length = 1.0;
    for (int k = 0; k < 3; ++k) d->normals[3 * v + k] = float(s[k] / length);
  }
}

} // extern "C"
