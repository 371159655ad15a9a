// The browser editor of `remora serve` (docs/server.md): paint a support and handles on the mesh,
// drag a handle with a manipulator, watch the support bend while the details ride along. All the
// geometry work happens on the server (the editing kernel, picking and brushes); this page paints,
// sends, and draws. This file holds the state of the edit and wires the modules together:
// view.js draws, api.js talks to the server, picking.js asks it what is under the pointer,
// panels.js is the panel and the keyboard.
import * as THREE from 'three';
import { ApiError, api, binary, compactIds, json, message, post, task, waitUntilReady, work } from './api.js';
import * as view from './view.js';
import { FIXED, FREE } from './view.js';
import { Coalescer, faceNormal, pick } from './picking.js';
import { RegionKernel, Relaxer, methodOf, sendFrame } from './drag_frames.js';
import { engine, loadEngine } from './engine.js';
import * as panels from './panels.js';

const $ = (id) => document.getElementById(id);
// Display options in the URL (rendering only; scripts/render_pictures.mjs uses them):
//   ui=0                          no panel, messages, progress or manipulator over the view;
//   camera=px,py,pz,tx,ty,tz[,ux,uy,uz]  the camera's position, target and up, instead of the fit;
//   show-base, show-wire, show-mesh, show-edges = 1|0   the "Show" checkboxes' initial state;
//   area-range=R                  the base's area colours saturate at ±R (default 0.2: ±20 %).
const params = new URLSearchParams(window.location.search);
const showUi = params.get('ui') !== '0';
if (!showUi) document.body.classList.add('no-ui');
for (const id of ['show-base', 'show-wire', 'show-mesh', 'show-edges'])
  if (params.has(id)) $(id).checked = params.get(id) === '1';
// Not for rendering: page-frames=0, the drags' frames from the server for every method
// (web/kernel.js evaluates them in the page otherwise).
const pageFrames = params.get('page-frames') !== '0';
// Not for rendering: kernel=js, the page's frames evaluated in JavaScript even where kernel.wasm
// is there (the benchmark compares both engines).
const kernelInJs = params.get('kernel') === 'js';
const areaRange = Number(params.get('area-range')) > 0 ? Number(params.get('area-range')) : 0.2;
let cameraParam = params.has('camera') ? params.get('camera').split(',').map(Number) : null;
if (cameraParam && !((cameraParam.length === 6 || cameraParam.length === 9) && cameraParam.every(Number.isFinite))) {
  console.error('camera= needs 6 or 9 numbers: px,py,pz,tx,ty,tz[,ux,uy,uz]; ignored');
  cameraParam = null;
}
view.createControls(cameraParam?.length === 9 ? cameraParam.slice(6) : null);
const { orbit, gizmo, pivot } = view;

// ---- state --------------------------------------------------------------------------------------
const MIN_SCALE = 0.05; // the manipulator's smallest scale per axis: the map keeps det(M) > 0
const state = {
  tool: 'orbit', selected: 0, handleCount: 1, k: 2, method: 'linear', converged: true,
  labels: null, positions: null, indices: null, // labels: FIXED, FREE or a handle index per vertex
  movable: null, sentMovable: null, serverHandles: 0, transforms: [], dirtyRegion: false, status: null, frameMs: undefined,
  held: { mesh: undefined, positions: undefined, region: undefined }, // the status ids of what the page holds
  marks: { paintMove: [], paintTrip: [], drag: [], dragBytes: [], dragServer: [], dragTrip: [], dragApply: [], dragKernel: [], kernel: [], regionReady: [], regionSteps: [], strokeEnd: null, paintable: null, relaxed: [], dragEnd: null },
};
const busy = () => state.status?.state === 'busy';

/// Polls until the server is idle, showing the progress; returns the status (its error shown).
async function settle() {
  const s = await waitUntilReady((b) => { state.status = b; panels.showProgress(b); placeGizmo(true); });
  $('progress').hidden = true;
  return s;
}

// ---- what the page holds: brought up to a status ------------------------------------------------
const changed = (id, held) => id === undefined || id !== held;

