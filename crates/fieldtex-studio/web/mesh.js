// fieldtex studio, mesh modes: align (crest lines, drawn curves, the field as
// streamlines, align jobs), solid (sketch curves on the surface or on a movable
// reference plane, the frame field, cut images computed on demand by an open solid on
// the server, cut meshes by solid jobs) and the GLB viewer (texture, wireframe, UV checker, patch colours).
// three.js comes from /vendor/ (embedded after scripts/setup-studio); without it the
// page says which command to run.
import { $, status, check, post } from './page.js';
import { renderJob, watchJob } from './jobs.js';
import { checkerTexture, patchGeometry } from './display.js';
import { camera, clearGroup, controls, fitCamera, groups, polyline, render, renderer, setupView } from './view.js';

const params = new URLSearchParams(location.search);
const mode = ['align', 'solid', 'viewer'].includes(params.get('mode')) ? params.get('mode') : 'align';
let THREE, OrbitControls, GLTFLoader;
let info = null;
let meshData = null; // {id, root, path, bbox, crest, ...}
let meshObj = null; // THREE.Mesh of the opened mesh
let glbRoot = null; // the GLB scene shown in the viewer
const crestUse = []; // per crest line: used as a curve
let drawn = []; // curves drawn on the surface (align) — arrays of [x, y, z]
let sketch = []; // solid sketch curves: {points, axis}
let drawing = null;
let cutPlaneObj = null;
let refPlaneObj = null;
let solid = null; // the open solid on the server: {id, key, sent}
const cuts = []; // cut latencies: {round_trip_ms, shown_ms, server_ms, computed, requested}
const timings = {};
window.studioMesh = {
  get mesh() { return meshData; },
  get drawn() { return mode === 'solid' ? sketch.map((s) => s.points) : drawn; },
  get glb() { return glbRoot; },
  get solid() { return solid; },
  get sketch() { return sketch; },
  cuts,
  timings,
  jobs: {},
};

// ---------------------------------------------------------------- 3-D view
function diag() {
  if (!meshData) return 1;
  const [lo, hi] = meshData.bbox;
  return Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

// ---------------------------------------------------------------- meshes
async function refreshLists() {
  const lists = await (await check(await fetch('/api/meshes'))).json();
  const fill = (sel, items) => {
    const keep = sel.value;
    sel.textContent = '';
    for (const it of items) {
      const o = new Option((it.root === 'workspace' ? 'workspace/' : '') + it.path, JSON.stringify(it));
      sel.appendChild(o);
    }
    if ([...sel.options].some((o) => o.value === keep)) sel.value = keep;
  };
  fill($('mesh-list'), lists.meshes);
  fill($('glb-list'), lists.glbs);
}

async function openMesh(ref) {
  status(`opening ${ref.path}…`);
  const t0 = performance.now();
  const buf = await (await post('/api/mesh/open', ref)).arrayBuffer();
  const view = new DataView(buf);
  const len = view.getUint32(0, true);
  const json = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 4, len)));
  const pos = new Float32Array(buf, 4 + len, json.vertices * 3);
  const idx = new Uint32Array(buf, 4 + len + json.vertices * 12, json.triangles * 3);
  meshData = json;
  const opt = [...$('mesh-list').options].find((o) => { const v = JSON.parse(o.value); return v.root === json.root && v.path === json.path; });
  if (opt) $('mesh-list').value = opt.value;
  clearGroup('mesh'); clearGroup('crest'); clearGroup('drawn'); clearGroup('field'); clearGroup('glb'); clearGroup('cut');
  glbRoot = null;
  groups.mesh.visible = true; groups.drawn.visible = true; groups.field.visible = true;
  $('cut-image').hidden = true;
  drawn = []; sketch = []; solid = null;
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(pos.slice(), 3));
  g.setIndex(new THREE.BufferAttribute(idx.slice(), 1));
  g.computeVertexNormals();
  meshObj = new THREE.Mesh(g, new THREE.MeshStandardMaterial({ color: 0xd9d4c7, roughness: 0.8, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 }));
  groups.mesh.add(meshObj);
  fitCamera(json.bbox[0], json.bbox[1]);
  crestUse.length = 0;
  const colors = { ridge: 0xcc2222, valley: 0x2255dd, crease: 0x11aa44, given: 0x885500 };
  const list = $('crest-list');
  list.textContent = '';
  json.crest.forEach((c, i) => {
    crestUse.push(true);
    const line = polyline(c.points, colors[c.kind] || 0x333333);
    line.userData.index = i;
    groups.crest.add(line);
    const l = document.createElement('label');
    const cb = document.createElement('input');
    cb.type = 'checkbox'; cb.checked = true; cb.dataset.index = i;
    cb.onchange = () => { crestUse[i] = cb.checked; line.visible = cb.checked; render(); };
    l.append(cb, ` ${c.kind} ${i + 1} (${c.points.length} pts)`);
    list.appendChild(l);
  });
  groups.crest.visible = mode === 'align' && $('show-crest').checked;
  timings.open_ms = performance.now() - t0;
  showInfo();
  applyDisplay();
  render();
  status(`${json.path}: ${json.vertices} vertices, ${json.triangles} triangles, ${json.crest.length} crest lines`);
  if (mode === 'solid') { placeCutPlane(); placeRefPlane(); }
}

