// The panel: tool, mode and handle buttons, the brush radius, k, the method, undo/redo, the view toggles,
// export, the stats and the progress bar, and the keyboard. It calls back into app.js through the
// `actions` given to bindPanels() and holds no state of the edit.
import { api, message, task } from './api.js';
import { HANDLE_COLORS } from './view.js';

const $ = (id) => document.getElementById(id);

export function setToolButtons(tool) {
  for (const b of document.querySelectorAll('#tools button')) b.classList.toggle('active', b.dataset.tool === tool);
}
export function setModeButtons(mode) {
  for (const b of document.querySelectorAll('#modes button')) b.classList.toggle('active', b.dataset.mode === mode);
}

/// The brush radius (the slider's value, in the mesh's units).
export const radius = () => parseFloat($('radius').value);
export function setRadius(r) {
  $('radius').value = r;
  $('radius-value').textContent = Number($('radius').value).toPrecision(3);
}
/// The slider's range for a mesh whose bounding sphere has radius R; the brush starts at R / 8.
export function fitRadius(R) {
  $('radius').max = R.toPrecision(3);
  $('radius').min = (R / 200).toPrecision(3);
  $('radius').step = 'any';
  setRadius(R / 8);
}
/// Multiplies the brush radius by `factor`, within the slider's range.
export function scaleRadius(factor) {
  setRadius(Math.min(parseFloat($('radius').max), Math.max(parseFloat($('radius').min), radius() * factor)));
}
export const brush = () => ($('geodesic').checked ? 'geodesic' : 'sphere');

export function setK(k) { $('k').value = String(k); }
export function setMethod(method) { $('method').value = method; }

/// The H1, H2, … buttons: `count` handles, `selected` highlighted; onSelect(j) on a click.
export function showHandles(count, selected, onSelect) {
  const box = $('handles');
  box.innerHTML = '';
  for (let j = 0; j < count; ++j) {
    const b = document.createElement('button');
    b.textContent = `H${j + 1}`;
    const [r, g, bl] = HANDLE_COLORS[j % HANDLE_COLORS.length];
    b.style.borderColor = `rgb(${255 * r},${255 * g},${255 * bl})`;
    b.className = j === selected ? 'active' : '';
    b.onclick = () => onSelect(j);
    box.appendChild(b);
  }
}

/// The server's status (and the page's last frame time) in the stats panel, and the buttons that
/// depend on it: undo, redo and export are off while the server is busy or has nothing for them.
export function showStats(s, frameMs) {
  if (!s) return;
  const lines = [];
  if (s.mesh) lines.push(`${s.mesh.name}: ${s.mesh.vertices.toLocaleString()} vertices, ${s.mesh.faces.toLocaleString()} faces`);
  if (s.base) {
    lines.push(`base ${s.base.vertices.toLocaleString()} vertices, preprocessing ${(s.base.preprocess_ms / 1000).toFixed(2)} s`);
    lines.push(`area spread ${s.base.area_rel_mad.toFixed(3)}, smallest angle ${s.base.min_angle_deg.toFixed(1)}°`);
  }
  if (s.region) {
    lines.push(`support ${s.region.support.toLocaleString()}, ${s.region.handles} handle(s), k = ${s.region.k}, ${s.region.method ?? 'linear'}`);
    lines.push(`set_region ${s.region.set_region_ms.toFixed(0)} ms, frame ${(frameMs ?? s.frame_ms ?? 0).toFixed(1)} ms`);
    const n = s.nonlinear;
    if (n) lines.push(n.fallback ? 'nonlinear: fell back to linear' : n.preparing ? 'nonlinear: preparing (linear until then)'
      : `nonlinear: ${n.converged ? 'converged' : 'iterating'}, ${n.iterations} iterations`);
  }
  $('stats').textContent = lines.join('\n');
  setBusy(s.state === 'busy', s);
}
export function setBusy(busy, s) {
  $('undo').disabled = busy || !s?.undo;
  $('redo').disabled = busy || !s?.redo;
  for (const b of document.querySelectorAll('#export button')) b.disabled = busy || s?.state !== 'ready';
}

