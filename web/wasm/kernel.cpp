// The page's frame in WebAssembly: the library's client replay (src/remora/multires/
// frame_replay.h) behind a C interface that web/kernel.js calls, and the drawn mesh's normals
// around the moved vertices (web/normals.js), as a step of the page's frame or alone. Built by scripts/build_web.sh with
// clang for wasm32 (no C library: each instance's memory is laid out by the JavaScript).
#include "remora/multires/frame_replay.h"

static_assert(sizeof(remora::FrameReplay) == 25 * 4,
              "web/kernel.js writes FrameReplay as 25 words");

/// The drawn mesh's vertex normals that a drag changes, with three.js's formula (web/normals.js,
/// updateNormals(): the sum over a vertex's faces of (c − b) × (a − b), normalized; a zero sum
/// gives (0, 0, 0)), in two parts that write disjoint vertices (web/normals.js,
/// drawnNormalsLayout(): a face whose corners belong to both parts is in both, each summing into
/// its own). Every field is 4 bytes: web/normals.js writes the struct as 11 words.
struct DisplayNormals {
  uint32_t face_begin[3]; ///< part p's faces are face_begin[p] … face_begin[p + 1] − 1
  uint32_t vertex_begin[3]; ///< part p writes the normals vertex_begin[p] … vertex_begin[p + 1] − 1
  const uint32_t* corner; ///< 3 per face: the corners' indices into positions (3 floats each)
  const int32_t* target;  ///< 3 per face: the corner's index into normals, or −1 (another part's)
  const float* positions; ///< x, y, z per index
  double* sums;           ///< 3 per vertex: working memory
  float* normals;         ///< 3 per vertex: the result
};
static_assert(sizeof(DisplayNormals) == 11 * 4, "web/normals.js writes DisplayNormals as 11 words");

namespace {

void display_normals_of(const DisplayNormals& d, uint32_t part) {
  double* sums = d.sums;
  for (uint32_t i = 3 * d.vertex_begin[part]; i < 3 * d.vertex_begin[part + 1]; ++i) sums[i] = 0.0;
  const float* p = d.positions;
  for (uint32_t f = d.face_begin[part]; f < d.face_begin[part + 1]; ++f) {
    const uint32_t* c = d.corner + 3 * f;
    const float* a = p + 3 * c[0];
    const float* b = p + 3 * c[1];
    const float* e = p + 3 * c[2];
    const double bx = b[0], by = b[1], bz = b[2];
    const double cbx = e[0] - bx, cby = e[1] - by, cbz = e[2] - bz;
    const double abx = a[0] - bx, aby = a[1] - by, abz = a[2] - bz;
    const double n[3] = {cby * abz - cbz * aby, cbz * abx - cbx * abz, cbx * aby - cby * abx};
    for (int k = 0; k < 3; ++k) {
      const int32_t t = d.target[3 * f + k];
      if (t < 0) continue;
      double* s = sums + 3 * t;
      s[0] += n[0];
      s[1] += n[1];
      s[2] += n[2];
    }
  }
  for (uint32_t v = d.vertex_begin[part]; v < d.vertex_begin[part + 1]; ++v) {
    const double* s = sums + 3 * v;
    double length = __builtin_sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (!(length > 0.0)) length = 1.0;
    for (int k = 0; k < 3; ++k) d.normals[3 * v + k] = float(s[k] / length);
  }
}

/// Part `part` of `parts` of one step of a linear frame: step 0 the blend (part 0 also moves the
/// handles' vertices), 1 the faces' cross products, 2 the vertex normals, 3 the decode (a
/// blended-motions frame, whose step 0 is the caller's, runs 1 to 3).
void frame_part(const remora::FrameReplay* f, const double* transforms, float* out, uint32_t step,
                uint32_t part, uint32_t parts) {
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

} // namespace

extern "C" {

/// Part `part` of `parts` (1 or 2) of the drawn normals: with one part, both halves.
__attribute__((export_name("display_normals_part"))) void
display_normals_part(const DisplayNormals* d, uint32_t part, uint32_t parts) {
  for (uint32_t half = part; half < 2; half += parts) display_normals_of(*d, half);
}

/// Part `part` of `parts` of one step of the page's frame, for a frame split over threads
/// (web/engine.js): steps 0 to 3 those of the region's frame (frame_part() above, on the kernel
/// `f` and the handles' `transforms`, writing `out`), step 4 the drawn normals around the moved
/// vertices (`drawn`, whose positions begin with `out`; null when the page has none). Every part
/// of a step must end before any part of the next begins.
__attribute__((export_name("page_part"))) void page_part(const remora::FrameReplay* f,
                                                         const double* transforms, float* out,
                                                         const DisplayNormals* drawn, uint32_t step,
                                                         uint32_t part, uint32_t parts) {
  if (step < 4)
    frame_part(f, transforms, out, step, part, parts);
  else if (step == 4 && drawn != nullptr)
    display_normals_part(drawn, part, parts);
}

} // extern "C"
