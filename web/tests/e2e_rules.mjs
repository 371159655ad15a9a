// The editor's rules a new user meets, checked with the mouse and the keyboard on the bunny
// (web/tests/e2e.mjs runs them before and after its core edit), the URL's display options, the
// creases of a CAD-like part, and a broken upload's message.
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import { args, boxObj, check, drag, ready, stroke } from './harness.mjs';

const remora = (page, what, ...a) => page.evaluate(([w, b]) => {
  const f = window.remora[w];
  return typeof f === 'function' ? f(...b) : undefined;
}, [what, a]);
const since = (log, from, pattern) => log.slice(from).filter((r) => pattern.test(r.what));
const activeTool = (page) => page.evaluate(() => document.querySelector('#tools button.active')?.dataset.tool);
const brushRadius = (page) => page.evaluate(() => Number(document.getElementById('radius').value));
const messageBox = (page) => page.evaluate(() => {
  const box = document.getElementById('message');
  return { text: box.textContent, kind: box.className, hidden: box.hidden };
});

/// A handle painted without support is not sent, and its paint and message stay.
async function handleWithoutSupport(page, log, site) {
  const from = log.length;
  await page.click('button[data-tool="handle"]');
  await remora(page, 'setRadius', site.handleRadius);
  await stroke(page, await remora(page, 'nearest', ...site.handle));
  await page.waitForTimeout(500);
  await ready(page);
  const painted = (await remora(page, 'labels')).filter((l) => l >= 0).length;
  const box = await messageBox(page);
  check(since(log, from, /POST region/).length === 0 && painted > 0 && !box.hidden && /support/i.test(box.text),
        `one Handle stroke on a fresh load: no region sent (${since(log, from, /POST region/).length} sent), ` +
        `the paint stays (${painted} vertices), and the message asks for the support ("${box.text}")`);
  await page.click('#clear');
}

/// Keys act after a click on a checkbox, the slider or the k select; [ ] and Ctrl+wheel scale the
/// brush; the brush cursor shows its radius on hover.
async function keysAndBrush(page, site) {
  await page.click('#show-edges');
  await page.click('#show-edges');
  await page.keyboard.press('s');
  const afterCheckbox = await activeTool(page);
  await page.focus('#k');
  await page.keyboard.press('h');
  const afterSelect = await activeTool(page);
  await page.focus('#radius');
  await page.keyboard.press('s');
  const afterSlider = await activeTool(page);
  check(afterCheckbox === 'support' && afterSelect === 'handle' && afterSlider === 'support',
        `S and H work after a click on a checkbox, the k select and the slider (${afterCheckbox}, ${afterSelect}, ${afterSlider})`);
  await remora(page, 'setRadius', site.supportRadius);
  const r0 = await brushRadius(page);
  await page.keyboard.press(']');
  const r1 = await brushRadius(page);
  await page.keyboard.press('[');
  await page.keyboard.press('[');
  const r2 = await brushRadius(page);
  const p = await remora(page, 'project', await remora(page, 'nearest', ...site.support));
  await page.mouse.move(p.x, p.y);
  await page.keyboard.down('Control');
  await page.mouse.wheel(0, 100);
  await page.keyboard.up('Control');
  const r3 = await brushRadius(page);
  const close = (a, b) => Math.abs(a - b) <= 1e-9 * Math.abs(b);
  check(close(r1, 1.25 * r0) && close(r2, 0.8 * r1 * 0.8) && close(r3, 0.8 * r2),
        `] grows the brush by 1.25, [ shrinks it by 0.8, Ctrl+wheel too (${r0}, ${r1}, ${r2}, ${r3})`);
  await page.mouse.move(p.x + 1, p.y);
  await page.waitForFunction(() => window.remora.shown?.().cursor, null, { timeout: 10000 }).catch(() => {});
  const shown = await remora(page, 'shown');
  check(shown?.cursor && close(shown.cursorRadius, r3),
        `hovering with a paint tool shows the brush ring of the brush's radius (${shown?.cursorRadius} against ${r3})`);
  await page.keyboard.press('o');
}

