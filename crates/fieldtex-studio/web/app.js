// fieldtex studio, orient mode: the page keeps no design of its own; every edit goes to
// the server, which re-solves the design and answers with the new state and field.
import { drawStreamlines, drawElements, handlePos } from './draw.js';
import { $, status, check, post } from './page.js';

const canvas = $('field');
const ctx = canvas.getContext('2d');
let info = null;
let state = null; // server JSON state
let field = null; // Float32Array, 2 per pixel
let tool = 'select';
let selected = null; // {type: 'singularity'|'stroke', id}
let drag = null;
let textureTimer = null;
let textureAbort = null;


/** Decodes `[u32 json length][json][f32 field]`. */
function decodeState(buf) {
  const view = new DataView(buf);
  const len = view.getUint32(0, true);
  const json = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 4, len)));
  const bytes = buf.slice(4 + len);
  return [json, new Float32Array(bytes)];
}

function k() { return canvas.width / state.width; }

function redraw() {
  if (!state) return;
  const t0 = performance.now();
  drawStreamlines(ctx, field, state.field_size, state.width, state.height);
  drawElements(ctx, state, selected, k());
  return performance.now() - t0;
}

function showTimings(extra) {
  const lines = [`design v${state.version}: ${state.singularities.length} singularities, ${state.strokes.length} strokes`,
    `server edit+solve+sample: ${state.solve_ms.toFixed(1)} ms`];
  if (extra) lines.push(extra);
  for (const w of state.warnings) lines.push('warning: ' + w);
  $('timings').textContent = lines.join('\n');
}

// Edit latencies for the page and the browser test: from the input event that caused
// the edit (or the request, when there is none) to the end of the redraw.
const timings = [];
// Texture latencies: from the input event of the edit the texture shows to the image
// decoded in the page, per size (128² first feedback, then the full size).
const textureTimings = [];
window.studio = { get state() { return state; }, get field() { return field; }, timings, textureTimings, get busy() { return inFlight || pending !== null; } };

async function setState(resp, t0, tEvent = t0) {
  const [json, f] = decodeState(await resp.arrayBuffer());
  const tNet = performance.now() - t0;
  state = json; field = f;
  const tDraw = redraw();
  const total = performance.now() - tEvent;
  if (timings.length > 1000) timings.shift();
  timings.push({ version: json.version, round_trip_ms: tNet, draw_ms: tDraw, event_to_draw_ms: total, solve_ms: json.solve_ms });
  showTimings(`round trip ${tNet.toFixed(1)} ms + draw ${tDraw.toFixed(1)} ms; event → drawn ${total.toFixed(1)} ms`);
  updateSelectionUi();
  scheduleTexture(tEvent);
  return json;
}

async function newSession(body) {
  try {
    const t0 = performance.now();
    const resp = await post('/api/session', body);
    await setState(resp, t0);
    sessionStorage.setItem('fieldtex-session', state.session);
    selected = null;
    buildTools();
    status('design ready');
  } catch (e) { status(e.message, true); }
}

// Edits: one in flight; while it runs, newer drag positions replace the pending one.
let inFlight = false;
let pending = null;
async function edit(op, tEvent = performance.now()) {
  if (inFlight) { pending = { op, tEvent }; return null; }
  inFlight = true;
  let result = null;
  try {
    const t0 = performance.now();
    const resp = await post(`/api/edit?session=${encodeURIComponent(state.session)}`, op);
    result = await setState(resp, t0, tEvent);
    status('ok');
  } catch (e) { status(e.message, true); }
  inFlight = false;
  if (pending) { const p = pending; pending = null; await edit(p.op, p.tEvent); }
  return result;
}

function buildTools() {
  const box = $('tools');
  box.textContent = '';
  for (const name of ['select', ...state.kinds, 'stroke']) {
    const b = document.createElement('button');
    b.textContent = name;
    b.dataset.tool = name;
    if (name === tool) b.className = 'active';
    b.onclick = () => { tool = name; for (const c of box.children) c.className = c.dataset.tool === tool ? 'active' : ''; };
    box.appendChild(b);
  }
  if (!['select', 'stroke', ...state.kinds].includes(tool)) tool = 'select';
}

function updateSelectionUi() {
  const s = selectedSingularity();
  $('remove').disabled = !selected || !findSelected();
  if (s) { $('angle').value = Math.round(((s.angle_deg + 180) % 360 + 360) % 360 - 180); $('angle-out').textContent = `${Math.round(s.angle_deg)}°`; }
}
function selectedSingularity() {
  return selected && selected.type === 'singularity' ? state.singularities.find((s) => s.id === selected.id) : null;
}
function findSelected() {
  if (!selected) return null;
  const list = selected.type === 'singularity' ? state.singularities : state.strokes;
  return list.find((e) => e.id === selected.id);
}

