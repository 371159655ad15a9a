// The browser editor's latency, measured in the page (performance.now() marks, window.remora.marks)
// while the real page is driven with the mouse in headless chromium (SwiftShader WebGL):
//   ready_ms             server start to a paintable page;
//   paint_move_ms        one pointer move while painting with a large brush, until its colours are set,
//                        nothing drawn (software WebGL's drawing not counted; paint_move_shown_ms:
//                        drawn; paint_pick_round_trip_ms: the pick request's part of it);
//   mouseup_to_gizmo_ms  the handle stroke's mouse-up to the manipulator on the solved region,
//                        nothing drawn;
//                        set_region_ms, the server's part of it (set_region_parts_ms: its steps),
//                        and the rest, mouseup_to_gizmo_beyond_set_region_ms;
//   drag_cycle_ms        one manipulator move to its positions and normals applied, nothing drawn;
//                        drag_cycle_shown_ms, drawn; of the hidden cycle: drag_server_ms, the server's
//                        frame (X-Frame-Ms), drag_round_trip_ms, the request's send to its answer
//                        read, drag_apply_ms, the positions and normals applied in the page;
//   drag_to_converged_ms the manipulator's release to the converged shape shown: the last relax
//                        step's answer applied (method nonlinear), or the drag's last answer;
//   bake_ms              a new stroke after a move (the edited shape baked, a new region) until paintable;
//                        The page evaluates the frames itself (web/kernel.js) once the region's
//                        kernel is here: drag_kernel_ms is that evaluation (--server-frames: the
//                        server's frames instead). With method linear and blended motions there is
//                        no server part or round trip; with the energies that iterate the server
//                        answers the moves with its base offsets, which the page adds from then on:
//                        drag_server_ms and drag_round_trip_ms are those answers' (the age of the
//                        nonlinear part of a frame shown); kernel_bytes, the region's
//                        kernel, and kernel_after_mouseup_ms, its arrival after the handle stroke's
//                        mouse-up (compare mouseup_to_gizmo_ms); nonlinear_after_mouseup_ms, method
//                        nonlinear's state of the region built (the status polled every 10 ms from
//                        the manipulator on), which the server builds after showing the region: the
//                        drags start after it and after the kernel;
//   bytes_per_frame      the transform answer's size; support_vertices, the region's support;
//   kernel_engine        'wasm' (kernel.wasm) or 'js' (--kernel js, or a page built without it);
//                        kernel_ms_by_engine, the page's frame alone per engine (wasm on two
//                        threads, wasm1 on one, js), medians of 31 each, interleaved (a corrected
//                        kernel, the nonlinear energies that iterate, has one thread: wasm is wasm1).
// The pointer moves one step per 1/60 s (a browser delivers moves once per display frame). All
// medians. The last line printed is one JSON object with these keys.
//
//   node web/tests/bench.mjs --cli build/bin/remora --web-root build/web [--mesh data/bunny.ply]
//        [--support-radius R] [--moves N] [--method linear|nonlinear|blended-motions] [--quick]
//        [--server-frames] [--kernel js] [--sphere-brush] [--support-count N] [--trace FILE]
// R is in the mesh's units (default: a fifth of its bounding radius); the support is painted at
// the surface under the view's centre. --method: the page's method switch, set before the support
// is painted (default linear). --quick: no drawn figures and no bake (their keys are
// null). --sphere-brush: the brushes take the straight-line distance (the far side too: the
// largest supports). --support-count N: instead of the support's strokes, the N vertices
// nearest the camera (no paint figures). --trace FILE: chromium's trace of the handle stroke
// until the manipulator (JSON for Perfetto or chrome://tracing: the page's tasks, its requests,
// the garbage collector). Exit code 0: done, 1: failed, 77: chromium or playwright-core missing.
import { args, chromiumOrSkip, client, drag, ready, startServer } from './harness.mjs';

