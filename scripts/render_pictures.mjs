#!/usr/bin/env node
// Renders the pictures in docs/images/ from real results: `remora serve` computes every edit and
// base, the project's own page (build/web) draws them in Debian's chromium (headless, SwiftShader
// WebGL, driven by playwright-core from web/node_modules), and this script composes two views into
// one PNG. A user's steps, through the HTTP API (docs/server.md): open the mesh, set the region,
// set the handle's transform and commit; then the page is opened and draws what the server holds.
// Its URL options (ui=0, camera=, show-*=, area-range=) only choose what is drawn and from where.
//
//   node scripts/render_pictures.mjs [--out docs/images] [--width 800] [--height 500] [--scale S]
//        [--only NAME[,NAME...]] [--cli build/bin/remora] [--web-root build/web]
//
// Pictures: bunny_ear, acrossriver_lift, base_area, needles_base, cylinder_twist and bunny_ear_twist
// (the methods linear, nonlinear and blended motions side by side; the bumpy cylinder is written by this script into
// the system's temporary folder). The shared meshes are read from
// ../shared/data beside the repository (REMORA_DATA overrides); a missing one skips its picture
// with a message. Each PNG is written to a temporary name and renamed, so none is ever partial.
// Exit code 0: done (maybe with skips), 1: failed, 2: usage error, 77: chromium or playwright-core
// missing (web/tests/pictures.mjs, the CI smoke test, reports that as skipped).
import { spawn } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, renameSync, rmSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { deflateSync } from 'node:zlib';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..');
const usage = `usage: node scripts/render_pictures.mjs [--out DIR] [--width W] [--height H] [--scale S]
       [--only NAME[,NAME...]] [--cli PATH] [--web-root DIR]
pictures: bunny_ear, acrossriver_lift, base_area, needles_base, cylinder_twist, bunny_ear_twist`;

// ---- options ------------------------------------------------------------------------------------
function parseOptions(argv) {
  const o = { out: join(root, 'docs/images'), width: 800, height: 500, scale: 1, only: null,
              cli: join(root, 'build/bin/remora'), 'web-root': join(root, 'build/web') };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    if (a === '--help' || a === '-h') { console.log(usage); process.exit(0); }
    const key = a.startsWith('--') ? a.slice(2) : null;
    if (!key || !(key in o)) usageError(`unknown argument '${a}'`);
    if (i + 1 >= argv.length) usageError(`${a} needs a value`);
    o[key] = argv[++i];
  }
  for (const key of ['width', 'height', 'scale']) {
    o[key] = Number(o[key]);
    if (!(o[key] > 0) || !Number.isFinite(o[key])) usageError(`--${key} must be a positive number`);
  }
  o.width = Math.round(o.width * o.scale);
  o.height = Math.round(o.height * o.scale);
  if (o.width < 64 || o.height < 64 || o.width > 4096 || o.height > 4096)
    usageError(`the picture size ${o.width}x${o.height} must lie within 64..4096 on each side`);
  if (o.only !== null) {
    o.only = o.only.split(',');
    for (const name of o.only)
      if (!PICTURES.some((p) => p.name === name)) usageError(`--only: no picture named '${name}'`);
  }
  for (const key of ['out', 'cli', 'web-root']) o[key] = resolve(o[key]);
  return o;
}
function usageError(text) {
  console.error(`render_pictures: ${text}\n${usage}`);
  process.exit(2);
}

// ---- the pictures -------------------------------------------------------------------------------
const dataDir = resolve(process.env.REMORA_DATA ?? join(root, '..', 'shared', 'data'));
const BUNNY = { path: join(root, 'data/bunny.ply'), bundled: true };
const ACROSS_RIVER = { path: join(dataDir, 'heightfield/AcrossRiver.stl') };
const FEATURETYPE = { path: join(dataDir, 'cad/featuretype.STL') };