/// Brings the page up to the ready status `s`, downloading only what changed: the faces when
/// mesh_id changed, the positions when positions_id changed, the region and movable vertices when
/// region_id changed (only the movable ones when `labelsKnown`: the page sent that region itself).
async function sync(s, { fit = false, labelsKnown = false, keepGizmo = false } = {}) {
  state.status = s;
  panels.showStats(s, state.frameMs);
  if (s.state !== 'ready') return;
  let fresh = false, moved = false;
  if (!state.indices || changed(s.mesh_id, state.held.mesh)) {
    state.indices = await binary('mesh/indices', Uint32Array);
    state.positions = await binary('mesh/positions', Float32Array);
    view.setMesh(state.positions, state.indices);
    showMesh();
    fresh = true;
  } else if (changed(s.positions_id, state.held.positions)) {
    state.positions.set(await binary('mesh/positions', Float32Array));
    view.positionsChanged();
    moved = true;
  }
  state.held.mesh = s.mesh_id;
  state.held.positions = s.positions_id;
  const regionChanged = fresh || changed(s.region_id, state.held.region);
  if (regionChanged) await fetchRegion(s, labelsKnown && !fresh);
  else if (moved) resyncKernel(); // undo, redo: the region's transforms changed under its kernel
  state.transforms = (s.transforms || []).map(rowsToMatrix);
  if (fit) panels.fitRadius(view.fitCamera(cameraParam));
  showHandleButtons();
  placeGizmo(keepGizmo && !fresh);
  if (baseShown() && (fresh || regionChanged || moved || !view.hasBase())) await showBase(fresh || regionChanged || !view.hasBase());
}

async function fetchRegion(s, labelsKnown) {
  if (!labelsKnown) {
    const n = state.positions.length / 3;
    state.labels = new Int32Array(n).fill(FIXED);
    const region = await json('region');
    if (region) {
      for (const v of region.support) state.labels[v] = FREE;
      region.handles.forEach((h, j) => { for (const v of h) state.labels[v] = j; });
      state.k = region.k;
      panels.setK(region.k);
      state.method = methodOf(region) ?? 'linear';
      panels.setMethod(state.method);
    }
    state.handleCount = Math.max(1, region?.handles.length ?? 0);
    state.selected = Math.min(state.selected, state.handleCount - 1);
    view.colour(state.labels);
  }
  state.serverHandles = s.region?.handles ?? 0;
  // The movable vertices are the support the page sent (sorted, handles included).
  if (labelsKnown && s.region && state.sentMovable) state.movable = state.sentMovable;
  else state.movable = s.region ? await binary('movable', Uint32Array) : null;
  view.setMovable(state.movable);
  state.sentMovable = null;
  state.held.region = s.region_id;
  loadKernel(s);
}

// ---- the frames of a drag in the page (drag_frames.js) -----------------------------------------
// A drag is evaluated here, from the region's kernel fetched once after the region is ready; the
// drag ends, and the pauses of the nonlinear method relax, on the server's positions. Until the
// kernel (and a corrected kernel's first offsets) is here, the server's answers are the frames.
let kernel = null; // a RegionKernel
const engineLoaded = kernelInJs ? Promise.resolve('js') : loadEngine();
function loadKernel(s) {
  kernel?.release();
  kernel = null;
  if (!pageFrames || !s.region || !state.movable) return;
  const regionId = s.region_id, movable = state.movable;
  RegionKernel.load(s, movable, view.drawnNormals(movable), engineLoaded).then((k) => {
    if (!k || state.held.region !== regionId || state.movable !== movable) return k?.release();
    kernel?.release();
    kernel = k;
    state.marks.kernel.push({ at: performance.now(), bytes: k.bytes });
    resyncKernel();
  }).catch((e) => console.warn(`region kernel: ${e.message}; the server's frames are shown`));
}
/// A corrected kernel waits for offsets of the server's current transforms (after its load, an
/// undo or a redo): a relax step answers them (nothing moves where the iteration has converged).
function resyncKernel() {
  if (!kernel?.data.corrected) return;
  kernel.synced = false;
  // A waiting move is not replaced: it asks for the offsets itself once the kernel is here.
  if (!frames.pending) frames.submit({ relax: true, offsets: true, kernel });
}
const kernelUsable = () => !!kernel && kernel.usable(state);
const kernelCorrected = () => !!kernel && kernel.corrected(state);
const transformRows = () => state.transforms.map(matrixToRows);
/// The page's frame under the live transforms, shown.
function showKernelFrame() {
  kernel.evaluate(transformRows());
  const evaluated = performance.now();
  view.applyMoved(state.movable, kernel.out, kernel.data.wasm?.drawn ?? null);
  return evaluated;
}
/// A frame of the drag evaluated in the page; false when it cannot be (then the server's is shown).
function localFrame(t0) {
  if (!kernelUsable()) return false;
  const evaluated = showKernelFrame();
  state.frameMs = evaluated - t0;
  const done = performance.now();
  state.marks.drag.push(done - t0);
  state.marks.dragKernel.push(evaluated - t0);
  state.marks.dragApply.push(done - evaluated);
  return true;
}

