// Vertex normals of the vertices a drag moves, for the page's latency only: the same area-weighted
// formula as three.js's BufferGeometry.computeVertexNormals() (the sum of the unnormalized face
// normals (c - b) x (a - b) over a vertex's faces, then normalized), evaluated only where a moved
// vertex can change it. web/tests/e2e.mjs checks the result against computeVertexNormals().
// Where the page has kernel.wasm, wasmNormals() computes the same sums there (display_normals()
// in web/wasm/kernel.cpp), in double precision.
import { wasmLayout } from './engine.js';

/// The faces around each vertex, built once per mesh: faces(v) are the face offsets (3 f) in
/// faces[begin[v] .. begin[v + 1]). indices: Uint32 triples.
export function vertexFaces(indices, vertexCount) {
  const begin = new Uint32Array(vertexCount + 1);
  for (let i = 0; i < indices.length; ++i) begin[indices[i] + 1] += 1;
  for (let v = 0; v < vertexCount; ++v) begin[v + 1] += begin[v];
  const fill = begin.slice(0, vertexCount), faces = new Uint32Array(indices.length);
  for (let i = 0; i < indices.length; ++i) faces[fill[indices[i]]++] = i - (i % 3);
  return { begin, faces };
}

/// The work of one region, computed once from the faces around its vertices (vertexFaces()):
/// `vertices`, the vertices whose normal depends on a movable vertex (the corners of every face
/// touching one), sorted; `faces`, every face touching one of those (their normals are the
/// sums); `first`, `last`, the smallest and largest of `vertices` (the attribute range to
/// upload); `affected`, 1 for each of `vertices`. indices: Uint32 triples; movable: vertex ids.
export function normalPlan(indices, around, movable) {
  // Plain index loops over typed arrays: this runs once per region, mostly before the JIT has
  // optimized it, where closures and iterators cost several times more.
  const { begin, faces: ring } = around;
  const vertexCount = begin.length - 1;
  const affected = new Uint8Array(vertexCount), list = new Uint32Array(vertexCount);
  let count = 0;
  for (let i = 0; i < movable.length; ++i) {
    const v = movable[i];
    for (let k = begin[v], end = begin[v + 1]; k < end; ++k)
      for (let c = ring[k], last = c + 3; c < last; ++c) {
        const w = indices[c];
        if (affected[w] === 0) { affected[w] = 1; list[count++] = w; }
      }
  }
  const seen = new Uint8Array(indices.length / 3), faceList = new Uint32Array(indices.length / 3);
  let faceCount = 0;
  for (let i = 0; i < count; ++i) {
    const v = list[i];
    for (let k = begin[v], end = begin[v + 1]; k < end; ++k) {
      const f = ring[k], t = (f / 3) | 0;
      if (seen[t] === 0) { seen[t] = 1; faceList[faceCount++] = f; }
    }
  }
  const vertices = list.slice(0, count).sort();
  return { vertices, faces: faceList.slice(0, faceCount).sort(), affected,
           first: count ? vertices[0] : 0, last: count ? vertices[count - 1] : -1 };
}

/// Recomputes normals[3v..3v+2] for every v in plan.vertices from positions (Float32 x, y, z per
/// vertex); every other normal is left as it is.
export function updateNormals(positions, indices, normals, plan) {
  const p = positions, n = normals, affected = plan.affected;
  for (const v of plan.vertices) { n[3 * v] = 0; n[3 * v + 1] = 0; n[3 * v + 2] = 0; }
  for (const f of plan.faces) {
    const a = indices[f], b = indices[f + 1], c = indices[f + 2];
    const bx = p[3 * b], by = p[3 * b + 1], bz = p[3 * b + 2];
    const cbx = p[3 * c] - bx, cby = p[3 * c + 1] - by, cbz = p[3 * c + 2] - bz;
    const abx = p[3 * a] - bx, aby = p[3 * a + 1] - by, abz = p[3 * a + 2] - bz;
    const x = cby * abz - cbz * aby, y = cbz * abx - cbx * abz, z = cbx * aby - cby * abx;
    if (affected[a]) { n[3 * a] += x; n[3 * a + 1] += y; n[3 * a + 2] += z; }
    if (affected[b]) { n[3 * b] += x; n[3 * b + 1] += y; n[3 * b + 2] += z; }
    if (affected[c]) { n[3 * c] += x; n[3 * c + 1] += y; n[3 * c + 2] += z; }
  }
  for (const v of plan.vertices) {
    const x = n[3 * v], y = n[3 * v + 1], z = n[3 * v + 2];
    const length = Math.sqrt(x * x + y * y + z * z) || 1;
    n[3 * v] = x / length; n[3 * v + 1] = y / length; n[3 * v + 2] = z / length;
  }
}

