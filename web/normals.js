// Vertex normals of the vertices a drag moves, for the page's latency only: the same area-weighted
// formula as three.js's BufferGeometry.computeVertexNormals() (the sum of the unnormalized face
// normals (c - b) x (a - b) over a vertex's faces, then normalized), evaluated only where a moved
// vertex can change it. web/tests/e2e.mjs checks the result against computeVertexNormals().
// Where the page has kernel.wasm, the same sums are computed there (display_normals_part() in
// web/wasm/kernel.cpp), in double precision: as the last step of the page's own frame, on its two
// threads (web/kernel.js), or alone on one thread for the server's frames (wasmNormals()).
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

/// The owner (0 or 1) of each of `vertices` (drawn ids; −1 for the others of `count`): the side
/// of a plane across the longest extent of their `positions` that holds about half of them, so
/// that few faces have corners of both.
function halves(positions, vertices, count) {
  const low = [Infinity, Infinity, Infinity], high = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < vertices.length; ++i)
    for (let c = 0; c < 3; ++c) {
      const x = positions[3 * vertices[i] + c];
      low[c] = Math.min(low[c], x); high[c] = Math.max(high[c], x);
    }
  const axis = [0, 1, 2].reduce((a, c) => (high[c] - low[c] > high[a] - low[a] ? c : a), 0);
  const bins = 1024, histogram = new Uint32Array(bins), scale = bins / (high[axis] - low[axis] || 1);
  const bin = (v) => Math.min(bins - 1, Math.floor((positions[3 * v + axis] - low[axis]) * scale));
  for (let i = 0; i < vertices.length; ++i) histogram[bin(vertices[i])] += 1;
  let split = 0;
  for (let sum = 0; split < bins && sum + histogram[split] <= vertices.length / 2; ++split) sum += histogram[split];
  const owner = new Int8Array(count).fill(-1);
  for (let i = 0; i < vertices.length; ++i) owner[vertices[i]] = bin(vertices[i]) < split ? 0 : 1;
  return owner;
}

/// The plan's faces as kernel.wasm's drawn normals read them (struct DisplayNormals,
/// web/wasm/kernel.cpp), for the frames of one region, in two parts that write disjoint vertices
/// (one per thread): halves() of the drawn `positions` splits the plan's vertices, and a face
/// with corners in both parts is in both (each part sums into its own corners). `corner` indexes the
/// positions: the slot of a moved vertex in `movable` (x, y, z per vertex of movable, in its
/// order: the frame's), or movable.length + i for `constants[i]`, a drawn vertex that does not
/// move, gathered from the drawn positions each frame. `target` is the corner's index into
/// `vertices` (drawn ids, part 0's first), or −1. `map`: the drawn vertex's mesh vertex (crease
/// copies), or null; meshVertices: the mesh's vertex count.
export function drawnNormalsLayout(indices, positions, plan, movable, map, meshVertices) {
  const drawn = plan.affected.length, faceCount = plan.faces.length;
  const slotOfMesh = new Int32Array(meshVertices).fill(-1);
  for (let i = 0; i < movable.length; ++i) slotOfMesh[movable[i]] = i;
  const owner = halves(positions, plan.vertices, drawn);
  const number = new Int32Array(drawn).fill(-1), vertices = new Uint32Array(plan.vertices.length);
  const vertexBegin = [0, 0, plan.vertices.length];
  let n = 0;
  for (let part = 0; part < 2; ++part) {
    vertexBegin[part] = n;
    for (let i = 0; i < plan.vertices.length; ++i) {
      const d = plan.vertices[i];
      if (owner[d] === part) { number[d] = n; vertices[n++] = d; }
    }
  }
  // Plain loops over typed arrays, as in normalPlan(): this runs once per region.
  const lists = [new Uint32Array(faceCount), new Uint32Array(faceCount)], sizes = [0, 0];
  for (let f = 0; f < faceCount; ++f) {
    const c = plan.faces[f], a = owner[indices[c]], b = owner[indices[c + 1]], e = owner[indices[c + 2]];
    if (a === 0 || b === 0 || e === 0) lists[0][sizes[0]++] = f;
    if (a === 1 || b === 1 || e === 1) lists[1][sizes[1]++] = f;
  }
  const total = sizes[0] + sizes[1];
  const corner = new Uint32Array(3 * total), target = new Int32Array(3 * total), reference = new Int32Array(drawn).fill(-1);
  const constants = [];
  let at = 0;
  for (let part = 0; part < 2; ++part)
    for (let i = 0; i < sizes[part]; ++i) {
      const f = lists[part][i];
      for (let k = 0; k < 3; ++k, ++at) {
        const d = indices[plan.faces[f] + k];
        if (reference[d] < 0) {
          const slot = slotOfMesh[map ? map[d] : d];
          reference[d] = slot >= 0 ? slot : movable.length + constants.push(d) - 1;
        }
        corner[at] = reference[d];
        target[at] = owner[d] === part ? number[d] : -1;
      }
    }
  return { movable, corner, target, vertices, constants: Uint32Array.from(constants),
           faceBegin: [0, sizes[0], total], vertexBegin };
}

