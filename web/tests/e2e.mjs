// End to end, in a real browser: `remora serve` on a mesh, Debian's chromium driven by
// playwright-core. Paints a support and a handle with mouse events, drags the manipulator, and
// checks through the API that the handle moved by the dragged amount, that nothing outside the
// support moved, and that undo restores the positions exactly; that the page's own normals after
// the drag equal three.js's full recomputation, and that a stroke downloads no mesh again. On the
// bundled bunny it also checks the editor's rules a new user meets (the manipulator only with the
// Orbit tool and for a handle the server holds, a handle painted without support, k after a move,
// the scale clamp, progress and busy buttons, export names, keys after a click, the brush keys,
// the stats in view), the URL's display options, a cube drawn with sharp creases, a large face's
// colours near and far from a painted corner, and a broken upload's message.
//
//   node web/tests/e2e.mjs --cli build/bin/remora --web-root build/web --mesh data/bunny.ply \
//        --screenshots build/
//   node web/tests/e2e.mjs --cli build/bin/remora --web-root build/web --large 520000 --out build/
//        (a bumpy torus of about that many triangles, written to build/, the core checks only)
// Exit code 0: passed, 1: failed, 77: skipped (chromium or playwright-core missing).
import { join } from 'node:path';
import { args, check, chromiumOrSkip, client, drag, ready, recordRequests, results, startServer, stroke,
         writeBumpyTorus } from './harness.mjs';
import { brokenUpload, bugChecks, creases, displayOptions, kernelAgrees, largeFaceColours, strokePaintsItsBrushes } from './e2e_rules.mjs';

const large = args.large ? Number(args.large) : 0;
// Where to paint: the bunny's left ear, or the top of the torus (seen from +z).
const site = large
  ? { support: [1, 0, 0.4], supportRadius: 0.3, handle: [1, 0, 0.4], handleRadius: 0.06 }
  : { support: [-0.03, 0.15, 0.0], supportRadius: 0.045, handle: [-0.035, 0.175, 0.0], handleRadius: 0.012 };
let mesh = args.mesh;
if (large) {
  const nv = 320, nu = Math.ceil(large / (2 * nv));
  mesh = join(args.out ?? '.', `torus_${2 * nu * nv}.ply`);
  const t0 = Date.now();
  writeBumpyTorus(mesh, nu, nv);
  console.log(`wrote ${mesh} (${2 * nu * nv} triangles) in ${Date.now() - t0} ms`);
}

const browser = await chromiumOrSkip();
const { server, url } = await startServer(args.cli, mesh, args['web-root'], ['--threads', '2']);
const { api, floats, json } = client(url);
const shot = async (page, name) => { if (args.screenshots) await page.screenshot({ path: join(args.screenshots, name) }); };

/// Paints the support and then the handle at `site`, with the mouse; returns the requests made
/// after the handle stroke's mouse-up, until the page is ready again.
async function paintRegion(page, log) {
  const near = (p) => page.evaluate((q) => window.remora.nearest(...q), p);
  await page.click('button[data-tool="support"]');
  await page.evaluate((r) => window.remora.setRadius(r), site.supportRadius);
  site.supportVertex = await near(site.support); // it rides along with later moves
  await strokePaintsItsBrushes(page, log, { api }, () => stroke(page, site.supportVertex, 12));
  await page.click('button[data-tool="handle"]');
  await page.evaluate((r) => window.remora.setRadius(r), site.handleRadius);
  const handleVertex = await near(site.handle);
  const p = await page.evaluate((v) => window.remora.project(v), handleVertex);
  await page.mouse.move(p.x, p.y);
  await page.mouse.down();
  for (let i = 1; i <= 5; ++i) await page.mouse.move(p.x + i, p.y + i);
  const from = log.length;
  await page.mouse.up();
  for (const end = Date.now() + 120000; Date.now() < end;) {
    const s = await json('status');
    if (s.state === 'ready' && s.region) break;
    await page.waitForTimeout(200);
  }
  await ready(page);
  return log.slice(from).map((r) => r.what);
}

/// Drags the manipulator's y arrow upwards; returns the pivot's displacement.
async function dragArrow(page) {
  await page.click('button[data-mode="translate"]');
  const pivot0 = await page.evaluate(() => window.remora.pivot());
  const centre = await page.evaluate((c) => window.remora.projectPoint(...c), pivot0);
  await drag(page, centre.x, centre.y - 75, 0, -8);
  await ready(page);
  await page.waitForTimeout(300);
  const pivot1 = await page.evaluate(() => window.remora.pivot());
  return pivot1.map((x, i) => x - pivot0[i]);
}