// ---- painting: the server picks, the page colours -----------------------------------------------
// The picks of a stroke carry its number, and the server answers each with only the vertices it
// has not answered in that stroke (the page keeps what it painted). A new tool or label, or a
// pick that failed, starts a new number, whose first answer is the whole brush.
let painting = false, lastHover = null;
const stroke = { number: 0, key: '' };
const picks = new Coalescer((q) => {
  q.sent = performance.now();
  return pick(q.ray, q.radius, q.brush, q.stroke).catch((e) => { stroke.number += 1; throw e; });
}, onPick);

function onPick(hit, q) {
  lastHover = hit;
  const onMesh = hit.face >= 0 && !!hit.point;
  if (onMesh && state.tool !== 'orbit') view.showCursor(hit.point, faceNormal(state.positions, state.indices, hit.face), panels.radius());
  else view.hideCursor();
  if (q.paint && onMesh) {
    state.marks.paintTrip.push(performance.now() - q.sent);
    paint(hit.ids, q.tool, q.label);
    state.marks.paintMove.push(performance.now() - q.t0);
  }
}

/// Paints ids with `label` as `tool` did when the stroke asked for them.
function paint(ids, tool, label) {
  const touched = [];
  for (const v of ids) {
    const old = state.labels[v];
    if (tool === 'support' && old >= 0) continue; // painting the support keeps handles
    if (old !== label) { state.labels[v] = label; touched.push(v); }
  }
  if (touched.length) { state.dirtyRegion = true; view.colour(state.labels, touched); if (painting) strokeChanged(); }
}

function submitPick(event, paintIt) {
  const tool = state.tool, label = tool === 'support' ? FREE : tool === 'handle' ? state.selected : FIXED;
  if (paintIt && stroke.key !== `${tool} ${label}`) { stroke.number += 1; stroke.key = `${tool} ${label}`; }
  picks.submit({ ray: view.rayAt(event), radius: paintIt ? panels.radius() : 0, brush: panels.brush(),
                 paint: paintIt, tool, label, stroke: paintIt ? stroke.number : undefined, t0: performance.now() });
}

// In the capture phase, before the orbit controls: a stroke that starts on the mesh paints, one
// that starts off it (as the last hover pick says) orbits.
view.container.addEventListener('pointerdown', (event) => {
  if (state.tool === 'orbit' || event.button !== 0 || !state.labels) return;
  if (lastHover && lastHover.face < 0 && !picks.busy) return;
  message('');
  orbit.enabled = false;
  painting = true;
  stroke.key = '';
  submitPick(event, true);
}, { capture: true });
view.renderer.domElement.addEventListener('pointermove', (event) => {
  if (painting) submitPick(event, true);
  else if (state.tool !== 'orbit' && state.labels && !gizmo.dragging && event.buttons === 0) submitPick(event, false);
});
view.renderer.domElement.addEventListener('pointerleave', () => { if (!painting) view.hideCursor(); });
window.addEventListener('pointerup', () => {
  if (!painting) return;
  painting = false;
  orbit.enabled = true;
  clearTimeout(pauseTimer);
  state.marks.strokeEnd = performance.now();
  task(async () => {
    await picks.idle();
    if (state.dirtyRegion) await sendRegion();
    else if (regionSent) await regionSent.then(regionShown); // sent in a pause of the stroke
  });
});

