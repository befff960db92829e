#!/usr/bin/env node
// The studio in a real browser: starts `fieldtex studio` on a fresh temporary workspace,
// drives the system Chromium (/usr/bin/chromium, or $CHROMIUM) with playwright-core and
// checks, in order:
//   orient — add a wedge by clicking, check the drawn field's index (winding) is ½
//            around the click and 0 elsewhere, drag it, check the index moved with it
//            and the canvas changed, print the drag → redraw latency (median, p90, max),
//            then the texture latencies after an edit (first 128², then full size);
//   align  — open fandisk, crest lines and streamlines drawn (pixel checks), draw a
//            curve on the surface by dragging, run an align job to completion over
//            server-sent events, open its model.glb in the viewer (pixel checks), then
//            the patch colours and UV checker displays;
//   solid  — draw a sketch curve on the torus and one on the tilted reference plane,
//            open the solid on the server, redraw the frame field through it, move the
//            cut plane slider through seven positions (each cut computed on demand; the
//            last repeats the first and must come from the kept blocks), print the cut
//            latencies, then run a solid job for the cut mesh and show it.
// Screenshots go to tools/studio-browser-test/out/ (and docs/gallery/studio-*.png with
// --gallery). Image checks compare statistics (share of non-background pixels, colour
// spread), never bytes. Any failure, including a browser that cannot start, exits 1.
'use strict';
const { chromium } = require('playwright-core');
const { spawn } = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');

const root = path.resolve(__dirname, '../..');
const bin = process.env.FIELDTEX_BIN || path.join(root, 'target/release/fieldtex');
const shared = process.env.FIELDTEX_SHARED_DATA || path.join(root, '../shared/data');
const browserPath = process.env.CHROMIUM || '/usr/bin/chromium';
const outDir = path.join(__dirname, 'out');
const gallery = process.argv.includes('--gallery') ? path.join(root, 'docs/gallery') : null;
const t0 = Date.now();
let failures = 0;

function log(msg) { console.log(`[studio-browser ${((Date.now() - t0) / 1000).toFixed(1)}s] ${msg}`); }
function check(cond, msg) {
  if (cond) { log(`ok   ${msg}`); } else { failures++; log(`FAIL ${msg}`); }
}
function fatal(msg) {
  console.error(`studio browser test: ${msg}`);
  process.exit(1);
}
function median(xs) { const s = [...xs].sort((a, b) => a - b); return s.length ? s[Math.floor((s.length - 1) / 2)] : NaN; }
function quantile(xs, q) { const s = [...xs].sort((a, b) => a - b); return s.length ? s[Math.min(s.length - 1, Math.floor(q * s.length))] : NaN; }

