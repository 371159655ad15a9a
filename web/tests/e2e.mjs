// End to end, in a real browser: `remora serve` on the bundled bunny, Debian's chromium driven by
// playwright-core. Paints a support and a handle with mouse events, drags the manipulator, and
// checks through the API that the handle moved by the dragged amount, that nothing outside the
// support moved, and that undo restores the positions exactly; then uploads a broken file and
// expects the server's message on the page. Saves screenshots for people to look at.
//
//   node web/tests/e2e.mjs --cli build/bin/remora --web-root build/web --mesh data/bunny.ply \
//        --screenshots build/
// Exit code 0: passed, 1: failed, 77: skipped (chromium or playwright-core missing).
import { spawn } from 'node:child_process';
import { existsSync } from 'node:fs';
import { join } from 'node:path';

const args = Object.fromEntries(process.argv.slice(2).reduce((pairs, a, i, all) =>
  (a.startsWith('--') ? [...pairs, [a.slice(2), all[i + 1]]] : pairs), []));
const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
let chromium;
try {
  ({ chromium } = await import('playwright-core'));
} catch (e) {
  console.log('SKIP: playwright-core is not installed (scripts/build_web.sh installs it)');
  process.exit(77);
}
if (!existsSync(chromiumPath)) {
  console.log(`SKIP: no chromium at ${chromiumPath} (scripts/bootstrap.sh --web installs it)`);
  process.exit(77);
}

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures += 1;
}