function showInfo(extra = '') {
  const lines = [];
  if (meshData) lines.push(`${meshData.path}: ${meshData.triangles} triangles`);
  if (meshData) for (const w of meshData.warnings.slice(0, 5)) lines.push('warning: ' + w);
  for (const [k, v] of Object.entries(timings)) lines.push(`${k}: ${typeof v === 'number' ? v.toFixed(1) : v}`);
  if (extra) lines.push(extra);
  $('timings').textContent = lines.join('\n');
}

// ---------------------------------------------------------------- drawing on the surface
const raycaster = () => new THREE.Raycaster();
const onRefPlane = () => mode === 'solid' && $('ref-draw').checked;
function pick(ev) {
  if (!meshObj) return null;
  const r = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((ev.clientX - r.left) / r.width) * 2 - 1, -((ev.clientY - r.top) / r.height) * 2 + 1);
  const rc = raycaster();
  rc.setFromCamera(ndc, camera);
  if (onRefPlane()) {
    // Ray-pick the reference plane, within the square drawn for it.
    const rp = refPlane();
    const n = new THREE.Vector3(...rp.normal);
    const o = new THREE.Vector3(...rp.point);
    const p = rc.ray.intersectPlane(new THREE.Plane().setFromNormalAndCoplanarPoint(n, o), new THREE.Vector3());
    if (!p || p.distanceTo(o) > diag() * 0.57) return null;
    return { p, n };
  }
  const hit = rc.intersectObject(meshObj, false)[0];
  if (!hit) return null;
  const n = hit.face ? hit.face.normal.clone().transformDirection(meshObj.matrixWorld) : new THREE.Vector3();
  return { p: hit.point, n };
}

function onPointerDown(ev) {
  if (!($('draw').checked || onRefPlane()) || mode === 'viewer' || ev.button !== 0) return;
  const h = pick(ev);
  if (!h) return;
  controls.enabled = false;
  renderer.domElement.setPointerCapture(ev.pointerId);
  drawing = { points: [h.p.toArray()], line: null, plane: onRefPlane() ? refPlane() : null };
  ev.preventDefault();
}
function onPointerMove(ev) {
  if (!drawing) return;
  const h = pick(ev);
  if (!h) return;
  const last = drawing.points[drawing.points.length - 1];
  if (Math.hypot(h.p.x - last[0], h.p.y - last[1], h.p.z - last[2]) < diag() * 0.006) return;
  drawing.points.push(h.p.toArray());
  if (drawing.line) groups.drawn.remove(drawing.line);
  drawing.line = drawing.plane ? planeCurve(drawing.points) : lifted(drawing.points, 0x0b8f3a);
  groups.drawn.add(drawing.line);
  render();
}
function onPointerUp() {
  if (!drawing) return;
  const d = drawing; drawing = null;
  controls.enabled = true;
  if (d.points.length >= 2) {
    if (mode === 'solid') {
      const c = { points: d.points, axis: $('sketch-axis').value };
      if (d.plane) c.plane = d.plane;
      sketch.push(c);
    } else drawn.push(d.points);
    status(`${mode === 'solid' ? sketch.length : drawn.length} curve(s) drawn`);
    if (mode === 'solid') sketchChanged();
  } else if (d.line) groups.drawn.remove(d.line);
  render();
}
/** A reference-plane curve: magenta, drawn over everything (it may run inside the mesh). */
function planeCurve(points) {
  const line = polyline(points, 0xc0148c, 2);
  line.material.depthTest = false;
  line.renderOrder = 10;
  return line;
}
/** A curve drawn a little off the surface (along the view) so it is not hidden. */
function lifted(points, color) {
  const eps = diag() * 0.002;
  const pts = points.map((p) => {
    const v = new THREE.Vector3(...p);
    const toCam = camera.position.clone().sub(v).normalize().multiplyScalar(eps);
    return v.add(toCam).toArray();
  });
  return polyline(pts, color, 2);
}