function designPoint(ev) {
  const r = canvas.getBoundingClientRect();
  const cx = ((ev.clientX - r.left) * canvas.width) / r.width;
  const cy = ((ev.clientY - r.top) * canvas.height) / r.height;
  return { cx, cy, x: cx / k(), y: cy / k() };
}

function hit(p) {
  for (const s of state.singularities) {
    const h = handlePos(s, k());
    if (Math.hypot(h[0] - p.cx, h[1] - p.cy) < 7) return { type: 'handle', id: s.id, s };
  }
  for (const s of state.singularities) {
    if (Math.hypot(s.x * k() - p.cx, s.y * k() - p.cy) < 10) return { type: 'singularity', id: s.id, s };
  }
  for (const s of state.strokes) {
    for (let i = 1; i < s.points.length; i++) {
      if (segDist(p, s.points[i - 1], s.points[i]) < 6) return { type: 'stroke', id: s.id, s };
    }
  }
  return null;
}
function segDist(p, a, b) {
  const kk = k();
  const ax = a[0] * kk, ay = a[1] * kk, bx = b[0] * kk, by = b[1] * kk;
  const dx = bx - ax, dy = by - ay;
  const t = Math.max(0, Math.min(1, ((p.cx - ax) * dx + (p.cy - ay) * dy) / (dx * dx + dy * dy || 1)));
  return Math.hypot(p.cx - ax - t * dx, p.cy - ay - t * dy);
}

canvas.addEventListener('pointerdown', async (ev) => {
  if (!state) return;
  canvas.setPointerCapture(ev.pointerId);
  const p = designPoint(ev);
  const h = hit(p);
  if (tool === 'stroke') { drag = { type: 'draw', points: [[p.x, p.y]] }; return; }
  if (h) {
    selected = { type: h.type === 'handle' ? 'singularity' : h.type, id: h.id };
    drag = { type: h.type, id: h.id, start: p, orig: h.s };
    updateSelectionUi();
    redraw();
    return;
  }
  if (tool !== 'select') {
    const r = await edit({ op: 'add_singularity', kind: tool, x: p.x, y: p.y, angle_deg: Number($('angle').value) }, ev.timeStamp);
    if (r && r.added !== null && r.added !== undefined) { selected = { type: 'singularity', id: r.added }; updateSelectionUi(); redraw(); }
  } else { selected = null; updateSelectionUi(); redraw(); }
});

canvas.addEventListener('pointermove', (ev) => {
  if (!drag) return;
  const p = designPoint(ev);
  if (drag.type === 'draw') {
    const last = drag.points[drag.points.length - 1];
    if (Math.hypot(p.x - last[0], p.y - last[1]) * k() >= 6) {
      drag.points.push([p.x, p.y]);
      redraw();
      ctx.strokeStyle = '#0b8f3a'; ctx.lineWidth = 3; ctx.beginPath();
      drag.points.forEach(([x, y], i) => (i ? ctx.lineTo(x * k(), y * k()) : ctx.moveTo(x * k(), y * k())));
      ctx.stroke();
    }
  } else if (drag.type === 'singularity') {
    edit({ op: 'move_singularity', id: drag.id, x: p.x, y: p.y }, ev.timeStamp);
  } else if (drag.type === 'handle') {
    const s = drag.orig;
    const a = (Math.atan2(p.y - s.y, p.x - s.x) * 180) / Math.PI;
    edit({ op: 'move_singularity', id: drag.id, x: s.x, y: s.y, angle_deg: a });
  } else if (drag.type === 'stroke') {
    const dx = p.x - drag.start.x, dy = p.y - drag.start.y;
    edit({ op: 'move_stroke', id: drag.id, points: drag.orig.points.map(([x, y]) => [x + dx, y + dy]) });
  }
});

canvas.addEventListener('pointerup', async () => {
  const d = drag; drag = null;
  if (d && d.type === 'draw' && d.points.length >= 2) {
    const r = await edit({ op: 'add_stroke', points: d.points });
    if (r && r.added !== null && r.added !== undefined) { selected = { type: 'stroke', id: r.added }; updateSelectionUi(); redraw(); }
  } else if (d && d.type === 'draw') redraw();
});

async function removeSelected() {
  if (!selected || !findSelected()) return;
  const op = selected.type === 'singularity' ? 'remove_singularity' : 'remove_stroke';
  const id = selected.id; selected = null;
  await edit({ op, id });
}
$('remove').onclick = removeSelected;
canvas.addEventListener('keydown', (ev) => { if (ev.key === 'Delete' || ev.key === 'Backspace') removeSelected(); });
$('angle').addEventListener('input', () => {
  $('angle-out').textContent = `${$('angle').value}°`;
  const s = selectedSingularity();
  if (s) edit({ op: 'move_singularity', id: s.id, x: s.x, y: s.y, angle_deg: Number($('angle').value) });
});