const moves = Number(args.moves ?? 30);
const quick = 'quick' in args;
const serverFrames = 'server-frames' in args;
const query = [serverFrames ? 'page-frames=0' : '', args.kernel === 'js' ? 'kernel=js' : ''].filter(Boolean).join('&');
// Pointer moves come one per display frame at 60 Hz, as a browser delivers them (it aligns them
// with its frames), not as fast as the driver can send them.
const frame = 1000 / 60;
const median = (xs) => { const s = [...xs].sort((a, b) => a - b); return s.length ? s[s.length >> 1] : null; };
const round = (x) => (x === null ? null : Math.round(x * 100) / 100);

const browser = await chromiumOrSkip();
const { server, url, started } = await startServer(args.cli, args.mesh ?? 'data/bunny.ply', args['web-root'], []);
const { json } = client(url);
let failed = false;
try {
  const page = await browser.newPage({ viewport: { width: 1200, height: 800 } });
  page.on('pageerror', (e) => { console.log('page error:', e.message); failed = true; });
  await page.goto(query ? `${url}?${query}` : url);
  await ready(page, 600000);
  if (args.method) await page.selectOption('#method', args.method);
  const marks = () => page.evaluate(() => window.remora.marks());
  const paintableAt = await page.evaluate(() => performance.timeOrigin + window.remora.marks().paintable);
  const box = await page.locator('canvas').boundingBox();
  const centre = { x: box.x + box.width / 2, y: box.y + box.height / 2 };
  const bound = await page.evaluate(() => Number(document.getElementById('radius').max));
  const supportRadius = Number(args['support-radius'] ?? bound / 5);

  // The support: strokes of `moves` pointer moves with the large brush, the mesh hidden, then shown.
  if ('sphere-brush' in args) await page.uncheck('#geodesic');
  await page.keyboard.press('s');
  await page.evaluate((r) => window.remora.setRadius(r), supportRadius);
  const paintStroke = async (dy) => {
    const from = (await marks()).paintMove.length;
    await drag(page, centre.x - moves, centre.y + dy, 2, 0, moves, frame);
    await ready(page);
    const mm = await marks();
    return { ms: mm.paintMove.slice(from), trips: mm.paintTrip.slice(from) };
  };
  await page.evaluate(() => window.remora.setDrawing(false));
  const supportCount = Number(args['support-count'] ?? 0);
  if (supportCount > 0) await page.evaluate((n) => window.remora.supportNearest(n), supportCount);
  const { ms: paintMove, trips: paintTrips } = supportCount > 0 ? { ms: [], trips: [] } : await paintStroke(0);
  await page.evaluate(() => window.remora.setDrawing(true));
  const { ms: paintMoveShown } = quick || supportCount > 0 ? { ms: [] } : await paintStroke(4);
  // The handle inside it, smaller; its mouse-up sends the region.
  await page.keyboard.press('h');
  await page.evaluate((r) => window.remora.setRadius(r / 4), supportRadius);
  await page.evaluate(() => window.remora.setDrawing(false));
  if (args.trace) {
    await browser.startTracing(page, { path: args.trace, categories: ['devtools.timeline', 'disabled-by-default-devtools.timeline', 'v8', 'blink', 'toplevel', 'loading'] });
  }
  await drag(page, centre.x, centre.y, 1, 0, 3);
  await ready(page, 600000);
  if (args.trace) await browser.stopTracing();
  await page.evaluate(() => window.remora.setDrawing(true));
  let m = await marks();
  const mouseupToGizmo = m.regionReady[m.regionReady.length - 1] - m.strokeEnd;
  console.log('region steps', JSON.stringify(m.regionSteps[m.regionSteps.length - 1]));
  const regionStatus = (await json('status')).region ?? {};
  const support = regionStatus.support ?? 0;
  const setRegion = regionStatus.set_region_ms ?? null;
  const setRegionParts = regionStatus.set_region_parts_ms ?? null;
  const pageOrigin = await page.evaluate(() => performance.timeOrigin); // the page's clock, from here
  const nonlinearBuilt = (async () => { // the status polled every 10 ms from the manipulator on
    while ((await json('status')).nonlinear?.preparing) await new Promise((r) => setTimeout(r, 10));
    return Date.now() - pageOrigin;
  })();

  // Drags of the manipulator's arrow, the mesh shown, then hidden.
  const dragCycle = async () => {
    const keys = ['drag', 'dragBytes', 'dragServer', 'dragTrip', 'dragApply', 'dragKernel', 'relaxed'];
    const before = await marks();
    const pivot = await page.evaluate(() => window.remora.pivot());
    const c = await page.evaluate((p) => window.remora.projectPoint(...p), pivot);
    await page.keyboard.press('w');
    await drag(page, c.x, c.y - 75, 0, -1, moves, frame);
    await ready(page);
    const mm = await marks();
    const [ms, bytes, server, trip, apply, kernel, relaxed] = keys.map((k) => mm[k].slice(before[k].length));
    return { ms, bytes, server, trip, apply, kernel, relaxed };
  };
  // The page evaluates the drag's frames once the region's kernel is here (for the energies that
  // iterate, with the server's first base offsets).
  if (!serverFrames)
    await page.waitForFunction(() => window.remora.kernelFrame([]) !== null, null, { timeout: 120000 }).catch(() => {});
  const afterKernel = await marks();
  const kernelMark = afterKernel.kernel.at(-1);
  // Method nonlinear: its state comes after the manipulator (docs/server.md), while a user
  // reaches for the manipulator. The drags start once it is there.
  const nonlinearAt = await nonlinearBuilt;
  const nonlinearReady = regionStatus.method === 'nonlinear' ? nonlinearAt - afterKernel.strokeEnd : null;
  const shown = quick ? { ms: [], bytes: [] } : await dragCycle();
  await page.evaluate(() => window.remora.setDrawing(false));
  const hidden = await dragCycle();
  await page.evaluate(() => window.remora.setDrawing(true));

  // A new support stroke after the move: the edited shape is baked into a new base.
  await page.keyboard.press('s');
  await page.evaluate((r) => window.remora.setRadius(1.3 * r), supportRadius);
  const regions = m.regionReady.length;
  if (!quick) {
    await drag(page, centre.x, centre.y, 1, 1, 3);
    await ready(page, 600000);
    m = await marks();
  }
  const bake = m.regionReady.length > regions ? m.regionReady[m.regionReady.length - 1] - m.strokeEnd : null;

  const result = {
    ready_ms: round(paintableAt - started), paint_move_ms: round(median(paintMove)),
    paint_move_shown_ms: round(median(paintMoveShown)), paint_pick_round_trip_ms: round(median(paintTrips)),
    mouseup_to_gizmo_ms: round(mouseupToGizmo), set_region_ms: round(setRegion),
    set_region_parts_ms: setRegionParts && Object.fromEntries(Object.entries(setRegionParts).map(([k, v]) => [k, round(v)])),
    mouseup_to_gizmo_beyond_set_region_ms: round(setRegion === null ? null : mouseupToGizmo - setRegion),
    drag_cycle_ms: round(median(hidden.ms)), drag_server_ms: round(median(hidden.server)),
    drag_round_trip_ms: round(median(hidden.trip)), drag_apply_ms: round(median(hidden.apply)),
    drag_kernel_ms: round(median(hidden.kernel)), drag_to_converged_ms: round(median(hidden.relaxed)),
    kernel_after_mouseup_ms: round(kernelMark ? kernelMark.at - afterKernel.strokeEnd : null),
    nonlinear_after_mouseup_ms: round(nonlinearReady),
    kernel_bytes: kernelMark?.bytes ?? null,
    kernel_engine: await page.evaluate(() => window.remora.kernelEngine()),
    kernel_ms_by_engine: await page.evaluate(() => window.remora.kernelTimes([[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1e-3]],
                                                                           ['wasm', 'wasm1', 'js'], 31)),
    drag_cycle_shown_ms: round(median(shown.ms)), bake_ms: round(bake),
    bytes_per_frame: median([...shown.bytes, ...hidden.bytes]), support_vertices: support,
    paint_moves: paintMove.length + paintMoveShown.length, drag_frames: hidden.ms.length + shown.ms.length,
  };
  console.log(JSON.stringify(result));
} catch (e) {
  console.log('bench failed:', e.message);
  failed = true;
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
process.exit(failed ? 1 : 0);