// The region's work hides behind the brush: when a stroke pauses (the pointer held still for
// PAUSE_MS), the region as painted so far goes to the server, which solves it while the user
// looks; a later change sends it again, and the server stops the stale job for it. At mouse-up
// nothing is left to send when nothing changed since.
const PAUSE_MS = 250;
let pauseTimer = 0, regionSent = null;
function strokeChanged() {
  clearTimeout(pauseTimer);
  pauseTimer = setTimeout(() => {
    if (painting && state.dirtyRegion) task(() => sendRegion({ inStroke: true }));
  }, PAUSE_MS);
}

/// The painted region as the API takes it; handles are renumbered so that none is empty (the
/// labels follow), and `free` counts the support's vertices outside every handle.
function regionLists() {
  // One index loop over the labels into a typed array (it runs once per stroke over every vertex,
  // mostly before the JIT has optimized it), then one over the support.
  const labels = state.labels, n = labels.length;
  const counts = new Array(state.handleCount).fill(0), all = new Uint32Array(n);
  let free = 0, m = 0;
  for (let v = 0; v < n; ++v) {
    const l = labels[v];
    if (l === FIXED) continue;
    all[m++] = v;
    if (l >= 0) counts[l] += 1; else free += 1;
  }
  const support = all.slice(0, m);
  const renumber = [];
  let kept = 0;
  counts.forEach((c, j) => { renumber[j] = c > 0 ? kept++ : -1; });
  const handles = Array.from({ length: kept }, () => []);
  for (let i = 0; i < support.length; ++i) {
    const v = support[i], l = labels[v];
    if (l >= 0) { labels[v] = renumber[l]; handles[renumber[l]].push(v); }
  }
  if (renumber.some((x, j) => x !== j)) view.colour(state.labels);
  if (kept > 0) {
    state.selected = renumber[state.selected] >= 0 ? renumber[state.selected] : kept - 1;
    state.handleCount = kept;
  }
  return { support, handles, free };
}

/// Sends the painted region when it can be solved; otherwise says what is missing. A refusal
/// (a 4xx or the job's error) keeps the paint and shows the server's message. A region sent
/// while the server solves an older one replaces it (the server stops the older job); only the
/// newest send brings the page up to the result. inStroke: sent in a pause of a stroke (no
/// hints, the tool stays); keepGizmo: a new k under the same region.
let regionSeq = 0, regionPosted = Promise.resolve();
async function sendRegion({ keepGizmo = false, inStroke = false } = {}) {
  const started = performance.now(), seq = ++regionSeq;
  relaxer.cancel();
  state.dirtyRegion = false;
  const { support, handles, free } = regionLists();
  showHandleButtons();
  if (!handles.length || !free) {
    regionSent = null;
    if (inStroke) { state.dirtyRegion = true; return; } // the mouse-up says what is missing
    if (!handles.length)
      message(support.length ? 'Now paint a handle inside the support (tool "Handle", H).'
                             : 'Paint a support (S), then a handle inside it (H).', 'hint');
    else message('The support has no free vertex: paint the support around the handle (tool "Support", S).', 'hint');
    return;
  }
  if (busy() && state.status?.progress?.job !== 'region') await settle(); // a load: wait for it
  const steps = { started, lists: performance.now() };
  // After the last POST's answer: on another connection a newer region could arrive first.
  const body = { support: compactIds(support), handles: handles.map(compactIds), k: state.k, ...methodRequest(state.method) };
  const posted = regionPosted.then(() => post('region', body));
  regionPosted = posted.catch(() => {});
  // The region's movable vertices are the support, handles included, sorted.
  state.sentMovable = support;
  steps.requested = performance.now();
  const outcome = (async () => {
    try {
      panels.showProgress(await (await posted).json());
    } catch (e) {
      return { failed: true };
    }
    steps.posted = performance.now();
    const s = await settle();
    steps.settled = performance.now();
    return { s };
  })();
  // Resolves once the page holds the result (only the newest send brings the page up to it).
  const sent = (async () => {
    const result = { ...(await outcome), seq, steps, keepGizmo };
    if (seq === regionSeq) await regionArrived(result);
    return result;
  })();
  regionSent = sent;
  const result = await sent;
  if (!inStroke && !painting) regionShown(result);
}