// ---------------------------------------------------------------- align: field
function usedCurves() {
  const c = meshData.crest.filter((_, i) => crestUse[i]).map((l) => l.points);
  return c.concat(drawn);
}
async function showField() {
  if (!meshData) { status('open a mesh first', true); return; }
  status('solving the field…');
  const t0 = performance.now();
  try {
    const r = await (await post(`/api/mesh/field?mesh=${meshData.id}`, { curves: usedCurves(), seeds: 400 })).json();
    clearGroup('field');
    const segs = [];
    for (const l of r.lines) for (let i = 1; i < l.length; i++) segs.push(...l[i - 1], ...l[i]);
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(segs, 3));
    const lines = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0x1d2a44 }));
    groups.field.add(lines);
    groups.field.visible = $('show-field-lines').checked;
    timings.field_server_ms = r.total_ms;
    timings.field_round_trip_ms = performance.now() - t0;
    timings.streamlines = r.lines.length;
    showInfo();
    render();
    status(`field of ${r.curves} curves: ${r.lines.length} streamlines`);
  } catch (e) { status(e.message, true); }
}

// ---------------------------------------------------------------- solid: frames and cut
function drawFrames(r) {
  clearGroup('field');
  const cols = [[0.85, 0.15, 0.1], [0.1, 0.6, 0.15], [0.1, 0.3, 0.9]];
  const pos = [], col = [];
  const h = diag() * 0.02;
  for (const f of r.frames) {
    for (let a = 0; a < 3; a++) {
      const ax = f.axes[a];
      pos.push(...f.p, f.p[0] + h * ax[0], f.p[1] + h * ax[1], f.p[2] + h * ax[2]);
      col.push(...cols[a], ...cols[a]);
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  g.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
  groups.field.add(new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true })));
  render();
}
async function showFrames() {
  if (!meshData) { status('open a mesh first', true); return; }
  try {
    const t0 = performance.now();
    let r;
    if (solid) {
      // The open solid edits its factored field (curve edits) and answers the frames.
      r = await syncSketch(true);
    } else {
      r = await (await post(`/api/mesh/frames?mesh=${meshData.id}`, { sketch: sketchJson() })).json();
      drawFrames(r);
      timings.frames_server_ms = r.total_ms;
    }
    timings.frames_round_trip_ms = performance.now() - t0;
    showInfo();
    status(`frame field: ${r.frames.length} frames, constraint error max ${r.alignment_error_max_deg.toFixed(2)}°`);
  } catch (e) { status(e.message, true); }
}
function sketchJson() {
  return { curves: sketch.map((s) => (s.plane ? { points: s.points, axis: s.axis, plane: s.plane } : { points: s.points, axis: s.axis })) };
}
/** The reference plane from its sliders: normal (turn about y, tilt towards y) and
 *  offset along the normal from the box centre (share of the diagonal). */