/// Changing k after a move keeps the move: the same transforms, the handle where it was, and
/// k = 2 again gives the k = 2 shape.
async function kAfterMove(page, c, edit) {
  const s0 = await c.json('status');
  const p2 = await c.floats('mesh/positions');
  const pivot0 = await remora(page, 'pivot');
  await page.selectOption('#k', '1');
  await ready(page);
  const s1 = await c.json('status');
  const p1 = await c.floats('mesh/positions');
  const same = JSON.stringify(s1.transforms) === JSON.stringify(s0.transforms);
  const handle = edit.region.handles[0];
  // The handle's base moves rigidly whatever k; its rim's details follow the base's normals, so
  // the median over the handle is the measure.
  const offs = handle.map((v) => Math.hypot(...[0, 1, 2].map((k) => p1[3 * v + k] - p2[3 * v + k]))).sort((a, b) => a - b);
  const handleOff = offs[offs.length >> 1];
  let supportChange = 0;
  for (const v of edit.region.support) for (let k = 0; k < 3; ++k) supportChange = Math.max(supportChange, Math.abs(p1[3 * v + k] - p2[3 * v + k]));
  const pivot1 = await remora(page, 'pivot');
  check(same && s1.region?.k === 1, `k = 1 after a move keeps the transforms (${JSON.stringify(s1.transforms?.[0]?.slice(9))})`);
  check(handleOff < 1e-6 && supportChange > 1e-5 && Math.hypot(...pivot1.map((x, i) => x - pivot0[i])) < 1e-9,
        `the handle stays moved (median off by ${handleOff.toExponential(2)}), the support bends otherwise ` +
        `(${supportChange.toExponential(2)}), the manipulator stays`);
  const pageOff = await page.evaluate(async () => {
    const server = new Float32Array(await (await fetch('api/mesh/positions')).arrayBuffer());
    const held = window.remora.positionsHeld?.() ?? [];
    let worst = held.length === server.length ? 0 : Infinity;
    for (let i = 0; i < held.length && worst < Infinity; ++i) worst = Math.max(worst, Math.abs(held[i] - server[i]));
    return worst;
  });
  check(pageOff === 0, `the page shows the new k's positions (off by ${pageOff})`);
  for (const k of ['3', '2']) { await page.selectOption('#k', k); await ready(page); }
  const back = await c.floats('mesh/positions');
  let off = 0;
  for (let i = 0; i < back.length; ++i) off = Math.max(off, Math.abs(back[i] - p2[i]));
  check(off < 1e-5, `k = 3 then 2 gives back the k = 2 shape without undo (off by ${off.toExponential(2)})`);
}

/// The page's positions against the server's: the largest difference.
const pageVsServer = (page) => page.evaluate(async () => {
  const server = new Float32Array(await (await fetch('api/mesh/positions')).arrayBuffer());
  const held = window.remora.positionsHeld?.() ?? [];
  let worst = held.length === server.length ? 0 : Infinity;
  for (let i = 0; i < held.length && worst < Infinity; ++i) worst = Math.max(worst, Math.abs(held[i] - server[i]));
  return worst;
});

/// The largest difference between the page's own frame under `transform` (12 numbers; waiting up
/// to 60 s for the region's kernel and its offsets) and the server's positions.
async function correctedKernelOff(page, transform) {
  for (const end = Date.now() + 60000; Date.now() < end;) {
    if (await page.evaluate((t) => window.remora.kernelFrame([t]) !== null, transform)) break;
    await page.waitForTimeout(200);
  }
  return page.evaluate(async (t) => {
    const local = window.remora.kernelFrame([t]);
    const movable = new Uint32Array(await (await fetch('api/movable')).arrayBuffer());
    const server = new Float32Array(await (await fetch('api/mesh/positions')).arrayBuffer());
    if (!local || local.length !== 3 * movable.length) return Infinity;
    let worst = 0;
    movable.forEach((v, i) => { for (let k = 0; k < 3; ++k) worst = Math.max(worst, Math.abs(local[3 * i + k] - server[3 * v + k])); });
    return worst;
  }, transform);
}