// The server, on a free port.
const server = spawn(args.cli, ['serve', args.mesh, '--port', '0', '--web-root', args['web-root'], '--threads', '2'],
                     { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((resolve, reject) => {
  let out = '';
  server.stdout.on('data', (d) => { out += d; const m = out.match(/http:\/\/[^\s]+/); if (m) resolve(m[0]); });
  server.on('exit', (code) => reject(new Error(`remora serve exited with ${code}`)));
  setTimeout(() => reject(new Error('remora serve printed no URL in 30 s')), 30000);
});
const api = async (path, options) => {
  const r = await fetch(url + 'api/' + path, options);
  if (!r.ok) throw new Error(`${path}: ${r.status} ${await r.text()}`);
  return r;
};
const floats = async (path) => new Float32Array(await (await api(path)).arrayBuffer());

const browser = await chromium.launch({ executablePath: chromiumPath, headless: true,
  args: ['--use-gl=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-sandbox'] });
try {
  const page = await browser.newPage({ viewport: { width: 1200, height: 800 } });
  page.on('pageerror', (e) => { console.log('page error:', e.message); failures += 1; });
  await page.goto(url);
  await page.waitForFunction(() => window.remora?.ready(), null, { timeout: 120000 });
  const before = await floats('mesh/positions');

  // Paint: the support around the left ear, then the handle at its tip, with the mouse.
  const ear = await page.evaluate(() => window.remora.nearest(-0.03, 0.15, 0.0));
  const tip = await page.evaluate(() => window.remora.nearest(-0.035, 0.175, 0.0));
  const stroke = async (vertex) => {
    const p = await page.evaluate((v) => window.remora.project(v), vertex);
    await page.mouse.move(p.x, p.y);
    await page.mouse.down();
    for (let i = 1; i <= 5; ++i) await page.mouse.move(p.x + i, p.y + i);
    await page.mouse.up();
  };
  await page.click('button[data-tool="support"]');
  await page.evaluate(() => window.remora.setRadius(0.045));
  await stroke(ear);
  await page.click('button[data-tool="handle"]');
  await page.evaluate(() => window.remora.setRadius(0.012));
  await stroke(tip);
  await page.waitForFunction(async () => {
    const s = await (await fetch('api/status')).json();
    return s.state === 'ready' && s.region;
  }, null, { timeout: 60000 });
  await page.waitForFunction(() => window.remora.ready(), null, { timeout: 60000 });
  const region = await (await api('region')).json();
  check(region && region.support.length > 1000 && region.handles.length === 1 && region.handles[0].length > 20,
        `painted a support (${region?.support.length} vertices) and a handle (${region?.handles[0]?.length})`);

  // Drag the manipulator's y arrow upwards.
  await page.click('button[data-mode="translate"]');
  const pivot0 = await page.evaluate(() => window.remora.pivot());
  const centre = await page.evaluate((c) => window.remora.projectPoint(c[0], c[1], c[2]), pivot0);
  await page.mouse.move(centre.x, centre.y - 75);
  await page.mouse.down();
  for (let i = 1; i <= 10; ++i) await page.mouse.move(centre.x, centre.y - 75 - 8 * i);
  await page.mouse.up();
  await page.waitForFunction(() => window.remora.ready(), null, { timeout: 60000 });
  await page.waitForTimeout(300);
  const pivot1 = await page.evaluate(() => window.remora.pivot());
  const dragged = pivot1.map((x, i) => x - pivot0[i]);
  const status = await (await api('status')).json();
  const t = status.transforms[0];
  const translation = [t[3], t[7], t[11]];
  check(Math.hypot(...dragged) > 0.005, `the drag moved the manipulator by ${Math.hypot(...dragged).toFixed(4)}`);
  check(Math.hypot(...translation.map((x, i) => x - dragged[i])) < 1e-6,
        'the server holds the dragged translation');
  const after = await floats('mesh/positions');
  // The handle's vertices moved by the dragged amount (median over the handle: the rim's details
  // rotate slightly with the bend).
  const moves = region.handles[0].map((v) => [0, 1, 2].map((c) => after[3 * v + c] - before[3 * v + c]));
  const median = [0, 1, 2].map((c) => moves.map((m) => m[c]).sort((a, b) => a - b)[moves.length >> 1]);
  const error = Math.hypot(...median.map((x, i) => x - translation[i]));
  check(error < 0.05 * Math.hypot(...translation), `handle vertices moved by the drag (median off by ${error.toExponential(2)})`);
  const inSupport = new Set(region.support);
  let outsideMoved = 0;
  for (let v = 0; v < before.length / 3; ++v)
    if (!inSupport.has(v))
      for (let c = 0; c < 3; ++c) if (after[3 * v + c] !== before[3 * v + c]) { outsideMoved += 1; break; }
  check(outsideMoved === 0, `no vertex outside the support moved (${outsideMoved} did)`);
  if (args.screenshots) await page.screenshot({ path: join(args.screenshots, 'editor-dragged.png') });
  // The hidden base and its wireframe coloured by vertex area.
  await page.check('#show-wire');
  await page.waitForFunction(() => window.remora.ready(), null, { timeout: 60000 });
  if (args.screenshots) await page.screenshot({ path: join(args.screenshots, 'editor-base-wireframe.png') });
  await page.uncheck('#show-wire');

  // Undo (the button) restores the positions before the drag exactly.
  await page.click('#undo');
  await page.waitForFunction(() => window.remora.ready(), null, { timeout: 60000 });
  await page.waitForTimeout(300);
  const undone = await floats('mesh/positions');
  let differ = 0;
  for (let i = 0; i < before.length; ++i) if (undone[i] !== before[i]) differ += 1;
  check(differ === 0, `undo restored every position exactly (${differ} coordinates differ)`);

  // The mesh's own triangles as a wireframe (the "its triangles" checkbox).
  await page.check('#show-edges');
  check((await page.evaluate(() => window.remora.shown())).edges, 'the "its triangles" checkbox shows the wireframe');
  await page.uncheck('#show-edges');
  check(!(await page.evaluate(() => window.remora.shown())).edges, 'and unchecking it hides the wireframe');

  // The display options in the URL (scripts/render_pictures.mjs): no panel or manipulator, the
  // camera given, the checkboxes set.
  const bare = await browser.newPage({ viewport: { width: 400, height: 300 } });
  bare.on('pageerror', (e) => { console.log('page error:', e.message); failures += 1; });
  await bare.goto(url + '?ui=0&show-mesh=0&show-edges=1&show-wire=1&camera=0.1,0.2,0.3,0,0.1,0');
  await bare.waitForFunction(() => window.remora?.ready(), null, { timeout: 120000 });
  const shown = await bare.evaluate(() => window.remora.shown());
  const cameraAt = await bare.evaluate(() => window.remora.camera());
  const canvasBox = await bare.locator('canvas').boundingBox();
  check(await bare.isHidden('#panel') && canvasBox.x === 0 && canvasBox.width === 400,
        'ui=0 hides the panel and the view fills the window');
  check(!shown.mesh && shown.edges && shown.wire && !shown.base && !shown.manipulator,
        `show-*= set the checkboxes, and ui=0 hides the manipulator (${JSON.stringify(shown)})`);
  check(Math.hypot(...cameraAt.map((x, i) => x - [0.1, 0.2, 0.3][i])) < 1e-9, `camera= places the camera (${cameraAt})`);
  await bare.close();

  // A broken upload: the server's message appears on the page.
  await page.setInputFiles('#file', { name: 'broken.ply', mimeType: 'application/octet-stream',
    buffer: Buffer.from('ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n2\n') });
  await page.waitForSelector('#message:not([hidden])', { timeout: 30000 });
  await page.waitForFunction(() => /broken\.ply/.test(document.getElementById('message').textContent), null, { timeout: 30000 });
  const text = await page.textContent('#message');
  check(/broken\.ply/.test(text), `a broken upload shows the server's message: "${text.trim()}"`);
  if (args.screenshots) await page.screenshot({ path: join(args.screenshots, 'editor-broken-upload.png') });
} catch (e) {
  console.log('FAIL', e.message);
  failures += 1;
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
console.log(failures ? `${failures} check(s) failed` : 'all checks passed');
process.exit(failures ? 1 : 0);