function refPlane() {
  const [lo, hi] = meshData.bbox;
  const yaw = (Number($('ref-yaw').value) * Math.PI) / 180;
  const pitch = (Number($('ref-pitch').value) * Math.PI) / 180;
  const n = [Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw)];
  const t = Number($('ref-pos').value) * diag();
  const c = [0, 1, 2].map((a) => (lo[a] + hi[a]) / 2 + t * n[a]);
  return { point: c, normal: n };
}
function placeRefPlane() {
  if (!meshData) return;
  clearGroup('ref');
  refPlaneObj = null;
  if (!$('ref-show').checked && !$('ref-draw').checked) { render(); return; }
  const rp = refPlane();
  const s = diag() * 0.8;
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(s, s), new THREE.MeshBasicMaterial({ color: 0xe07b20, transparent: true, opacity: 0.16, side: THREE.DoubleSide, depthWrite: false }));
  plane.position.set(...rp.point);
  plane.lookAt(rp.point[0] + rp.normal[0], rp.point[1] + rp.normal[1], rp.point[2] + rp.normal[2]);
  const edge = new THREE.LineSegments(new THREE.EdgesGeometry(plane.geometry), new THREE.LineBasicMaterial({ color: 0xb05a10 }));
  plane.add(edge);
  refPlaneObj = plane;
  groups.ref.add(plane);
  render();
}

// ---------------------------------------------------------------- solid: the open solid
function solidKey() {
  return JSON.stringify([meshData.id, exemplarRef(), Number($('solid-res').value) || 64]);
}
/** Opens the solid on the server (exemplar analysis, frame field) unless the open one
 *  has the same mesh, exemplar and voxels. */
async function ensureSolid() {
  if (!meshData) throw new Error('open a mesh first');
  const key = solidKey();
  if (solid && solid.key === key) return;
  status('opening the solid (exemplar analysis)…');
  const t0 = performance.now();
  const body = { mesh: { root: meshData.root, path: meshData.path }, exemplar: exemplarRef(), resolution: Number($('solid-res').value) || 64 };
  if (sketch.length) body.sketch = sketchJson();
  const r = await (await post('/api/solid/open', body)).json();
  solid = { id: r.id, key, sent: JSON.stringify(sketchJson()), grid: r.grid };
  timings.solid_open_ms = performance.now() - t0;
  timings.solid_build_server_ms = r.build_ms;
  drawFrames(r);
  showInfo();
  status(`solid open: ${r.grid.sizes.join('×')} voxels, built in ${r.build_ms.toFixed(0)} ms`);
}
/** Sends the sketch to the open solid if it changed (or when `force`); draws the frames. */
async function syncSketch(force = false) {
  const text = JSON.stringify(sketchJson());
  if (!solid || (!force && solid.sent === text)) return null;
  const t0 = performance.now();
  const r = await (await post(`/api/solid/sketch?solid=${solid.id}`, { sketch: sketchJson() })).json();
  solid.sent = text;
  timings.sketch_edit_server_ms = r.edit_ms;
  timings.sketch_round_trip_ms = performance.now() - t0;
  timings.frames_server_ms = r.edit_ms;
  drawFrames(r);
  showInfo();
  return r;
}
function sketchChanged() {
  if (solid) syncSketch().then(() => { if ($('cut-auto').checked) requestCut(); }).catch((e) => status(e.message, true));
  else if ($('cut-auto').checked) requestCut();
}
/** The cut image on its plane in the 3-D view (a textured quad, transparent outside the
 *  mesh), and the mesh clipped to the kept (negative) side of the plane. */