/// The method switch after a move: nonlinear keeps the transforms and bends the support
/// otherwise, converged; a drag under it is shown by the page's own frames (the kernel corrected
/// by the server's base offsets, which answer every move) and, once the pointer rests, relaxed
/// until the server says converged, the page holding the server's positions and its own frame
/// agreeing with them; blended
/// motions keep the move too; linear again gives back the linear shape.
async function methodAfterMove(page, c, edit) {
  const s0 = await c.json('status');
  const linear = await c.floats('mesh/positions');
  await page.selectOption('#method', 'nonlinear');
  await ready(page);
  const s1 = await c.json('status');
  const moved = await c.floats('mesh/positions');
  const inSupport = new Set(edit.region.support);
  let change = 0, outside = 0;
  for (let v = 0; v < linear.length / 3; ++v)
    for (let k = 0; k < 3; ++k) {
      const d = Math.abs(moved[3 * v + k] - linear[3 * v + k]);
      if (inSupport.has(v)) change = Math.max(change, d); else if (d !== 0) outside += 1;
    }
  check(s1.region?.method === 'nonlinear' && JSON.stringify(s1.transforms) === JSON.stringify(s0.transforms) &&
        s1.nonlinear?.converged === true && !s1.nonlinear?.fallback,
        `the method nonlinear after a move keeps the transforms and converges (${JSON.stringify(s1.nonlinear)})`);
  check(change > 1e-6 && outside === 0, `nonlinear bends the support otherwise (by ${change.toExponential(2)}), nothing outside it moves (${outside})`);
  check(await pageVsServer(page) === 0, 'the page shows the nonlinear positions');
  // A drag under nonlinear, shown by the page's own frames once the region's corrected kernel
  // and its first base offsets are here.
  const identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0];
  for (const end = Date.now() + 60000; Date.now() < end;) {
    if (await page.evaluate((t) => window.remora.kernelFrame([t]) !== null, identity)) break;
    await page.waitForTimeout(200);
  }
  const marks0 = await remora(page, 'marks');
  const frames0 = marks0.drag.length;
  await page.click('button[data-mode="translate"]');
  const pivot = await remora(page, 'pivot');
  const centre = await page.evaluate((q) => window.remora.projectPoint(...q), pivot);
  // Downwards: the manipulator stays in view for the rules after this one.
  await drag(page, centre.x, centre.y - 75, 0, 6);
  await ready(page);
  const s2 = await c.json('status');
  const frames = (await remora(page, 'marks')).drag.length - frames0;
  const off = await pageVsServer(page);
  const marks2 = await remora(page, 'marks');
  const localFrames = marks2.dragKernel.length - marks0.dragKernel.length;
  const offsetAnswers = marks2.dragTrip.length - marks0.dragTrip.length;
  check(frames > 0 && localFrames === frames && offsetAnswers > 0 && s2.nonlinear?.converged === true && off < 1e-6,
        `a nonlinear drag: ${frames} frames, ${localFrames} of them the page's own, ${offsetAnswers} base offsets answered, ` +
        `then relaxed until converged (${JSON.stringify(s2.nonlinear)}), the page holding the server's positions (off by ${off})`);
  // The page's frame under the live transforms, with the offsets of the server's converged frame,
  // is the server's frame; after an undo, with the offsets the page asks for again.
  const diagonal = boxDiagonal(edit.rest);
  const corrected = await correctedKernelOff(page, s2.transforms[0]);
  check(corrected <= 1e-5 * diagonal, `the page's nonlinear frame with the server's base offsets is the server's ` +
        `(off by ${corrected.toExponential(2)}, bound ${(1e-5 * diagonal).toExponential(2)})`);
  await page.click('#undo');
  await ready(page);
  const undone = await c.json('status');
  const afterUndo = await correctedKernelOff(page, undone.transforms[0]);
  check(JSON.stringify(undone.transforms) === JSON.stringify(s1.transforms) && afterUndo <= 1e-5 * diagonal,
        `after an undo the page's nonlinear frame is the server's again (off by ${afterUndo.toExponential(2)})`);
  await page.click('#redo');
  await ready(page);
  // Blended motions: method nonlinear with that energy, the same transforms, no iteration.
  await page.selectOption('#method', 'blended-motions');
  await ready(page);
  const sb = await c.json('status');
  check(sb.region?.method === 'nonlinear' && sb.region?.energy === 'blended-motions' &&
        JSON.stringify(sb.transforms) === JSON.stringify(s2.transforms) &&
        sb.nonlinear?.converged === true && sb.nonlinear?.iterations === 0 &&
        await pageVsServer(page) === 0,
        `blended motions keep the transforms, converge at once, the page shows them (${JSON.stringify(sb.region)})`);
  await kernelAgrees(page, c, edit.rest, edit.region, sb.transforms[0], 'with blended motions the page\'s frame');
  await page.selectOption('#method', 'linear');
  await ready(page);
  const s3 = await c.json('status');
  check(s3.region?.method === 'linear' && !s3.nonlinear && await pageVsServer(page) === 0,
        'the method linear again: the page shows its positions');
}

