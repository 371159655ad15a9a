// The frames of a drag evaluated in the page, so that a drag waits for no round trip: the blend
// of the basis functions (for the nonlinear energies that iterate, plus the base offsets of the
// server's last frame; for blended-motions, of the handles' motions instead), the base's normals
// where they can change and the Phong decode, the same steps and
// formulas as the server's frame (src/remora/multires/frame.h, frame_export.h, motion_blend.h,
// phong_decode.h) on the data of `GET /api/region/kernel` (single precision). The server stays
// the reference: the page sends every map to it and shows its answer at the end of a drag;
// web/tests/e2e.mjs checks that both agree.
//
// Two engines give the same numbers (bit for bit: the same operations in the same order, in
// double precision): kernel.wasm, the library's own replay (src/remora/multires/frame_replay.h)
// compiled to WebAssembly by scripts/build_web.sh, each step split over two threads
// (web/engine.js); and the JavaScript below, used when the page has no kernel.wasm and for the
// step the library's replay leaves to its caller (blended motions' step 1).

import { FrameThreads, wasmLayout } from './engine.js';
import { placeDrawnNormals } from './normals.js';

const HEADER_WORDS = 16;
const WORKER_STACK = 1 << 16; // the worker instance's stack, in the region's memory

/// The kernel of a region from the bytes of `GET /api/region/kernel` (docs/server.md). Throws
/// an Error for a buffer whose sections do not add up. `drawn`: the drawn normals around the
/// region's movable vertices (web/normals.js, drawnNormalsLayout()), which its frames in
/// kernel.wasm then compute as their last step (k.wasm.drawn: applyMoved()'s `fromFrame`,
/// web/view.js), or null.
export function parseKernel(buffer, drawn = null) {
  const header = new Uint32Array(buffer, 0, HEADER_WORDS);
  const [version, handles, local, rows, columns, handleVertices, faces, normalVertices, ringLength,
    records, residuals, hasOffsets, blended, corrected] = header;
  if (version !== 1) throw new Error(`region kernel: version ${version}, expected 1`);
  let at = 4 * HEADER_WORDS;
  const take = (Type, n) => {
    const view = new Type(buffer, at, n);
    at += 4 * n;
    return view;
  };
  const k = {
    handles, local, rows, columns, records, blended: blended === 1, corrected: corrected === 1,
    rest: take(Float32Array, 6 * local),
    freeLocal: take(Uint32Array, rows),
    basis: take(Float32Array, rows * columns),
    handleBegin: take(Uint32Array, handles + 1),
    handleLocal: take(Uint32Array, handleVertices),
    faces: take(Uint32Array, 3 * faces),
    normalVertices: take(Uint32Array, normalVertices),
    ringBegin: take(Uint32Array, normalVertices + 1),
    ring: take(Uint32Array, ringLength),
    recordFace: take(Uint32Array, records),
    recordSlot: take(Uint32Array, records),
    recordBary: take(Float32Array, 3 * records),
    recordOffset: take(Float32Array, records),
    recordResidual: take(Int32Array, records),
    residuals: take(Float32Array, 3 * residuals),
    offsets: hasOffsets ? take(Float32Array, 3 * records) : null,
    // Added to step 1's blend: the server's base offsets (setRowOffsets()), zero until they come.
    rowOffsets: corrected === 1 ? new Float32Array(3 * rows) : null,
  };
  if (at !== buffer.byteLength || columns !== 3 + 4 * handles)
    throw new Error(`region kernel: ${buffer.byteLength} bytes, its header describes ${at}`);
  sortRecords(k);
  k.slots = 0; // the movable vertices the records write: max slot + 1
  for (let r = 0; r < records; ++r) k.slots = Math.max(k.slots, k.recordSlot[r] + 1);
  let ringFaces = 0;
  for (let i = 0; i < k.ring.length; ++i) ringFaces = Math.max(ringFaces, k.ring[i] + 1);
  k.ringFaces = ringFaces; // the normals' faces come first among the faces
  // Blended motions: the handles' pivots, the centroids of their rest positions.
  k.pivots = [];
  for (let j = 0; j < handles; ++j) {
    const o = [0, 0, 0], count = k.handleBegin[j + 1] - k.handleBegin[j];
    for (let i = k.handleBegin[j]; i < k.handleBegin[j + 1]; ++i)
      for (let c = 0; c < 3; ++c) o[c] += k.rest[6 * k.handleLocal[i] + c] / count;
    k.pivots.push(o);
  }
  const layout = wasmLayout();
  if (layout) attachWasm(k, layout, drawn);
  // The frame's working rows, a vertex's position and normal side by side (one cache line read per
  // corner), in double precision, at rest to begin with (rows that no frame writes keep them).
  else k.xn = Float64Array.from(k.rest);
  return k;
}

