// What the page draws: the renderer, camera and lights, the orbit controls and the manipulator,
// the edited mesh (its colours, its normals kept current during a drag), the remeshed base and the
// brush cursor. Holds the three.js objects; the state of the edit lives in app.js.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TransformControls } from 'three/addons/controls/TransformControls.js';
import { drawnNormalsLayout, normalPlan, updateNormals, vertexFaces, wasmNormals } from './normals.js';
import { splitCreases, withCopies } from './creases.js';
import { engine } from './engine.js';

export const FIXED = -2, FREE = -1;
export const HANDLE_COLORS = [[0.90, 0.30, 0.25], [0.25, 0.55, 0.95], [0.30, 0.80, 0.40], [0.85, 0.45, 0.90],
                              [0.95, 0.60, 0.20], [0.20, 0.80, 0.80]];
const FIXED_RGB = [0.78, 0.78, 0.78], FREE_RGB = [0.96, 0.86, 0.45];
export const labelColour = (l) => (l === FIXED ? FIXED_RGB : l === FREE ? FREE_RGB : HANDLE_COLORS[l % HANDLE_COLORS.length]);

export const container = document.getElementById('view');
export const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
container.appendChild(renderer.domElement);
export const scene = new THREE.Scene();
scene.background = new THREE.Color(0x20242a);
export const camera = new THREE.PerspectiveCamera(40, 1, 0.001, 1000);
scene.add(camera);
// A headlight and a grazing key light: surface detail shows as shading.
scene.add(new THREE.HemisphereLight(0xffffff, 0x404048, 0.9));
const key = new THREE.DirectionalLight(0xffffff, 1.6);
key.position.set(-1, 1.5, 1);
camera.add(key);

/// The camera's up must be set before the orbit controls exist (they orbit about the up they find).
export let orbit = null;
export let gizmo = null, gizmoHelper = null;
export const pivot = new THREE.Object3D();
export function createControls(up) {
  if (up) camera.up.fromArray(up).normalize();
  orbit = new OrbitControls(camera, renderer.domElement);
  orbit.enableDamping = false;
  orbit.addEventListener('change', redraw);
  gizmo = new TransformControls(camera, renderer.domElement);
  gizmo.addEventListener('change', redraw);
  scene.add(pivot);
  gizmoHelper = gizmo.getHelper ? gizmo.getHelper() : gizmo;
  scene.add(gizmoHelper);
  showGizmo(false);
}
/// Shows the manipulator on the pivot and lets it take the mouse, or hides and disables it (it
/// stays attached, so that showing it again keeps its place and orientation).
export function showGizmo(on) {
  if (on && gizmo.object !== pivot) gizmo.attach(pivot);
  gizmo.enabled = on;
  gizmoHelper.visible = on;
  redraw();
}
export const gizmoPlaced = () => gizmo.object === pivot;
/// Forgets the manipulator's place (a new region or handle places it again).
export function detachGizmo() { gizmo.detach(); showGizmo(false); }

// The surface sits a little behind its own wireframe (show-edges), which shares its geometry.
const material = new THREE.MeshStandardMaterial({ vertexColors: true, roughness: 0.75, metalness: 0.0,
                                                  side: THREE.DoubleSide,
                                                  polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 });
// Region colours stop half-way between a painted and an unpainted corner (where a corner's
// weight passes 1/2), not at the far corner: on a CAD part's large faces a painted corner would
// otherwise tint the whole face. `painted` is 1 at a painted vertex, 0 elsewhere; the unpainted
// corners all have FIXED_RGB, so vColor minus their share is the painted corners' mix.
material.onBeforeCompile = (shader) => {
  shader.uniforms.fixedColour = { value: new THREE.Vector3(...FIXED_RGB) };
  shader.vertexShader = 'attribute float painted;\nvarying float vPainted;\n' +
    shader.vertexShader.replace('#include <color_vertex>', '#include <color_vertex>\n  vPainted = painted;');
  shader.fragmentShader = 'uniform vec3 fixedColour;\nvarying float vPainted;\n' +
    shader.fragmentShader.replace('#include <color_fragment>', `
      diffuseColor.rgb *= vPainted < 0.5 ? fixedColour : (vColor - (1.0 - vPainted) * fixedColour) / vPainted;`);
};
const edgeMaterial = new THREE.MeshBasicMaterial({ color: 0x30343c, wireframe: true });
/// The drawn objects (null until there is something to draw).
export const shown = { mesh: null, edges: null, baseLines: null, baseSurface: null };
let plan = null; // normalPlan() of the current movable vertices (display ids)
let planLayout = null; // its drawnNormalsLayout(), when the page has kernel.wasm
let planInWasm = null; // its normals in kernel.wasm (wasmNormals()), when the page has it
let planned = { movable: null, done: true }; // the movable vertices of setMovable(), planned or not
let around = null; // vertexFaces() of the drawn mesh
// The mesh as drawn: splitCreases() of it, or null when the display is the mesh itself; the mesh's
// positions (held, not copied); the display copies of the movable vertices.
let display = null, meshPositions = null, movedCopies = [];