/// The unpainted vertex nearest `centre`: a stroke that starts there changes the region whatever
/// earlier strokes painted.
async function unpaintedNear(page, centre) {
  return page.evaluate((c) => {
    const p = window.remora.positionsHeld(), labels = window.remora.labels();
    let best = -1, bestD = Infinity;
    for (let v = 0; v < labels.length; ++v) {
      if (labels[v] !== -2) continue;
      const d = (p[3 * v] - c[0]) ** 2 + (p[3 * v + 1] - c[1]) ** 2 + (p[3 * v + 2] - c[2]) ** 2;
      if (d < bestD) { bestD = d; best = v; }
    }
    return best;
  }, centre);
}

/// While a job runs (a stroke after a move: the shape is baked into a new base) the progress shows
/// "phase — NN %" and undo, redo and export are disabled. The bake may start in a pause of the
/// stroke and end before mouse-up, so the page is watched from the stroke's start.
async function busyButtons(page, site) {
  await page.keyboard.press('s');
  await remora(page, 'setRadius', 1.4 * site.supportRadius);
  await page.evaluate(() => {
    const seen = (window.__busySeen = []);
    const look = () => {
      if (document.getElementById('progress').hidden) return;
      seen.push({
        text: document.getElementById('progress-text').textContent,
        disabled: ['#undo', '#redo', '#export button, #panel a.button']
          .map((q) => [...document.querySelectorAll(q)].every((b) => b.disabled)),
      });
    };
    window.__busyObserver = new MutationObserver(look);
    window.__busyObserver.observe(document.getElementById('panel'), { attributes: true, childList: true, subtree: true, characterData: true });
  });
  await stroke(page, await unpaintedNear(page, site.support)); // a stroke that changes the region
  await ready(page, 180000);
  const seen = await page.evaluate(() => { window.__busyObserver.disconnect(); return window.__busySeen; });
  const during = seen.find((x) => /\d+ %/.test(x.text)) ?? { text: null, disabled: [] };
  const allDisabled = seen.filter((x) => /\d+ %/.test(x.text)).every((x) => x.disabled.every(Boolean));
  check(during.text && allDisabled && during.disabled.length === 3,
        `while a bake runs: "${during.text}", undo, redo and export disabled (${during.disabled}; ${seen.length} views of the progress)`);
  await page.keyboard.press('o');
}

/// Scaling through the pivot never sends a map that flips orientation (det > 0).
async function scaleClamp(page, log) {
  await page.keyboard.press('r');
  const centre = await remora(page, 'projectPoint', ...(await remora(page, 'pivot')));
  const from = log.length;
  await drag(page, centre.x, centre.y - 75, 0, 15, 12);
  await ready(page);
  const sent = since(log, from, /POST transform/).map((r) => r.body.matrix);
  const det = (m) => m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) + m[2] * (m[4] * m[9] - m[5] * m[8]);
  const smallest = Math.min(...sent.map(det));
  check(sent.length > 0 && smallest > 0, `scaling through the pivot: ${sent.length} maps sent, smallest det ${smallest.toFixed(4)}`);
  await page.keyboard.press('w');
}

/// Export downloads a file named after the mesh, and a refused export shows the server's message.
async function exportName(page) {
  const button = '#panel :is(a, button):text-is("PLY")';
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click(button)]);
  check(download.suggestedFilename() === 'bunny_edited.ply', `export is named ${download.suggestedFilename()}`);
  const refusal = 'the session is busy (a refusal made by the test)';
  await page.route('**/api/export*', (route) => route.fulfill({
    status: 409, contentType: 'application/json', body: JSON.stringify({ error: refusal }) }));
  await page.click(button);
  await page.waitForFunction((t) => document.getElementById('message').textContent === t, refusal, { timeout: 10000 })
    .catch(() => {});
  const box = await messageBox(page);
  check(!box.hidden && box.text === refusal, `a refused export shows the server's message ("${box.hidden ? '' : box.text}")`);
  await page.unroute('**/api/export*');
}