/// The arrays only the JavaScript steps read, built the first time they run (a region evaluated
/// in WebAssembly does without them: 18 MB at a 480k-vertex support): the faces' corners and the
/// records' as offsets into the working rows, and the faces' cross products.
function javascriptRows(k) {
  if (k.faceRows) return;
  k.faceRows = new Uint32Array(3 * k.ringFaces);
  for (let i = 0; i < k.faceRows.length; ++i) k.faceRows[i] = 6 * k.faces[i];
  k.recordRows = new Uint32Array(3 * k.records);
  for (let r = 0; r < k.records; ++r)
    for (let c = 0; c < 3; ++c) k.recordRows[3 * r + c] = 6 * k.faces[3 * k.recordFace[r] + c];
  k.cross = new Float64Array(3 * k.ringFaces);
}

/// Copies the kernel's arrays into the memory of a new instance of kernel.wasm (web/engine.js; one
/// per region: its memory goes with the kernel) and lays out struct FrameReplay (frame_replay.h:
/// 25 words of 4 bytes) over them. k.xn becomes the instance's working rows, so that the
/// JavaScript steps (blended motions) write where the WebAssembly ones read. The drawn normals'
/// positions begin with the frame's result (the moved vertices' slots are its slots).
function attachWasm(k, layout, drawn) {
  const sections = [];
  const place = (array) => {
    if (!array) return 0; // a null pointer: no offsets
    const offset = layout.reserve(array.BYTES_PER_ELEMENT * array.length);
    sections.push([offset, array]);
    return offset;
  };
  const names = ['rest', 'freeLocal', 'basis', 'handleBegin', 'handleLocal', 'faces', 'normalVertices', 'ringBegin',
    'ring', 'recordFace', 'recordSlot', 'recordBary', 'recordOffset', 'recordResidual', 'residuals', 'offsets'];
  const pointers = names.map((name) => place(k[name]));
  const rowOffsets = place(k.rowOffsets);
  const x = layout.reserve(8 * 6 * k.local), cross = layout.reserve(8 * 3 * k.ringFaces);
  if (drawn && drawn.movable.length !== k.slots) drawn = null; // not the movable vertices of these records
  const slots = drawn ? drawn.movable.length + drawn.constants.length : k.slots;
  const transforms = layout.reserve(8 * 12 * k.handles), out = layout.reserve(4 * 3 * slots);
  const placeDrawn = drawn ? placeDrawnNormals(layout, drawn, out) : null;
  const struct = layout.reserve(4 * 25), control = layout.reserve(16), stack = layout.reserve(WORKER_STACK);
  const instance = layout.instantiate(), memory = instance.buffer;
  // The JavaScript steps read the same copies: the region's data is held once.
  for (const [offset, array] of sections) new array.constructor(memory, offset, array.length).set(array);
  names.forEach((name, i) => { if (k[name]) k[name] = new k[name].constructor(memory, pointers[i], k[name].length); });
  if (k.rowOffsets) k.rowOffsets = new Float32Array(memory, rowOffsets, k.rowOffsets.length);
  new Uint32Array(memory, struct, 25).set([k.handles, k.rows, k.columns, k.normalVertices.length, k.records,
    k.ringFaces, ...pointers, x, cross, rowOffsets]);
  k.xn = new Float64Array(memory, x, 6 * k.local);
  k.xn.set(k.rest);
  const placed = placeDrawn ? placeDrawn(memory) : null;
  // A corrected kernel's frames keep to the page's thread: the server iterates on both cores
  // during its drags, and a worker waiting for the next step would take one of them.
  const threads = new FrameThreads(instance, [struct, transforms, out, placed?.struct ?? 0], control, stack + WORKER_STACK,
                                   !k.corrected);
  k.wasm = { threads, maps: new Float64Array(memory, transforms, 12 * k.handles), result: new Float32Array(memory, out, 3 * k.slots),
             drawn: placed && { movable: placed.movable, update: (positions, normals) => placed.update(positions, normals, () => threads.run(4)) } };
}