// Frames are drawn on demand (redraw(), or an attribute touched): an idle page costs nothing,
// and software WebGL does not hold back input events with frames nobody needs.
let dirty = true, drawing = true;
export function redraw() { dirty = true; }
/// Off: nothing is drawn (changes wait until it is on again). The browser benchmark measures the
/// page's own work this way, without software WebGL's drawing.
export function setDrawing(on) { drawing = on; dirty = true; }

function resize() {
  const w = container.clientWidth, h = container.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  redraw();
}
new ResizeObserver(resize).observe(container); // the window, and the panel shown or hidden (ui=0)
resize();
// Attribute changes since the last frame: attribute -> { lo, hi } (a vertex range) or null (all),
// uploaded once per frame, so that several changes between two frames are all kept.
const touched = new Map();
function touch(attribute, lo = null, hi = null) {
  const old = touched.get(attribute);
  if (lo === null || old === null) { touched.set(attribute, null); return; }
  touched.set(attribute, old ? { lo: Math.min(old.lo, lo), hi: Math.max(old.hi, hi) } : { lo, hi });
}
renderer.setAnimationLoop(() => {
  if (!drawing || (!dirty && touched.size === 0)) return;
  dirty = false;
  for (const [attribute, range] of touched) {
    attribute.clearUpdateRanges();
    if (range) attribute.addUpdateRange(attribute.itemSize * range.lo, attribute.itemSize * (range.hi - range.lo + 1));
    attribute.needsUpdate = true;
  }
  touched.clear();
  renderer.render(scene, camera);
});

