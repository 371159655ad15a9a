// A drag's frames (web/app.js wires them): the region's kernel evaluated in the page (web/kernel.js)
// and the requests that tell the server each map (POST transform, POST relax). Under method
// linear and the energy blended-motions the server is sent every map without an answer. Under
// the energies that iterate the kernel is corrected: every map is answered with the base offsets
// of the server's nonlinear frame (docs/server.md), which the page adds to its linear blend from
// then on, so a frame shown is the server's last nonlinear base plus the linear change since.
import { ApiError, api, bodyBytes } from './api.js';
import { evaluateKernel, parseKernel, releaseKernel, setRowOffsets } from './kernel.js';

/// The page's method choice ('linear', 'nonlinear', 'blended-motions') of a region of the status.
export const methodOf = (region) =>
  (region?.method === 'nonlinear' && region.energy === 'blended-motions' ? 'blended-motions' : region?.method);

/// A region's kernel in the page: { regionId, method, data (parseKernel()), out, synced }. A
/// corrected kernel is synced once the offsets of the server's current transforms are here.
export class RegionKernel {
  /// Fetches the kernel of the status `s`'s region for the vertices `movable` (its drawn normals
  /// `drawn`, view.drawnNormals()); resolves to null when the server has none.
  static async load(s, movable, drawn, engineLoaded) {
    const [buffer] = await Promise.all([fetch('api/region/kernel').then((r) => (r.ok ? bodyBytes(r) : null)), engineLoaded]);
    if (!buffer) return null;
    const k = new RegionKernel();
    Object.assign(k, { regionId: s.region_id, method: methodOf(s.region), data: parseKernel(buffer, drawn),
                       out: new Float32Array(3 * movable.length), bytes: buffer.byteLength });
    k.synced = !k.data.corrected;
    return k;
  }
  release() { releaseKernel(this.data); }
  /// Of the region and method the page holds.
  current(state) { return this.regionId === state.held.region && this.method === state.method; }
  /// Whether the page can show a frame of the drag with it.
  usable(state) {
    return this.synced && this.current(state) && !!state.movable && this.out.length === 3 * state.movable.length &&
           state.selected < this.data.handles;
  }
  /// Whether the server's answers should carry base offsets for it.
  corrected(state) { return this.data.corrected && this.current(state); }
  /// The answer's base offsets, taken; false when they are not this kernel's.
  takeOffsets(offsets) {
    if (!setRowOffsets(this.data, offsets)) return false;
    this.synced = true;
    return true;
  }
  /// The frame under `transforms` (per handle the 12 numbers of [M | t]) into `out`.
  evaluate(transforms, out = this.out, how = 'wasm') { return evaluateKernel(this.data, transforms, out, how); }
}

/// While the nonlinear iteration is not converged, more iterations once the pointer has rested
/// PAUSE_MS (soon()), in relax steps whose budget doubles from BUDGET_MS to BUDGET_MAX_MS: a
/// step's answer that is not converged asks for the next; a move (moved()) starts over. A release
/// (released()) has no pause to wait for: its first step has RELEASE_BUDGET_MS, so that the
/// iteration usually converges in one step (each answer's handling in the page takes the server's
/// cores from the iteration), and later ones BUDGET_MAX_MS. A grab of the handle does not wait
/// for a long step: its move is sent at once and ends the step (app.js's frames). `submit(budget)`
/// sends a step; `pending()`: a request waits to be sent (a newer move replaces a waiting step),
/// or a step is in flight (its answer asks for the next).
export class Relaxer {
  static PAUSE_MS = 120;
  static BUDGET_MS = 40;
  static BUDGET_MAX_MS = 320;
  static RELEASE_BUDGET_MS = 1500;
  constructor(submit, pending) {
    Object.assign(this, { submit, pending, lastMove: 0, timer: null, steps: 0, afterRelease: false });
  }
  moved(now) {
    this.lastMove = now;
    this.steps = 0;
    this.afterRelease = false;
  }
  released(at) {
    this.lastMove = Math.min(this.lastMove, at - Relaxer.PAUSE_MS);
    this.steps = Math.log2(Relaxer.BUDGET_MAX_MS / Relaxer.BUDGET_MS);
    this.afterRelease = true;
  }
  /// No step is waiting for its pause.
  get idle() { return this.timer === null; }
  cancel() {
    clearTimeout(this.timer);
    this.timer = null;
  }
  soon() {
    clearTimeout(this.timer);
    const wait = Math.max(0, this.lastMove + Relaxer.PAUSE_MS - performance.now());
    this.timer = setTimeout(() => {
      this.timer = null;
      const budget = this.afterRelease ? Relaxer.RELEASE_BUDGET_MS : Math.min(Relaxer.BUDGET_MAX_MS, Relaxer.BUDGET_MS * 2 ** this.steps);
      if (!this.pending() && performance.now() - this.lastMove >= Relaxer.PAUSE_MS) {
        this.submit(budget);
        ++this.steps;
        this.afterRelease = false;
      } else if (!this.pending()) this.soon();
    }, wait);
  }
}

/// What a frame request asks the server to answer: the movable vertices' positions, none for a
/// frame the page showed itself, and for a corrected kernel the base offsets after them.
function frameAnswer(request) {
  if (request.local) return request.offsets ? 'base-offsets' : 'none';
  return request.offsets ? 'positions-and-base-offsets' : 'positions';
}

/// A frame request: a handle's new map (POST transform; the drag's last, `request.last`, leaves
/// the server iterating on), or for the nonlinear method more iterations under the same maps
/// while the pointer rests (POST relax, `relaxBudgetMs`). Resolves to { moved, offsets, bytes,
/// ms, converged } of the answer.
export async function sendFrame(request, relaxBudgetMs) {
  request.sent = performance.now();
  const answer = frameAnswer(request);
  // A refused relax (the server busy with a new region) is dropped without a message.
  const response = request.relax
    ? await fetch('api/relax', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                 body: JSON.stringify({ budget_ms: relaxBudgetMs, answer }) })
    : await api('transform', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                               body: JSON.stringify({ handle: request.handle, matrix: request.matrix, answer,
                                                      relax: !!request.last }) });
  if (!response.ok) throw new ApiError(response.status, 'relax refused');
  const buffer = await bodyBytes(response), floats = new Float32Array(buffer);
  const withOffsets = response.headers.has('X-Base-Offset-Rows');
  const rows = withOffsets ? Number(response.headers.get('X-Base-Offset-Rows')) : 0, split = floats.length - 3 * rows;
  return { moved: floats.subarray(0, split), offsets: withOffsets ? floats.subarray(split) : null, bytes: buffer.byteLength,
           ms: parseFloat(response.headers.get('X-Frame-Ms')), converged: response.headers.get('X-Converged') !== '0' };
}