/// A corrected kernel's row offsets (Float32Array, x, y, z per basis row: the server's answer
/// "base-offsets", docs/server.md), which the next frames add to their blend. False, and nothing
/// changes, when the kernel is not corrected or the rows do not match.
export function setRowOffsets(k, offsets) {
  if (!k.rowOffsets || offsets.length !== k.rowOffsets.length) return false;
  k.rowOffsets.set(offsets);
  return true;
}

/// Ends what a kernel holds beyond its arrays (the worker of its frames).
export function releaseKernel(k) {
  k?.wasm?.threads.stop();
}

/// Puts the records in the order of their faces' first corners in the kernel's local numbering.
/// The server sends them in the order of the first corners' base ids (multires/frame.h), which
/// the local numbering need not follow; in this order the decode reads its three rows nearly in
/// sequence and scatters only its writes. The frames are the same numbers.
function sortRecords(k) {
  const order = Uint32Array.from({ length: k.records }, (_, i) => i);
  const first = (i) => k.faces[3 * k.recordFace[i]];
  order.sort((a, b) => first(a) - first(b) || a - b);
  const pick = (array, width) => {
    if (!array) return array;
    const out = new array.constructor(array.length);
    for (let i = 0; i < order.length; ++i)
      out.set(array.subarray(width * order[i], width * order[i] + width), width * i);
    return out;
  };
  Object.assign(k, {
    recordFace: pick(k.recordFace, 1), recordSlot: pick(k.recordSlot, 1), recordBary: pick(k.recordBary, 3),
    recordOffset: pick(k.recordOffset, 1), recordResidual: pick(k.recordResidual, 1), offsets: pick(k.offsets, 3),
  });
}

/// Positions (x, y, z per slot, the order of the region's movable vertices) into `out`
/// (Float32Array, 3 per movable vertex) under `transforms`: per handle the 12 numbers of the rows
/// of [M | t] (identity for a missing one).
/// `engine`: 'wasm' (when the kernel has it), 'wasm1' (the same on one thread) or 'js', for the
/// test and the benchmark that compare them.
export function evaluateKernel(k, transforms, out, engine = 'wasm') {
  if (k.wasm && engine.startsWith('wasm')) {
    const { threads, maps, result } = k.wasm, single = engine === 'wasm1';
    if (k.blended) blendMotions(k, transforms);
    else {
      for (let j = 0; j < k.handles; ++j) maps.set(transforms[j] ?? IDENTITY, 12 * j);
      threads.run(0, single);
    }
    for (const step of [1, 2, 3]) threads.run(step, single);
    out.set(result.length <= out.length ? result : result.subarray(0, out.length));
    return out;
  }
  javascriptRows(k);
  if (k.blended) blendMotions(k, transforms);
  else blend(k, transforms);
  normals(k);
  decode(k, out);
  return out;
}

const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0];