// Texture: coarse 128² first, then the full size; a newer edit cancels both.
function currentExemplar() {
  const v = $('exemplar').value;
  return v ? JSON.parse(v) : null;
}
let textureEvent = 0;
function scheduleTexture(tEvent = performance.now()) {
  if (!$('auto-texture').checked) return;
  clearTimeout(textureTimer);
  textureEvent = tEvent;
  textureTimer = setTimeout(synthesise, 100);
}
async function synthesise() {
  const tEvent = textureEvent || performance.now();
  const ex = currentExemplar();
  if (!ex || !state) return;
  if (textureAbort) textureAbort.abort();
  const abort = new AbortController();
  textureAbort = abort;
  const version = state.version;
  for (const size of [128, Math.min(1024, Math.round(state.width))]) {
    try {
      const t0 = performance.now();
      const resp = await fetch(`/api/texture?session=${encodeURIComponent(state.session)}`, {
        method: 'POST', signal: abort.signal, headers: { 'Content-Type': 'application/json' },
        body: JSON.stringify({ exemplar: ex, size, scale: Number($('scale').value) || 1, version }),
      });
      if (resp.status === 409) return; // design changed meanwhile; a newer request follows
      await check(resp);
      const blob = await resp.blob();
      if (abort.signal.aborted) return;
      const img = $('texture');
      if (img.src.startsWith('blob:')) URL.revokeObjectURL(img.src);
      img.src = URL.createObjectURL(blob);
      await img.decode().catch(() => {});
      if (abort.signal.aborted) return;
      if (textureTimings.length > 1000) textureTimings.shift();
      textureTimings.push({ version, size, since_edit_ms: performance.now() - tEvent, request_ms: performance.now() - t0, synth_ms: Number(resp.headers.get('X-Synth-Ms')) });
      status(`texture ${size}²: ${(performance.now() - t0).toFixed(0)} ms (synthesis ${resp.headers.get('X-Synth-Ms')} ms)`);
    } catch (e) {
      if (e.name !== 'AbortError') status(e.message, true);
      return;
    }
  }
}
$('texture-now').onclick = () => { textureEvent = performance.now(); synthesise(); };
$('exemplar').onchange = () => { textureEvent = performance.now(); synthesise(); };

$('upload').onchange = async () => {
  const f = $('upload').files[0];
  if (!f) return;
  if (f.size > info.max_upload_bytes) { status(`${f.name} is over ${info.max_upload_bytes} bytes`, true); return; }
  try {
    const resp = await check(await fetch(`/api/upload?name=${encodeURIComponent(f.name.replace(/[^A-Za-z0-9._-]/g, '_'))}`, { method: 'POST', body: f }));
    const ref = await resp.json();
    addExemplarOption(ref, true);
    synthesise();
  } catch (e) { status(e.message, true); }
};

$('export').onclick = async () => {
  try {
    const body = { dir: $('export-dir').value, scale: Number($('scale').value) || 1 };
    const ex = currentExemplar();
    if (ex) body.exemplar = ex;
    status('exporting…');
    const out = await (await post(`/api/export?session=${encodeURIComponent(state.session)}`, body)).json();
    const ul = $('exported');
    ul.textContent = '';
    for (const f of out.files) {
      const li = document.createElement('li');
      const a = document.createElement('a');
      a.href = `/api/file?path=${encodeURIComponent(f)}`; a.textContent = f; a.download = f.split('/').pop();
      li.appendChild(a); ul.appendChild(li);
    }
    status('exported');
  } catch (e) { status(e.message, true); }
};

function addExemplarOption(ref, select = false) {
  const o = document.createElement('option');
  o.value = JSON.stringify(ref);
  o.textContent = (ref.root === 'exemplars' ? '' : 'workspace/') + ref.path;
  $('exemplar').appendChild(o);
  if (select) $('exemplar').value = o.value;
}

$('load-preset').onclick = () => newSession({ preset: $('preset').value });
$('new-blank').onclick = () => newSession({ symmetry: $('symmetry').value });

async function start() {
  try {
    info = await (await check(await fetch('/api/info'))).json();
  } catch (e) { status(e.message, true); return; }
  for (const p of info.presets) { const o = document.createElement('option'); o.textContent = p; $('preset').appendChild(o); }
  $('exemplar').appendChild(new Option('(none)', ''));
  for (const ex of info.exemplars) addExemplarOption(ex);
  // Preselect a striped exemplar (or the first one) so the first edit shows a texture.
  const pick = info.exemplars.find((e) => /fingerprint|stripes/.test(e.path)) || info.exemplars[0];
  if (pick) $('exemplar').value = JSON.stringify(pick);
  const old = sessionStorage.getItem('fieldtex-session');
  if (old) {
    try {
      const t0 = performance.now();
      await setState(await check(await fetch(`/api/state?session=${encodeURIComponent(old)}`)), t0);
      buildTools();
      return;
    } catch (_) { /* expired: start anew */ }
  }
  await newSession({ preset: 'left-loop' });
}
start();
