// Picking and brushes, done by the server (POST /api/pick, docs/server.md) on the positions it
// holds: the face under a ray, its point and nearest corner, and the vertices within a radius of
// that point (geodesic distance along the surface, or Euclidean for the "sphere" brush).
import { api, bodyBytes } from './api.js';

/// One pick: ray { origin, direction } (world space), radius >= 0, brush 'geodesic' | 'sphere',
/// stroke: a number for the picks of one paint stroke (the server then answers only the vertices
/// its earlier picks did not), or undefined. Returns { ids: Uint32Array (the brush's vertices,
/// empty for radius 0 or a miss), face (-1 on a miss), point: [x, y, z] | null, vertex (the hit
/// face's nearest corner, -1 on a miss) }.
export async function pick(ray, radius, brush, stroke) {
  const response = await api('pick', {
    method: 'POST', headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify({ origin: ray.origin, direction: ray.direction, radius, brush, stroke }),
  });
  const ids = new Uint32Array(await bodyBytes(response));
  const face = parseInt(response.headers.get('X-Hit-Face') ?? '-1', 10);
  const point = face >= 0 ? (response.headers.get('X-Hit-Point') ?? '').trim().split(/\s+/).map(Number) : null;
  const vertex = face >= 0 ? parseInt(response.headers.get('X-Hit-Vertex') ?? '-1', 10) : -1;
  return { ids, face, point: point?.length === 3 && point.every(Number.isFinite) ? point : null, vertex };
}

/// At most one request in flight; a newer submission replaces a waiting one (the latest wins, so
/// the answers never lag behind a queue). send(request) returns a promise; its result goes to
/// receive(result, request); a failure is left to send (api() has shown the message).
/// `overtakes(waiting, inFlight)` (default never): whether a waiting request is sent at once, while
/// the one in flight is unanswered (then two are in flight, no more); answers are received in the
/// order the requests were sent.
export class Coalescer {
  constructor(send, receive, overtakes = () => false) {
    Object.assign(this, { send, receive, overtakes, pending: null, inFlight: null, current: null, early: null });
  }
  /// Queues `request`; resolves when it (or a later request that replaced it) has been answered.
  submit(request) {
    this.pending = request;
    if (!this.inFlight) this.inFlight = this.drain();
    else if (this.current && !this.early && this.overtakes(request, this.current)) {
      this.pending = null;
      this.early = { request, answer: this.start(request) };
      this.early.answer.catch(() => {}); // received (or its failure dropped) by drain()
    }
    return this.inFlight;
  }
  start(request) {
    try { return this.send(request); } catch (e) { return Promise.reject(e); }
  }
  /// The requests sent and not yet answered (at most two).
  get sent() { return [this.current, this.early?.request].filter(Boolean); }
  /// Resolves when nothing is in flight or waiting.
  idle() { return this.inFlight ?? Promise.resolve(); }
  get busy() { return !!this.inFlight; }
  async drain() {
    try {
      while (this.early || this.pending) {
        let request = this.early?.request, answer = this.early?.answer;
        if (this.early) this.early = null;
        else {
          request = this.pending;
          this.pending = null;
          answer = this.start(request);
        }
        this.current = request;
        try { this.receive(await answer, request); } catch (e) { /* shown by api() */ }
      }
    } finally {
      this.inFlight = null;
      this.current = null;
    }
  }
}

/// The unit normal of face f (indices: Uint32 triples; positions: Float32 x, y, z per vertex), for
/// placing the brush cursor; [0, 0, 0] for a degenerate face.
export function faceNormal(positions, indices, f) {
  const p = positions, a = indices[3 * f], b = indices[3 * f + 1], c = indices[3 * f + 2];
  const ux = p[3 * b] - p[3 * a], uy = p[3 * b + 1] - p[3 * a + 1], uz = p[3 * b + 2] - p[3 * a + 2];
  const vx = p[3 * c] - p[3 * a], vy = p[3 * c + 1] - p[3 * a + 1], vz = p[3 * c + 2] - p[3 * a + 2];
  const n = [uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx];
  const length = Math.hypot(...n);
  return length > 0 ? n.map((x) => x / length) : [0, 0, 0];
}