/// Step 1 of the nonlinear energy blended-motions (motion_blend.h): each free vertex p goes to
/// exp(Σ_j w_j log G_j) applied to p + Σ_j w_j (S_j − I)(p − o_j), w_j its handle weights (the
/// basis's "1" columns); the handles' own vertices move with their maps as in blend().
function blendMotions(k, transforms) {
  const { columns, basis, freeLocal, rows, xn: x, rest, handles } = k; // rest: 6 per local vertex
  const motions = [];
  for (let j = 0; j < handles; ++j) motions.push(handleMotion(transforms[j] ?? IDENTITY, k.pivots[j]));
  const stretched = motions.some((m) => m.stretched);
  for (let i = 0; i < rows; ++i) {
    const v = 6 * freeLocal[i], px = rest[v], py = rest[v + 1], pz = rest[v + 2];
    let wx = 0, wy = 0, wz = 0, ux = 0, uy = 0, uz = 0, yx = px, yy = py, yz = pz;
    for (let j = 0; j < handles; ++j) {
      const w = basis[i * columns + 3 + 4 * j + 3], m = motions[j];
      wx += w * m.omega[0]; wy += w * m.omega[1]; wz += w * m.omega[2];
      ux += w * m.v[0]; uy += w * m.v[1]; uz += w * m.v[2];
      if (stretched) {
        const S = m.stretch, dx = px - m.pivot[0], dy = py - m.pivot[1], dz = pz - m.pivot[2];
        yx += w * ((S[0] - 1) * dx + S[1] * dy + S[2] * dz);
        yy += w * (S[3] * dx + (S[4] - 1) * dy + S[5] * dz);
        yz += w * (S[6] * dx + S[7] * dy + (S[8] - 1) * dz);
      }
    }
    screwApply(wx, wy, wz, ux, uy, uz, yx, yy, yz, x, v);
  }
  moveHandles(k, transforms);
}

/// A handle's map M = R S (polar) split at its pivot o into the stretch about o and the rigid
/// motion G(y) = R y + t + R (S − I) o, as handle_motions() does; G as the twist (omega, v).
function handleMotion(t, pivot) {
  const M = [t[0], t[1], t[2], t[4], t[5], t[6], t[8], t[9], t[10]];
  const R = polarRotation(M);
  const S = mul(transpose(R), M); // R⁻¹ M
  for (let r = 0; r < 3; ++r) for (let c = r + 1; c < 3; ++c) S[3 * r + c] = S[3 * c + r] = 0.5 * (S[3 * r + c] + S[3 * c + r]);
  const d = [0, 1, 2].map((r) => (S[3 * r] - (r === 0)) * pivot[0] + (S[3 * r + 1] - (r === 1)) * pivot[1] + (S[3 * r + 2] - (r === 2)) * pivot[2]);
  const tr = [0, 1, 2].map((r) => t[4 * r + 3] + R[3 * r] * d[0] + R[3 * r + 1] * d[1] + R[3 * r + 2] * d[2]);
  const omega = rotationLog(R);
  const theta = Math.hypot(...omega);
  // V⁻¹ t = t − W t / 2 + c W² t, c = (1 − θ sin θ / (2 (1 − cos θ))) / θ² (screw_log()).
  const c = theta < 1e-4 ? 1 / 12 + (theta * theta) / 720 : (1 - (theta * Math.sin(theta)) / (2 * (1 - Math.cos(theta)))) / (theta * theta);
  const wt = cross(omega, tr), wwt = cross(omega, wt);
  const v = [0, 1, 2].map((r) => tr[r] - 0.5 * wt[r] + c * wwt[r]);
  let stretched = false;
  for (let r = 0; r < 3; ++r) for (let q = 0; q < 3; ++q) if (Math.abs(S[3 * r + q] - (r === q)) > 1e-12) stretched = true;
  return { omega, v, stretch: S, pivot, stretched };
}

