// The smoke test of scripts/render_pictures.mjs, so that the script behind docs/images/*.png
// cannot rot: renders every picture at a low resolution into a scratch folder (never docs/images)
// and checks that each PNG it wrote is a valid PNG (signature, chunk CRCs, the image data inflates
// to its size) of the requested size that shows something (not one flat colour), that the bunny
// pictures were always written and the shared-data ones whenever their meshes exist, and that no
// temporary file was left behind.
//
//   node web/tests/pictures.mjs --cli build/bin/remora --web-root build/web --out build/pictures \
//        [--width 400 --height 250]
// Exit code 0: passed, 1: failed, 77: skipped (chromium or playwright-core missing).
import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { inflateSync } from 'node:zlib';

const root = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
const args = Object.fromEntries(process.argv.slice(2).reduce((pairs, a, i, all) =>
  (a.startsWith('--') ? [...pairs, [a.slice(2), all[i + 1]]] : pairs), []));
const width = Number(args.width ?? 400), height = Number(args.height ?? 250);
const out = resolve(args.out);
const dataDir = resolve(process.env.REMORA_DATA ?? join(root, '..', 'shared', 'data'));
const expected = {
  bunny_ear: join(root, 'data/bunny.ply'),
  bunny_ear_twist: join(root, 'data/bunny.ply'),
  cylinder_twist: null, // written by the script
  base_area: join(root, 'data/bunny.ply'),
  needles_base: join(dataDir, 'cad/featuretype.STL'),
  acrossriver_lift: join(dataDir, 'heightfield/AcrossRiver.stl'),
};

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures += 1;
}

// A scratch folder of our own: earlier pictures must not pass for new ones.
rmSync(out, { recursive: true, force: true });
mkdirSync(out, { recursive: true });
const started = Date.now();
const run = spawnSync(process.execPath, [join(root, 'scripts/render_pictures.mjs'), '--out', out,
                                         '--width', String(width), '--height', String(height),
                                         '--cli', args.cli, '--web-root', args['web-root']],
                      { stdio: 'inherit' });
if (run.status === 77) {
  console.log('SKIP: render_pictures.mjs found no chromium or no playwright-core');
  process.exit(77);
}
check(run.status === 0, `render_pictures.mjs exited with ${run.status ?? run.signal} ` +
                        `after ${((Date.now() - started) / 1000).toFixed(1)} s`);

/// The PNG's size and pixels (one array of samples per row, unfiltered), or throws naming the flaw.
function readPng(path) {
  const png = readFileSync(path);
  if (!png.subarray(0, 8).equals(Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a])))
    throw new Error('no PNG signature');
  const table = Array.from({ length: 256 }, (_, n) => {
    let c = n;
    for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    return c >>> 0;
  });
  const crc = (b) => { let c = 0xffffffff; for (const x of b) c = table[(c ^ x) & 0xff] ^ (c >>> 8); return (c ^ 0xffffffff) >>> 0; };
  let offset = 8, ihdr = null, ended = false;
  const idat = [];
  while (offset < png.length) {
    if (offset + 12 > png.length) throw new Error('a truncated chunk');
    const length = png.readUInt32BE(offset), type = png.toString('ascii', offset + 4, offset + 8);
    if (offset + 12 + length > png.length) throw new Error(`chunk ${type} runs past the end`);
    const data = png.subarray(offset + 8, offset + 8 + length);
    if (crc(png.subarray(offset + 4, offset + 8 + length)) !== png.readUInt32BE(offset + 8 + length))
      throw new Error(`chunk ${type}: bad CRC`);
    if (type === 'IHDR') ihdr = data;
    if (type === 'IDAT') idat.push(data);
    if (type === 'IEND') { ended = true; break; }
    offset += 12 + length;
  }
  if (!ihdr || !idat.length || !ended) throw new Error('IHDR, IDAT or IEND missing');
  const w = ihdr.readUInt32BE(0), h = ihdr.readUInt32BE(4), depth = ihdr[8], type = ihdr[9];
  const channels = { 0: 1, 2: 3, 3: 1, 4: 2, 6: 4 }[type];
  if (depth !== 8 || !channels || ihdr[12] !== 0) throw new Error(`unexpected bit depth ${depth}, colour type ${type} or interlace`);
  const raw = inflateSync(Buffer.concat(idat));
  const stride = w * channels;
  if (raw.length !== h * (stride + 1)) throw new Error(`image data of ${raw.length} bytes, expected ${h * (stride + 1)}`);
  const rows = [];
  let prev = new Uint8Array(stride);
  for (let y = 0; y < h; ++y) {
    const filter = raw[y * (stride + 1)], line = new Uint8Array(raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1)));
    if (filter > 4) throw new Error(`row ${y}: filter ${filter}`);
    for (let i = 0; i < stride; ++i) {
      const a = i >= channels ? line[i - channels] : 0, b = prev[i], c = i >= channels ? prev[i - channels] : 0;
      const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
      const predictor = [0, a, b, (a + b) >> 1, pa <= pb && pa <= pc ? a : pb <= pc ? b : c][filter];
      line[i] = (line[i] + predictor) & 0xff;
    }
    rows.push(line);
    prev = line;
  }
  return { width: w, height: h, channels, rows, bytes: png.length };
}

for (const [name, mesh] of Object.entries(expected)) {
  const path = join(out, `${name}.png`);
  if (mesh !== null && !existsSync(mesh)) {
    check(!existsSync(path), `${name}.png: not written, as ${mesh} is missing`);
    continue;
  }
  if (!existsSync(path)) { check(false, `${name}.png was written`); continue; }
  try {
    const png = readPng(path);
    // The size asked is a two-panel picture's; the methods' pictures have a third panel beside.
    const wide = ['cylinder_twist', 'bunny_ear_twist'].includes(name) ? Math.round((width * 3) / 2) : width;
    check(png.width === wide && png.height === height,
          `${name}.png is a valid PNG of ${png.width}x${png.height} (${(png.bytes / 1024).toFixed(0)} KB); asked for ${wide}x${height}`);
    // Something drawn: the most common pixel (the background) covers well under nine tenths.
    const counts = new Map();
    for (const row of png.rows)
      for (let x = 0; x < row.length; x += png.channels) {
        const key = row.subarray(x, x + png.channels).join(',');
        counts.set(key, (counts.get(key) ?? 0) + 1);
      }
    const background = Math.max(...counts.values()) / (png.width * png.height);
    check(background < 0.9 && counts.size > 20,
          `${name}.png shows something: ${counts.size} colours, the most common on ${(100 * background).toFixed(0)} % of it`);
  } catch (e) {
    check(false, `${name}.png: ${e.message}`);
  }
}
const leftovers = readdirSync(out).filter((f) => !/^[a-z_]+\.png$/.test(f));
check(leftovers.length === 0, `no temporary files left (${leftovers.join(', ') || 'none'})`);
console.log(failures ? `${failures} check(s) failed` : 'all checks passed');
process.exit(failures ? 1 : 0);