/// An open cylinder of radius 1 and height 4 about z with bumps of amplitude 0.02 (12 around,
/// wavelength 0.5 along z): make_cylinder(70, 96, 1, 4) of src/remora/mesh/primitives.h and the
/// bumps of tests/test_nonlinear.cpp, as an OBJ file.
function writeBumpyCylinder(path) {
  const rings = 70, segments = 96, lines = [];
  for (let k = 0; k <= rings; ++k)
    for (let s = 0; s < segments; ++s) {
      const phi = 2 * Math.PI * (s + (k % 2 ? 0.5 : 0)) / segments, z = 4 * k / rings;
      const r = 1 + 0.02 * Math.sin(12 * phi) * Math.sin(2 * Math.PI * z / 0.5);
      lines.push(`v ${r * Math.cos(phi)} ${r * Math.sin(phi)} ${z}`);
    }
  const id = (k, s) => k * segments + (s % segments) + 1;
  for (let k = 0; k < rings; ++k)
    for (let s = 0; s < segments; ++s)
      if (k % 2 === 0) lines.push(`f ${id(k, s)} ${id(k, s + 1)} ${id(k + 1, s)}`, `f ${id(k, s + 1)} ${id(k + 1, s + 1)} ${id(k + 1, s)}`);
      else lines.push(`f ${id(k, s)} ${id(k + 1, s + 1)} ${id(k + 1, s)}`, `f ${id(k, s)} ${id(k, s + 1)} ${id(k + 1, s + 1)}`);
  writeFileSync(path, lines.join('\n') + '\n');
}
const CYLINDER = { path: join(tmpdir(), `remora_bumpy_cylinder_${process.pid}.obj`), generate: writeBumpyCylinder };