function startServer(ws) {
  return new Promise((resolve, reject) => {
    const args = ['studio', '--port', '0', '--workspace', ws,
      '--exemplars', path.join(shared, 'exemplars'), '--meshes', path.join(shared, 'meshes')];
    const child = spawn(bin, args, { stdio: ['ignore', 'ignore', 'pipe'] });
    let err = '';
    const timer = setTimeout(() => reject(new Error(`no URL from ${bin} within 20 s: ${err}`)), 20000);
    child.stderr.on('data', (d) => {
      err += d.toString();
      const m = err.match(/http:\/\/[0-9.:]+\//);
      if (m) { clearTimeout(timer); resolve({ child, url: m[0] }); }
    });
    child.on('error', (e) => { clearTimeout(timer); reject(e); });
    child.on('exit', (code) => { clearTimeout(timer); reject(new Error(`${bin} exited with ${code}: ${err}`)); });
  });
}

// Statistics of a canvas (2-D or WebGL with preserveDrawingBuffer) or an image, computed
// in the page: the share of non-background (not near-white) pixels and the colour spread
// over all pixels; with `opaque`, the share of opaque pixels and the spread over those.
const pixelStats = ([sel, opaque]) => {
  const src = document.querySelector(sel);
  const c = document.createElement('canvas');
  c.width = src.naturalWidth || src.width; c.height = src.naturalHeight || src.height;
  const x = c.getContext('2d');
  x.drawImage(src, 0, 0);
  const d = x.getImageData(0, 0, c.width, c.height).data;
  let n = 0; let non = 0; const sum = [0, 0, 0]; const sq = [0, 0, 0];
  for (let i = 0; i < d.length; i += 4) {
    if (opaque && d[i + 3] < 128) continue;
    n++;
    if (d[i] < 245 || d[i + 1] < 245 || d[i + 2] < 245) non++;
    for (let k = 0; k < 3; k++) { sum[k] += d[i + k]; sq[k] += d[i + k] * d[i + k]; }
  }
  const all = Math.max(1, c.width * c.height);
  const varc = sq.map((s, k) => (n ? s / n - (sum[k] / n) ** 2 : 0));
  return { nonBackground: non / all, opaque: n / all, colorStd: Math.sqrt(Math.max(0, (varc[0] + varc[1] + varc[2]) / 3)), width: c.width, height: c.height };
};

async function shot(page, name, selector) {
  const file = path.join(outDir, `${name}.png`);
  if (selector) await page.locator(selector).screenshot({ path: file });
  else await page.screenshot({ path: file });
  if (gallery) fs.copyFileSync(file, path.join(gallery, `${name}.png`));
  log(`screenshot ${path.relative(root, file)}`);
}

async function waitFor(page, fn, arg, timeout, what) {
  try {
    await page.waitForFunction(fn, arg, { timeout, polling: 50 });
    return true;
  } catch (e) {
    failures++;
    log(`FAIL timed out after ${timeout} ms waiting for ${what}`);
    return false;
  }
}

// ------------------------------------------------------------------ orient
async function orientMode(page, url) {
  await page.goto(url);
  await waitFor(page, () => window.studio && window.studio.state, null, 15000, 'the first design');
  await page.click('#new-blank');
  await waitFor(page, () => window.studio.state && window.studio.state.singularities.length === 0 && !window.studio.busy, null, 10000, 'a blank design');
  // The field index around a design point, from the field the page drew.
  await page.evaluate(() => {
    window.fieldIndex = (cx, cy, r) => {
      const s = window.studio.state;
      const f = window.studio.field;
      const n = s.field_size;
      let total = 0; let prev = null;
      for (let k = 0; k <= 64; k++) {
        const a = (2 * Math.PI * k) / 64;
        const x = cx + r * Math.cos(a); const y = cy + r * Math.sin(a);
        const i = Math.min(n - 1, Math.max(0, Math.floor((x / s.width) * n)));
        const j = Math.min(n - 1, Math.max(0, Math.floor((y / s.height) * n)));
        const th = 2 * Math.atan2(f[(j * n + i) * 2 + 1], f[(j * n + i) * 2]); // line field: doubled angle
        if (prev !== null) { let d = th - prev; while (d > Math.PI) d -= 2 * Math.PI; while (d < -Math.PI) d += 2 * Math.PI; total += d; }
        prev = th;
      }
      return total / (2 * Math.PI) / 2;
    };
    const c = document.getElementById('field');
    window.snapshot = () => c.getContext('2d').getImageData(0, 0, c.width, c.height).data.slice();
    window.diffShare = (a, b, x0, y0, w, h) => {
      let changed = 0;
      for (let y = y0; y < y0 + h; y++) for (let x = x0; x < x0 + w; x++) {
        const i = (y * c.width + x) * 4;
        if (Math.abs(a[i] - b[i]) + Math.abs(a[i + 1] - b[i + 1]) + Math.abs(a[i + 2] - b[i + 2]) > 30) changed++;
      }
      return changed / (w * h);
    };
    window.before = window.snapshot();
  });
  const kind = await page.evaluate(() => window.studio.state.kinds[0]);
  await page.click(`#tools button[data-tool="${kind}"]`);
  const canvas = await page.locator('#field').boundingBox();
  const A = [150, 170]; const B = [360, 330]; // canvas pixels (512² canvas)
  await page.mouse.click(canvas.x + A[0], canvas.y + A[1]);
  await waitFor(page, () => window.studio.state.singularities.length === 1 && !window.studio.busy, null, 10000, 'the added singularity');
  const k = await page.evaluate(() => 512 / window.studio.state.width);
  const idx = await page.evaluate(([a, b, k]) => ({
    atA: window.fieldIndex(a[0] / k, a[1] / k, 24 / k),
    atB: window.fieldIndex(b[0] / k, b[1] / k, 24 / k),
    changedNearA: window.diffShare(window.before, window.snapshot(), a[0] - 40, a[1] - 40, 80, 80),
  }), [A, B, k]);
  check(Math.abs(idx.atA - 0.5) < 0.13 || Math.abs(idx.atA + 0.5) < 0.13, `${kind} added by a click: field index around it ${idx.atA.toFixed(2)} (expected ±½)`);
  check(Math.abs(idx.atB) < 0.13, `field index away from it ${idx.atB.toFixed(2)} (expected 0)`);
  check(idx.changedNearA > 0.02, `drawn field changed near the click (${(100 * idx.changedNearA).toFixed(1)} % of pixels)`);
  await shot(page, 'studio-orient-added', '.views');
  // Drag A → B in 30 steps at ~30 Hz, as a hand would (the screenshot may have
  // scrolled the page: measure the canvas again).
  const canvas2 = await page.locator('#field').boundingBox();
  canvas.x = canvas2.x; canvas.y = canvas2.y;
  await page.evaluate(() => { window.studio.timings.length = 0; window.before = window.snapshot(); });
  await page.mouse.move(canvas.x + A[0], canvas.y + A[1]);
  await page.mouse.down();
  for (let s = 1; s <= 30; s++) {
    const x = A[0] + ((B[0] - A[0]) * s) / 30; const y = A[1] + ((B[1] - A[1]) * s) / 30;
    await page.mouse.move(canvas.x + x, canvas.y + y);
    await page.waitForTimeout(33);
  }
  await page.mouse.up();
  await waitFor(page, () => !window.studio.busy, null, 10000, 'the drag to settle');
  const after = await page.evaluate(([a, b, k]) => ({
    sing: window.studio.state.singularities[0],
    atA: window.fieldIndex(a[0] / k, a[1] / k, 24 / k),
    atB: window.fieldIndex(b[0] / k, b[1] / k, 24 / k),
    changedNearB: window.diffShare(window.before, window.snapshot(), b[0] - 40, b[1] - 40, 80, 80),
    timings: window.studio.timings,
  }), [A, B, k]);
  check(Math.hypot(after.sing.x * k - B[0], after.sing.y * k - B[1]) < 3, `singularity dragged to (${(after.sing.x * k).toFixed(0)}, ${(after.sing.y * k).toFixed(0)}) px, expected (${B})`);
  check(Math.abs(Math.abs(after.atB) - 0.5) < 0.13 && Math.abs(after.atA) < 0.13, `field index followed the drag: ${after.atA.toFixed(2)} at the start, ${after.atB.toFixed(2)} at the end`);
  check(after.changedNearB > 0.02, `drawn field changed at the drop point (${(100 * after.changedNearB).toFixed(1)} %)`);
  const lat = after.timings.map((t) => t.event_to_draw_ms);
  const solve = after.timings.map((t) => t.solve_ms);
  check(lat.length >= 5, `${lat.length} drag redraws`);
  log(`LATENCY drag event → field redrawn: median ${median(lat).toFixed(1)} ms, p90 ${quantile(lat, 0.9).toFixed(1)} ms, max ${Math.max(...lat).toFixed(1)} ms over ${lat.length} redraws (server solve median ${median(solve).toFixed(1)} ms; target 50 ms)`);
  // Texture after an edit: three short drags of the singularity (8 px), each waited
  // out until the full-size texture of its design version is shown.
  const full = await page.evaluate(() => Math.min(1024, Math.round(window.studio.state.width)));
  const first = []; const whole = [];
  let at = [...B];
  for (let r = 0; r < 3; r++) {
    const c3 = await page.locator('#field').boundingBox();
    await page.mouse.move(c3.x + at[0], c3.y + at[1]);
    await page.mouse.down();
    at = [at[0] - 8, at[1] - 6];
    await page.mouse.move(c3.x + at[0], c3.y + at[1]);
    await page.mouse.up();
    await waitFor(page, () => !window.studio.busy, null, 10000, 'the edit to settle');
    const version = await page.evaluate(() => window.studio.state.version);
    if (!await waitFor(page, ([v, n]) => window.studio.textureTimings.some((t) => t.version === v && t.size === n), [version, full], 20000, `the ${full}² texture of version ${version}`)) break;
    const t = await page.evaluate((v) => window.studio.textureTimings.filter((x) => x.version === v), version);
    const a = t.find((x) => x.size === 128); const b = t.find((x) => x.size === full);
    if (a) first.push(a.since_edit_ms);
    whole.push(b.since_edit_ms);
    log(`texture after edit ${r + 1}: 128² shown at ${a ? a.since_edit_ms.toFixed(0) : '-'} ms (synthesis ${a ? a.synth_ms.toFixed(0) : '-'} ms), ${full}² at ${b.since_edit_ms.toFixed(0)} ms (synthesis ${b.synth_ms.toFixed(0)} ms)`);
  }
  check(first.length >= 1 && whole.length >= 1, `texture latencies measured (${first.length} first, ${whole.length} full)`);
  log(`LATENCY edit → first texture (128²) shown: median ${median(first).toFixed(0)} ms (target 300 ms); edit → full ${full}² texture shown: median ${median(whole).toFixed(0)} ms (target 1500 ms); ${whole.length} edits, 100 ms debounce included`);
  await shot(page, 'studio-orient', 'main');
  return { median: median(lat), p90: quantile(lat, 0.9), max: Math.max(...lat), n: lat.length, first: median(first), full: median(whole), fullSize: full };
}

// ------------------------------------------------------------------ align + viewer
async function alignMode(page, url) {
  const mesh = encodeURIComponent(JSON.stringify({ root: 'meshes', path: 'fandisk.obj' }));
  await page.goto(`${url}mesh.html?mode=align&mesh=${mesh}`);
  if (!await waitFor(page, () => window.studioMesh && window.studioMesh.ready && window.studioMesh.mesh, null, 30000, 'fandisk to open')) return;
  const crest = await page.evaluate(() => window.studioMesh.mesh.crest.length);
  check(crest > 5, `fandisk crest lines: ${crest}`);
  const s0 = await page.evaluate(pixelStats, ['#viewport canvas', false]);
  check(s0.nonBackground > 0.1, `mesh drawn: ${(100 * s0.nonBackground).toFixed(1)} % of the view`);
  await page.click('#show-field');
  await waitFor(page, () => window.studioMesh.timings.streamlines > 0, null, 20000, 'streamlines');
  const tf = await page.evaluate(() => window.studioMesh.timings);
  log(`field: ${tf.streamlines} streamlines, server ${tf.field_server_ms.toFixed(0)} ms, round trip ${tf.field_round_trip_ms.toFixed(0)} ms`);
  // Draw a curve on the surface: drag across the middle of the view.
  await page.check('#draw');
  const v = await page.locator('#viewport canvas').boundingBox();
  await page.mouse.move(v.x + v.width * 0.42, v.y + v.height * 0.45);
  await page.mouse.down();
  for (let s = 1; s <= 20; s++) {
    await page.mouse.move(v.x + v.width * (0.42 + 0.16 * s / 20), v.y + v.height * (0.45 + 0.06 * s / 20));
  }
  await page.mouse.up();
  const drawn = await page.evaluate(() => window.studioMesh.drawn.map((c) => c.length));
  check(drawn.length === 1 && drawn[0] >= 3, `curve drawn on the surface: ${drawn.length} curve(s), points ${drawn}`);
  await page.uncheck('#draw');
  await shot(page, 'studio-align', 'main');
  // Run align, watch it over SSE, open the result.
  await page.fill('#size', '128');
  const tJob = Date.now();
  await page.click('#run');
  const done = await waitFor(page, () => Object.values(window.studioMesh.jobs).some((j) => j.kind === 'align' && ['done', 'failed', 'cancelled'].includes(j.state)), null, 90000, 'the align job');
  const job = await page.evaluate(() => Object.values(window.studioMesh.jobs).find((j) => j.kind === 'align'));
  if (!done || !job) return;
  check(job.state === 'done', `align job ${job.state}${job.error ? ': ' + job.error : ''} in ${((Date.now() - tJob) / 1000).toFixed(1)} s (server ${job.seconds.toFixed(1)} s)`);
  check(job.files.includes('model.glb') && job.files.includes('report.json'), `job outputs listed: ${job.files.join(', ')}`);
  await waitFor(page, () => window.studioMesh.glbLoaded, null, 20000, 'the GLB in the viewer');
  await page.waitForTimeout(300);
  const sg = await page.evaluate(pixelStats, ['#viewport canvas', false]);
  check(sg.nonBackground > 0.1 && sg.colorStd > 20, `textured result shown: ${(100 * sg.nonBackground).toFixed(1)} % covered, colour std ${sg.colorStd.toFixed(1)}`);
  await shot(page, 'studio-viewer-texture', '#viewport');
  await page.check('input[name=display][value=patches]');
  const patches = await page.evaluate(() => window.studioMesh.patches);
  check(patches >= 2, `patch colours: ${patches} patches`);
  await shot(page, 'studio-viewer-patches', '#viewport');
  await page.check('input[name=display][value=checker]');
  const sc = await page.evaluate(pixelStats, ['#viewport canvas', false]);
  check(sc.colorStd > 30, `UV checker shown: colour std ${sc.colorStd.toFixed(1)}`);
  await shot(page, 'studio-viewer-checker', '#viewport');
  await page.check('input[name=display][value=wireframe]');
  await shot(page, 'studio-viewer-wireframe', '#viewport');
}

// ------------------------------------------------------------------ solid
async function dragAcross(page, from, to) {
  const v = await page.locator('#viewport canvas').boundingBox();
  await page.mouse.move(v.x + v.width * from[0], v.y + v.height * from[1]);
  await page.mouse.down();
  for (let s = 1; s <= 20; s++) await page.mouse.move(v.x + v.width * (from[0] + (to[0] - from[0]) * s / 20), v.y + v.height * (from[1] + (to[1] - from[1]) * s / 20));
  await page.mouse.up();
}

async function solidMode(page, url) {
  const mesh = encodeURIComponent(JSON.stringify({ root: 'meshes', path: 'torus.obj' }));
  await page.goto(`${url}mesh.html?mode=solid&mesh=${mesh}`);
  if (!await waitFor(page, () => window.studioMesh && window.studioMesh.ready && window.studioMesh.mesh, null, 30000, 'the torus to open')) return;
  await page.uncheck('#cut-auto');
  // A curve on the surface.
  await page.check('#draw');
  await dragAcross(page, [0.3, 0.5], [0.5, 0.4]);
  await page.uncheck('#draw');
  // A curve on the reference plane: tilted, moved, then drawn on by ray picking.
  await page.check('#ref-draw');
  for (const [id, v] of [['ref-pitch', '70'], ['ref-yaw', '30'], ['ref-pos', '0.05']]) {
    await page.evaluate(([i, x]) => { const e = document.getElementById(i); e.value = x; e.dispatchEvent(new Event('input')); }, [id, v]);
  }
  await dragAcross(page, [0.35, 0.55], [0.65, 0.5]);
  await page.uncheck('#ref-draw');
  await page.check('#ref-show');
  const sk = await page.evaluate(() => window.studioMesh.sketch.map((c) => ({ n: c.points.length, plane: !!c.plane })));
  check(sk.length === 2 && !sk[0].plane && sk[1].plane && sk[1].n >= 3, `sketch: a surface curve and a reference-plane curve (${JSON.stringify(sk)})`);
  const onPlane = await page.evaluate(() => {
    const c = window.studioMesh.sketch[1];
    const n = c.plane.normal; const o = c.plane.point;
    return Math.max(...c.points.map((p) => Math.abs((p[0] - o[0]) * n[0] + (p[1] - o[1]) * n[1] + (p[2] - o[2]) * n[2])));
  });
  check(onPlane < 1e-6, `reference-plane curve lies on its plane (max distance ${onPlane.toExponential(1)})`);
  // Open the solid (exemplar analysis, frame field of both curves).
  await page.fill('#solid-res', '64');
  const tOpen = Date.now();
  await page.click('#solid-open');
  if (!await waitFor(page, () => window.studioMesh.solid && window.studioMesh.timings.solid_open_ms > 0, null, 60000, 'the open solid')) return;
  const to = await page.evaluate(() => window.studioMesh.timings);
  log(`solid opened in ${((Date.now() - tOpen) / 1000).toFixed(1)} s (server build ${to.solid_build_server_ms.toFixed(0)} ms: exemplar analysis + frame field)`);
  // A sketch edit through the open solid (the frames redrawn).
  await page.click('#show-frames');
  await waitFor(page, () => window.studioMesh.timings.sketch_edit_server_ms >= 0, null, 20000, 'the frame field');
  const tf = await page.evaluate(() => window.studioMesh.timings);
  log(`frame field redraw: server ${tf.frames_server_ms.toFixed(0)} ms, round trip ${tf.frames_round_trip_ms.toFixed(0)} ms`);
  await shot(page, 'studio-solid-sketch', 'main');
  // Cuts: the first, then the slider moved through five positions (each redrawn from the
  // open solid), then back to the first position (the kept blocks).
  await page.selectOption('#cut-axis', '1'); // normal y: the torus's ring
  await page.check('#cut-auto');
  const cutAt = async (v, what) => {
    const before = await page.evaluate(() => window.studioMesh.cuts.length);
    await page.evaluate((x) => { const e = document.getElementById('cut-pos'); e.value = x; e.dispatchEvent(new Event('input')); }, v);
    return waitFor(page, (b) => window.studioMesh.cuts.length > b, before, 30000, what);
  };
  if (!await cutAt('0.5', 'the first cut')) return;
  for (const v of ['0.45', '0.4', '0.35', '0.6', '0.65']) await cutAt(v, `the cut at ${v}`);
  await cutAt('0.5', 'the cut at 0.5 again');
  const cs = await page.evaluate(() => window.studioMesh.cuts);
  const later = cs.slice(1, -1).map((c) => c.shown_ms);
  check(cs.length === 7, `${cs.length} cuts drawn from the open solid`);
  check(cs[cs.length - 1].computed === 0, `the repeated cut came from the kept blocks (${cs[cs.length - 1].computed} voxels computed)`);
  const st = await page.evaluate(pixelStats, ['#cut-image', true]);
  check(st.opaque > 0.2 && st.colorStd > 5, `cut image ${st.width}×${st.height}: ${(100 * st.opaque).toFixed(0)} % inside, colour std ${st.colorStd.toFixed(1)}`);
  log(`LATENCY cut plane moved → cut image shown: first cut ${cs[0].shown_ms.toFixed(0)} ms (server ${cs[0].server_ms.toFixed(0)} ms, ${cs[0].computed} voxels computed); later cuts median ${median(later).toFixed(0)} ms, max ${Math.max(...later).toFixed(0)} ms (server median ${median(cs.slice(1, -1).map((c) => c.server_ms)).toFixed(0)} ms); repeated cut ${cs[cs.length - 1].shown_ms.toFixed(0)} ms`);
  await shot(page, 'studio-solid', 'main');
  // The cut mesh as a solid job (capped mesh part, textured from the same solid).
  await page.uncheck('#cut-auto');
  await page.fill('#solid-res', '32');
  await page.fill('#size', '128');
  const tJob = Date.now();
  await page.click('#cut-now');
  const done = await waitFor(page, () => Object.values(window.studioMesh.jobs).some((j) => j.kind === 'solid' && ['done', 'failed', 'cancelled'].includes(j.state)), null, 90000, 'the solid cut job');
  const job = await page.evaluate(() => Object.values(window.studioMesh.jobs).find((j) => j.kind === 'solid'));
  if (!done || !job) return;
  check(job.state === 'done', `solid cut-mesh job ${job.state}${job.error ? ': ' + job.error : ''} in ${((Date.now() - tJob) / 1000).toFixed(1)} s`);
  await waitFor(page, () => (window.studioMesh.glbLoaded || '').endsWith('cut-1.glb'), null, 10000, 'the cut mesh');
  const sg = await page.evaluate(pixelStats, ['#viewport canvas', false]);
  check(sg.nonBackground > 0.05 && sg.colorStd > 10, `cut mesh shown: ${(100 * sg.nonBackground).toFixed(1)} % covered, colour std ${sg.colorStd.toFixed(1)}`);
  await shot(page, 'studio-solid-cut-mesh', 'main');
  return { first: cs[0].shown_ms, later: median(later), firstServer: cs[0].server_ms };
}

async function main() {
  if (!fs.existsSync(bin)) fatal(`${bin} not found: build it first (cargo build --release -p fieldtex-cli)`);
  if (!fs.existsSync(browserPath)) fatal(`${browserPath} not found: install Chromium (apt-get install -y chromium) or set CHROMIUM`);
  if (!fs.existsSync(path.join(shared, 'meshes/fandisk.obj'))) fatal(`shared data not found at ${shared} (set FIELDTEX_SHARED_DATA)`);
  fs.mkdirSync(outDir, { recursive: true });
  if (gallery) fs.mkdirSync(gallery, { recursive: true });
  const ws = fs.mkdtempSync(path.join(os.tmpdir(), 'fieldtex-studio-browser-'));
  const { child, url } = await startServer(ws);
  log(`studio at ${url}, workspace ${ws}`);
  let browser;
  try {
    browser = await chromium.launch({
      executablePath: browserPath,
      headless: true,
      args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
    });
  } catch (e) {
    child.kill();
    fatal(`the browser did not start (${browserPath}): ${e.message}`);
  }
  let latency = null;
  let solidLatency = null;
  try {
    const page = await browser.newPage({ viewport: { width: 1120, height: 720 } });
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    latency = await orientMode(page, url);
    await alignMode(page, url);
    solidLatency = await solidMode(page, url);
    check(errors.length === 0, `no uncaught page errors${errors.length ? ': ' + errors.join(' | ') : ''}`);
  } catch (e) {
    failures++;
    log(`FAIL ${e.stack || e}`);
  } finally {
    await browser.close();
    child.kill();
    fs.rmSync(ws, { recursive: true, force: true });
  }
  const secs = (Date.now() - t0) / 1000;
  if (latency) log(`summary: drag → field median ${latency.median.toFixed(1)} ms (p90 ${latency.p90.toFixed(1)}, max ${latency.max.toFixed(1)}, n ${latency.n}); edit → first texture ${latency.first.toFixed(0)} ms, → full ${latency.fullSize}² ${latency.full.toFixed(0)} ms`);
  if (solidLatency) log(`summary: cut shown: first ${solidLatency.first.toFixed(0)} ms (server ${solidLatency.firstServer.toFixed(0)} ms), later median ${solidLatency.later.toFixed(0)} ms`);
  log(`${secs.toFixed(1)} s in all`);
  // One machine-readable line for bench/studio_browser.sh.
  console.log(`METRICS ${JSON.stringify({
    drag_median_ms: latency ? latency.median : null,
    texture_first_ms: latency ? latency.first : null,
    texture_full_ms: latency ? latency.full : null,
    cut_first_ms: solidLatency ? solidLatency.first : null,
    cut_later_ms: solidLatency ? solidLatency.later : null,
    total_s: secs,
  })}`);
  if (failures) fatal(`${failures} check(s) failed`);
  log('all checks passed');
}

main().catch((e) => fatal(e.stack || String(e)));