/// The core: paint, drag, the handle moved by the drag and nothing outside the support, the
/// page's normals, no mesh download after a stroke, undo exact.
async function core(page, log) {
  const before = await floats('mesh/positions');
  const afterStroke = await paintRegion(page, log);
  const region = await json('region');
  check(region && region.support.length > 1000 && region.handles.length === 1 && region.handles[0].length > 20,
        `painted a support (${region?.support.length} vertices) and a handle (${region?.handles[0]?.length})`);
  const downloads = afterStroke.filter((w) => /GET mesh\/(indices|positions)/.test(w));
  check(downloads.length === 0, `a stroke's mouse-up downloads no mesh/indices or mesh/positions (${downloads.join(', ') || 'none'}; ` +
        `requests: ${[...new Set(afterStroke)].join(', ')})`);
  check(await page.evaluate(() => document.querySelector('#tools button.active')?.dataset.tool) === 'orbit' &&
        (await page.evaluate(() => window.remora.shown())).manipulator,
        'a ready region switches to the Orbit tool and shows the manipulator');

  // Undo goes back to the region as set; its positions are the input's up to round-off.
  const beforeDrag = await floats('mesh/positions');
  // The region's kernel arrives after the manipulator: the drag is shown by the page's own frames.
  const identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0];
  for (const end = Date.now() + 60000; Date.now() < end;) {
    if (await page.evaluate((t) => window.remora.kernelFrame([t]) !== null, identity)) break;
    await page.waitForTimeout(200);
  }
  const kernelMarks = (await page.evaluate(() => window.remora.marks())).dragKernel.length;
  const dragged = await dragArrow(page);
  const localFrames = (await page.evaluate(() => window.remora.marks())).dragKernel.length - kernelMarks;
  check(localFrames > 0, `the drag was shown by the page's own frames (${localFrames} of them)`);
  const status = await json('status');
  const t = status.transforms[0];
  const translation = [t[3], t[7], t[11]];
  check(Math.hypot(...dragged) > 0.005 * (large ? 10 : 1), `the drag moved the manipulator by ${Math.hypot(...dragged).toFixed(4)}`);
  check(Math.hypot(...translation.map((x, i) => x - dragged[i])) < 1e-6, 'the server holds the dragged translation');
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
  // The page placed the drag's answers on the vertices the server moved (it takes the support it
  // sent as the movable vertices, without asking).
  const pageOff = await page.evaluate((server) => {
    const held = window.remora.positionsHeld?.() ?? [];
    let worst = held.length === server.length ? 0 : Infinity;
    for (let i = 0; i < held.length && worst < Infinity; ++i) worst = Math.max(worst, Math.abs(held[i] - server[i]));
    return worst;
  }, Array.from(after));
  check(pageOff < 1e-6, `after the drag the page holds the server's positions (off by ${pageOff})`);
  await kernelAgrees(page, { api, floats, json }, before, region, t);
  const normalError = await page.evaluate(() => window.remora.normalError?.() ?? Infinity);
  const normalsEngine = await page.evaluate(() => window.remora.normalsEngine());
  check(normalError < 1e-5 && normalsEngine === await page.evaluate(() => window.remora.kernelEngine()),
        `after the drag the page's normals (${normalsEngine}) equal a full computeVertexNormals() (off by ${normalError.toExponential(2)})`);
  if (normalsEngine === 'wasm') {
    const frameNormalError = await page.evaluate(() => window.remora.frameNormalError());
    check(frameNormalError !== null && frameNormalError < 1e-5,
          `the page's frame computes the drawn normals on its threads as a full computeVertexNormals() does (off by ${frameNormalError?.toExponential(2)})`);
  }
  await shot(page, large ? 'editor-large-dragged.png' : 'editor-dragged.png');
  if (!large) {
    // The hidden base and its wireframe coloured by vertex area.
    await page.check('#show-wire');
    await ready(page);
    await shot(page, 'editor-base-wireframe.png');
    await page.uncheck('#show-wire');
  }

  // Undo (the button) restores the positions before the drag exactly; redo brings the drag back.
  await page.click('#undo');
  await ready(page);
  await page.waitForTimeout(300);
  const undone = await floats('mesh/positions');
  let differ = 0, roundOff = 0;
  for (let i = 0; i < before.length; ++i) {
    if (undone[i] !== beforeDrag[i]) differ += 1;
    roundOff = Math.max(roundOff, Math.abs(beforeDrag[i] - before[i]));
  }
  check(differ === 0, `undo restored every position exactly (${differ} coordinates differ; the region as set ` +
        `is the input within ${roundOff.toExponential(1)})`);
  await page.click('#redo');
  await ready(page);
  return { region, translation, rest: before };
}

let page;
try {
  page = await browser.newPage({ viewport: { width: 1200, height: 800 } });
  page.on('pageerror', (e) => { console.log('page error:', e.message); results.failures += 1; });
  if (process.env.E2E_DEBUG) page.on('console', (m) => { if (/DBG/.test(m.text())) console.log(m.text()); });
  const log = recordRequests(page);
  await page.goto(url);
  await ready(page, 300000);
  if (!large) await bugChecks.beforeRegion(page, log, { api, floats, json }, site);
  const edit = await core(page, log);
  if (!large) {
    await bugChecks.afterRegion(page, log, { api, floats, json }, edit, site);
    await displayOptions(browser, url);
    await creases(page);
    await shot(page, 'editor-box.png');
    await largeFaceColours(page);
    await brokenUpload(page, args.screenshots);
  }
} catch (e) {
  console.log('FAIL', e.message);
  results.failures += 1;
  if (page) await shot(page, 'editor-failure.png').catch(() => {});
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
console.log(results.failures ? `${results.failures} check(s) failed` : 'all checks passed');
process.exit(results.failures ? 1 : 0);