/// Brings the page up to a region's result (or back to the region it had, on a refusal).
async function regionArrived({ failed, s, keepGizmo }) {
  if (failed || s.error) {
    state.sentMovable = null;
    if (s) {
      state.status = s;
      panels.showStats(s, state.frameMs);
    }
    state.dirtyRegion = true;
    placeGizmo(true);
    return;
  }
  await sync(s, { labelsKnown: true, keepGizmo });
  state.sentMovable = null;
}

/// After the stroke: the manipulator on the region (the Orbit tool), and the marks of the
/// benchmark.
function regionShown({ failed, s, steps, keepGizmo, seq }) {
  if (failed || s?.error || seq !== regionSeq || painting) return;
  regionSent = null;
  state.marks.regionReady.push(performance.now());
  const relative = { ...steps };
  for (const key of Object.keys(relative)) relative[key] -= state.marks.strokeEnd;
  state.marks.regionSteps.push(relative);
  if (keepGizmo) {
    placeGizmo(true);
    return;
  }
  setTool('orbit');
  placeGizmo(); // on the handle of this region
  // A support of long triangles (a CAD part's own) bends in facets: said, with what to do.
  if (s.region?.coarse_support) message(`Region ready, but ${s.region.coarse_support}.`, 'hint');
  else message('Region ready; the Orbit tool is on: drag the arrows to move the handle (S, H: paint again).', 'info');
}

// ---- handles and the manipulator ----------------------------------------------------------------
function showHandleButtons() {
  panels.showHandles(state.handleCount, state.selected, (j) => { state.selected = j; showHandleButtons(); placeGizmo(); });
}

function handleCentre(j) {
  const p = state.positions, c = new THREE.Vector3();
  let count = 0;
  for (let v = 0; v < state.labels.length; ++v)
    if (state.labels[v] === j) { c.x += p[3 * v]; c.y += p[3 * v + 1]; c.z += p[3 * v + 2]; ++count; }
  return count ? c.divideScalar(count) : null;
}

/// The manipulator is shown, and takes the mouse, only with the Orbit tool, for a handle the
/// server holds, while the server is idle. keep: leave an attached manipulator where it is.
function placeGizmo(keep = false) {
  const wanted = showUi && state.tool === 'orbit' && !!state.movable && !!state.labels && !busy() &&
                 state.selected < state.serverHandles;
  if (!wanted) { view.showGizmo(false); return; }
  if (keep && view.gizmoPlaced()) { view.showGizmo(true); return; }
  const centre = handleCentre(state.selected);
  if (!centre) { view.showGizmo(false); return; }
  pivot.position.copy(centre);
  pivot.quaternion.identity();
  pivot.scale.set(1, 1, 1);
  pivot.updateMatrix();
  view.showGizmo(true);
}

function rowsToMatrix(rows) {
  const m = new THREE.Matrix4();
  m.set(rows[0], rows[1], rows[2], rows[3], rows[4], rows[5], rows[6], rows[7],
        rows[8], rows[9], rows[10], rows[11], 0, 0, 0, 1);
  return m;
}
function matrixToRows(m) {
  const e = m.elements; // column-major
  return [e[0], e[4], e[8], e[12], e[1], e[5], e[9], e[13], e[2], e[6], e[10], e[14]];
}