/// With a paint tool the manipulator is hidden and a stroke from its arrow paints or orbits, it
/// never moves the handle; a new handle detaches it.
async function manipulatorRules(page, log) {
  const pivot0 = await remora(page, 'pivot');
  const centre = await remora(page, 'projectPoint', ...pivot0);
  await page.keyboard.press('s');
  const hidden = !(await remora(page, 'shown')).manipulator;
  let from = log.length;
  await drag(page, centre.x, centre.y - 75, 0, -8);
  await ready(page);
  const moved = since(log, from, /POST transform/).length;
  check(hidden && moved === 0, `with the Support tool the manipulator is hidden (${hidden}) and a stroke from its arrow sends no move (${moved})`);
  await page.keyboard.press('o');
  await page.click('#new-handle');
  await page.keyboard.press('o');
  const shown = (await remora(page, 'shown')).manipulator;
  const centre1 = await remora(page, 'projectPoint', ...(await remora(page, 'pivot')));
  from = log.length;
  await drag(page, centre1.x, centre1.y - 75, 0, -8);
  await ready(page);
  const box = await messageBox(page);
  const sent = since(log, from, /POST transform/).length;
  check(!shown && sent === 0 && !/does not exist/.test(box.text),
        `after New handle the manipulator is hidden (${shown}) and its old place sends no move (${sent}; "${box.hidden ? '' : box.text}")`);
}

/// Holds the pointer still until the page has sent the region (at most 15 s): 250 ms after the
/// stroke's last painted answer, which a loaded machine can delay.
async function regionSentInPause(page, log, from) {
  await page.waitForTimeout(900);
  for (const end = Date.now() + 15000; Date.now() < end && since(log, from, /POST region/).length === 0;)
    await page.waitForTimeout(100);
}

/// The region's work hides behind the brush: a stroke that pauses sends the region painted so
/// far; painting on after it sends the region again (the server stops the stale job) and the
/// server ends with the region as painted at mouse-up; a pause with nothing painted after it
/// leaves nothing to send at mouse-up.
async function regionInPause(page, log, c, site) {
  await page.keyboard.press('s');
  await remora(page, 'setRadius', 0.8 * site.supportRadius);
  const start = await remora(page, 'project', await unpaintedNear(page, site.support));
  // A stroke with a pause in the middle, then more paint elsewhere.
  let from = log.length;
  await page.mouse.move(start.x, start.y);
  await page.mouse.down();
  for (let i = 1; i <= 4; ++i) await page.mouse.move(start.x + 2 * i, start.y);
  await regionSentInPause(page, log, from);
  const inPause = since(log, from, /POST region/).length;
  for (let i = 1; i <= 6; ++i) await page.mouse.move(start.x + 8, start.y + 4 * i);
  await page.mouse.up();
  await ready(page, 120000);
  const sent = since(log, from, /POST region/);
  const labels = await remora(page, 'labels');
  const region = await c.json('region');
  const painted = labels.flatMap((l, v) => (l !== -2 ? [v] : []));
  // The bunny's vertex order keeps neighbours together: the support travels as ranges of ids.
  const ranged = sent.filter((r) => Array.isArray(r.body?.support?.ranges)).length;
  check(inPause >= 1 && sent.length >= 2 && ranged === sent.length &&
        JSON.stringify(region?.support) === JSON.stringify(painted),
        `a stroke's pause sends the region (${inPause} during it, ${sent.length} in all, ${ranged} as ranges) ` +
        `and the server ends with the region painted at mouse-up (${region?.support.length} = ${painted.length} vertices)`);
  // A pause, then mouse-up without more paint: nothing left to send, the manipulator comes.
  await page.keyboard.press('s');
  from = log.length;
  await page.mouse.move(start.x - 6, start.y - 6);
  await page.mouse.down();
  for (let i = 1; i <= 3; ++i) await page.mouse.move(start.x - 6 - 2 * i, start.y - 6);
  await regionSentInPause(page, log, from);
  await ready(page, 120000).catch(() => {});
  const before = since(log, from, /POST region/).length;
  await page.mouse.up();
  await ready(page, 120000);
  const after = since(log, from, /POST region/).length;
  check(before >= 1 && after === before && await activeTool(page) === 'orbit' &&
        (await remora(page, 'shown')).manipulator,
        `a pause then mouse-up sends nothing more (${before} then ${after}) and shows the manipulator`);
}