/// exp(twist (w, v)) applied to y, into x[at .. at + 2] (screw_apply()): y + s w×y + a w×(w×y)
/// + v + a w×v + b w×(w×v). Scalars only: it runs once per vertex.
function screwApply(w0, w1, w2, v0, v1, v2, y0, y1, y2, x, at) {
  const t2 = w0 * w0 + w1 * w1 + w2 * w2, theta = Math.sqrt(t2);
  let a, b, s;
  if (theta < 1e-4) {
    a = 0.5 - t2 / 24; b = 1 / 6 - t2 / 120; s = 1 - t2 / 6;
  } else {
    const sin = Math.sin(theta);
    a = (1 - Math.cos(theta)) / t2; b = (theta - sin) / (t2 * theta); s = sin / theta;
  }
  // p = w×y, q = w×p, r = w×v, u = w×r.
  const p0 = w1 * y2 - w2 * y1, p1 = w2 * y0 - w0 * y2, p2 = w0 * y1 - w1 * y0;
  const q0 = w1 * p2 - w2 * p1, q1 = w2 * p0 - w0 * p2, q2 = w0 * p1 - w1 * p0;
  const r0 = w1 * v2 - w2 * v1, r1 = w2 * v0 - w0 * v2, r2 = w0 * v1 - w1 * v0;
  const u0 = w1 * r2 - w2 * r1, u1 = w2 * r0 - w0 * r2, u2 = w0 * r1 - w1 * r0;
  x[at] = y0 + s * p0 + a * q0 + v0 + a * r0 + b * u0;
  x[at + 1] = y1 + s * p1 + a * q1 + v1 + a * r1 + b * u1;
  x[at + 2] = y2 + s * p2 + a * q2 + v2 + a * r2 + b * u2;
}

/// The rotation of the polar decomposition of M (3×3 row-major, det M > 0): Higham's iteration
/// R ← (R + R⁻ᵀ) / 2, which converges quadratically to it.
function polarRotation(M) {
  let R = M.slice();
  for (let i = 0; i < 50; ++i) {
    const inverse = inverseTranspose(R), next = R.map((r, q) => 0.5 * (r + inverse[q]));
    let change = 0;
    for (let q = 0; q < 9; ++q) change = Math.max(change, Math.abs(next[q] - R[q]));
    R = next;
    if (change < 1e-15) break;
  }
  return R;
}

/// The rotation vector of R (angle in [0, π]), through its unit quaternion (rotation_log()).
function rotationLog(R) {
  const trace = R[0] + R[4] + R[8];
  let w, x, y, z;
  if (trace > 0) {
    const s = 2 * Math.sqrt(trace + 1);
    w = s / 4; x = (R[7] - R[5]) / s; y = (R[2] - R[6]) / s; z = (R[3] - R[1]) / s;
  } else if (R[0] > R[4] && R[0] > R[8]) {
    const s = 2 * Math.sqrt(1 + R[0] - R[4] - R[8]);
    w = (R[7] - R[5]) / s; x = s / 4; y = (R[1] + R[3]) / s; z = (R[2] + R[6]) / s;
  } else if (R[4] > R[8]) {
    const s = 2 * Math.sqrt(1 + R[4] - R[0] - R[8]);
    w = (R[2] - R[6]) / s; x = (R[1] + R[3]) / s; y = s / 4; z = (R[5] + R[7]) / s;
  } else {
    const s = 2 * Math.sqrt(1 + R[8] - R[0] - R[4]);
    w = (R[3] - R[1]) / s; x = (R[2] + R[6]) / s; y = (R[5] + R[7]) / s; z = s / 4;
  }
  if (w < 0) { w = -w; x = -x; y = -y; z = -z; }
  const s = Math.hypot(x, y, z);
  if (s < 1e-300) return [0, 0, 0];
  const angle = 2 * Math.atan2(s, w);
  return [x * (angle / s), y * (angle / s), z * (angle / s)];
}