// A frame: a handle's new map, or, while the pointer rests, more nonlinear iterations in steps
// (drag_frames.js's Relaxer).
/// A corrected kernel takes the answer's base offsets (those of the kernel the request was sent
/// with); after the drag's last move the page's frame is shown again with them.
function receiveOffsets(result, request) {
  if (!result.offsets || request.kernel !== kernel || !kernelCorrected() || !kernel.takeOffsets(result.offsets)) return;
  if (!request.local || !kernelUsable()) return;
  const received = performance.now();
  if (!frames.pending) showKernelFrame();
  state.marks.dragBytes.push(result.bytes);
  state.marks.dragServer.push(result.ms);
  state.marks.dragTrip.push(received - request.sent);
  state.converged = result.converged;
  if (!result.converged) relaxer.soon();
}
// A move goes out while a relax step is in flight: the server ends the step after the iteration
// under way and answers it first.
const overtakes = (waiting, inFlight) => inFlight.relax && !waiting.relax;
const frames = new Coalescer((request) => sendFrame(request, request.budget ?? Relaxer.BUDGET_MS), (result, request) => {
  receiveOffsets(result, request);
  if (request.local) return; // shown by localFrame(), which also timed it
  if (!state.movable || result.moved.length !== 3 * state.movable.length) return;
  state.frameMs = result.ms;
  const received = performance.now();
  // A move after the request was sent is shown already by the page's frame: keep it.
  if (relaxer.lastMove > request.sent && kernelUsable()) showKernelFrame();
  else view.applyMoved(state.movable, result.moved);
  if (!request.relax && !request.last) {
    const done = performance.now();
    state.marks.drag.push(done - request.t0);
    state.marks.dragBytes.push(result.bytes);
    state.marks.dragServer.push(result.ms);
    state.marks.dragTrip.push(received - request.sent);
    state.marks.dragApply.push(done - received);
  }
  state.converged = result.converged;
  if (result.converged && state.marks.dragEnd !== null && (request.relax || request.last)) { // release to converged
    state.marks.relaxed.push(performance.now() - state.marks.dragEnd);
    state.marks.dragEnd = null;
  }
  if (!result.converged) relaxer.soon();
  else if (request.relax) task(refreshStatus);
}, overtakes);
const relaxer = new Relaxer((budget) => frames.submit({ relax: true, budget, offsets: kernelCorrected(), kernel }),
                            () => !!frames.pending || frames.sent.some((r) => r.relax));
async function refreshStatus() {
  try { state.status = await json('status'); panels.showStats(state.status, state.frameMs); } catch (e) { /* shown */ }
  if (state.status?.nonlinear?.fallback) message(state.status.nonlinear.fallback, 'hint');
}

let dragStart = null, dragBase = null, draggedLocally = false;
gizmo.addEventListener('dragging-changed', (event) => {
  orbit.enabled = !event.value;
  if (event.value) {
    state.marks.dragEnd = null;
    pivot.updateMatrix();
    dragStart = pivot.matrix.clone().invert();
    dragBase = (state.transforms[state.selected] || new THREE.Matrix4()).clone();
    draggedLocally = false;
    return;
  }
  dragStart = null;
  state.marks.dragEnd = performance.now();
  relaxer.released(state.marks.dragEnd);
  const handle = state.selected, last = draggedLocally;
  task(async () => {
    // The page showed its own frames: the drag ends on the server's (the reference).
    // The server iterates on after answering it ("relax": true) until the relax step comes.
    if (last) frames.submit({ handle, matrix: matrixToRows(state.transforms[handle]), t0: performance.now(), last: true, offsets: kernelCorrected(), kernel });
    await frames.idle();
    try { await post('commit'); state.status = await json('status'); panels.showStats(state.status, state.frameMs); } catch (e) { /* shown */ }
    if (baseShown()) await showBase(false);
  });
});
gizmo.addEventListener('objectChange', () => {
  if (!dragStart) return;
  // Through the pivot the scale would flip sign: the map must keep its orientation (det > 0).
  for (const axis of ['x', 'y', 'z']) pivot.scale[axis] = Math.max(MIN_SCALE, pivot.scale[axis]);
  pivot.updateMatrix();
  const t = pivot.matrix.clone().multiply(dragStart).multiply(dragBase);
  state.transforms[state.selected] = t;
  const now = performance.now();
  relaxer.moved(now);
  const local = localFrame(now);
  draggedLocally ||= local;
  frames.submit({ handle: state.selected, matrix: matrixToRows(t), t0: now, local, offsets: kernelCorrected(), kernel });
});

// ---- the base surface ---------------------------------------------------------------------------
const baseShown = () => $('show-base').checked || $('show-wire').checked;
/// Draws the base when a checkbox asks for it: its faces and areas again when `refetchIndices`
/// (a new mesh or region), otherwise its current positions.
async function showBase(refetchIndices) {
  if (baseShown() && state.status?.state === 'ready') {
    const positions = await binary('base/positions', Float32Array);
    if (refetchIndices || !view.hasBase())
      view.setBase(positions, await binary('base/indices', Uint32Array), await binary('base/areas', Float32Array), areaRange);
    else view.setBase(positions, null);
  }
  view.showBase($('show-base').checked, $('show-wire').checked);
}
const showMesh = () => view.showMesh($('show-mesh').checked, $('show-edges').checked);