const sphere = (c, r) => (p) => (p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 + (p[2] - c[2]) ** 2 <= r * r;
const disc = (c, r) => (p) => (p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 <= r * r; // in x, y (plan view)
const above = (z) => (p) => p[2] > z;

// A picture: the mesh, an optional edit (a support and a handle as vertex predicates, the handle's
// translation and rotation about its centroid, as `remora edit` does), and two or three panels, each
// a view of the page (its URL options) before or after the edit (after it with the panel's method
// as the page's switch names it, linear unless it says), side by side (row) or stacked (column).
const PICTURES = [
  {
    name: 'base_area', mesh: BUNNY, layout: 'row',
    caption: 'vertex area / mean area:  blue -10 % (or less),  white 0,  red +10 % (or more)',
    panels: [
      { label: 'the remeshed base of bunny.ply, coloured by vertex area',
        show: { 'show-mesh': 0, 'show-base': 1, 'show-wire': 1, 'area-range': 0.1 },
        camera: [-0.07, 0.16, 0.16, -0.045, 0.13, 0.01] },
      { label: 'closer',
        show: { 'show-mesh': 0, 'show-base': 1, 'show-wire': 1, 'area-range': 0.1 },
        camera: [-0.02, 0.122, 0.085, -0.024, 0.117, 0.038] },
    ],
  },
  {
    name: 'bunny_ear', mesh: BUNNY, layout: 'row',
    edit: { support: sphere([-0.03, 0.15, 0], 0.05), handle: sphere([-0.03, 0.17, 0], 0.015),
            translate: [0, 0.02, 0], rotate: { axis: [0, 1, 0], degrees: 20 } },
    caption: 'support yellow, handle red: lifted 2 cm and turned 20° about y',
    panels: [
      { label: 'bunny.ply', stage: 'before', camera: [0.1, 0.2, 0.34, -0.02, 0.115, 0.0] },
      { label: 'after the edit', stage: 'after', camera: [0.1, 0.2, 0.34, -0.02, 0.115, 0.0] },
    ],
  },
  {
    name: 'cylinder_twist', mesh: CYLINDER, layout: 'row',
    edit: { support: above(0.01), handle: above(3.99), rotate: { axis: [0, 0, 1], degrees: 90 } },
    caption: 'an open cylinder with bumps, everything but the bottom circle free, the top circle turned 90°; the worst circle\'s mean radius',
    panels: [
      { label: 'linear: 0.80', stage: 'after', method: 'linear',
        camera: [6.5, -6.5, 4.0, 0, 0, 1.9, 0, 0, 1] },
      { label: 'nonlinear: 0.94', stage: 'after', method: 'nonlinear',
        camera: [6.5, -6.5, 4.0, 0, 0, 1.9, 0, 0, 1] },
      { label: 'blended motions: 1.00', stage: 'after', method: 'blended-motions',
        camera: [6.5, -6.5, 4.0, 0, 0, 1.9, 0, 0, 1] },
    ],
  },
  {
    name: 'bunny_ear_twist', mesh: BUNNY, layout: 'row',
    edit: { support: sphere([-0.03, 0.15, 0], 0.05), handle: sphere([-0.03, 0.17, 0], 0.015),
            rotate: { axis: [0, 1, 0], degrees: 90 } },
    caption: 'the ear\'s tip turned 90° about y',
    panels: [
      { label: 'linear', stage: 'after', method: 'linear', camera: [0.02, 0.19, 0.16, -0.035, 0.15, 0.0] },
      { label: 'nonlinear', stage: 'after', method: 'nonlinear', camera: [0.02, 0.19, 0.16, -0.035, 0.15, 0.0] },
      { label: 'blended motions', stage: 'after', method: 'blended-motions', camera: [0.02, 0.19, 0.16, -0.035, 0.15, 0.0] },
    ],
  },
  {
    name: 'needles_base', mesh: FEATURETYPE, layout: 'column',
    panels: [
      { label: 'featuretype.STL: its own triangles (74 % needles)',
        show: { 'show-edges': 1 },
        camera: [2.2, -4.1, 3.6, 0, -0.15, 0.3, 0, 0, 1] },
      { label: 'its remeshed base, coloured by vertex area',
        show: { 'show-mesh': 0, 'show-base': 1, 'show-wire': 1 },
        camera: [2.2, -4.1, 3.6, 0, -0.15, 0.3, 0, 0, 1] },
    ],
  },
  {
    name: 'acrossriver_lift', mesh: ACROSS_RIVER, layout: 'column',
    edit: { support: disc([660540, 4752990], 1000), handle: disc([660540, 4752990], 300),
            translate: [0, 0, 250] },
    caption: 'support yellow, handle red: lifted 250 m',
    panels: [
      { label: 'AcrossRiver.stl (Snake River canyon)', stage: 'before',
        camera: [660700, 4750750, 2200, 660700, 4752900, 850, 0, 0, 1] },
      { label: 'after the lift: the canyon rides along', stage: 'after',
        camera: [660700, 4750750, 2200, 660700, 4752900, 850, 0, 0, 1] },
    ],
  },
];

// ---- PNG ----------------------------------------------------------------------------------------
const CRC_TABLE = Array.from({ length: 256 }, (_, n) => {
  let c = n;
  for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
  return c >>> 0;
});
function crc32(buffer) {
  let c = 0xffffffff;
  for (const b of buffer) c = CRC_TABLE[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}
function chunk(type, data) {
  const out = Buffer.alloc(12 + data.length);
  out.writeUInt32BE(data.length, 0);
  out.write(type, 4, 'ascii');
  data.copy(out, 8);
  out.writeUInt32BE(crc32(out.subarray(4, 8 + data.length)), 8 + data.length);
  return out;
}

/// A PNG of RGBA pixels (alpha dropped): 8-bit RGB, or, when that exceeds `budget` bytes (a dense
/// wireframe), a palette of 256, 128 or 64 colours chosen by median cut: the first that fits.
function encodePng(rgba, width, height, budget) {
  let best = encodeRgb(rgba, width, height);
  for (const colours of [256, 128, 64]) {
    if (best.length <= budget) break;
    const indexed = encodeIndexed(rgba, width, height, colours);
    if (indexed.length < best.length) best = indexed;
  }
  return best;
}

const PNG_SIGNATURE = Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
function header(width, height, colourType) {
  const h = Buffer.alloc(13);
  h.writeUInt32BE(width, 0);
  h.writeUInt32BE(height, 4);
  h[8] = 8; // bit depth
  h[9] = colourType;
  return chunk('IHDR', h);
}

/// 8-bit RGB, each row with the filter whose output has the smallest sum of absolute values (the
/// usual heuristic), deflated at level 9.
function encodeRgb(rgba, width, height) {
  const stride = 3 * width;
  const raw = Buffer.alloc((stride + 1) * height);
  let prev = Buffer.alloc(stride);
  const filtered = Array.from({ length: 5 }, () => Buffer.alloc(stride));
  for (let y = 0; y < height; ++y) {
    const line = Buffer.alloc(stride);
    for (let x = 0; x < width; ++x)
      for (let c = 0; c < 3; ++c) line[3 * x + c] = rgba[4 * (y * width + x) + c];
    let best = 0, bestScore = Infinity;
    for (let f = 0; f < 5; ++f) {
      const out = filtered[f];
      let score = 0;
      for (let i = 0; i < stride; ++i) {
        const a = i >= 3 ? line[i - 3] : 0, b = prev[i], c = i >= 3 ? prev[i - 3] : 0;
        let predictor = 0;
        if (f === 1) predictor = a;
        else if (f === 2) predictor = b;
        else if (f === 3) predictor = (a + b) >> 1;
        else if (f === 4) {
          const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
          predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
        }
        const v = (line[i] - predictor) & 0xff;
        out[i] = v;
        score += v < 128 ? v : 256 - v;
      }
      if (score < bestScore) { bestScore = score; best = f; }
    }
    raw[y * (stride + 1)] = best;
    filtered[best].copy(raw, y * (stride + 1) + 1);
    prev = line;
  }
  return Buffer.concat([PNG_SIGNATURE, header(width, height, 2),
                        chunk('IDAT', deflateSync(raw, { level: 9, memLevel: 9 })), chunk('IEND', Buffer.alloc(0))]);
}

/// A palette of `colours` colours: median cut over a 5-bit-per-channel histogram, each pixel
/// mapped to the palette colour nearest its bin's mean; rows unfiltered (the usual choice).
function encodeIndexed(rgba, width, height, colours) {
  const n = width * height;
  const bin = new Uint16Array(n);
  const count = new Float64Array(32768), sum = new Float64Array(3 * 32768);
  for (let i = 0; i < n; ++i) {
    const r = rgba[4 * i], g = rgba[4 * i + 1], b = rgba[4 * i + 2];
    const k = ((r >> 3) << 10) | ((g >> 3) << 5) | (b >> 3);
    bin[i] = k;
    count[k] += 1; sum[3 * k] += r; sum[3 * k + 1] += g; sum[3 * k + 2] += b;
  }
  const mean = (k, c) => sum[3 * k + c] / count[k];
  let boxes = [Array.from({ length: 32768 }, (_, k) => k).filter((k) => count[k] > 0)];
  while (boxes.length < colours) {
    // Split the box with the widest channel range (weighted by its pixels) at its weighted median.
    let best = -1, bestScore = 0, bestChannel = 0;
    boxes.forEach((box, i) => {
      if (box.length < 2) return;
      let weight = 0;
      for (const k of box) weight += count[k];
      for (let c = 0; c < 3; ++c) {
        let lo = 255, hi = 0;
        for (const k of box) { const v = mean(k, c); lo = Math.min(lo, v); hi = Math.max(hi, v); }
        const score = (hi - lo) * Math.sqrt(weight);
        if (score > bestScore) { bestScore = score; best = i; bestChannel = c; }
      }
    });
    if (best < 0) break;
    const box = boxes[best].sort((a, b) => mean(a, bestChannel) - mean(b, bestChannel));
    let total = 0, half = 0, cut = 1;
    for (const k of box) total += count[k];
    for (let i = 0; i < box.length - 1; ++i) { half += count[box[i]]; cut = i + 1; if (half >= total / 2) break; }
    boxes.splice(best, 1, box.slice(0, cut), box.slice(cut));
  }
  const palette = boxes.map((box) => {
    let w = 0; const c = [0, 0, 0];
    for (const k of box) { w += count[k]; for (let j = 0; j < 3; ++j) c[j] += sum[3 * k + j]; }
    return c.map((x) => Math.round(x / w));
  });
  const index = new Uint8Array(32768);
  for (let k = 0; k < 32768; ++k) {
    if (!count[k]) continue;
    let best = 0, bestD = Infinity;
    palette.forEach((p, i) => {
      const d = (p[0] - mean(k, 0)) ** 2 + (p[1] - mean(k, 1)) ** 2 + (p[2] - mean(k, 2)) ** 2;
      if (d < bestD) { bestD = d; best = i; }
    });
    index[k] = best;
  }
  const raw = Buffer.alloc((width + 1) * height);
  for (let y = 0; y < height; ++y)
    for (let x = 0; x < width; ++x) raw[y * (width + 1) + 1 + x] = index[bin[y * width + x]];
  return Buffer.concat([PNG_SIGNATURE, header(width, height, 3), chunk('PLTE', Buffer.from(palette.flat())),
                        chunk('IDAT', deflateSync(raw, { level: 9, memLevel: 9 })), chunk('IEND', Buffer.alloc(0))]);
}

/// Writes to a temporary name beside `path`, then renames: a failure leaves no partial PNG.
function writeAtomically(path, data) {
  const temporary = join(dirname(path), `.${basename(path)}.${process.pid}.tmp`);
  try {
    writeFileSync(temporary, data);
    renameSync(temporary, path);
  } catch (e) {
    rmSync(temporary, { force: true });
    throw e;
  }
}

// ---- the server ---------------------------------------------------------------------------------
let server = null;
function stopServer() {
  if (server && server.exitCode === null && server.signalCode === null) server.kill('SIGTERM');
}
process.on('exit', stopServer);
for (const signal of ['SIGINT', 'SIGTERM'])
  process.on(signal, () => { console.error(`render_pictures: ${signal}; stopping`); process.exit(130); });

async function startServer(cli, webRoot, mesh) {
  server = spawn(cli, ['serve', mesh, '--port', '0', '--web-root', webRoot, '--threads', '2'],
                 { stdio: ['ignore', 'pipe', 'inherit'] });
  return new Promise((resolveUrl, reject) => {
    let out = '';
    const timer = setTimeout(() => reject(new Error('remora serve printed no URL in 30 s')), 30000);
    server.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/[^\s]+/);
      if (m) { clearTimeout(timer); resolveUrl(m[0]); }
    });
    server.on('error', (e) => { clearTimeout(timer); reject(new Error(`cannot start ${cli}: ${e.message}`)); });
    server.on('exit', (code, signal) => {
      clearTimeout(timer);
      reject(new Error(`remora serve exited (${signal ?? `code ${code}`}) before it printed its URL`));
    });
  });
}

