//! The correction step of lazy solid synthesis (paper E §4.3; module docs of
//! [`super`], step 3): the three in-plane `N × N` neighbourhoods of a voxel's frame,
//! sampled at nearest voxels, trilinearly, or along positions integrated through the
//! field, and the best of the predicted candidate triples. Split from the synthesizer's
//! block and cache logic, which calls [`SolidSynthesizer::correct`] for every pass of a
//! primary or dual block.

use super::*;

impl SolidSynthesizer<'_> {
    /// Corrects the block voxels `[r, r + m)³` of the `s³` region starting at voxel
    /// `origin` for `passes` passes; returns the block (`m³`, x fastest).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn correct(
        &self,
        c: usize,
        origin: [i32; 3],
        s: i32,
        r: i32,
        m: i32,
        region: &mut [Triple],
        passes: usize,
    ) -> (Vec<Triple>, Counts) {
        let mut counts = Counts { corrections: 0, evaluations: 0 };
        let idx = |x: i32, y: i32, z: i32| ((z * s + y) * s + x) as usize;
        if passes > 0 {
            let mut colors: Vec<[f32; 4]> =
                region.iter().map(|t| self.triple_matched(c, t)).collect();
            let mut frames = Vec::with_capacity((m * m * m) as usize);
            for z in 0..m {
                for y in 0..m {
                    for x in 0..m {
                        let v = [origin[0] + r + x, origin[1] + r + y, origin[2] + r + z];
                        frames.push(self.frame_f32(c, v));
                    }
                }
            }
            let mut scratch = Scratch::new(self.exemplar);
            let subpasses = if self.options.subpasses { 8 } else { 1 };
            let mut updates: Vec<(usize, Triple)> = Vec::new();
            for _ in 0..passes {
                for sub in 0..subpasses {
                    updates.clear();
                    for z in 0..m {
                        for y in 0..m {
                            for x in 0..m {
                                let g = [origin[0] + r + x, origin[1] + r + y, origin[2] + r + z];
                                let class = (g[0] & 1) | ((g[1] & 1) << 1) | ((g[2] & 1) << 2);
                                if subpasses == 8 && class != sub {
                                    continue;
                                }
                                let at = [x + r, y + r, z + r];
                                let f = &frames[((z * m + y) * m + x) as usize];
                                let (best, evals) = self.best_candidate(
                                    c,
                                    region,
                                    &colors,
                                    s,
                                    at,
                                    g,
                                    f,
                                    &mut scratch,
                                );
                                counts.corrections += 1;
                                counts.evaluations += evals;
                                let i = idx(at[0], at[1], at[2]);
                                if best != region[i] {
                                    updates.push((i, best));
                                }
                            }
                        }
                    }
                    for &(i, t) in &updates {
                        region[i] = t;
                        colors[i] = self.triple_matched(c, &t);
                    }
                }
            }
        }
        let mut out = Vec::with_capacity((m * m * m) as usize);
        for z in 0..m {
            for y in 0..m {
                for x in 0..m {
                    out.push(region[idx(x + r, y + r, z + r)]);
                }
            }
        }
        (out, counts)
    }

    /// The frame at level-`c` lattice position `g + q` (`q` in level-`c` voxels).
    fn frame_near(&self, c: usize, g: [i32; 3], q: [f64; 3]) -> [f64; 9] {
        let centre = self.lattice.centre(c, g);
        let step = (1i64 << c) as f64 * self.lattice.spacing;
        self.frames.frame(std::array::from_fn(|a| centre[a] + q[a] * step))
    }

    /// Offsets (level-`c` voxels) of the `N × N` samples of plane `(a1, a2)` around
    /// voxel `g`, integrated along the field (module docs), into `out` (`t`-major).
    fn integrated_offsets(
        &self,
        c: usize,
        g: [i32; 3],
        (a1, a2): (usize, usize),
        row: &mut [[f64; 3]],
        out: &mut [[f32; 3]],
    ) {
        let n = self.exemplar.options.neighbourhood;
        let half = n / 2;
        let walk = |from: [f64; 3], axis: usize, dir: f64| -> [f64; 3] {
            let f = self.frame_near(c, g, from);
            std::array::from_fn(|a| from[a] + dir * f[3 * a + axis])
        };
        row[half] = [0.0; 3];
        for step in 1..=half {
            row[half + step] = walk(row[half + step - 1], a1, 1.0);
            row[half - step] = walk(row[half - step + 1], a1, -1.0);
        }
        for (si, start) in row.iter().enumerate().take(n) {
            out[half * n + si] = start.map(|x| x as f32);
            let (mut up, mut down) = (*start, *start);
            for step in 1..=half {
                up = walk(up, a2, 1.0);
                down = walk(down, a2, -1.0);
                out[(half + step) * n + si] = up.map(|x| x as f32);
                out[(half - step) * n + si] = down.map(|x| x as f32);
            }
        }
    }

    /// The best candidate for the voxel at region position `at`, lattice voxel `g`
    /// (§4.3).
    #[allow(clippy::too_many_arguments)]
    fn best_candidate(
        &self,
        c: usize,
        region: &[Triple],
        colors: &[[f32; 4]],
        s: i32,
        at: [i32; 3],
        g: [i32; 3],
        f: &[f32; 9],
        scratch: &mut Scratch,
    ) -> (Triple, u64) {
        let n = self.exemplar.options.neighbourhood as i32;
        let half = n / 2;
        let h = 1i32 << c;
        // Matched channels: RGB, and the feature channel with masks.
        let ch = self.exemplar.channels();
        let idx = |p: [i32; 3]| ((p[2] * s + p[1]) * s + p[0]) as usize;
        let current = region[idx(at)];
        scratch.candidates.clear();
        scratch.candidates.push(current);
        let weights = self.exemplar.options.plane_weights;
        let trilinear = c + self.options.trilinear_levels >= self.cache.len();
        let integrate = c + self.options.integrate_levels >= self.cache.len();
        let projected = self.options.projected_predictions;
        // Integrated samples stay where trilinear interpolation has both corners.
        let reach = self.halo() as f32;
        let nn = (n * n) as usize;
        let base = idx(at) as isize;
        // Region index of every in-plane offset `(s, t)` of every plane (the voxel
        // nearest `at + s·u + t·w`), shared by the neighbourhoods and the candidate
        // predictions; the pixels the 3 × 3 in-plane neighbours predict (the voxel's
        // own at the centre), whose candidate-table entries are asked into the cache
        // now so that those misses overlap the neighbourhood work below (no effect on
        // results).
        for p in 0..3 {
            let (a1, a2) = (p, (p + 1) % 3);
            let u = [f[a1], f[3 + a1], f[6 + a1]];
            let w = [f[a2], f[3 + a2], f[6 + a2]];
            let offsets = &mut scratch.offsets[p * nn..(p + 1) * nn];
            let mut k = 0;
            for t in -half..=half {
                for ss in -half..=half {
                    let (sf, tf) = (ss as f32, t as f32);
                    let d: [i32; 3] = std::array::from_fn(|a| round_i32(sf * u[a] + tf * w[a]));
                    offsets[k] = base + ((d[2] * s + d[1]) * s + d[0]) as isize;
                    if (-1..=1).contains(&ss) && (-1..=1).contains(&t) {
                        scratch.near[p][((t + 1) * 3 + ss + 1) as usize] = d;
                    }
                    k += 1;
                }
            }
            let table = &self.heads[c][p];
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let pix = if dx == 0 && dy == 0 {
                        current[p]
                    } else {
                        let o = offsets[((dy + half) * n + dx + half) as usize] as usize;
                        let nb = region[o][p];
                        if projected {
                            // The neighbour's lattice offset in the frame's plane axes.
                            let d = scratch.near[p][((dy + 1) * 3 + dx + 1) as usize];
                            let df = d.map(|x| x as f32);
                            let l1 = u[0] * df[0] + u[1] * df[1] + u[2] * df[2];
                            let l2 = w[0] * df[0] + w[1] * df[1] + w[2] * df[2];
                            let hf = h as f32;
                            [nb[0] - round_i32(hf * l1), nb[1] - round_i32(hf * l2)]
                        } else {
                            [nb[0] - h * dx, nb[1] - h * dy]
                        }
                    };
                    scratch.predicted[p][((dy + 1) * 3 + dx + 1) as usize] = pix;
                    table.prefetch(pix[0], pix[1]);
                }
            }
        }
        for p in 0..3 {
            let (a1, a2) = (p, (p + 1) % 3);
            let u = [f[a1], f[3 + a1], f[6 + a1]];
            let w = [f[a2], f[3 + a2], f[6 + a2]];
            let lvl = &self.exemplar.planes[p].levels[c];
            // A zero-weight plane contributes candidates but no neighbourhood.
            if weights[p] > 0.0 && trilinear {
                // The halo `r ≥ ⌈N_h √2⌉` holds both corners of every axis: each
                // component of `s u + t w` lies in `[−N_h √2, N_h √2]`; integrated
                // paths can reach further and are clamped to the halo.
                if integrate {
                    self.integrated_offsets(c, g, (a1, a2), &mut scratch.row, &mut scratch.path);
                }
                let mut j = 0;
                for t in -half..=half {
                    for ss in -half..=half {
                        let (sf, tf) = (ss as f32, t as f32);
                        let d: [f32; 3] = if integrate {
                            scratch.path[j].map(|x| x.clamp(-reach, reach - 1e-3))
                        } else {
                            std::array::from_fn(|a| sf * u[a] + tf * w[a])
                        };
                        let fl = d.map(f32::floor);
                        let fr: [f32; 3] = std::array::from_fn(|a| d[a] - fl[a]);
                        let cell =
                            base + ((fl[2] as i32 * s + fl[1] as i32) * s + fl[0] as i32) as isize;
                        let lo = fr.map(|f| 1.0 - f);
                        let mut acc = [0.0f32; 4];
                        for corner in 0..8 {
                            let (cx, cy, cz) = (corner & 1, (corner >> 1) & 1, corner >> 2);
                            let wx = if cx == 1 { fr[0] } else { lo[0] };
                            let wy = if cy == 1 { fr[1] } else { lo[1] };
                            let wz = if cz == 1 { fr[2] } else { lo[2] };
                            let wt = wx * wy * wz;
                            let at = cell + ((cz * s + cy) * s + cx) as isize;
                            let col = &colors[at as usize];
                            for k in 0..ch {
                                acc[k] += wt * col[k];
                            }
                        }
                        scratch.buf[ch * j..ch * (j + 1)].copy_from_slice(&acc[..ch]);
                        j += 1;
                    }
                }
            } else if weights[p] > 0.0 && integrate {
                // Nearest voxel to each integrated sample position (clamped to the halo).
                self.integrated_offsets(c, g, (a1, a2), &mut scratch.row, &mut scratch.path);
                for j in 0..(n * n) as usize {
                    let d = scratch.path[j].map(|x| round_i32(x.clamp(-reach, reach)));
                    let o = base + ((d[2] * s + d[1]) * s + d[0]) as isize;
                    scratch.buf[ch * j..ch * (j + 1)].copy_from_slice(&colors[o as usize][..ch]);
                }
            } else if weights[p] > 0.0 {
                for (j, &o) in scratch.offsets[p * nn..(p + 1) * nn].iter().enumerate() {
                    scratch.buf[ch * j..ch * (j + 1)].copy_from_slice(&colors[o as usize][..ch]);
                }
            }
            let dims = if weights[p] > 0.0 { lvl.dims() } else { 0 };
            if dims > 0 {
                // proj_j = Σ_i basis[j][i] · buf[i] − bias_j, each sum in the order of
                // i, all j at once (the transposed basis's rows).
                let dim = (n * n) as usize * ch;
                let proj = &mut scratch.proj[p][..dims];
                proj.fill(0.0);
                for (row, &b) in self.bases[c][p].chunks_exact(dims).zip(&scratch.buf[..dim]) {
                    for (acc, &a) in proj.iter_mut().zip(row) {
                        *acc += a * b;
                    }
                }
                for (acc, &bias) in proj.iter_mut().zip(&lvl.bias) {
                    *acc -= bias;
                }
            }
        }
        // The candidates: each predicted pixel's `k` table entries, plane by plane in
        // the 3 × 3 offsets' order. A pixel predicted again within a plane adds the
        // same triples again, whose costs equal the first ones', so it is skipped (the
        // earliest of equal costs wins either way: same result).
        for p in 0..3 {
            let table = &self.heads[c][p];
            let pred = &scratch.predicted[p];
            for (j, pix) in pred.iter().enumerate() {
                if pred[..j].contains(pix) {
                    continue;
                }
                for kk in 0..self.options.k {
                    scratch.candidates.push(table.get(pix[0], pix[1], kk));
                }
            }
        }
        // Their appearance vectors into the cache, all at once (no effect on results).
        for cand in &scratch.candidates {
            for p in 0..3 {
                if weights[p] > 0.0 {
                    self.exemplar.prefetch_appearance(p, c, cand[p]);
                }
            }
        }
        let mut best = (f32::INFINITY, current);
        for cand in &scratch.candidates {
            let mut cost = 0.0f32;
            for p in 0..3 {
                if weights[p] == 0.0 {
                    continue;
                }
                let e = &self.exemplar.planes[p];
                let lvl = &e.levels[c];
                let dims = lvl.dims();
                let pix = cand[p][1] as usize * e.width + cand[p][0] as usize;
                let a = &lvl.appearance[pix * dims..(pix + 1) * dims];
                let mut plane_cost = 0.0f32;
                for j in 0..dims {
                    let d = a[j] - scratch.proj[p][j];
                    plane_cost += d * d;
                }
                cost += weights[p] * plane_cost;
            }
            if cost < best.0 {
                best = (cost, *cand);
            }
        }
        (best.1, scratch.candidates.len() as u64)
    }
}