const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const transpose = (A) => [A[0], A[3], A[6], A[1], A[4], A[7], A[2], A[5], A[8]];
function mul(A, B) {
  const C = new Array(9).fill(0);
  for (let r = 0; r < 3; ++r) for (let c = 0; c < 3; ++c) for (let q = 0; q < 3; ++q) C[3 * r + c] += A[3 * r + q] * B[3 * q + c];
  return C;
}
function inverseTranspose(A) {
  const cof = [A[4] * A[8] - A[5] * A[7], A[5] * A[6] - A[3] * A[8], A[3] * A[7] - A[4] * A[6],
    A[2] * A[7] - A[1] * A[8], A[0] * A[8] - A[2] * A[6], A[1] * A[6] - A[0] * A[7],
    A[1] * A[5] - A[2] * A[4], A[2] * A[3] - A[0] * A[5], A[0] * A[4] - A[1] * A[3]];
  const det = A[0] * cof[0] + A[1] * cof[1] + A[2] * cof[2];
  return cof.map((c) => c / det); // the cofactor matrix over det is A⁻ᵀ
}

/// Step 1: the basis rows times C = [I; M_0ᵀ; t_0ᵀ; ...] (the identity's three columns, then
/// per handle w · the rows of [M_j | t_j], summed in the order of the columns, as
/// frame_replay.h does), plus the row offsets of a corrected kernel, and the handles' own
/// vertices moved rigidly with their maps.
function blend(k, transforms) {
  const { columns, basis, freeLocal, rows, xn: x, handles, rowOffsets } = k;
  const maps = [];
  for (let j = 0; j < handles; ++j) maps.push(transforms[j] ?? IDENTITY);
  for (let i = 0; i < rows; ++i) {
    const b = i * columns;
    let px = basis[b], py = basis[b + 1], pz = basis[b + 2];
    for (let j = 0; j < handles; ++j) {
      const t = maps[j], w = b + 3 + 4 * j;
      for (let c = 0; c < 4; ++c) {
        const wc = basis[w + c];
        px += wc * t[c]; py += wc * t[4 + c]; pz += wc * t[8 + c];
      }
    }
    if (rowOffsets) { px += rowOffsets[3 * i]; py += rowOffsets[3 * i + 1]; pz += rowOffsets[3 * i + 2]; }
    const v = 6 * freeLocal[i];
    x[v] = px; x[v + 1] = py; x[v + 2] = pz;
  }
  moveHandles(k, transforms);
}

/// The handles' own vertices, moved with their maps.
function moveHandles(k, transforms) {
  const { xn: x, rest } = k;
  for (let j = 0; j < k.handles; ++j) {
    const t = transforms[j] ?? IDENTITY;
    for (let i = k.handleBegin[j]; i < k.handleBegin[j + 1]; ++i) {
      const v = k.handleLocal[i], rx = rest[6 * v], ry = rest[6 * v + 1], rz = rest[6 * v + 2];
      x[6 * v] = t[0] * rx + t[1] * ry + t[2] * rz + t[3];
      x[6 * v + 1] = t[4] * rx + t[5] * ry + t[6] * rz + t[7];
      x[6 * v + 2] = t[8] * rx + t[9] * ry + t[10] * rz + t[11];
    }
  }
}