// ---- main ---------------------------------------------------------------------------------------
async function main() {
  const o = parseOptions(process.argv.slice(2));
  const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
  let chromium;
  try {
    ({ chromium } = createRequire(join(root, 'web', 'package.json'))('playwright-core'));
  } catch (e) {
    console.error('render_pictures: playwright-core is not installed in web/node_modules ' +
                  '(scripts/build_web.sh installs it; make build runs it)');
    return 77;
  }
  if (!existsSync(chromiumPath)) {
    console.error(`render_pictures: no chromium at ${chromiumPath} (scripts/bootstrap.sh --web installs it; ` +
                  'or set CHROMIUM)');
    return 77;
  }
  if (!existsSync(o.cli)) throw new Error(`no remora binary at ${o.cli} (make build, or --cli PATH)`);
  if (!existsSync(join(o['web-root'], 'index.html')))
    throw new Error(`no page in ${o['web-root']} (make build, or --web-root DIR)`);

  const todo = [];
  for (const picture of PICTURES) {
    if (o.only && !o.only.includes(picture.name)) continue;
    if (picture.mesh.generate && !existsSync(picture.mesh.path)) picture.mesh.generate(picture.mesh.path);
    if (!existsSync(picture.mesh.path)) {
      console.log(`skip ${picture.name}.png: ${picture.mesh.path} is missing (point REMORA_DATA at the shared data)`);
      continue;
    }
    todo.push(picture);
  }
  if (!todo.length) return 0;
  mkdirSync(o.out, { recursive: true });

  const url = await startServer(o.cli, o['web-root'], BUNNY.path);
  const api = async (path, options) => {
    const r = await fetch(url + 'api/' + path, options);
    if (!r.ok) throw new Error(`${path}: ${r.status} ${await r.text()}`);
    return r;
  };
  const post = (path, body) => api(path, { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                           body: JSON.stringify(body ?? {}) });
  const settle = async () => {
    for (const start = Date.now(); Date.now() - start < 300000;) {
      const s = await (await api('status')).json();
      if (s.error) throw new Error(`the server: ${s.error}`);
      if (s.state !== 'busy') return s;
      await new Promise((r) => setTimeout(r, 100));
    }
    throw new Error('the server stayed busy for 5 minutes');
  };

  await settle(); // the bunny's preprocessing
  const browser = await chromium.launch({ executablePath: chromiumPath, headless: true,
    args: ['--use-gl=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-sandbox'] });
  try {
    let loaded = { path: BUNNY.path, pristine: true }; // what the server holds
    for (const picture of todo) {
      const started = Date.now();
      const horizontal = picture.layout === 'row';
      // --width and --height are a two-panel picture's; a third panel widens (or heightens) it.
      const n = picture.panels.length;
      const width = horizontal ? Math.round((o.width * n) / 2) : o.width;
      const height = horizontal ? o.height : Math.round((o.height * n) / 2);
      const panelWidth = horizontal ? Math.floor(width / n) : width;
      const panelHeight = horizontal ? height : Math.floor(height / n);
      const page = await browser.newPage({ viewport: { width: panelWidth, height: panelHeight }, deviceScaleFactor: 1 });
      const errors = [];
      page.on('pageerror', (e) => errors.push(e.message));
      const view = async (options) => {
        const query = new URLSearchParams({ ui: '0', ...options });
        await page.goto(`${url}?${query}`);
        await page.waitForFunction(() => window.remora?.ready(), null, { timeout: 120000 });
        // Two frames: the last state is on the canvas (whose drawing buffer the page preserves),
        // the whole view with ui=0.
        const shot = await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(
          () => r(document.querySelector('#view canvas').toDataURL('image/png'))))));
        if (errors.length) throw new Error(`the page: ${errors.join('; ')}`);
        // A blank page while the server works: the page's render loop would compete for the cores.
        await page.goto('about:blank');
        return shot;
      };

      // Open the mesh (Open mesh… in the page posts the same), unless the server holds it unedited.
      if (loaded.path !== picture.mesh.path || !loaded.pristine) {
        const name = basename(picture.mesh.path);
        await api(`load?name=${encodeURIComponent(name)}`, { method: 'POST', body: readFileSync(picture.mesh.path),
                                                            headers: { 'Content-Type': 'application/octet-stream' } });
        const s = await settle();
        if (s.state !== 'ready' || s.mesh?.name !== name) throw new Error(`${name}: the server did not load it`);
        loaded = { path: picture.mesh.path, pristine: true };
      }

      const shots = {};
      const shoot = async (stage) => {
        for (const [i, panel] of picture.panels.entries())
          if ((panel.stage ?? 'before') === stage)
            shots[i] = await view({ camera: panel.camera.join(','), ...(panel.show ?? {}) });
      };
      if (!picture.edit) {
        await shoot('before');
      } else {
        // The region, as the page would send it: vertex ids of the support and the handle.
        const positions = new Float32Array(await (await api('mesh/positions')).arrayBuffer());
        const support = [], handle = [];
        for (let v = 0; v < positions.length / 3; ++v) {
          const p = positions.subarray(3 * v, 3 * v + 3);
          const inHandle = picture.edit.handle(p);
          if (inHandle) handle.push(v);
          if (inHandle || picture.edit.support(p)) support.push(v);
        }
        if (handle.length < 3 || support.length <= handle.length)
          throw new Error(`${picture.name}: the region selects ${support.length} support and ${handle.length} handle vertices`);
        loaded.pristine = false;
        await post('region', { support, handles: [handle], k: 2, method: 'linear' });
        await settle();
        await shoot('before');
        await post('transform', { handle: 0, matrix: handleMatrix(picture.edit, positions, handle) });
        await post('commit');
        await settle();
        // The same region and move under each panel's method (a new method keeps the move).
        for (const method of [...new Set(picture.panels.map((p) => p.method ?? 'linear'))]) {
          if (method !== 'linear') {
            // 'blended-motions' is method nonlinear with that energy, as the page's switch sends it.
            const request = method === 'blended-motions' ? { method: 'nonlinear', energy: method } : { method };
            await post('region', { support, handles: [handle], k: 2, ...request });
            await settle();
          }
          for (const [i, panel] of picture.panels.entries())
            if (panel.stage === 'after' && (panel.method ?? 'linear') === method)
              shots[i] = await view({ camera: panel.camera.join(','), ...(panel.show ?? {}) });
        }
      }
      await page.close();

      const png = await compose(browser, picture, shots, width, height, horizontal);
      const path = join(o.out, `${picture.name}.png`);
      writeAtomically(path, png);
      console.log(`wrote ${path} (${width}x${height}, ${(png.length / 1024).toFixed(0)} KB, ` +
                  `${((Date.now() - started) / 1000).toFixed(1)} s)`);
    }
  } finally {
    await browser.close();
    stopServer();
    rmSync(CYLINDER.path, { force: true });
  }
  return 0;
}