function showCutInView(img, placement, plane) {
  const old = groups.cut.getObjectByName('cut-image');
  if (old) { groups.cut.remove(old); old.geometry.dispose(); old.material.map.dispose(); old.material.dispose(); }
  if (placement && img.naturalWidth > 0) {
    const [c, u, v] = placement;
    const at = (a, b) => [0, 1, 2].map((k) => c[k] + a * u[k] + b * v[k]);
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute([...at(0, 0), ...at(1, 0), ...at(1, 1), ...at(0, 1)], 3));
    g.setAttribute('uv', new THREE.Float32BufferAttribute([0, 1, 1, 1, 1, 0, 0, 0], 2));
    g.setIndex([0, 1, 2, 0, 2, 3]);
    const canvas = document.createElement('canvas');
    canvas.width = img.naturalWidth; canvas.height = img.naturalHeight;
    canvas.getContext('2d').drawImage(img, 0, 0);
    const tex = new THREE.CanvasTexture(canvas);
    tex.colorSpace = THREE.SRGBColorSpace;
    tex.magFilter = THREE.NearestFilter;
    const quad = new THREE.Mesh(g, new THREE.MeshBasicMaterial({ map: tex, transparent: true, alphaTest: 0.5, side: THREE.DoubleSide }));
    quad.name = 'cut-image';
    groups.cut.add(quad);
  }
  clipMesh(plane);
  render();
}
function clipMesh(plane) {
  if (!meshObj) return;
  renderer.localClippingEnabled = true;
  const on = plane && $('cut-clip').checked;
  const n = plane ? new THREE.Vector3(plane[3], plane[4], plane[5]).normalize() : null;
  meshObj.material.clippingPlanes = on ? [new THREE.Plane(n.clone().negate(), n.dot(new THREE.Vector3(plane[0], plane[1], plane[2])))] : [];
  meshObj.material.needsUpdate = true;
}
let cutBusy = false;
let cutPending = false;
/** Redraws the cut image from the open solid; while one cut runs, the newest plane waits. */
async function requestCut() {
  if (!meshData) return;
  if (cutBusy) { cutPending = true; return; }
  cutBusy = true;
  try {
    await ensureSolid();
    await syncSketch();
    const plane = cutPlane();
    const t0 = performance.now();
    const resp = await post(`/api/solid/cut?solid=${solid.id}`, { plane });
    const blob = await resp.blob();
    const rt = performance.now() - t0;
    const img = $('cut-image');
    if (img.src.startsWith('blob:')) URL.revokeObjectURL(img.src);
    img.src = URL.createObjectURL(blob);
    img.hidden = false;
    await img.decode().catch(() => {});
    showCutInView(img, JSON.parse(resp.headers.get('X-Cut-Placement') || 'null'), plane);
    const c = {
      round_trip_ms: rt,
      shown_ms: performance.now() - t0,
      server_ms: Number(resp.headers.get('X-Cut-Ms')),
      computed: Number(resp.headers.get('X-Voxels-Computed')),
      requested: Number(resp.headers.get('X-Voxels-Requested')),
    };
    if (cuts.length > 1000) cuts.shift();
    cuts.push(c);
    timings.cut_shown_ms = c.shown_ms;
    timings.cut_server_ms = c.server_ms;
    timings.cut_voxels_computed = c.computed;
    showInfo();
    status(`cut ${img.naturalWidth}×${img.naturalHeight}: ${c.shown_ms.toFixed(0)} ms (server ${c.server_ms.toFixed(0)} ms, ${c.computed} voxels computed)`);
  } catch (e) { status(e.message, true); }
  cutBusy = false;
  if (cutPending) { cutPending = false; requestCut(); }
}
function cutPlane() {
  const [lo, hi] = meshData.bbox;
  const a = Number($('cut-axis').value);
  const t = Number($('cut-pos').value);
  const p = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2];
  p[a] = lo[a] + t * (hi[a] - lo[a]);
  const n = [0, 0, 0]; n[a] = 1;
  return [...p, ...n];
}
function placeCutPlane() {
  if (!meshData) return;
  clearGroup('cut');
  const c = cutPlane();
  const s = diag();
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(s, s), new THREE.MeshBasicMaterial({ color: 0x3366cc, transparent: true, opacity: 0.12, side: THREE.DoubleSide, depthWrite: false }));
  plane.position.set(c[0], c[1], c[2]);
  plane.lookAt(c[0] + c[3], c[1] + c[4], c[2] + c[5]);
  cutPlaneObj = plane;
  groups.cut.add(plane);
  if (solid && cuts.length) clipMesh(c);
  render();
}

// ---------------------------------------------------------------- jobs
function exemplarRef() { return $('exemplar').value ? JSON.parse($('exemplar').value) : null; }
async function runJob(kind = mode) {
  if (!meshData) { status('open a mesh first', true); return null; }
  const body = { kind, mesh: { root: meshData.root, path: meshData.path }, exemplar: exemplarRef(), size: Number($('size').value) || 256 };
  if (kind === 'align') body.curves = usedCurves();
  if (kind === 'solid') {
    if (sketch.length) body.sketch = sketchJson();
    body.cuts = [cutPlane()];
    body.resolution = Number($('solid-res').value) || 64;
    body.size = Math.min(body.size, 256);
  }
  try {
    const job = await (await post('/api/jobs', body)).json();
    status(`${kind} job ${job.id} queued`);
    watchJob(job, jobHandlers);
    return job;
  } catch (e) { status(e.message, true); return null; }
}

