// Streamline drawing of a sampled direction field on a 2-D canvas.
// The field is `n × n` unit vectors (dx, dy), row-major, y down, covering the design
// rectangle `width × height`. Orientation fields have no sign: each step is flipped to
// continue the previous direction. Seeds lie on a regular grid; a coarse occupancy
// grid stops lines that run into earlier ones, so the spacing stays roughly even.

/** Bilinear lookup of the field at design point (x, y), sign-aligned to `ref`. */
function sample(field, n, sx, sy, x, y, ref) {
  const fx = x / sx - 0.5, fy = y / sy - 0.5;
  const x0 = Math.max(0, Math.min(n - 1, Math.floor(fx)));
  const y0 = Math.max(0, Math.min(n - 1, Math.floor(fy)));
  const x1 = Math.min(n - 1, x0 + 1), y1 = Math.min(n - 1, y0 + 1);
  const tx = Math.max(0, Math.min(1, fx - x0)), ty = Math.max(0, Math.min(1, fy - y0));
  let ax = 0, ay = 0;
  const add = (i, w) => {
    let dx = field[2 * i], dy = field[2 * i + 1];
    if (dx * ref[0] + dy * ref[1] < 0) { dx = -dx; dy = -dy; }
    ax += w * dx; ay += w * dy;
  };
  add(y0 * n + x0, (1 - tx) * (1 - ty));
  add(y0 * n + x1, tx * (1 - ty));
  add(y1 * n + x0, (1 - tx) * ty);
  add(y1 * n + x1, tx * ty);
  const len = Math.hypot(ax, ay);
  return len > 1e-9 ? [ax / len, ay / len] : null;
}

/** Draws streamlines of `field` on `ctx` scaled to the canvas. */
export function drawStreamlines(ctx, field, n, width, height, spacing = 9) {
  const cw = ctx.canvas.width, ch = ctx.canvas.height;
  const sx = width / n, sy = height / n;
  const k = cw / width;
  const cell = spacing * 0.5;
  const gw = Math.ceil(width / cell), gh = Math.ceil(height / cell);
  const occupied = new Uint8Array(gw * gh);
  const occ = (x, y) => {
    const i = Math.floor(x / cell), j = Math.floor(y / cell);
    return i < 0 || j < 0 || i >= gw || j >= gh ? 1 : occupied[j * gw + i];
  };
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, cw, ch);
  ctx.strokeStyle = '#2b3a55';
  ctx.lineWidth = 1;
  const step = Math.min(sx, sy, 2);
  ctx.beginPath(); // one path for all lines: one stroke call
  for (let j = 0; j * spacing < height; j++) {
    for (let i = 0; i * spacing < width; i++) {
      const x0 = (i + 0.5) * spacing, y0 = (j + 0.5) * spacing;
      if (occ(x0, y0)) continue;
      const first = sample(field, n, sx, sy, x0, y0, [1, 0]);
      if (!first) continue;
      const line = [];
      for (const dir of [1, -1]) {
        let x = x0, y = y0, ref = [dir * first[0], dir * first[1]];
        const pts = [];
        const mine = new Set();
        for (let s = 0; s < 200; s++) {
          const v = sample(field, n, sx, sy, x, y, ref);
          if (!v) break;
          x += step * v[0]; y += step * v[1]; ref = v;
          const key = Math.floor(y / cell) * gw + Math.floor(x / cell);
          if (x < 0 || y < 0 || x >= width || y >= height) break;
          if (occupied[key] && !mine.has(key)) break;
          mine.add(key);
          pts.push([x, y]);
        }
        if (dir === 1) line.push(...pts.reverse());
        else { line.reverse(); line.push([x0, y0], ...pts); }
      }
      if (line.length < 4) continue;
      for (const [x, y] of line) {
        const i2 = Math.floor(x / cell), j2 = Math.floor(y / cell);
        if (i2 >= 0 && j2 >= 0 && i2 < gw && j2 < gh) occupied[j2 * gw + i2] = 1;
      }
      ctx.moveTo(line[0][0] * k, line[0][1] * k);
      for (const [x, y] of line) ctx.lineTo(x * k, y * k);
    }
  }
  ctx.stroke();
}

const COLORS = { wedge: '#d62b1a', trisector: '#1a59f2', source: '#e08a00', sink: '#7a3ad6', vortex: '#0a9a6a', saddle: '#444' };

/** Draws the singularities (marker + rotation handle) and strokes. */
export function drawElements(ctx, state, selected, k) {
  ctx.lineWidth = 3;
  for (const s of state.strokes) {
    ctx.strokeStyle = selected && selected.type === 'stroke' && selected.id === s.id ? '#f5a300' : '#0b8f3a';
    ctx.beginPath();
    s.points.forEach(([x, y], i) => (i ? ctx.lineTo(x * k, y * k) : ctx.moveTo(x * k, y * k)));
    ctx.stroke();
  }
  for (const s of state.singularities) {
    const x = s.x * k, y = s.y * k;
    const sel = selected && selected.type === 'singularity' && selected.id === s.id;
    const h = handlePos(s, k);
    ctx.strokeStyle = '#111';
    ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(h[0], h[1]); ctx.stroke();
    ctx.fillStyle = '#fff';
    ctx.beginPath(); ctx.arc(h[0], h[1], 4, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
    ctx.fillStyle = COLORS[s.kind] || '#000';
    ctx.beginPath(); ctx.arc(x, y, sel ? 9 : 7, 0, 2 * Math.PI); ctx.fill();
    ctx.lineWidth = sel ? 3 : 1; ctx.strokeStyle = sel ? '#f5a300' : '#fff'; ctx.stroke();
  }
}

/** Canvas position of a singularity's rotation handle (22 px along α). */
export function handlePos(s, k) {
  const a = (s.angle_deg * Math.PI) / 180;
  return [s.x * k + 22 * Math.cos(a), s.y * k + 22 * Math.sin(a)];
}