/// The progress of a busy status: the bar at status.progress.fraction (or step / steps), and
/// "phase — NN %".
export function showProgress(s) {
  const p = s?.progress;
  $('progress').hidden = !p;
  if (!p) return;
  const fraction = Number.isFinite(p.fraction) ? p.fraction : p.steps ? p.step / p.steps : null;
  $('progress-text').textContent = fraction === null ? `${p.job}: ${p.phase}`
    : `${p.job}: ${p.phase} — ${Math.round(100 * Math.min(1, Math.max(0, fraction)))} %`;
  $('progress-bar').style.width = fraction === null ? '15%' : `${100 * Math.min(1, Math.max(0, fraction))}%`;
  setBusy(true, s);
}

/// Downloads the current result as `format`, named after the loaded mesh (bunny.ply gives
/// bunny_edited.ply); a refusal shows the server's message.
async function exportMesh(format, name) {
  try {
    const blob = await (await api(`export?format=${format}`)).blob();
    const stem = (name || 'mesh').replace(/\.[^.]*$/, '');
    const link = document.createElement('a');
    link.href = URL.createObjectURL(blob);
    link.download = `${stem}_edited.${format}`;
    document.body.appendChild(link);
    link.click();
    link.remove();
    setTimeout(() => URL.revokeObjectURL(link.href), 10000);
  } catch (e) { /* shown */ }
}

/// A key typed into a text field is text, not a command; every other element passes keys on.
function typing(target) {
  if (target?.isContentEditable || target?.tagName === 'TEXTAREA') return true;
  if (target?.tagName !== 'INPUT') return false;
  return ['text', 'search', 'email', 'url', 'tel', 'password', 'number'].includes(target.type);
}

function onKey(event, actions) {
  if (typing(event.target)) return;
  const key = event.key.toLowerCase();
  if ((event.ctrlKey || event.metaKey) && key === 'z') {
    event.preventDefault();
    actions.history(event.shiftKey ? 'redo' : 'undo');
    return;
  }
  if (event.ctrlKey || event.metaKey || event.altKey) return;
  const modes = { w: 'translate', e: 'rotate', r: 'scale' };
  const tools = { o: 'orbit', s: 'support', h: 'handle', x: 'erase' };
  if (modes[key]) actions.setMode(modes[key]);
  else if (tools[key]) actions.setTool(tools[key]);
  else if (key === '[' || key === ']') { event.preventDefault(); actions.scaleRadius(key === '[' ? 0.8 : 1.25); }
}

/// Connects the panel's controls and the keyboard to `actions` (app.js): setTool, setMode,
/// newHandle, clear, setK, setMethod, history('undo' | 'redo'), showBase, showMesh, upload(file),
/// scaleRadius(factor), meshName().
export function bindPanels(actions) {
  for (const b of document.querySelectorAll('#tools button')) b.onclick = () => actions.setTool(b.dataset.tool);
  for (const b of document.querySelectorAll('#modes button')) b.onclick = () => actions.setMode(b.dataset.mode);
  $('radius').oninput = () => { $('radius-value').textContent = radius().toPrecision(3); };
  $('new-handle').onclick = actions.newHandle;
  $('clear').onclick = actions.clear;
  $('k').onchange = () => actions.setK(parseInt($('k').value, 10));
  $('method').onchange = () => actions.setMethod($('method').value);
  $('undo').onclick = () => actions.history('undo');
  $('redo').onclick = () => actions.history('redo');
  $('show-base').onchange = actions.showBase;
  $('show-wire').onchange = actions.showBase;
  $('show-mesh').onchange = actions.showMesh;
  $('show-edges').onchange = actions.showMesh;
  for (const b of document.querySelectorAll('#export button'))
    b.onclick = () => task(() => exportMesh(b.dataset.format, actions.meshName()));
  window.addEventListener('keydown', (event) => onKey(event, actions));
  $('file').onchange = (event) => { if (event.target.files[0]) actions.upload(event.target.files[0]); };
  const view = $('view');
  view.addEventListener('dragover', (event) => event.preventDefault());
  view.addEventListener('drop', (event) => {
    event.preventDefault();
    if (event.dataTransfer.files[0]) actions.upload(event.dataTransfer.files[0]);
  });
  view.addEventListener('wheel', (event) => {
    if (!event.ctrlKey) return;
    event.preventDefault();
    event.stopPropagation();
    actions.scaleRadius(event.deltaY > 0 ? 0.8 : 1.25);
  }, { capture: true, passive: false });
}

/// Clears a shown message at the start of a user action, so that new hints can show.
export const clearMessage = () => message('');