// ---- actions of the panel and the keyboard ------------------------------------------------------
function setTool(tool) {
  state.tool = tool;
  panels.setToolButtons(tool);
  if (tool === 'orbit') view.hideCursor();
  placeGizmo(true);
}
function setMode(mode) {
  gizmo.setMode(mode);
  panels.setModeButtons(mode);
}
function newHandle() {
  state.handleCount += 1;
  state.selected = state.handleCount - 1;
  setTool('handle');
  showHandleButtons();
  placeGizmo();
}
function clear() {
  if (!state.labels) return;
  state.labels.fill(FIXED);
  state.handleCount = 1;
  state.selected = 0;
  view.colour(state.labels);
  showHandleButtons();
  view.detachGizmo();
}
function setK(k) {
  state.k = k;
  if (state.movable && state.labels && !painting) task(() => sendRegion({ keepGizmo: true }));
}
/// The page's method choice as the API's: 'linear', 'nonlinear' (the server's default energy) or
/// 'blended-motions' (method nonlinear with that energy: docs/nonlinear.md).
function methodRequest(choice) {
  if (choice === 'blended-motions') return { method: 'nonlinear', energy: 'blended-motions' };
  return { method: choice };
}
function setMethod(method) {
  state.method = method;
  if (state.movable && state.labels && !painting) task(() => sendRegion({ keepGizmo: true }));
}
async function history(which) {
  if (busy() || frames.busy || painting) return;
  message('');
  try { await post(which); } catch (e) { return; }
  await sync(await settle());
}
async function upload(file) {
  message('');
  try {
    await api(`load?name=${encodeURIComponent(file.name)}`, { method: 'POST', body: await file.arrayBuffer() });
  } catch (e) { return; }
  const s = await settle();
  if (s.error) { state.status = s; panels.showStats(s); return; }
  state.selected = 0;
  await sync(s, { fit: true });
  message(`Loaded ${file.name}. Paint a support (S), then a handle inside it (H).`, 'info');
}
panels.bindPanels({
  setTool, setMode, newHandle, clear, setK, setMethod, showMesh,
  history: (which) => task(() => history(which)),
  showBase: () => task(() => showBase(false)),
  upload: (file) => task(() => upload(file)),
  scaleRadius: (factor) => { panels.scaleRadius(factor); view.setCursorRadius(panels.radius()); },
  meshName: () => state.status?.mesh?.name,
});