/// Per-block scratch buffers.
struct Scratch {
    buf: Vec<f32>,
    /// Region indices of the `N × N` in-plane offsets of each plane (plane-major).
    offsets: Vec<isize>,
    /// Per plane, the pixels predicted by the 3 × 3 in-plane offsets (row-major).
    predicted: [[[i32; 2]; 9]; 3],
    /// Per plane, the lattice offsets of the 3 × 3 in-plane neighbours (row-major).
    near: [[[i32; 3]; 9]; 3],
    proj: [[f32; 32]; 3],
    candidates: Vec<Triple>,
    /// Integrated sample offsets (`N × N`) and the first axis's path (`N`).
    path: Vec<[f32; 3]>,
    row: Vec<[f64; 3]>,
}

impl Scratch {
    fn new(e: &SolidExemplar) -> Self {
        let n = e.options.neighbourhood;
        Self {
            buf: vec![0.0; n * n * e.channels()],
            offsets: vec![0; 3 * n * n],
            predicted: [[[0; 2]; 9]; 3],
            near: [[[0; 3]; 9]; 3],
            proj: [[0.0; 32]; 3],
            candidates: Vec::with_capacity(64),
            path: vec![[0.0; 3]; n * n],
            row: vec![[0.0; 3]; n],
        }
    }
}