/// The diagonal of the bounding box of positions (x, y, z per vertex).
function boxDiagonal(positions) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; ++i) { lo[i % 3] = Math.min(lo[i % 3], positions[i]); hi[i % 3] = Math.max(hi[i % 3], positions[i]); }
  return Math.hypot(...hi.map((h, i) => h - lo[i]));
}

/// The page's own frame (web/kernel.js, single-precision data) against the server's under a map
/// that rotates by 40 degrees about z through the handle's centre and scales anisotropically:
/// every coordinate within 1e-5 of the mesh's bounding diagonal. Then back to the map `dragged`
/// (12 numbers). `rest`: the positions at rest; c: the API client.
export async function kernelAgrees(page, c, rest, region, dragged, what = 'the page\'s frame') {
  const diagonal = boxDiagonal(rest), o = [0, 0, 0];
  for (const v of region.handles[0]) for (let k = 0; k < 3; ++k) o[k] += rest[3 * v + k] / region.handles[0].length;
  const a = (40 * Math.PI) / 180, cs = Math.cos(a), sn = Math.sin(a);
  const M = [[1.2 * cs, -sn, 0], [1.2 * sn, cs, 0], [0, 0, 0.9]];
  const rows = [];
  for (let r = 0; r < 3; ++r) rows.push(...M[r], o[r] - M[r][0] * o[0] - M[r][1] * o[1] - M[r][2] * o[2] + dragged[4 * r + 3]);
  let local = null;
  for (const end = Date.now() + 60000; !local && Date.now() < end;) {
    local = await page.evaluate((t) => window.remora.kernelFrame([t]), rows);
    if (!local) await page.waitForTimeout(200);
  }
  const post = (matrix) => c.api('transform', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                              body: JSON.stringify({ handle: 0, matrix }) });
  const server = new Float32Array(await (await post(rows)).arrayBuffer());
  let worst = local && local.length === server.length ? 0 : Infinity;
  for (let i = 0; i < server.length && worst < Infinity; ++i) worst = Math.max(worst, Math.abs(local[i] - server[i]));
  check(worst <= 1e-5 * diagonal, `${what} equals the server's under a rotation and a scaling ` +
        `(${server.length / 3} vertices, off by ${worst.toExponential(2)}, bound ${(1e-5 * diagonal).toExponential(2)})`);
  // Both engines: kernel.wasm (the library's replay) where the build has it, and the JavaScript.
  const engine = await page.evaluate(() => window.remora.kernelEngine());
  const wasmBuilt = existsSync(join(args['web-root'] ?? '', 'kernel.wasm'));
  const cores = await page.evaluate(() => navigator.hardwareConcurrency);
  // A new region's frame worker starts with the region's kernel; on a loaded machine it may not
  // have answered yet (until then the page's thread evaluates the whole frame).
  if (engine === 'wasm' && cores >= 2)
    await page.waitForFunction(() => window.remora.kernelThreads() >= 2, null, { timeout: 10000 }).catch(() => {});
  const threads = await page.evaluate(() => window.remora.kernelThreads());
  check(engine === (wasmBuilt ? 'wasm' : 'js') && (engine === 'js' || threads === Math.min(2, cores)),
        `${what} runs in ${engine} on ${threads} threads (kernel.wasm ${wasmBuilt ? '' : 'not '}built, ${cores} cores)`);
  const js = await page.evaluate((t) => window.remora.kernelFrame([t], 'js'), rows);
  let apart = js && local && js.length === local.length ? 0 : Infinity;
  for (let i = 0; i < local.length && apart < Infinity; ++i) apart = Math.max(apart, Math.abs(js[i] - local[i]));
  check(apart === 0, `${what}: WebAssembly and JavaScript give the same numbers (apart by ${apart})`);
  await post(dragged);
}