/// The plan's normals in an instance of kernel.wasm (web/engine.js), for the frames of one region:
/// update(positions, moved, normals) takes the drawn positions (the moved vertices already
/// written) and `moved` (x, y, z per vertex of this `movable`, in its order: the caller checks
/// that its frame is of these vertices) and writes the plan's normals into `normals`, as
/// updateNormals() does. `map`: the drawn vertex's mesh vertex (crease copies),
/// or null; meshVertices: the mesh's vertex count. Null without kernel.wasm.
export function wasmNormals(indices, plan, movable, map, meshVertices) {
  const layout = wasmLayout();
  if (!layout) return null;
  const drawn = plan.affected.length;
  // Where each drawn corner's position is: the slot of its mesh vertex among the moved ones, or
  // one of the constant positions (corners that do not move), gathered each frame.
  const slotOfMesh = new Int32Array(meshVertices).fill(-1);
  for (let i = 0; i < movable.length; ++i) slotOfMesh[movable[i]] = i;
  const reference = new Int32Array(drawn).fill(-1), constants = [];
  const target = new Int32Array(drawn).fill(-1);
  for (let i = 0; i < plan.vertices.length; ++i) target[plan.vertices[i]] = i;
  const faces = plan.faces.length, corner = new Uint32Array(3 * faces), toward = new Int32Array(3 * faces);
  for (let f = 0; f < faces; ++f)
    for (let k = 0; k < 3; ++k) {
      const d = indices[plan.faces[f] + k];
      if (reference[d] < 0) {
        const slot = slotOfMesh[map ? map[d] : d];
        if (slot >= 0) reference[d] = slot;
        else { reference[d] = movable.length + constants.length; constants.push(d); }
      }
      corner[3 * f + k] = reference[d];
      toward[3 * f + k] = target[d];
    }
  const vertices = plan.vertices.length, positionCount = movable.length + constants.length;
  const cornerAt = layout.reserve(4 * corner.length), targetAt = layout.reserve(4 * toward.length);
  const positionsAt = layout.reserve(12 * positionCount), sumsAt = layout.reserve(24 * vertices);
  const normalsAt = layout.reserve(12 * vertices), struct = layout.reserve(4 * 7);
  const instance = layout.instantiate(), w = instance.exports, memory = instance.buffer;
  new Uint32Array(memory, cornerAt, corner.length).set(corner);
  new Int32Array(memory, targetAt, toward.length).set(toward);
  new Uint32Array(memory, struct, 7).set([faces, vertices, cornerAt, targetAt, positionsAt, sumsAt, normalsAt]);
  const moving = new Float32Array(memory, positionsAt, 3 * movable.length);
  const fixed = new Float32Array(memory, positionsAt + 12 * movable.length, 3 * constants.length);
  const result = new Float32Array(memory, normalsAt, 3 * vertices), still = Uint32Array.from(constants);
  return {
    movable,
    update(positions, moved, normals) {
      moving.set(moved);
      for (let i = 0; i < still.length; ++i) {
        const d = still[i];
        fixed[3 * i] = positions[3 * d]; fixed[3 * i + 1] = positions[3 * d + 1]; fixed[3 * i + 2] = positions[3 * d + 2];
      }
      w.display_normals(struct);
      const list = plan.vertices;
      for (let i = 0; i < list.length; ++i) {
        const v = list[i];
        normals[3 * v] = result[3 * i]; normals[3 * v + 1] = result[3 * i + 1]; normals[3 * v + 2] = result[3 * i + 2];
      }
    },
  };
}
