// The browser editor of `remora serve` (docs/server.md): paint a support and handles on the mesh,
// drag a handle with a manipulator, watch the support bend while the details ride along. All the
// geometry work happens on the server (the editing kernel); this page paints, sends, and draws.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TransformControls } from 'three/addons/controls/TransformControls.js';

const FIXED = -2, FREE = -1;
const HANDLE_COLORS = [[0.90, 0.30, 0.25], [0.25, 0.55, 0.95], [0.30, 0.80, 0.40], [0.85, 0.45, 0.90],
                       [0.95, 0.60, 0.20], [0.20, 0.80, 0.80]];
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
const areaRange = Number(params.get('area-range')) > 0 ? Number(params.get('area-range')) : 0.2;
let cameraParam = params.has('camera') ? params.get('camera').split(',').map(Number) : null;
if (cameraParam && !((cameraParam.length === 6 || cameraParam.length === 9) && cameraParam.every(Number.isFinite))) {
  console.error('camera= needs 6 or 9 numbers: px,py,pz,tx,ty,tz[,ux,uy,uz]; ignored');
  cameraParam = null;
}

// ---- view ---------------------------------------------------------------------------------------
const view = $('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x20242a);
const camera = new THREE.PerspectiveCamera(40, 1, 0.001, 1000);
scene.add(camera);
// Before the orbit controls, which orbit about the up they find.
if (cameraParam?.length === 9) camera.up.fromArray(cameraParam, 6).normalize();
// A headlight and a grazing key light: surface detail shows as shading.
scene.add(new THREE.HemisphereLight(0xffffff, 0x404048, 0.9));
const key = new THREE.DirectionalLight(0xffffff, 1.6);
key.position.set(-1, 1.5, 1);
camera.add(key);
const orbit = new OrbitControls(camera, renderer.domElement);
orbit.enableDamping = false;
const gizmo = new TransformControls(camera, renderer.domElement);
const pivot = new THREE.Object3D();
scene.add(pivot);
const gizmoHelper = gizmo.getHelper ? gizmo.getHelper() : gizmo;
scene.add(gizmoHelper);

// The surface sits a little behind its own wireframe (show-edges), which shares its geometry.
const material = new THREE.MeshStandardMaterial({ vertexColors: true, roughness: 0.75, metalness: 0.0,
                                                  side: THREE.DoubleSide,
                                                  polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 });
const edgeMaterial = new THREE.MeshBasicMaterial({ color: 0x30343c, wireframe: true });
let mesh = null, edges = null, baseLines = null;

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();
renderer.setAnimationLoop(() => renderer.render(scene, camera));

// ---- state --------------------------------------------------------------------------------------
const state = {
  tool: 'orbit', selected: 0, handleCount: 1, k: 2,
  labels: null, positions: null, indices: null, neighbours: null, offsets: null,
  movable: null, transforms: [], dirtyRegion: false, status: null,
  tasks: 0, // requests and refreshes under way (the end-to-end test waits for 0)
};

/// Runs an asynchronous piece of work, counted in state.tasks.
async function task(work) {
  state.tasks += 1;
  try { return await work(); } finally { state.tasks -= 1; }
}

// ---- messages and the API -----------------------------------------------------------------------
function message(text, kind = 'error') {
  const box = $('message');
  box.textContent = text;
  box.className = kind;
  box.hidden = !text;
  if (kind === 'info' && text) setTimeout(() => { if (box.textContent === text) box.hidden = true; }, 2500);
}

async function api(path, options = {}) {
  const response = await fetch('api/' + path, options);
  if (!response.ok) {
    let text = `${response.status} ${response.statusText}`;
    try { text = (await response.json()).error || text; } catch (e) { /* not JSON */ }
    message(text);
    throw new Error(text);
  }
  return response;
}
const json = async (path, options) => (await api(path, options)).json();
const binary = async (path, Type) => new Type(await (await api(path)).arrayBuffer());
const post = (path, body) => api(path, { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                         body: JSON.stringify(body ?? {}) });

async function waitUntilReady() {
  for (;;) {
    const s = await json('status');
    state.status = s;
    if (s.state !== 'busy') {
      $('progress').hidden = true;
      if (s.error) message(s.error);
      showStats();
      return s;
    }
    const p = s.progress || {};
    $('progress').hidden = false;
    $('progress-text').textContent = `${p.job}: ${p.phase}`;
    $('progress-bar').style.width = p.steps ? `${100 * p.step / p.steps}%` : '15%';
    await new Promise((r) => setTimeout(r, 150));
  }
}

// ---- the mesh -----------------------------------------------------------------------------------
async function fetchMesh(fit) {
  const s = await waitUntilReady();
  if (s.state !== 'ready') return;
  state.indices = await binary('mesh/indices', Uint32Array);
  state.positions = await binary('mesh/positions', Float32Array);
  const n = state.positions.length / 3;
  buildAdjacency(n);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(state.positions, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
  geometry.setIndex(new THREE.BufferAttribute(state.indices, 1));
  geometry.computeVertexNormals();
  geometry.computeBoundingSphere();
  if (mesh) { scene.remove(mesh); scene.remove(edges); mesh.geometry.dispose(); }
  mesh = new THREE.Mesh(geometry, material);
  edges = new THREE.Mesh(geometry, edgeMaterial);
  showMesh();
  scene.add(mesh);
  scene.add(edges);
  await fetchRegion();
  if (fit) fitCamera();
  if (baseShown()) await showBase(true);
}

function fitCamera() {
  const sphere = mesh.geometry.boundingSphere;
  orbit.target.copy(sphere.center);
  camera.near = sphere.radius / 100;
  camera.far = sphere.radius * 100;
  camera.position.copy(sphere.center).add(new THREE.Vector3(0, 0, sphere.radius * 2.8));
  if (cameraParam) {
    camera.position.fromArray(cameraParam, 0);
    orbit.target.fromArray(cameraParam, 3);
  }
  camera.updateProjectionMatrix();
  orbit.update();
  $('radius').max = (sphere.radius).toPrecision(3);
  $('radius').min = (sphere.radius / 200).toPrecision(3);
  $('radius').step = (sphere.radius / 1000).toPrecision(3);
  $('radius').value = (sphere.radius / 8).toPrecision(3);
  $('radius-value').textContent = $('radius').value;
}

function buildAdjacency(n) {
  const count = new Uint32Array(n + 1);
  const f = state.indices;
  for (let i = 0; i < f.length; i += 3)
    for (let k = 0; k < 3; ++k) { count[f[i + k] + 1] += 2; }
  for (let v = 0; v < n; ++v) count[v + 1] += count[v];
  const fill = count.slice(0, n);
  const neighbours = new Uint32Array(count[n]);
  for (let i = 0; i < f.length; i += 3)
    for (let k = 0; k < 3; ++k) {
      const a = f[i + k];
      neighbours[fill[a]++] = f[i + (k + 1) % 3];
      neighbours[fill[a]++] = f[i + (k + 2) % 3];
    }
  state.offsets = count;
  state.neighbours = neighbours;
}

async function fetchRegion() {
  const n = state.positions.length / 3;
  state.labels = new Int32Array(n).fill(FIXED);
  const region = await json('region');
  state.movable = null;
  if (region) {
    for (const v of region.support) state.labels[v] = FREE;
    region.handles.forEach((h, j) => { for (const v of h) state.labels[v] = j; });
    state.handleCount = Math.max(1, region.handles.length);
    state.k = region.k;
    $('k').value = String(region.k);
    state.movable = await binary('movable', Uint32Array);
    const s = state.status;
    state.transforms = (s.transforms || []).map(rowsToMatrix);
  } else {
    state.handleCount = 1;
    state.transforms = [];
  }
  state.selected = Math.min(state.selected, state.handleCount - 1);
  updateHandleButtons();
  recolour();
  placeGizmo();
}

function recolour() {
  if (!mesh) return;
  const colours = mesh.geometry.getAttribute('color');
  const c = colours.array;
  for (let v = 0; v < state.labels.length; ++v) {
    const l = state.labels[v];
    const rgb = l === FIXED ? [0.78, 0.78, 0.78] : l === FREE ? [0.96, 0.86, 0.45] : HANDLE_COLORS[l % HANDLE_COLORS.length];
    c[3 * v] = rgb[0]; c[3 * v + 1] = rgb[1]; c[3 * v + 2] = rgb[2];
  }
  colours.needsUpdate = true;
}

// ---- painting -----------------------------------------------------------------------------------
const raycaster = new THREE.Raycaster();
let painting = false;

function hitAt(event) {
  if (!mesh) return null;
  const rect = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
                                -((event.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  const hits = raycaster.intersectObject(mesh, false);
  return hits.length ? hits[0] : null;
}

function brushVertices(hit) {
  const radius = parseFloat($('radius').value);
  const p = state.positions, point = hit.point;
  const out = [];
  if (!$('geodesic').checked) {
    const r2 = radius * radius;
    for (let v = 0; v < p.length / 3; ++v) {
      const dx = p[3 * v] - point.x, dy = p[3 * v + 1] - point.y, dz = p[3 * v + 2] - point.z;
      if (dx * dx + dy * dy + dz * dz <= r2) out.push(v);
    }
    return out;
  }
  // Geodesic: Dijkstra over the edges from the hit face's corners.
  const dist = new Map();
  const heap = [];
  const push = (d, v) => { heap.push([d, v]); let i = heap.length - 1;
    while (i > 0) { const parent = (i - 1) >> 1; if (heap[parent][0] <= heap[i][0]) break;
      [heap[parent], heap[i]] = [heap[i], heap[parent]]; i = parent; } };
  const pop = () => { const top = heap[0]; const last = heap.pop();
    if (heap.length) { heap[0] = last; let i = 0;
      for (;;) { const l = 2 * i + 1, r = l + 1; let m = i;
        if (l < heap.length && heap[l][0] < heap[m][0]) m = l;
        if (r < heap.length && heap[r][0] < heap[m][0]) m = r;
        if (m === i) break; [heap[m], heap[i]] = [heap[i], heap[m]]; i = m; } }
    return top; };
  for (const v of [hit.face.a, hit.face.b, hit.face.c]) {
    const d = Math.hypot(p[3 * v] - point.x, p[3 * v + 1] - point.y, p[3 * v + 2] - point.z);
    if (!dist.has(v) || d < dist.get(v)) { dist.set(v, d); push(d, v); }
  }
  const done = new Set();
  while (heap.length) {
    const [d, v] = pop();
    if (done.has(v) || d > radius) continue;
    done.add(v);
    out.push(v);
    for (let k = state.offsets[v]; k < state.offsets[v + 1]; ++k) {
      const w = state.neighbours[k];
      const nd = d + Math.hypot(p[3 * v] - p[3 * w], p[3 * v + 1] - p[3 * w + 1], p[3 * v + 2] - p[3 * w + 2]);
      if (nd <= radius && (!dist.has(w) || nd < dist.get(w))) { dist.set(w, nd); push(nd, w); }
    }
  }
  return out;
}

function paint(hit) {
  const label = state.tool === 'support' ? FREE : state.tool === 'handle' ? state.selected : FIXED;
  for (const v of brushVertices(hit)) {
    const old = state.labels[v];
    if (state.tool === 'support' && old >= 0) continue; // painting the support keeps handles
    if (old !== label) { state.labels[v] = label; state.dirtyRegion = true; }
  }
  recolour();
}

renderer.domElement.addEventListener('pointerdown', (event) => {
  if (state.tool === 'orbit' || event.button !== 0 || gizmo.dragging) return;
  const hit = hitAt(event);
  if (!hit) return; // a miss orbits
  orbit.enabled = false;
  painting = true;
  paint(hit);
});
renderer.domElement.addEventListener('pointermove', (event) => {
  if (!painting) return;
  const hit = hitAt(event);
  if (hit) paint(hit);
});
window.addEventListener('pointerup', () => {
  if (!painting) return;
  painting = false;
  orbit.enabled = true;
  if (state.dirtyRegion) task(sendRegion);
});

function regionLists() {
  const support = [], handles = Array.from({ length: state.handleCount }, () => []);
  for (let v = 0; v < state.labels.length; ++v) {
    const l = state.labels[v];
    if (l === FIXED) continue;
    support.push(v);
    if (l >= 0) handles[l].push(v);
  }
  return { support, handles: handles.filter((h) => h.length > 0) };
}

async function sendRegion() {
  const { support, handles } = regionLists();
  state.dirtyRegion = false;
  if (!support.length || !handles.length) {
    message(support.length ? 'Now paint a handle inside the support (tool "Handle").'
                           : 'Paint a support, then a handle inside it.', 'info');
    return;
  }
  try {
    await post('region', { support, handles, k: state.k });
    await fetchMesh(false);
    message('Drag the arrows to move the handle.', 'info');
  } catch (e) { /* shown */ }
}

// ---- handles and the manipulator ----------------------------------------------------------------
function updateHandleButtons() {
  const box = $('handles');
  box.innerHTML = '';
  for (let j = 0; j < state.handleCount; ++j) {
    const b = document.createElement('button');
    b.textContent = `H${j + 1}`;
    const [r, g, bl] = HANDLE_COLORS[j % HANDLE_COLORS.length];
    b.style.borderColor = `rgb(${255 * r},${255 * g},${255 * bl})`;
    b.className = j === state.selected ? 'active' : '';
    b.onclick = () => { state.selected = j; updateHandleButtons(); placeGizmo(); };
    box.appendChild(b);
  }
}

function handleCentre(j) {
  const p = state.positions, c = new THREE.Vector3();
  let count = 0;
  for (let v = 0; v < state.labels.length; ++v)
    if (state.labels[v] === j) { c.x += p[3 * v]; c.y += p[3 * v + 1]; c.z += p[3 * v + 2]; ++count; }
  return count ? c.divideScalar(count) : null;
}

function placeGizmo() {
  const centre = state.movable && state.labels ? handleCentre(state.selected) : null;
  if (!centre || !showUi) { gizmo.detach(); return; }
  pivot.position.copy(centre);
  pivot.quaternion.identity();
  pivot.scale.set(1, 1, 1);
  pivot.updateMatrix();
  gizmo.attach(pivot);
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

let dragStart = null, dragBase = null, inFlight = false, pending = null;
gizmo.addEventListener('dragging-changed', async (event) => {
  orbit.enabled = !event.value;
  if (event.value) {
    pivot.updateMatrix();
    dragStart = pivot.matrix.clone().invert();
    dragBase = (state.transforms[state.selected] || new THREE.Matrix4()).clone();
  } else {
    dragStart = null;
    await task(async () => {
      await flush();
      try { await post('commit'); state.status = await json('status'); showStats(); } catch (e) { /* shown */ }
      if (baseShown()) await showBase(false);
    });
  }
});
gizmo.addEventListener('objectChange', () => {
  if (!dragStart) return;
  pivot.updateMatrix();
  const delta = pivot.matrix.clone().multiply(dragStart);
  const t = delta.multiply(dragBase);
  state.transforms[state.selected] = t;
  pending = { handle: state.selected, matrix: matrixToRows(t) };
  if (!inFlight) flush();
});

async function flush() {
  while (pending && !inFlight) {
    const request = pending;
    pending = null;
    inFlight = true;
    try {
      const response = await api('transform', { method: 'POST', headers: { 'Content-Type': 'application/json' },
                                                  body: JSON.stringify(request) });
      const moved = new Float32Array(await response.arrayBuffer());
      state.frameMs = parseFloat(response.headers.get('X-Frame-Ms'));
      applyMoved(moved);
    } catch (e) { /* shown */ }
    inFlight = false;
  }
}

function applyMoved(moved) {
  const p = state.positions, ids = state.movable;
  for (let i = 0; i < ids.length; ++i) {
    const v = ids[i];
    p[3 * v] = moved[3 * i]; p[3 * v + 1] = moved[3 * i + 1]; p[3 * v + 2] = moved[3 * i + 2];
  }
  const g = mesh.geometry;
  g.getAttribute('position').needsUpdate = true;
  g.computeVertexNormals();
  g.computeBoundingSphere();
}

// ---- the base surface: shaded, and as a wireframe coloured by vertex area -----------------------
let baseSurface = null;
const baseShown = () => $('show-base').checked || $('show-wire').checked;
async function showBase(refetchIndices) {
  if (!baseShown()) {
    if (baseLines) baseLines.visible = false;
    if (baseSurface) baseSurface.visible = false;
    return;
  }
  const positions = await binary('base/positions', Float32Array);
  if (!baseLines || refetchIndices) {
    const indices = await binary('base/indices', Uint32Array);
    const areas = await binary('base/areas', Float32Array);
    const colours = new Float32Array(3 * areas.length);
    for (let v = 0; v < areas.length; ++v) {
      // Blue below the mean area, white at it, red above: ±20 % saturates (area-range= in the URL).
      const t = Math.max(-1, Math.min(1, (areas[v] - 1) / areaRange));
      colours[3 * v] = t > 0 ? 1 : 1 + t; colours[3 * v + 1] = 1 - Math.abs(t); colours[3 * v + 2] = t < 0 ? 1 : 1 - t;
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
    geometry.setIndex(new THREE.BufferAttribute(indices, 1));
    geometry.computeVertexNormals();
    for (const old of [baseLines, baseSurface]) if (old) scene.remove(old);
    if (baseLines) baseLines.geometry.dispose();
    baseLines = new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ vertexColors: true, wireframe: true }));
    baseSurface = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({
      color: 0x8fb0d8, roughness: 0.6, side: THREE.DoubleSide,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 }));
    scene.add(baseSurface);
    scene.add(baseLines);
  } else {
    const attribute = baseLines.geometry.getAttribute('position');
    attribute.array.set(positions);
    attribute.needsUpdate = true;
    baseLines.geometry.computeVertexNormals();
  }
  baseLines.visible = $('show-wire').checked;
  baseSurface.visible = $('show-base').checked;
}

// ---- stats --------------------------------------------------------------------------------------
function showStats() {
  const s = state.status;
  if (!s) return;
  const lines = [];
  if (s.mesh) lines.push(`${s.mesh.name}`, `${s.mesh.vertices.toLocaleString()} vertices, ${s.mesh.faces.toLocaleString()} faces`);
  if (s.base) {
    lines.push(`base: ${s.base.vertices.toLocaleString()} vertices (remeshed)`);
    lines.push(`preprocessing ${(s.base.preprocess_ms / 1000).toFixed(2)} s`);
    lines.push(`area spread (rel MAD) ${s.base.area_rel_mad.toFixed(3)}, smallest angle ${s.base.min_angle_deg.toFixed(1)}°`);
  }
  if (s.region) {
    lines.push(`support ${s.region.support.toLocaleString()} vertices, ${s.region.handles} handle(s), k = ${s.region.k}`);
    lines.push(`set_region ${s.region.set_region_ms.toFixed(0)} ms, frame ${(state.frameMs ?? s.frame_ms).toFixed(1)} ms`);
  }
  $('stats').textContent = lines.join('\n');
  $('undo').disabled = !s.undo;
  $('redo').disabled = !s.redo;
}

// ---- controls -----------------------------------------------------------------------------------
function setTool(tool) {
  state.tool = tool;
  for (const b of document.querySelectorAll('#tools button')) b.classList.toggle('active', b.dataset.tool === tool);
}
for (const b of document.querySelectorAll('#tools button')) b.onclick = () => setTool(b.dataset.tool);
function setMode(mode) {
  gizmo.setMode(mode);
  for (const b of document.querySelectorAll('#modes button')) b.classList.toggle('active', b.dataset.mode === mode);
}
for (const b of document.querySelectorAll('#modes button')) b.onclick = () => setMode(b.dataset.mode);
$('radius').oninput = () => { $('radius-value').textContent = $('radius').value; };
$('new-handle').onclick = () => {
  state.handleCount += 1; state.selected = state.handleCount - 1; setTool('handle'); updateHandleButtons();
};
$('clear').onclick = () => {
  if (!state.labels) return;
  state.labels.fill(FIXED); state.handleCount = 1; state.selected = 0; recolour(); updateHandleButtons(); gizmo.detach();
};
$('k').onchange = () => { state.k = parseInt($('k').value, 10); if (state.movable) task(sendRegion); };
async function history(which) {
  try {
    await post(which);
    await fetchMesh(false);
  } catch (e) { /* shown */ }
}
$('undo').onclick = () => task(() => history('undo'));
$('redo').onclick = () => task(() => history('redo'));
$('show-base').onchange = () => task(() => showBase(false));
$('show-wire').onchange = () => task(() => showBase(false));
function showMesh() {
  if (!mesh) return;
  mesh.visible = $('show-mesh').checked;
  edges.visible = $('show-edges').checked;
}
$('show-mesh').onchange = showMesh;
$('show-edges').onchange = showMesh;
window.addEventListener('keydown', (event) => {
  if (event.target.tagName === 'INPUT') return;
  const key = event.key.toLowerCase();
  if ((event.ctrlKey || event.metaKey) && key === 'z') { event.preventDefault(); task(() => history(event.shiftKey ? 'redo' : 'undo')); return; }
  if (event.ctrlKey || event.metaKey) return;
  if (key === 'w') setMode('translate');
  if (key === 'e') setMode('rotate');
  if (key === 'r') setMode('scale');
  if (key === 'o') setTool('orbit');
  if (key === 's') setTool('support');
  if (key === 'h') setTool('handle');
  if (key === 'x') setTool('erase');
});

// ---- loading ------------------------------------------------------------------------------------
async function upload(file) {
  message('');
  try {
    await api(`load?name=${encodeURIComponent(file.name)}`, { method: 'POST', body: await file.arrayBuffer() });
    const s = await waitUntilReady();
    if (s.error) return;
    state.selected = 0;
    await fetchMesh(true);
    message(`Loaded ${file.name}. Paint a support, then a handle.`, 'info');
  } catch (e) { /* shown */ }
}
$('file').onchange = (event) => { if (event.target.files[0]) task(() => upload(event.target.files[0])); };
view.addEventListener('dragover', (event) => event.preventDefault());
view.addEventListener('drop', (event) => {
  event.preventDefault();
  if (event.dataTransfer.files[0]) task(() => upload(event.dataTransfer.files[0]));
});

// ---- for the end-to-end test: where a vertex is on screen, and the page's state ------------------
window.remora = {
  project(v) {
    const rect = renderer.domElement.getBoundingClientRect();
    const p = new THREE.Vector3(state.positions[3 * v], state.positions[3 * v + 1], state.positions[3 * v + 2]).project(camera);
    return { x: rect.left + (p.x + 1) / 2 * rect.width, y: rect.top + (1 - p.y) / 2 * rect.height };
  },
  projectPoint(x, y, z) {
    const rect = renderer.domElement.getBoundingClientRect();
    const p = new THREE.Vector3(x, y, z).project(camera);
    return { x: rect.left + (p.x + 1) / 2 * rect.width, y: rect.top + (1 - p.y) / 2 * rect.height };
  },
  nearest(x, y, z) {
    let best = -1, bestD = Infinity;
    const p = state.positions;
    for (let v = 0; v < p.length / 3; ++v) {
      const d = (p[3 * v] - x) ** 2 + (p[3 * v + 1] - y) ** 2 + (p[3 * v + 2] - z) ** 2;
      if (d < bestD) { bestD = d; best = v; }
    }
    return best;
  },
  setRadius(r) { $('radius').value = r; $('radius-value').textContent = String(r); },
  pivot: () => pivot.position.toArray(),
  camera: () => camera.position.toArray(),
  shown: () => ({ mesh: !!mesh?.visible, edges: !!edges?.visible, base: !!baseSurface?.visible,
                  wire: !!baseLines?.visible, manipulator: !!gizmo.object }),
  labels: () => Array.from(state.labels ?? []),
  ready: () => !!mesh && state.tasks === 0 && !inFlight && !pending && state.status?.state === 'ready',
  setTool, setMode,
};

task(async () => {
  try {
    const s = await waitUntilReady();
    if (s.state === 'ready') {
      await fetchMesh(true);
      message('Paint a support (S), then a handle inside it (H); drag the arrows.', 'info');
    } else {
      message('Open a mesh (or drop one here) to start.', 'info');
    }
  } catch (e) { /* shown */ }
});
