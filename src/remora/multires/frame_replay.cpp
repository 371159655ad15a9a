#include "remora/multires/frame_replay.h"

namespace remora {
namespace {

struct P3 {
  double x, y, z;
};
inline P3 operator-(P3 a, P3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline P3 cross(P3 a, P3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double dot(P3 a, P3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline double norm(P3 a) {
  return __builtin_sqrt(dot(a, a));
}
inline P3 row(const double* x, uint32_t v) {
  return {x[6 * v], x[6 * v + 1], x[6 * v + 2]};
}

/// phong_decode.h's face_frame(): edge 0-1, normal × edge, normal; false without area.
bool face_frame(P3 a, P3 b, P3 c, P3& t1, P3& t2, P3& nf) {
  const P3 e1 = b - a, e2 = c - a, n = cross(e1, e2);
  const double len = norm(e1), area2 = norm(n), d2 = dot(e2, e2);
  if (!(area2 > 1e-14 * (len * len > d2 ? len * len : d2)) || !(len > 0.0)) return false;
  t1 = {e1.x / len, e1.y / len, e1.z / len};
  nf = {n.x / area2, n.y / area2, n.z / area2};
  t2 = cross(nf, t1);
  return true;
}

} // namespace

void replay_blend(const FrameReplay& f, const double* transforms) {
  replay_blend_rows(f, transforms, 0, f.rows);
}

void replay_blend_rows(const FrameReplay& f, const double* transforms, uint32_t begin,
                       uint32_t end) {
  const uint32_t columns = f.columns;
  for (uint32_t i = begin; i < end; ++i) {
    double p[3];
    replay_blend_row(f.basis + uint64_t(i) * columns, f.handles, transforms, p);
    if (f.row_offsets) {
      const float* d = f.row_offsets + 3 * uint64_t(i);
      p[0] += d[0];
      p[1] += d[1];
      p[2] += d[2];
    }
    double* out = f.x + 6 * uint64_t(f.free_local[i]);
    out[0] = p[0];
    out[1] = p[1];
    out[2] = p[2];
  }
}

void replay_move_handles(const FrameReplay& f, const double* transforms) {
  for (uint32_t j = 0; j < f.handles; ++j) {
    const double* t = transforms + 12 * j;
    for (uint32_t i = f.handle_begin[j]; i < f.handle_begin[j + 1]; ++i) {
      const uint32_t v = f.handle_local[i];
      const double rx = f.rest[6 * v], ry = f.rest[6 * v + 1], rz = f.rest[6 * v + 2];
      double* out = f.x + 6 * uint64_t(v);
      out[0] = t[0] * rx + t[1] * ry + t[2] * rz + t[3];
      out[1] = t[4] * rx + t[5] * ry + t[6] * rz + t[7];
      out[2] = t[8] * rx + t[9] * ry + t[10] * rz + t[11];
    }
  }
}

void replay_normals(const FrameReplay& f) {
  replay_face_crosses(f, 0, f.ring_faces);
  replay_vertex_normals(f, 0, f.normal_count);
}

void replay_face_crosses(const FrameReplay& f, uint32_t begin, uint32_t end) {
  const double* x = f.x;
  for (uint32_t t = begin; t < end; ++t) {
    const uint32_t* c = f.faces + 3 * uint64_t(t);
    const P3 p0 = row(x, c[0]), n = cross(row(x, c[1]) - p0, row(x, c[2]) - p0);
    f.cross[3 * t] = n.x;
    f.cross[3 * t + 1] = n.y;
    f.cross[3 * t + 2] = n.z;
  }
}

void replay_vertex_normals(const FrameReplay& f, uint32_t begin, uint32_t end) {
  for (uint32_t i = begin; i < end; ++i) {
    double sx = 0.0, sy = 0.0, sz = 0.0;
    for (uint32_t r = f.ring_begin[i]; r < f.ring_begin[i + 1]; ++r) {
      const double* s = f.cross + 3 * uint64_t(f.ring[r]);
      sx += s[0];
      sy += s[1];
      sz += s[2];
    }
    const double len = __builtin_sqrt(sx * sx + sy * sy + sz * sz);
    const double scale = len > 0.0 ? 1.0 / len : 0.0;
    double* n = f.x + 6 * uint64_t(f.normal_vertices[i]) + 3;
    n[0] = sx * scale;
    n[1] = sy * scale;
    n[2] = sz * scale;
  }
}

void replay_decode(const FrameReplay& f, float* out) {
  replay_decode_records(f, out, 0, f.record_count);
}

void replay_decode_records(const FrameReplay& f, float* out, uint32_t begin, uint32_t end) {
  const double* x = f.x;
  for (uint32_t r = begin; r < end; ++r) {
    const uint32_t* c = f.faces + 3 * uint64_t(f.record_face[r]);
    const double* a = x + 6 * uint64_t(c[0]);
    const double* b = x + 6 * uint64_t(c[1]);
    const double* d = x + 6 * uint64_t(c[2]);
    const double wa = f.record_bary[3 * r], wb = f.record_bary[3 * r + 1],
                 wc = f.record_bary[3 * r + 2];
    double p[3], n[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = wa * a[k] + wb * b[k] + wc * d[k];
      n[k] = wa * a[3 + k] + wb * b[3 + k] + wc * d[3 + k];
    }
    const double len = __builtin_sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0.0) {
      const double s = f.record_offset[r] / len;
      for (int k = 0; k < 3; ++k) p[k] += s * n[k];
    }
    const int32_t q = f.record_residual[r];
    if (q >= 0) {
      const float* e = f.residuals + 3 * uint64_t(q);
      P3 t1, t2, nf;
      if (face_frame(row(x, c[0]), row(x, c[1]), row(x, c[2]), t1, t2, nf)) {
        p[0] += e[0] * t1.x + e[1] * t2.x + e[2] * nf.x;
        p[1] += e[0] * t1.y + e[1] * t2.y + e[2] * nf.y;
        p[2] += e[0] * t1.z + e[1] * t2.z + e[2] * nf.z;
      } else {
        for (int k = 0; k < 3; ++k) p[k] += e[k];
      }
    }
    if (f.offsets)
      for (int k = 0; k < 3; ++k) p[k] += f.offsets[3 * r + k];
    float* o = out + 3 * uint64_t(f.record_slot[r]);
    for (int k = 0; k < 3; ++k) o[k] = float(p[k]);
  }
}

} // namespace remora