/// Lays out a drawnNormalsLayout() in an instance of kernel.wasm that is being laid out
/// (web/engine.js, wasmLayout()), with `positionsAt`, the offset of its positions (room for
/// x, y, z of each of movable and of constants). Returns fill(memory), which copies the layout in
/// once the instance exists and returns the drawn normals of its frames: { struct (the
/// DisplayNormals offset), movable, update(drawn, normals) }. update() gathers the constants from
/// `drawn` (the drawn positions), expects the moved positions at positionsAt already, and calls
/// `compute` (the instance's display_normals_part on one or two threads), then writes the normals
/// into `normals` (the drawn normals, 3 per drawn vertex).
export function placeDrawnNormals(layout, drawn, positionsAt) {
  const vertexCount = drawn.vertices.length, movable = drawn.movable.length;
  const cornerAt = layout.reserve(4 * drawn.corner.length), targetAt = layout.reserve(4 * drawn.target.length);
  const sumsAt = layout.reserve(24 * vertexCount), normalsAt = layout.reserve(12 * vertexCount);
  const struct = layout.reserve(4 * 11);
  return (memory) => {
    new Uint32Array(memory, cornerAt, drawn.corner.length).set(drawn.corner);
    new Int32Array(memory, targetAt, drawn.target.length).set(drawn.target);
    new Uint32Array(memory, struct, 11).set([...drawn.faceBegin, ...drawn.vertexBegin, cornerAt, targetAt, positionsAt, sumsAt, normalsAt]);
    const fixed = new Float32Array(memory, positionsAt + 12 * movable, 3 * drawn.constants.length);
    const result = new Float32Array(memory, normalsAt, 3 * vertexCount), still = drawn.constants, list = drawn.vertices;
    return {
      struct, movable: drawn.movable,
      update(positions, normals, compute) {
        for (let i = 0; i < still.length; ++i) {
          const d = still[i];
          fixed[3 * i] = positions[3 * d]; fixed[3 * i + 1] = positions[3 * d + 1]; fixed[3 * i + 2] = positions[3 * d + 2];
        }
        compute();
        for (let i = 0; i < list.length; ++i) {
          const v = list[i];
          normals[3 * v] = result[3 * i]; normals[3 * v + 1] = result[3 * i + 1]; normals[3 * v + 2] = result[3 * i + 2];
        }
      },
    };
  };
}

/// The drawn normals of a drawnNormalsLayout() in an instance of kernel.wasm of their own, on one
/// thread, for frames that come from the server: update(positions, moved, normals) takes the
/// drawn positions (the moved vertices already written) and `moved` (x, y, z per vertex of this
/// `movable`, in its order: the caller checks that its frame is of these vertices) and writes the
/// plan's normals into `normals`, as updateNormals() does. Null without kernel.wasm.
export function wasmNormals(drawn) {
  const layout = wasmLayout();
  if (!layout) return null;
  const positionsAt = layout.reserve(12 * (drawn.movable.length + drawn.constants.length));
  const fill = placeDrawnNormals(layout, drawn, positionsAt);
  const instance = layout.instantiate(), w = instance.exports;
  const placed = fill(instance.buffer);
  const moving = new Float32Array(instance.buffer, positionsAt, 3 * drawn.movable.length);
  return {
    movable: drawn.movable,
    update(positions, moved, normals) {
      moving.set(moved);
      placed.update(positions, normals, () => w.display_normals_part(placed.struct, 0, 1));
    },
  };
}
