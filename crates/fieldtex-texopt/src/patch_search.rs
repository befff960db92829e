//! Nearest-exemplar-patch search for one sample (Kwatra et al. 2005 §3, search step;
//! paper A §5.2 constrained candidates).
//!
//! The sample's current colours are gathered into the `8 × 8` descriptor grid of its
//! oriented patch: every *active* carrier (all carriers at `w = 8`, a subset about
//! `0.75·s·h` apart for coarser patches) within the footprint (same side of the surface, patch
//! coordinates in `[−½, 7½)²`) is splatted bilinearly onto the grid, and empty grid
//! points take the patch mean. Candidates, each compared with the exact 192-D distance:
//! - the sample's previous match;
//! - coherence: each neighbouring sample's previous match shifted by the offset of this
//!   sample in the neighbour's patch frame (Ashikhmin 2001 / Kwatra 2005 style);
//! - seeded random positions;
//! - the two best positions of an exhaustive scan in PCA space, over all positions when
//!   `samples × positions` fits the budget, else over a strided subset (the same for
//!   all samples of an iteration, shifted between iterations).
//!
//! A *constrained* sample (paper A §5.2: curve distance `d < w/2` pixels) only accepts
//! positions whose centre's feature distance is within the threshold of `d`; its PCA
//! scan runs over the feature-distance bins around `d` (at most 1024 positions, strided)
//! instead. When no position qualifies the constraint is dropped for that sample.

use crate::exemplar_patches::{DIM, GRID, HALF};
use crate::texture_optimisation::LevelContext;
use fieldtex_core::rng::stream_seed;
use fieldtex_core::vec3::{dot, sub};

/// Most candidates per sample.
const MAX_CANDIDATES: usize = 48;
/// Cap on the positions scanned for a constrained sample.
const MAX_CONSTRAINED_SCAN: usize = 1024;

/// Where a sample's patch sits in the exemplar: an integer position (whose descriptor
/// is compared) and an offset of the origin within half the origin lattice's stride
/// (`[−½, ½]²` pixels at stride 1), inherited from
/// coherence so that neighbouring patches copied from one exemplar region agree exactly
/// (no blur from rounding).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Placement {
    pub position: u32,
    pub offset: [f32; 2],
}

impl Placement {
    pub fn at(position: u32) -> Self {
        Self { position, offset: [0.0; 2] }
    }
}

/// Outcome of one sample's search.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Match {
    pub placement: Placement,
    /// Squared 192-D distance between the gathered patch and the match.
    pub distance2: f32,
    /// Whether the feature constraint was applied.
    pub constrained: bool,
}

/// Gathers the current colours of sample `p`'s patch into `out`; returns false when no
/// carrier lies in the footprint.
pub(crate) fn gather_patch(
    ctx: &LevelContext,
    colors: &[[f32; 4]],
    p: usize,
    out: &mut [f32; DIM],
) -> bool {
    let f = &ctx.frames[p];
    let mut acc = [0.0f32; DIM];
    let mut wsum = [0.0f32; GRID * GRID];
    ctx.carrier_grid.for_each_within(&ctx.active_positions, f.pos, ctx.radius, |a, _| {
        let c = ctx.active[a as usize] as usize;
        let Some((u, v)) = ctx.footprint_coords(p, c) else {
            return;
        };
        let (u, v) = (u.clamp(0.0, HALF * 2.0), v.clamp(0.0, HALF * 2.0));
        let (i0, j0) = ((u.floor() as usize).min(GRID - 2), (v.floor() as usize).min(GRID - 2));
        let (a, b) = ((u - i0 as f64) as f32, (v - j0 as f64) as f32);
        let col = colors[c];
        for (di, dj, wt) in [
            (0, 0, (1.0 - a) * (1.0 - b)),
            (1, 0, a * (1.0 - b)),
            (0, 1, (1.0 - a) * b),
            (1, 1, a * b),
        ] {
            let g = (j0 + dj) * GRID + i0 + di;
            wsum[g] += wt;
            for k in 0..3 {
                acc[g * 3 + k] += wt * col[k];
            }
        }
    });
    let total: f32 = wsum.iter().sum();
    if total <= 0.0 {
        return false;
    }
    let mut mean = [0.0f32; 3];
    for g in 0..GRID * GRID {
        for k in 0..3 {
            mean[k] += acc[g * 3 + k];
        }
    }
    for m in &mut mean {
        *m /= total;
    }
    for g in 0..GRID * GRID {
        for k in 0..3 {
            out[g * 3 + k] = if wsum[g] > 1e-6 { acc[g * 3 + k] / wsum[g] } else { mean[k] };
        }
    }
    true
}

struct Candidates {
    list: [Placement; MAX_CANDIDATES],
    len: usize,
}

impl Candidates {
    fn push(&mut self, c: Placement) {
        if self.len < MAX_CANDIDATES
            && !self.list[..self.len].iter().any(|o| o.position == c.position)
        {
            self.list[self.len] = c;
            self.len += 1;
        }
    }
}

/// Keeps the two smallest `(distance, position)` pairs.
#[inline]
fn keep_best(best: &mut [(f32, u32); 2], d: f32, c: u32) {
    if d < best[0].0 {
        best[1] = best[0];
        best[0] = (d, c);
    } else if d < best[1].0 {
        best[1] = (d, c);
    }
}