async function onJobEnd(job) {
  if (job.state === 'failed') { status(`${job.kind} failed: ${job.error}`, true); return; }
  if (job.state !== 'done') { status(`${job.kind} ${job.state}`); return; }
  status(`${job.kind} done in ${job.seconds.toFixed(1)} s`);
  await refreshLists().catch(() => {});
  if (job.kind === 'solid' && job.files.includes('cut-1.png')) {
    if (job.files.includes('cut-1.glb')) await openGlb({ root: 'workspace', path: `${job.dir}/cut-1.glb` }, false);
  } else if (job.files.includes('model.glb')) {
    await openGlb({ root: 'workspace', path: `${job.dir}/model.glb` });
  }
}
const jobHandlers = { onView: (ref) => openGlb(ref), onEnd: onJobEnd };

// ---------------------------------------------------------------- viewer
async function openGlb(ref, fit = true) {
  status(`loading ${ref.path}…`);
  try {
    const url = `/api/file?root=${ref.root}&path=${encodeURIComponent(ref.path)}`;
    const gltf = await new GLTFLoader().loadAsync(url);
    clearGroup('glb');
    glbRoot = gltf.scene;
    glbRoot.traverse((o) => { if (o.isMesh) o.userData.original = o.material; });
    groups.glb.add(glbRoot);
    if (groups.mesh) groups.mesh.visible = false;
    // In solid mode the sketch, the frames and the cut plane stay visible over the cut
    // mesh; elsewhere the GLB is shown alone.
    groups.crest.visible = false;
    groups.drawn.visible = mode === 'solid';
    groups.field.visible = mode === 'solid';
    if (fit) {
      const b = new THREE.Box3().setFromObject(glbRoot);
      fitCamera(b.min.toArray(), b.max.toArray());
    }
    applyDisplay();
    render();
    status(`${ref.path} loaded`);
    window.studioMesh.glbLoaded = ref.path;
  } catch (e) { status(`${ref.path}: ${e.message || e}`, true); }
}

function applyDisplay() {
  const d = document.querySelector('input[name=display]:checked').value;
  const targets = [];
  if (glbRoot) glbRoot.traverse((o) => { if (o.isMesh) targets.push(o); });
  else if (meshObj) targets.push(meshObj);
  let patches = 0;
  for (const o of targets) {
    if (!o.userData.original) o.userData.original = o.material;
    if (!o.userData.geometry) o.userData.geometry = o.geometry;
    o.geometry = o.userData.geometry;
    if (d === 'texture') o.material = o.userData.original;
    else if (d === 'wireframe') o.material = new THREE.MeshBasicMaterial({ color: 0x223355, wireframe: true });
    else if (d === 'checker') {
      o.material = o.geometry.attributes.uv
        ? new THREE.MeshBasicMaterial({ map: checkerTexture(THREE) })
        : new THREE.MeshBasicMaterial({ color: 0xcc4444 });
    } else {
      if (!o.userData.patchGeometry) o.userData.patchGeometry = patchGeometry(THREE, o.userData.geometry);
      o.geometry = o.userData.patchGeometry;
      patches += o.geometry.userData.patches;
      o.material = new THREE.MeshBasicMaterial({ vertexColors: true });
    }
  }
  timings.display = d + (d === 'patches' ? ` (${patches} patches)` : '');
  window.studioMesh.patches = patches;
  showInfo();
  render();
}

// ---------------------------------------------------------------- start
async function upload(input, after) {
  const f = input.files[0];
  if (!f) return;
  if (f.size > info.max_upload_bytes) { status(`${f.name} is over ${info.max_upload_bytes} bytes`, true); return; }
  try {
    const name = f.name.replace(/[^A-Za-z0-9._-]/g, '_');
    const ref = await (await check(await fetch(`/api/upload?name=${encodeURIComponent(name)}`, { method: 'POST', body: f }))).json();
    await refreshLists();
    await after(ref);
  } catch (e) { status(e.message, true); }
}

