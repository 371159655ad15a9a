// Vertex normals of the vertices a drag moves, for the page's latency only: the same area-weighted
// formula as three.js's BufferGeometry.computeVertexNormals() (the sum of the unnormalized face
// normals (c - b) x (a - b) over a vertex's faces, then normalized), evaluated only where a moved
// vertex can change it. web/tests/e2e.mjs checks the result against computeVertexNormals().

/// The work of one region, computed once: `vertices`, the vertices whose normal depends on a
/// movable vertex (the corners of every face touching one), sorted; `faces`, every face touching
/// one of those (their normals are the sums); `first`, `last`, the smallest and largest of
/// `vertices` (the attribute range to upload). indices: Uint32 triples; movable: vertex ids.
export function normalPlan(indices, vertexCount, movable) {
  const moves = new Uint8Array(vertexCount);
  for (const v of movable) moves[v] = 1;
  const affected = new Uint8Array(vertexCount);
  for (let f = 0; f < indices.length; f += 3) {
    const a = indices[f], b = indices[f + 1], c = indices[f + 2];
    if (moves[a] || moves[b] || moves[c]) { affected[a] = 1; affected[b] = 1; affected[c] = 1; }
  }
  const faces = [];
  for (let f = 0; f < indices.length; f += 3)
    if (affected[indices[f]] || affected[indices[f + 1]] || affected[indices[f + 2]]) faces.push(f);
  const vertices = [];
  for (let v = 0; v < vertexCount; ++v) if (affected[v]) vertices.push(v);
  return { vertices: Uint32Array.from(vertices), faces: Uint32Array.from(faces), affected,
           first: vertices.length ? vertices[0] : 0, last: vertices.length ? vertices[vertices.length - 1] : -1 };
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
