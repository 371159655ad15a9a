// What the browser tests share: their command line, `remora serve` on a free port, Debian's
// chromium (headless, SwiftShader WebGL) through playwright-core, the API from node, mouse strokes
// and drags on the page, and a procedural mesh written as binary PLY.
import { spawn } from 'node:child_process';
import { existsSync, mkdirSync, writeFileSync } from 'node:fs';
import { dirname } from 'node:path';

/// --key value pairs of the command line.
export const args = Object.fromEntries(process.argv.slice(2).reduce((pairs, a, i, all) =>
  (a.startsWith('--') ? [...pairs, [a.slice(2), all[i + 1]]] : pairs), []));

/// playwright-core's chromium, or exits with 77 (skipped) naming what is missing.
export async function chromiumOrSkip() {
  const path = process.env.CHROMIUM ?? '/usr/bin/chromium';
  let chromium;
  try {
    ({ chromium } = await import('playwright-core'));
  } catch (e) {
    console.log('SKIP: playwright-core is not installed (scripts/build_web.sh installs it)');
    process.exit(77);
  }
  if (!existsSync(path)) {
    console.log(`SKIP: no chromium at ${path} (scripts/bootstrap.sh --web installs it)`);
    process.exit(77);
  }
  return chromium.launch({ executablePath: path, headless: true,
    args: ['--use-gl=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-sandbox'] });
}