async function start() {
  $('mode-name').textContent = mode;
  for (const a of document.querySelectorAll('#modes a[data-mode]')) if (a.dataset.mode === mode) a.className = 'active';
  for (const el of document.querySelectorAll('fieldset[class]')) el.hidden = !el.classList.contains(`for-${mode}`);
  try {
    info = await (await check(await fetch('/api/info'))).json();
  } catch (e) { status(e.message, true); return; }
  if (!info.three) {
    const s = $('setup');
    s.hidden = false;
    s.textContent = `three.js is not embedded in this build, so the mesh modes cannot start. Run: ${info.setup_command} — then restart fieldtex studio.`;
    status('three.js missing', true);
    return;
  }
  try {
    THREE = await import('three');
    ({ OrbitControls } = await import('three/addons/controls/OrbitControls.js'));
    ({ GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js'));
  } catch (e) { status(`cannot load three.js: ${e.message}`, true); return; }
  setupView(THREE, OrbitControls, $('viewport'), { onPointerDown, onPointerMove, onPointerUp });
  for (const ex of info.exemplars) {
    $('exemplar').appendChild(new Option((ex.root === 'workspace' ? 'workspace/' : '') + ex.path, JSON.stringify(ex)));
  }
  const pick = info.exemplars.find((e) => /stripes|woodgrain/.test(e.path)) || info.exemplars[0];
  if (pick) $('exemplar').value = JSON.stringify(pick);
  await refreshLists().catch((e) => status(e.message, true));
  $('mesh-open').onclick = () => $('mesh-list').value && openMesh(JSON.parse($('mesh-list').value)).catch((e) => status(e.message, true));
  $('glb-open').onclick = () => $('glb-list').value && openGlb(JSON.parse($('glb-list').value));
  $('mesh-upload').onchange = () => upload($('mesh-upload'), (ref) => openMesh(ref));
  $('glb-upload').onchange = () => upload($('glb-upload'), (ref) => openGlb(ref));
  $('clear-drawn').onclick = () => { drawn = []; sketch = []; clearGroup('drawn'); render(); if (mode === 'solid' && solid) sketchChanged(); };
  $('show-crest').onchange = () => { groups.crest.visible = $('show-crest').checked; render(); };
  const setAll = (v) => {
    crestUse.fill(v);
    for (const cb of $('crest-list').querySelectorAll('input')) cb.checked = v;
    groups.crest.children.forEach((l) => { l.visible = v; });
    render();
  };
  $('crest-all').onclick = () => setAll(true);
  $('crest-none').onclick = () => setAll(false);
  $('show-field').onclick = showField;
  $('show-field-lines').onchange = () => { groups.field.visible = $('show-field-lines').checked; render(); };
  $('show-frames').onclick = showFrames;
  $('cut-pos').oninput = () => { placeCutPlane(); if ($('cut-auto').checked && solid) requestCut(); };
  $('cut-axis').onchange = () => { placeCutPlane(); if ($('cut-auto').checked && solid) requestCut(); };
  $('cut-show').onclick = () => requestCut();
  $('cut-clip').onchange = () => { if (meshData) clipMesh(cuts.length ? cutPlane() : null); render(); };
  $('solid-open').onclick = () => ensureSolid().catch((e) => status(e.message, true));
  $('cut-now').onclick = () => runJob('solid');
  for (const id of ['ref-show', 'ref-draw', 'ref-pos', 'ref-yaw', 'ref-pitch']) $(id).oninput = placeRefPlane;
  for (const id of ['ref-show', 'ref-draw']) $(id).onchange = placeRefPlane;
  $('run').onclick = () => runJob(mode);
  for (const r of document.querySelectorAll('input[name=display]')) r.onchange = applyDisplay;
  const jobs = await (await fetch('/api/jobs')).json().catch(() => ({ jobs: [] }));
  for (const j of jobs.jobs || []) renderJob(j, jobHandlers);
  const want = params.get('mesh');
  if (want && mode !== 'viewer') await openMesh(JSON.parse(want)).catch((e) => status(e.message, true));
  const glb = params.get('glb');
  if (glb) await openGlb(JSON.parse(glb));
  status('ready');
  window.studioMesh.ready = true;
}
start();