export const bugChecks = {
  async beforeRegion(page, log, c, site) {
    await handleWithoutSupport(page, log, site);
    await keysAndBrush(page, site);
  },
  async afterRegion(page, log, c, edit, site) {
    const box = await page.locator('#stats').boundingBox();
    const text = await page.textContent('#stats');
    check(box && box.y >= 0 && box.y + box.height <= 800 && /set_region/.test(text),
          `at 1200x800 the stats, set_region line included, are in view (${box?.y.toFixed(0)}..${(box?.y + box?.height).toFixed(0)})`);
    await kAfterMove(page, c, edit);
    await methodAfterMove(page, c, edit);
    await busyButtons(page, site);
    await scaleClamp(page, log);
    await exportName(page);
    await manipulatorRules(page, log);
    await regionInPause(page, log, c, site);
  },
};

/// The display options in the URL (scripts/render_pictures.mjs): no panel or manipulator, the
/// camera given, the checkboxes set.
export async function displayOptions(browser, url) {
  const bare = await browser.newPage({ viewport: { width: 400, height: 300 } });
  bare.on('pageerror', (e) => { check(false, `page error: ${e.message}`); });
  await bare.goto(url + '?ui=0&show-mesh=0&show-edges=1&show-wire=1&camera=0.1,0.2,0.3,0,0.1,0');
  await ready(bare);
  const shown = await bare.evaluate(() => window.remora.shown());
  const cameraAt = await bare.evaluate(() => window.remora.camera());
  const canvasBox = await bare.locator('canvas').boundingBox();
  check(await bare.isHidden('#panel') && canvasBox.x === 0 && canvasBox.width === 400,
        'ui=0 hides the panel and the view fills the window');
  check(!shown.mesh && shown.edges && shown.wire && !shown.base && !shown.manipulator,
        `show-*= set the checkboxes, and ui=0 hides the manipulator (${JSON.stringify(shown)})`);
  check(Math.hypot(...cameraAt.map((x, i) => x - [0.1, 0.2, 0.3][i])) < 1e-9, `camera= places the camera (${cameraAt})`);
  await bare.close();
}

/// A broken upload: the server's message appears on the page.
export async function brokenUpload(page, screenshots) {
  await page.setInputFiles('#file', { name: 'broken.ply', mimeType: 'application/octet-stream',
    buffer: Buffer.from('ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n2\n') });
  await page.waitForFunction(() => /broken\.ply/.test(document.getElementById('message').textContent), null, { timeout: 30000 });
  const text = await page.textContent('#message');
  check(/broken\.ply/.test(text), `a broken upload shows the server's message: "${text.trim()}"`);
  if (screenshots) await page.screenshot({ path: join(screenshots, 'editor-broken-upload.png') });
}

/// A CAD-like part (a cube of grids) is drawn with sharp creases: its edge vertices are drawn once
/// per side, and every drawn normal is a side's normal.
export async function creases(page) {
  await page.setInputFiles('#file', { name: 'box.obj', mimeType: 'text/plain', buffer: Buffer.from(boxObj(8)) });
  await page.waitForFunction(() => window.remora.ready() && window.remora.meshName?.() === 'box.obj', null, { timeout: 120000 })
    .catch(() => {});
  const drawn = await page.evaluate(() => ({ vertices: window.remora.positionsHeld?.().length / 3,
    drawn: window.remora.drawnVertices?.(), worst: window.remora.normalOffAxis?.() }));
  check(drawn.drawn > drawn.vertices && drawn.worst < 1e-6,
        `a cube is drawn with its creases split: ${drawn.drawn} vertices drawn for ${drawn.vertices}, ` +
        `normals off the sides' by ${drawn.worst}`);
}