export const results = { failures: 0 };
const t0 = Date.now();
export function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what} [${((Date.now() - t0) / 1000).toFixed(0)} s]`);
  if (!ok) results.failures += 1;
}

/// `remora serve MESH --port 0` with extra arguments; resolves to { server, url, started } once it
/// prints its URL (started: Date.now() at the spawn).
export async function startServer(cli, mesh, webRoot, extra = []) {
  const started = Date.now();
  const server = spawn(cli, ['serve', mesh, '--port', '0', '--web-root', webRoot, ...extra],
                       { stdio: ['ignore', 'pipe', 'inherit'] });
  const url = await new Promise((resolve, reject) => {
    let out = '';
    server.stdout.on('data', (d) => { out += d; const m = out.match(/http:\/\/[^\s]+/); if (m) resolve(m[0]); });
    server.on('exit', (code) => reject(new Error(`remora serve exited with ${code}`)));
    setTimeout(() => reject(new Error('remora serve printed no URL in 30 s')), 30000);
  });
  return { server, url, started };
}

/// The API of the server at `url`, from node: api(path) throws on a refusal.
export function client(url) {
  const api = async (path, options) => {
    const r = await fetch(url + 'api/' + path, options);
    if (!r.ok) throw new Error(`${path}: ${r.status} ${await r.text()}`);
    return r;
  };
  return { api, floats: async (path) => new Float32Array(await (await api(path)).arrayBuffer()),
           json: async (path) => (await api(path)).json() };
}

export const ready = (page, timeout = 120000) => page.waitForFunction(() => window.remora?.ready(), null, { timeout });

/// A short stroke with the mouse from the screen position of vertex `vertex`.
export async function stroke(page, vertex, steps = 5) {
  const p = await page.evaluate((v) => window.remora.project(v), vertex);
  await page.mouse.move(p.x, p.y);
  await page.mouse.down();
  for (let i = 1; i <= steps; ++i) await page.mouse.move(p.x + i, p.y + i);
  await page.mouse.up();
}

/// Drags with the mouse from (x, y) by (dx, dy) per step, `steps` steps; with `interval` (ms), a
/// step starts no sooner than that after the one before (a hand's pace), else at once.
export async function drag(page, x, y, dx, dy, steps = 10, interval = 0) {
  await page.mouse.move(x, y);
  await page.mouse.down();
  let next = performance.now();
  for (let i = 1; i <= steps; ++i) {
    const wait = next - performance.now();
    if (wait > 0) await new Promise((resolve) => setTimeout(resolve, wait));
    next = performance.now() + interval;
    await page.mouse.move(x + dx * i, y + dy * i);
  }
  await page.mouse.up();
}

/// The requests the page makes, as "METHOD path" (path after /api/), with their JSON bodies.
export function recordRequests(page) {
  const log = [];
  page.on('request', (r) => {
    const path = new URL(r.url()).pathname.replace(/^\/api\//, '');
    let body = null;
    try { body = JSON.parse(r.postData() ?? 'null'); } catch (e) { /* binary */ }
    log.push({ what: `${r.method()} ${path}`, body });
  });
  return log;
}

/// Writes a closed bumpy torus of 2 * nu * nv triangles (nu around its axis z, nv around its
/// tube; major radius 1, tube radius 0.4 with bumps of 3 %) as a binary little-endian PLY.
/// Every vertex has six neighbours: a clean mesh of any size for the tests.
export function writeBumpyTorus(path, nu, nv) {
  mkdirSync(dirname(path), { recursive: true });
  const header = Buffer.from(`ply\nformat binary_little_endian 1.0\nelement vertex ${nu * nv}\n` +
    'property float x\nproperty float y\nproperty float z\n' +
    `element face ${2 * nu * nv}\nproperty list uchar int vertex_indices\nend_header\n`);
  const vertices = Buffer.alloc(12 * nu * nv);
  for (let i = 0; i < nu; ++i)
    for (let j = 0; j < nv; ++j) {
      const u = 2 * Math.PI * i / nu, v = 2 * Math.PI * j / nv;
      const r = 0.4 * (1 + 0.03 * Math.sin(12 * u) * Math.sin(8 * v));
      const o = 12 * (i * nv + j);
      vertices.writeFloatLE((1 + r * Math.cos(v)) * Math.cos(u), o);
      vertices.writeFloatLE((1 + r * Math.cos(v)) * Math.sin(u), o + 4);
      vertices.writeFloatLE(r * Math.sin(v), o + 8);
    }
  const faces = Buffer.alloc(13 * 2 * nu * nv);
  let o = 0;
  const id = (i, j) => (i % nu) * nv + (j % nv);
  for (let i = 0; i < nu; ++i)
    for (let j = 0; j < nv; ++j)
      for (const f of [[id(i, j), id(i + 1, j), id(i + 1, j + 1)], [id(i, j), id(i + 1, j + 1), id(i, j + 1)]]) {
        faces.writeUInt8(3, o);
        faces.writeInt32LE(f[0], o + 1); faces.writeInt32LE(f[1], o + 5); faces.writeInt32LE(f[2], o + 9);
        o += 13;
      }
  writeFileSync(path, Buffer.concat([header, vertices, faces]));
}

/// The text of an OBJ file: the cube [-1, 1]^3 with each side an n x n grid of squares split in
/// two triangles, vertices shared along the edges (a closed CAD-like part with 90° creases).
export function boxObj(n) {
  const ids = new Map(), lines = [];
  const vertex = (p) => {
    const key = p.map((x) => x.toFixed(6)).join(' ');
    if (!ids.has(key)) { ids.set(key, ids.size + 1); lines.push(`v ${key}`); }
    return ids.get(key);
  };
  for (let axis = 0; axis < 3; ++axis)
    for (const side of [-1, 1]) {
      const at = (i, j) => {
        const p = [0, 0, 0];
        p[axis] = side; p[(axis + 1) % 3] = -1 + 2 * i / n; p[(axis + 2) % 3] = -1 + 2 * j / n;
        return vertex(p);
      };
      for (let i = 0; i < n; ++i)
        for (let j = 0; j < n; ++j) {
          const [a, b, c, d] = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
          // Outward: counter-clockwise seen from outside.
          lines.push(side > 0 ? `f ${a} ${b} ${c}\nf ${a} ${c} ${d}` : `f ${a} ${c} ${b}\nf ${a} ${d} ${c}`);
        }
    }
  return lines.join('\n') + '\n';
}