/// Searches the best exemplar position for sample `p` given the previous matches.
pub(crate) fn search_sample(
    ctx: &LevelContext,
    colors: &[[f32; 4]],
    prev: &[Placement],
    p: usize,
    iteration: usize,
) -> Match {
    let lvl = ctx.level;
    let m = lvl.len() as u64;
    let mut x = [0.0f32; DIM];
    if !gather_patch(ctx, colors, p, &mut x) {
        return Match { placement: prev[p], distance2: 0.0, constrained: false };
    }
    let mut cand = Candidates { list: [Placement::at(0); MAX_CANDIDATES], len: 0 };
    cand.push(prev[p]);
    let f = &ctx.frames[p];
    let s = lvl.step as f64;
    for &q in &ctx.neighbours[p * ctx.k_neighbours..(p + 1) * ctx.k_neighbours] {
        if q == u32::MAX {
            break;
        }
        let fq = &ctx.frames[q as usize];
        let pq = prev[q as usize];
        let [ox, oy] = lvl.origin(pq.position);
        let d = sub(f.pos, fq.pos);
        let x = ox as f64 + pq.offset[0] as f64 + dot(d, fq.tx) * s;
        let y = oy as f64 + pq.offset[1] as f64 + dot(d, fq.ty) * s;
        cand.push(lvl.placement_near(x, y));
    }
    let n_coherent = cand.len;
    // Random search (PatchMatch style): alternately uniform over the exemplar and in a
    // window around the previous match that halves with each draw.
    let rbase = ((ctx.level_index as u64 * 1024 + iteration as u64) << 36) | ((p as u64) << 4);
    let [px, py] = lvl.origin(prev[p].position);
    let mut window = lvl.width.max(lvl.height) as f64 * 0.25;
    for k in 0..ctx.random_candidates.min(16) {
        let r = stream_seed(ctx.seed, "texopt-random", rbase | k as u64);
        if k % 2 == 0 {
            cand.push(Placement::at((r % m) as u32));
        } else {
            let (a, b) =
                ((r >> 11) as u32 as f64 / u32::MAX as f64, (r >> 43) as f64 / (1u64 << 21) as f64);
            let (dx, dy) = ((2.0 * a - 1.0) * window, (2.0 * b - 1.0) * window);
            cand.push(Placement::at(lvl.position_near(px as f64 + dx, py as f64 + dy)));
            window = (window * 0.5).max(2.0);
        }
    }
    let mut q = [0.0f32; DIM];
    lvl.project(&x, &mut q);
    let q = &q[..lvl.kp];
    let mut best = [(f32::INFINITY, u32::MAX); 2];
    let mut constrained = false;
    if let (Some(dp), Some(cd)) = (ctx.constraint[p], lvl.centre_distance.as_ref()) {
        let thr = ctx.feature_threshold as f32;
        let lo = (dp - thr).max(0.0).round() as usize;
        let hi = ((dp + thr).round() as usize).min(lvl.feature_bins.len().saturating_sub(1));
        let n: usize = lvl.feature_bins.get(lo..=hi).map_or(0, |b| b.iter().map(Vec::len).sum());
        if n > 0 {
            constrained = true;
            let stride = n.div_ceil(MAX_CONSTRAINED_SCAN);
            let offset = (p + iteration) % stride;
            let mut i = 0usize;
            for bin in &lvl.feature_bins[lo..=hi] {
                for &c in bin {
                    if i % stride == offset && (cd[c as usize] - dp).abs() <= thr {
                        let d = lvl.coord_distance2(q, c, best[1].0);
                        keep_best(&mut best, d, c);
                    }
                    i += 1;
                }
            }
            // Keep only the earlier candidates that satisfy the constraint.
            let mut kept = 0;
            for i in 0..cand.len {
                let c = cand.list[i];
                if (cd[c.position as usize] - dp).abs() <= thr {
                    cand.list[kept] = c;
                    kept += 1;
                }
            }
            cand.len = kept;
        }
    }
    if !constrained {
        let pairs = ctx.samples as u64 * m;
        let stride = pairs.div_ceil(ctx.exact_budget.max(1) as u64).max(1);
        // One subset per iteration for all samples (cache friendly), shifted each time.
        let offset = stream_seed(ctx.seed, "texopt-scan", rbase >> 36) % stride;
        let mut c = offset;
        while c < m {
            let d = lvl.coord_distance2(q, c as u32, best[1].0);
            keep_best(&mut best, d, c as u32);
            c += stride;
        }
    }
    for (_, c) in best {
        if c != u32::MAX {
            cand.push(Placement::at(c));
        }
    }
    let mut out = Match { placement: prev[p], distance2: f32::INFINITY, constrained };
    let mut best_score = f32::INFINITY;
    // Constrained samples (paper A §5.2) put feature alignment first: no bias (their
    // candidate list was also filtered, so its first entries are not all coherent).
    let penalty = if constrained { 1.0 } else { 1.0 + ctx.coherence_bias as f32 };
    for (i, &c) in cand.list[..cand.len].iter().enumerate() {
        let d = lvl.distance2(&x, c.position);
        // Ashikhmin-style coherence bias: a jump to an unrelated exemplar place must be
        // clearly better than continuing a neighbour's (or its own) patch.
        let score = if i < n_coherent.min(cand.len) { d } else { d * penalty };
        if score < best_score {
            best_score = score;
            out.distance2 = d;
            out.placement = c;
        }
    }
    if !out.distance2.is_finite() {
        out.distance2 = lvl.distance2(&x, out.placement.position);
    }
    out
}
