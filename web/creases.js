// Sharp creases for display only: where faces around a vertex meet at more than `angle` degrees,
// the vertex is drawn once per group of faces, so that its normals do not smooth across the
// crease (a CAD part's edges stay sharp instead of showing dark streaks). The mesh itself, its
// ids and everything sent to the server are unchanged: the display keeps a map back to them.
import { vertexFaces } from './normals.js';

/// Splits the corners of `indices` (Uint32 triples over positions' vertices) at creases sharper
/// than `angle` degrees. Returns null when nothing is split, otherwise { indices: the display's
/// faces, map: Uint32Array display vertex -> mesh vertex (the first n are the mesh's own, in
/// order), copies: { start, ids }, for mesh vertex v the extra display vertices
/// ids[start[v]..start[v+1]) }. A face of zero area joins a vertex's first group.
export function splitCreases(positions, indices, angle = 60) {
  const n = positions.length / 3;
  const normals = faceNormals(positions, indices);
  const { begin: start, faces: facesOf } = vertexFaces(indices, n); // face offsets 3 f

  const cosLimit = Math.cos(angle * Math.PI / 180);
  const corners = Uint32Array.from(indices);
  const extra = [];
  const groups = []; // per vertex: [face whose normal represents the group, display id]
  for (let v = 0; v < n; ++v) {
    groups.length = 0;
    for (let i = start[v]; i < start[v + 1]; ++i) {
      const f = facesOf[i] / 3;
      let id = -1;
      for (const [g, gid] of groups) {
        const d = normals[3 * f] * normals[3 * g] + normals[3 * f + 1] * normals[3 * g + 1] + normals[3 * f + 2] * normals[3 * g + 2];
        if (d >= cosLimit || !hasArea(normals, f) || !hasArea(normals, g)) { id = gid; break; }
      }
      if (id < 0) {
        id = groups.length ? n + extra.length : v;
        if (groups.length) extra.push(v);
        groups.push([f, id]);
      }
      for (let k = 0; k < 3; ++k) if (indices[3 * f + k] === v) corners[3 * f + k] = id;
    }
  }
  if (!extra.length) return null;
  const map = new Uint32Array(n + extra.length);
  for (let v = 0; v < n; ++v) map[v] = v;
  map.set(extra, n);
  return { indices: corners, map, copies: copiesOf(n, extra) };
}

const hasArea = (normals, f) => normals[3 * f] !== 0 || normals[3 * f + 1] !== 0 || normals[3 * f + 2] !== 0;

function faceNormals(p, indices) {
  const out = new Float32Array(indices.length);
  for (let f = 0; f < indices.length; f += 3) {
    const a = indices[f], b = indices[f + 1], c = indices[f + 2];
    const ux = p[3 * b] - p[3 * a], uy = p[3 * b + 1] - p[3 * a + 1], uz = p[3 * b + 2] - p[3 * a + 2];
    const vx = p[3 * c] - p[3 * a], vy = p[3 * c + 1] - p[3 * a + 1], vz = p[3 * c + 2] - p[3 * a + 2];
    const x = uy * vz - uz * vy, y = uz * vx - ux * vz, z = ux * vy - uy * vx;
    const length = Math.sqrt(x * x + y * y + z * z);
    if (length > 0) { out[f] = x / length; out[f + 1] = y / length; out[f + 2] = z / length; }
  }
  return out;
}

/// For each mesh vertex the display vertices beyond the first n that copy it.
function copiesOf(n, extra) {
  const start = new Uint32Array(n + 1);
  for (const v of extra) start[v + 1] += 1;
  for (let v = 0; v < n; ++v) start[v + 1] += start[v];
  const fill = start.slice(0, n), ids = new Uint32Array(extra.length);
  extra.forEach((v, j) => { ids[fill[v]++] = n + j; });
  return { start, ids };
}

/// The display ids of mesh vertices `ids`: each id and its copies.
export function withCopies(ids, copies) {
  if (!copies) return ids;
  const out = Array.from(ids);
  for (const v of ids) for (let i = copies.start[v]; i < copies.start[v + 1]; ++i) out.push(copies.ids[i]);
  return out;
}