// ---- for the tests and the benchmark: where things are on screen, and the page's state ----------
window.remora = {
  project: (v) => view.project(state.positions[3 * v], state.positions[3 * v + 1], state.positions[3 * v + 2]),
  projectPoint: (x, y, z) => view.project(x, y, z),
  nearest(x, y, z) {
    let best = -1, bestD = Infinity;
    const p = state.positions;
    for (let v = 0; v < p.length / 3; ++v) {
      const d = (p[3 * v] - x) ** 2 + (p[3 * v + 1] - y) ** 2 + (p[3 * v + 2] - z) ** 2;
      if (d < bestD) { bestD = d; best = v; }
    }
    return best;
  },
  setRadius: (r) => panels.setRadius(r),
  /// The benchmark's largest supports: the `count` vertices nearest the camera painted as
  /// support (a stroke reaches only the side in view).
  supportNearest(count) {
    const p = state.positions, c = view.camera.position, n = p.length / 3, d = new Float64Array(n);
    for (let v = 0; v < n; ++v) d[v] = (p[3 * v] - c.x) ** 2 + (p[3 * v + 1] - c.y) ** 2 + (p[3 * v + 2] - c.z) ** 2;
    const order = Uint32Array.from({ length: n }, (_, i) => i).sort((a, b) => d[a] - d[b]);
    for (let i = 0; i < Math.min(count, n); ++i) state.labels[order[i]] = FREE;
    state.dirtyRegion = true;
    view.colour(state.labels);
  },
  radius: () => panels.radius(),
  pivot: () => pivot.position.toArray(),
  camera: () => view.camera.position.toArray(),
  shown: () => ({ mesh: !!view.shown.mesh?.visible, edges: !!view.shown.edges?.visible, base: !!view.shown.baseSurface?.visible,
                  wire: !!view.shown.baseLines?.visible, manipulator: !!gizmo.object && gizmo.enabled && view.gizmoHelper.visible,
                  cursor: view.cursorShown(), cursorRadius: view.cursorRadius() }),
  labels: () => Array.from(state.labels ?? []),
  positionsHeld: () => state.positions,
  /// The page's own frame (kernel.js) under `transforms` (per handle the 12 numbers of [M | t]),
  /// x, y, z per movable vertex; null before the region's kernel is here. how: the engine, 'wasm'
  /// (when the page has it) or 'js'.
  kernelFrame: (transforms, how = 'wasm') => (kernelUsable() ? Array.from(kernel.evaluate(transforms, new Float32Array(kernel.out.length), how)) : null),
  /// The engine of the page's frames: 'wasm' (kernel.wasm) or 'js'.
  kernelEngine: () => (kernelUsable() && kernel.data.wasm ? 'wasm' : engine()),
  /// Median milliseconds of the page's frame under `transforms` per engine ('wasm', 'wasm1': one
  /// thread, 'js'), over `n` frames of each, interleaved; null before the region's kernel is here.
  kernelTimes(transforms, engines, n) {
    if (!kernelUsable()) return null;
    const out = new Float32Array(kernel.out.length), times = Object.fromEntries(engines.map((e) => [e, []]));
    for (let i = 0; i < n; ++i)
      for (const e of engines) {
        const t0 = performance.now();
        kernel.evaluate(transforms, out, e);
        times[e].push(performance.now() - t0);
      }
    return Object.fromEntries(engines.map((e) => [e, times[e].sort((a, b) => a - b)[n >> 1]]));
  },
  /// The threads of the page's frames: 2 once the worker of the region's kernel is ready.
  kernelThreads: () => (kernelUsable() ? kernel.data.wasm?.threads.threads ?? 1 : 0),
  movableHeld: () => Array.from(state.movable ?? []),
  indicesHeld: () => state.indices,
  tool: () => state.tool,
  selected: () => state.selected,
  /// The largest difference between the page's normals and three.js's full computeVertexNormals().
  normalError() {
    const a = view.normals(), b = view.referenceNormals();
    let worst = 0;
    for (let i = 0; i < a.length; ++i) worst = Math.max(worst, Math.abs(a[i] - b[i]));
    return worst;
  },
  /// normalError() of the page's own frame under the live transforms, its drawn normals computed
  /// as its last step (kernel.wasm on two threads); then the positions shown before come back.
  /// Null when the region's kernel has no such step.
  frameNormalError() {
    if (!kernelUsable() || !kernel.data.wasm?.drawn) return null;
    const shownBefore = new Float32Array(3 * state.movable.length);
    state.movable.forEach((v, i) => { for (let c = 0; c < 3; ++c) shownBefore[3 * i + c] = state.positions[3 * v + c]; });
    localFrame(performance.now());
    const error = this.normalError();
    view.applyMoved(state.movable, shownBefore);
    return error;
  },
  /// Where a drag's normals are computed: 'wasm' (kernel.wasm) or 'js'.
  normalsEngine: () => view.normalsEngine(),
  marks: () => JSON.parse(JSON.stringify(state.marks)),
  setDrawing: (on) => view.setDrawing(on),
  meshName: () => state.status?.mesh?.name,
  drawnVertices: () => view.drawnVertices(),
  /// The largest distance of a drawn normal from the nearest axis direction (a cube's sides).
  normalOffAxis() {
    const n = view.normals();
    let worst = 0;
    for (let i = 0; i < n.length; i += 3) worst = Math.max(worst, 1 - Math.max(Math.abs(n[i]), Math.abs(n[i + 1]), Math.abs(n[i + 2])));
    return worst;
  },
  ready: () => !!view.shown.mesh && work.tasks === 0 && !frames.busy && relaxer.idle && !picks.busy &&
               state.status?.state === 'ready',
  converged: () => state.converged,
  method: () => state.method,
  setTool, setMode,
};

task(async () => {
  try {
    const s = await settle();
    if (s.state === 'ready') {
      await sync(s, { fit: true });
      state.marks.paintable = performance.now();
      message('Paint a support (S), then a handle inside it (H); drag the arrows.', 'info');
    } else {
      message('Open a mesh (or drop one here) to start.', 'info');
    }
  } catch (e) {
    if (!(e instanceof ApiError)) message(`the page failed: ${e.message}`);
  }
});