/// The handle's affine map as the 12 numbers /api/transform takes: rotate about the handle's
/// centroid, then translate (the order of `remora edit`).
function handleMatrix(edit, positions, handle) {
  const c = [0, 1, 2].map((k) => handle.reduce((s, v) => s + positions[3 * v + k], 0) / handle.length);
  let R = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
  if (edit.rotate) {
    const n = Math.hypot(...edit.rotate.axis);
    const [x, y, z] = edit.rotate.axis.map((a) => a / n);
    const t = edit.rotate.degrees * Math.PI / 180, cs = Math.cos(t), sn = Math.sin(t), C = 1 - cs;
    R = [[cs + x * x * C, x * y * C - z * sn, x * z * C + y * sn],
         [y * x * C + z * sn, cs + y * y * C, y * z * C - x * sn],
         [z * x * C - y * sn, z * y * C + x * sn, cs + z * z * C]];
  }
  const t = edit.translate ?? [0, 0, 0];
  const rows = [];
  for (let i = 0; i < 3; ++i)
    rows.push(...R[i], c[i] - R[i].reduce((s, r, k) => s + r * c[k], 0) + t[i]);
  return rows;
}

/// The panels side by side (or stacked) with their labels and the caption, on a canvas in the
/// browser; its pixels come back and are encoded here.
async function compose(browser, picture, shots, width, height, horizontal) {
  const page = await browser.newPage({ viewport: { width, height }, deviceScaleFactor: 1 });
  try {
    await page.setContent(`<canvas id="c" width="${width}" height="${height}"></canvas>`);
    const pixels = await page.evaluate(async ({ images, labels, caption, width, height, horizontal }) => {
      const canvas = document.getElementById('c');
      const g = canvas.getContext('2d');
      g.fillStyle = '#20242a';
      g.fillRect(0, 0, width, height);
      const font = Math.max(9, Math.round(Math.min(width, 2 * height) / 60));
      // Text on a box of the background's colour, so that it stays legible over the mesh.
      const text = (words, x, y, size, colour) => {
        g.font = `${size}px "DejaVu Sans", sans-serif`;
        g.fillStyle = '#20242acc';
        g.fillRect(x - size * 0.4, y - size * 1.1, g.measureText(words).width + size * 0.8, size * 1.5);
        g.fillStyle = colour;
        g.fillText(words, x, y);
      };
      for (let i = 0; i < images.length; ++i) {
        const image = new Image();
        image.src = images[i];
        await image.decode();
        const x = horizontal ? i * Math.floor(width / images.length) : 0;
        const y = horizontal ? 0 : i * Math.floor(height / images.length);
        g.drawImage(image, x, y);
        text(labels[i], x + font * 0.8, y + font * 1.6, font, '#dde2ea');
        if (i > 0) {
          g.fillStyle = '#3a414c';
          if (horizontal) g.fillRect(x, 0, 1, height); else g.fillRect(0, y, width, 1);
        }
      }
      if (caption) text(caption, font * 0.8, height - font * 0.8, Math.round(font * 0.9), '#c4ccd6');
      const data = g.getImageData(0, 0, width, height).data;
      let bytes = '';
      for (let i = 0; i < data.length; i += 0x8000) bytes += String.fromCharCode(...data.subarray(i, i + 0x8000));
      return btoa(bytes);
    }, { images: picture.panels.map((_, i) => shots[i]), labels: picture.panels.map((p) => p.label),
         caption: picture.caption ?? '', width, height, horizontal });
    // 150 KB for 800x500, in proportion to the area.
    return encodePng(Buffer.from(pixels, 'base64'), width, height, 150e3 * width * height / 400e3);
  } finally {
    await page.close();
  }
}

main().then((code) => process.exit(code), (e) => {
  console.error(`render_pictures: ${e.message}`);
  stopServer();
  process.exit(1);
});
