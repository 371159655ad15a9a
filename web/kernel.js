// The linear method's frame evaluated in the page, so that a drag waits for no round trip: the
// blend of the basis functions, the base's normals where they can change and the Phong decode,
// the same steps and formulas as the server's frame (src/remora/multires/frame.h,
// frame_export.h, phong_decode.h) on the data of `GET /api/region/kernel` (single precision).
// The server stays the reference: the page sends every map to it and shows its answer at the
// end of a drag; web/tests/e2e.mjs checks that both agree.

const HEADER_WORDS = 16;

/// The kernel of a region from the bytes of `GET /api/region/kernel` (docs/server.md). Throws
/// an Error for a buffer whose sections do not add up.
export function parseKernel(buffer) {
  const header = new Uint32Array(buffer, 0, HEADER_WORDS);
  const [version, handles, local, rows, columns, handleVertices, faces, normalVertices, ringLength,
    records, residuals, hasOffsets] = header;
  if (version !== 1) throw new Error(`region kernel: version ${version}, expected 1`);
  let at = 4 * HEADER_WORDS;
  const take = (Type, n) => {
    const view = new Type(buffer, at, n);
    at += 4 * n;
    return view;
  };
  const k = {
    handles, local, rows, columns, records,
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
  };
  if (at !== buffer.byteLength || columns !== 3 + 4 * handles)
    throw new Error(`region kernel: ${buffer.byteLength} bytes, its header describes ${at}`);
  let ringFaces = 0;
  for (let i = 0; i < k.ring.length; ++i) ringFaces = Math.max(ringFaces, k.ring[i] + 1);
  k.ringFaces = ringFaces; // the normals' faces come first among the faces
  // The frame's working rows, a vertex's position and normal side by side (one cache line read per
  // corner), in double precision, at rest to begin with (rows that no frame writes keep them); the
  // faces' corners as offsets into them.
  k.xn = Float64Array.from(k.rest);
  k.faceRows = new Uint32Array(3 * ringFaces);
  for (let i = 0; i < k.faceRows.length; ++i) k.faceRows[i] = 6 * k.faces[i];
  k.recordRows = new Uint32Array(3 * records);
  for (let r = 0; r < records; ++r)
    for (let c = 0; c < 3; ++c) k.recordRows[3 * r + c] = 6 * k.faces[3 * k.recordFace[r] + c];
  k.cross = new Float64Array(3 * ringFaces);
  k.coefficients = new Float64Array(3 * columns);
  return k;
}

/// Positions (x, y, z per slot, the order of the region's movable vertices) into `out`
/// (Float32Array, 3 per movable vertex) under `transforms`: per handle the 12 numbers of the rows
/// of [M | t] (identity for a missing one).
export function evaluateKernel(k, transforms, out) {
  blend(k, transforms);
  normals(k);
  decode(k, out);
  return out;
}

const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0];

/// Step 1: the basis rows times C = [I; M_0ᵀ; t_0ᵀ; ...], and the handles' own vertices moved
/// rigidly with their maps.
function blend(k, transforms) {
  const { columns, basis, freeLocal, rows, xn: x, rest, coefficients: C } = k;
  C.fill(0);
  C[0] = C[4] = C[8] = 1;
  for (let j = 0; j < k.handles; ++j) {
    const t = transforms[j] ?? IDENTITY;
    for (let c = 0; c < 4; ++c)
      for (let r = 0; r < 3; ++r) C[3 * (3 + 4 * j + c) + r] = t[4 * r + c];
  }
  for (let i = 0; i < rows; ++i) {
    let px = 0, py = 0, pz = 0;
    for (let c = 0, b = i * columns; c < columns; ++c, ++b) {
      const w = basis[b];
      px += w * C[3 * c]; py += w * C[3 * c + 1]; pz += w * C[3 * c + 2];
    }
    const v = 6 * freeLocal[i];
    x[v] = px; x[v + 1] = py; x[v + 2] = pz;
  }
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
  const len = Math.hypot(...e1), area2 = Math.hypot(...cr);
  if (!(area2 > 1e-14 * Math.max(len * len, e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2])) || !(len > 0)) return null;
  const t1 = e1.map((v) => v / len), nf = cr.map((v) => v / area2);
  const t2 = [nf[1] * t1[2] - nf[2] * t1[1], nf[2] * t1[0] - nf[0] * t1[2], nf[0] * t1[1] - nf[1] * t1[0]];
  return [t1, t2, nf];
}