/// Draws a new mesh: positions (Float32 x, y, z per vertex) and indices (Uint32 triples) are held,
/// not copied. The bounding sphere is computed here once; the mesh is never frustum-culled, so a
/// drag needs no new bounds.
export function setMesh(positions, indices) {
  display = splitCreases(positions, indices);
  meshPositions = positions;
  const drawn = display ? gather(positions, new Float32Array(3 * display.map.length)) : positions;
  const n = drawn.length / 3;
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(drawn, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
  geometry.setAttribute('painted', new THREE.BufferAttribute(new Float32Array(n), 1));
  geometry.setIndex(new THREE.BufferAttribute(display ? display.indices : indices, 1));
  geometry.computeVertexNormals();
  geometry.computeBoundingSphere();
  if (shown.mesh) { scene.remove(shown.mesh); scene.remove(shown.edges); shown.mesh.geometry.dispose(); }
  shown.mesh = new THREE.Mesh(geometry, material);
  shown.edges = new THREE.Mesh(geometry, edgeMaterial);
  shown.mesh.frustumCulled = false;
  shown.edges.frustumCulled = false;
  scene.add(shown.mesh);
  scene.add(shown.edges);
  plan = null;
  planLayout = null;
  planInWasm = null;
  planned = { movable: null, done: true };
  around = vertexFaces(geometry.getIndex().array, n);
  redraw();
}

/// The display's positions from the mesh's.
function gather(positions, out) {
  const map = display.map;
  for (let d = 0; d < map.length; ++d) {
    const v = map[d];
    out[3 * d] = positions[3 * v]; out[3 * d + 1] = positions[3 * v + 1]; out[3 * d + 2] = positions[3 * v + 2];
  }
  return out;
}

/// Every position changed (undo, redo, a new k): positions.set() was called on the held array.
export function positionsChanged() {
  const g = shown.mesh.geometry;
  if (display) gather(meshPositions, g.getAttribute('position').array);
  touch(g.getAttribute('position'));
  g.computeVertexNormals();
  touch(g.getAttribute('normal'));
}

/// Prepares applyMoved() for a region's movable vertices (once per region). The work (tens of
/// milliseconds for a large support) is done after the next frame is drawn, when nothing waits
/// for it (the manipulator shows first, and a server solving a region keeps both cores), or at
/// the first applyMoved() before that.
export function setMovable(movable) {
  const mine = { movable, done: false };
  planned = mine;
  requestAnimationFrame(() => setTimeout(() => { if (planned === mine) makePlan(); }, 0));
}

function makePlan() {
  if (planned.done) return;
  // Nothing of the previous region's plan stays should this one fail.
  plan = null;
  planLayout = null;
  planInWasm = null;
  movedCopies = [];
  const g = shown.mesh.geometry, movable = planned.movable;
  const ids = movable && display ? withCopies(movable, display.copies) : movable;
  const made = ids ? normalPlan(g.getIndex().array, around, ids) : null;
  movedCopies = ids && display ? ids.slice(movable.length) : [];
  if (made && engine() === 'wasm') {
    planLayout = drawnNormalsLayout(g.getIndex().array, g.getAttribute('position').array, made, movable, display?.map ?? null, meshPositions.length / 3);
    planInWasm = wasmNormals(planLayout);
  }
  plan = made;
  planned.done = true;
}

export const normalsEngine = () => { makePlan(); return planInWasm ? 'wasm' : 'js'; };

/// The drawnNormalsLayout() of setMovable()'s `movable`, for a region's kernel that computes the
/// drawn normals as a step of its frames (web/kernel.js); null without kernel.wasm or for other
/// vertices.
export function drawnNormals(movable) {
  if (planned.movable !== movable) return null;
  makePlan();
  return planLayout;
}

/// A drag's frame: moved holds x, y, z for each of movable (setMovable's ids, in that order).
/// Recomputes the normals that can change and uploads only the range that holds them.
/// `fromFrame`: the drawn normals of the kernel that computed `moved` ({ movable,
/// update(positions, normals) }, web/kernel.js), or null (the normals are computed here).
export function applyMoved(movable, moved, fromFrame = null) {
  makePlan();
  const g = shown.mesh.geometry;
  const position = g.getAttribute('position'), normal = g.getAttribute('normal');
  const p = position.array;
  for (const q of display ? [meshPositions, p] : [p])
    for (let i = 0; i < movable.length; ++i) {
      const v = movable[i];
      q[3 * v] = moved[3 * i]; q[3 * v + 1] = moved[3 * i + 1]; q[3 * v + 2] = moved[3 * i + 2];
    }
  for (const d of movedCopies) {
    const v = display.map[d];
    p[3 * d] = meshPositions[3 * v]; p[3 * d + 1] = meshPositions[3 * v + 1]; p[3 * d + 2] = meshPositions[3 * v + 2];
  }
  // A frame of the region before (an answer that crossed a new region's plan): the plain sums.
  const frameOfPlan = moved.length === 3 * movable.length;
  if (fromFrame && fromFrame.movable === movable && frameOfPlan) fromFrame.update(p, normal.array);
  else if (planInWasm && planInWasm.movable === movable && frameOfPlan) planInWasm.update(p, moved, normal.array);
  else updateNormals(p, g.getIndex().array, normal.array, plan);
  if (plan.last < plan.first) return;
  touch(position, plan.first, plan.last);
  touch(normal, plan.first, plan.last);
}

/// The full recomputation (three.js's), for the test that compares it with applyMoved's normals.
export function referenceNormals() {
  const g = shown.mesh.geometry.clone();
  g.deleteAttribute('normal');
  g.computeVertexNormals();
  return g.getAttribute('normal').array;
}
export const normals = () => shown.mesh.geometry.getAttribute('normal').array;

/// Colours every vertex by its label (FIXED, FREE, or a handle index; labels per mesh vertex), or
/// only the mesh vertices `ids`.
export function colour(labels, ids = null) {
  const colours = shown.mesh.geometry.getAttribute('color'), painted = shown.mesh.geometry.getAttribute('painted');
  const c = colours.array, p = painted.array, map = display?.map;
  const set = (d) => {
    const label = labels[map ? map[d] : d], rgb = labelColour(label);
    c[3 * d] = rgb[0]; c[3 * d + 1] = rgb[1]; c[3 * d + 2] = rgb[2];
    p[d] = label === FIXED ? 0 : 1;
  };
  if (ids) {
    let lo = Infinity, hi = -1;
    for (const d of display ? withCopies(ids, display.copies) : ids) { set(d); lo = Math.min(lo, d); hi = Math.max(hi, d); }
    if (hi >= 0) { touch(colours, lo, hi); touch(painted, lo, hi); }
  } else {
    for (let d = 0; d < colours.count; ++d) set(d);
    touch(colours);
    touch(painted);
  }
}
/// The number of vertices drawn (the mesh's, and the copies at creases).
export const drawnVertices = () => shown.mesh?.geometry.getAttribute('position').count ?? 0;

/// Places the camera to see the whole mesh, or at cameraParam (px,py,pz,tx,ty,tz[,up]); returns
/// the bounding sphere's radius.
export function fitCamera(cameraParam) {
  const sphere = shown.mesh.geometry.boundingSphere;
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
  redraw();
  return sphere.radius;
}

export function showMesh(mesh, edges) {
  if (!shown.mesh) return;
  shown.mesh.visible = mesh;
  shown.edges.visible = edges;
  redraw();
}

/// The world-space ray under a pointer event: { origin: [x, y, z], direction: [x, y, z] }.
const raycaster = new THREE.Raycaster();
export function rayAt(event) {
  const rect = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
                                -((event.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  return { origin: raycaster.ray.origin.toArray(), direction: raycaster.ray.direction.toArray() };
}

/// Where a world point is on screen, in client pixels.
export function project(x, y, z) {
  const rect = renderer.domElement.getBoundingClientRect();
  const p = new THREE.Vector3(x, y, z).project(camera);
  return { x: rect.left + (p.x + 1) / 2 * rect.width, y: rect.top + (1 - p.y) / 2 * rect.height };
}

// ---- the base surface: shaded, and as a wireframe coloured by vertex area -----------------------
/// Draws the base: new faces and areas (areas / mean area, coloured blue below 1, white at 1, red
/// above, saturating at ±areaRange) or, with indices null, new positions for the same faces.
export function setBase(positions, indices, areas, areaRange) {
  if (!indices) {
    const attribute = shown.baseLines.geometry.getAttribute('position');
    attribute.array.set(positions);
    touch(attribute);
    shown.baseLines.geometry.computeVertexNormals();
    touch(shown.baseLines.geometry.getAttribute('normal'));
    return;
  }
  const colours = new Float32Array(3 * areas.length);
  for (let v = 0; v < areas.length; ++v) {
    const t = Math.max(-1, Math.min(1, (areas[v] - 1) / areaRange));
    colours[3 * v] = t > 0 ? 1 : 1 + t; colours[3 * v + 1] = 1 - Math.abs(t); colours[3 * v + 2] = t < 0 ? 1 : 1 - t;
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
  geometry.setIndex(new THREE.BufferAttribute(indices, 1));
  geometry.computeVertexNormals();
  for (const old of [shown.baseLines, shown.baseSurface]) if (old) scene.remove(old);
  if (shown.baseLines) shown.baseLines.geometry.dispose();
  shown.baseLines = new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ vertexColors: true, wireframe: true }));
  shown.baseSurface = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({
    color: 0x8fb0d8, roughness: 0.6, side: THREE.DoubleSide,
    polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 }));
  scene.add(shown.baseSurface);
  scene.add(shown.baseLines);
  redraw();
}
export const hasBase = () => !!shown.baseLines;
export function showBase(surface, wire) {
  if (shown.baseLines) shown.baseLines.visible = wire;
  if (shown.baseSurface) shown.baseSurface.visible = surface;
  redraw();
}