/// Step 2: the normals that can change, the normalized sums of their faces' cross products.
function normals(k) {
  const { faceRows, xn: x, cross, ringFaces } = k;
  for (let f = 0; f < ringFaces; ++f) {
    const a = faceRows[3 * f], b = faceRows[3 * f + 1], c = faceRows[3 * f + 2];
    const ux = x[b] - x[a], uy = x[b + 1] - x[a + 1], uz = x[b + 2] - x[a + 2];
    const vx = x[c] - x[a], vy = x[c + 1] - x[a + 1], vz = x[c + 2] - x[a + 2];
    cross[3 * f] = uy * vz - uz * vy; cross[3 * f + 1] = uz * vx - ux * vz; cross[3 * f + 2] = ux * vy - uy * vx;
  }
  const { normalVertices, ringBegin, ring } = k;
  for (let i = 0; i < normalVertices.length; ++i) {
    let sx = 0, sy = 0, sz = 0;
    for (let r = ringBegin[i], end = ringBegin[i + 1]; r < end; ++r) {
      const s = 3 * ring[r];
      sx += cross[s]; sy += cross[s + 1]; sz += cross[s + 2];
    }
    const len = Math.sqrt(sx * sx + sy * sy + sz * sz), v = 6 * normalVertices[i] + 3;
    const scale = len > 0 ? 1 / len : 0;
    x[v] = sx * scale; x[v + 1] = sy * scale; x[v + 2] = sz * scale;
  }
}

/// Step 3: each detail on its base face: b + offset n̂(b), plus its residual in the face's frame.
function decode(k, out) {
  const { recordRows, xn: x, recordSlot, recordBary, recordOffset, recordResidual, residuals, offsets, records } = k;
  for (let r = 0; r < records; ++r) {
    const a = recordRows[3 * r], b = recordRows[3 * r + 1], c = recordRows[3 * r + 2];
    const wa = recordBary[3 * r], wb = recordBary[3 * r + 1], wc = recordBary[3 * r + 2];
    let px = wa * x[a] + wb * x[b] + wc * x[c];
    let py = wa * x[a + 1] + wb * x[b + 1] + wc * x[c + 1];
    let pz = wa * x[a + 2] + wb * x[b + 2] + wc * x[c + 2];
    const nx = wa * x[a + 3] + wb * x[b + 3] + wc * x[c + 3];
    const ny = wa * x[a + 4] + wb * x[b + 4] + wc * x[c + 4];
    const nz = wa * x[a + 5] + wb * x[b + 5] + wc * x[c + 5];
    const len = Math.sqrt(nx * nx + ny * ny + nz * nz);
    if (len > 0) {
      const s = recordOffset[r] / len;
      px += s * nx; py += s * ny; pz += s * nz;
    }
    const q = recordResidual[r];
    if (q >= 0) {
      const r0 = residuals[3 * q], r1 = residuals[3 * q + 1], r2 = residuals[3 * q + 2];
      const frame = faceFrame(x, a, b, c);
      if (frame) {
        const [t1, t2, nf] = frame;
        px += r0 * t1[0] + r1 * t2[0] + r2 * nf[0];
        py += r0 * t1[1] + r1 * t2[1] + r2 * nf[1];
        pz += r0 * t1[2] + r1 * t2[2] + r2 * nf[2];
      } else {
        px += r0; py += r1; pz += r2;
      }
    }
    if (offsets) { px += offsets[3 * r]; py += offsets[3 * r + 1]; pz += offsets[3 * r + 2]; }
    const o = 3 * recordSlot[r];
    out[o] = px; out[o + 1] = py; out[o + 2] = pz;
  }
}

/// A face's frame as phong_decode.h's face_frame(): edge 0-1, normal × edge, normal; null for a
/// face without area.
function faceFrame(x, a, b, c) {
  const e1 = [x[b] - x[a], x[b + 1] - x[a + 1], x[b + 2] - x[a + 2]];
  const e2 = [x[c] - x[a], x[c + 1] - x[a + 1], x[c + 2] - x[a + 2]];
  const cr = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
  const len = Math.sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  const area2 = Math.sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
  if (!(area2 > 1e-14 * Math.max(len * len, e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2])) || !(len > 0)) return null;
  const t1 = e1.map((v) => v / len), nf = cr.map((v) => v / area2);
  const t2 = [nf[1] * t1[2] - nf[2] * t1[1], nf[2] * t1[0] - nf[0] * t1[2], nf[0] * t1[1] - nf[1] * t1[0]];
  return [t1, t2, nf];
}