/// On a part of large faces (a cube of two triangles per side) a painted corner colours its face
/// only up to half-way: far from the corner the face keeps the unpainted colour, near it the
/// colour changes. The pixels are compared before and after painting the one corner.
export async function largeFaceColours(page) {
  await page.setInputFiles('#file', { name: 'box1.obj', mimeType: 'text/plain', buffer: Buffer.from(boxObj(1)) });
  await page.waitForFunction(() => window.remora.ready() && window.remora.meshName?.() === 'box1.obj', null, { timeout: 120000 })
    .catch(() => {});
  const setup = await page.evaluate(() => {
    const p = window.remora.positionsHeld(), f = window.remora.indicesHeld(), eye = window.remora.camera();
    const at = (v) => [p[3 * v], p[3 * v + 1], p[3 * v + 2]];
    const v = window.remora.nearest(...eye);
    let best = null;
    for (let t = 0; t < f.length; t += 3) {
      const c = [f[t], f[t + 1], f[t + 2]];
      if (!c.includes(v)) continue;
      const [a, b] = c.filter((x) => x !== v).map(at), o = at(v);
      const mix = (wv, wa, wb) => [0, 1, 2].map((k) => wv * o[k] + wa * a[k] + wb * b[k]);
      const screen = (q) => window.remora.projectPoint(...q);
      const sa = screen(a), sb = screen(b), so = screen(o);
      const area = Math.abs((sa.x - so.x) * (sb.y - so.y) - (sa.y - so.y) * (sb.x - so.x));
      if (!best || area > best.area)
        best = { area, start: screen(mix(0.97, 0.015, 0.015)), near: screen(mix(0.8, 0.1, 0.1)), far: screen(mix(0.25, 0.375, 0.375)) };
    }
    return { v, ...best };
  });
  const pixels = () => page.evaluate(async (points) => {
    await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
    const c = document.querySelector('#view canvas'), box = c.getBoundingClientRect(), s = c.width / box.width;
    const t = document.createElement('canvas');
    t.width = c.width; t.height = c.height;
    const g = t.getContext('2d');
    g.drawImage(c, 0, 0);
    return points.map((q) => Array.from(g.getImageData(Math.round((q.x - box.left) * s), Math.round((q.y - box.top) * s), 1, 1).data));
  }, [setup.near, setup.far]);
  await page.keyboard.press('s');
  await page.evaluate(() => window.remora.setRadius(0.3));
  await page.mouse.move(setup.start.x, setup.start.y);
  await page.waitForFunction(() => window.remora.shown().cursor, null, { timeout: 10000 }).catch(() => {});
  const before = await pixels();
  await drag(page, setup.start.x, setup.start.y, 0, 0, 2);
  await ready(page);
  const painted = await page.evaluate(() => window.remora.labels().filter((l) => l !== -2).length);
  const after = await pixels();
  const change = (i) => Math.max(...[0, 1, 2].map((k) => Math.abs(after[i][k] - before[i][k])));
  check(painted === 1 && change(1) <= 2 && change(0) >= 20,
        `a painted corner of a large face colours it only near the corner: ${painted} vertex painted, ` +
        `pixel change near it ${change(0)}, far from it ${change(1)} (of 255)`);
}

/// A paint stroke's picks carry one stroke number and the server answers each with the vertices
/// it has not answered in the stroke: what the stroke painted must be what the whole brushes of
/// its picks hold (asked again without the number), added to what was painted before. `paint`
/// makes a stroke with the Support tool.
export async function strokePaintsItsBrushes(page, log, { api }, paint) {
  const before = await remora(page, 'labels');
  const from = log.length;
  await paint();
  await ready(page);
  const after = await remora(page, 'labels');
  const picks = log.slice(from).filter((r) => r.what === 'POST pick' && r.body?.radius > 0);
  const numbers = new Set(picks.map((r) => r.body.stroke));
  const union = new Set();
  let answered = 0;
  for (const { body } of picks) {
    const { stroke: _, ...whole } = body;
    const r = await api('pick', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(whole) });
    const ids = new Uint32Array(await r.arrayBuffer());
    answered += ids.length;
    for (const v of ids) union.add(v);
  }
  // The Support tool: a brushed vertex becomes free unless a handle holds it; nothing else changes.
  let wrong = 0;
  for (let v = 0; v < after.length; ++v)
    if (after[v] !== (union.has(v) && before[v] < 0 ? -1 : before[v])) wrong += 1;
  check(picks.length > 1 && numbers.size === 1 && !numbers.has(undefined) && union.size > 0 && wrong === 0,
        `a stroke's ${picks.length} picks carried one stroke number (${[...numbers].join(', ')}) and it painted ` +
        `the union of their whole brushes (${union.size} vertices, ${answered} in the whole answers; ${wrong} wrong)`);
}