// ---- the brush cursor: a ring of the brush's radius on the surface under the pointer ------------
const ringPoints = Array.from({ length: 64 }, (_, i) =>
  new THREE.Vector3(Math.cos(i / 32 * Math.PI), Math.sin(i / 32 * Math.PI), 0));
const cursor = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(ringPoints),
                                  new THREE.LineBasicMaterial({ color: 0xffffff, depthTest: false, transparent: true, opacity: 0.85 }));
cursor.renderOrder = 10;
cursor.visible = false;
cursor.frustumCulled = false;
scene.add(cursor);
const zAxis = new THREE.Vector3(0, 0, 1);
/// Shows the ring at point (x, y, z) in the plane normal to `normal`, of the given radius.
export function showCursor(point, normal, radius) {
  cursor.position.fromArray(point);
  const n = new THREE.Vector3().fromArray(normal);
  if (n.lengthSq() > 0) cursor.quaternion.setFromUnitVectors(zAxis, n.normalize());
  cursor.scale.setScalar(Math.max(radius, 1e-9));
  cursor.visible = true;
  redraw();
}
export function setCursorRadius(radius) { cursor.scale.setScalar(Math.max(radius, 1e-9)); redraw(); }
export function hideCursor() { if (cursor.visible) { cursor.visible = false; redraw(); } }
export const cursorShown = () => cursor.visible;
export const cursorRadius = () => (cursor.visible ? cursor.scale.x : 0);
