//! Field-aligned lazy solid synthesis with dual-grid correction (paper E §4–5, on
//! Dong, Lefebvre, Tong & Drettakis 2008 and Lefebvre & Hoppe 2005).
//!
//! Every voxel of every level holds a coordinate [`Triple`]. Levels run coarse to fine
//! over the [`super::voxel_lattice`]:
//!
//! 1. **Initialisation** (coarsest level, §4.1): candidate slabs tiled over space and
//!    warped by the field in subparts of `K³` voxels: voxel `v` in subpart `s` (centre
//!    `o`) reads the slab at `w = [Rᵥᵀ (v − o)]`; slab layer `m = ⌊w_z / N⌋` of subpart
//!    `s` is the xy exemplar shifted by a seeded offset, thickened along z by the
//!    z-sticks of each pixel's best candidate triple.
//! 2. **Upsampling** (eq. 3–4): `T(v) = T(v_p) + R_pᵀ (h_c δ)` with `δ = v − 2 v_p` and
//!    the 3-vector added to the triple as `(xy + (d_x, d_y), yz + (d_y, d_z), zx + (d_z, d_x))`.
//! 3. **Correction** (§4.3): three `N × N` neighbourhoods in the planes of the voxel's
//!    frame (`v + R (s, t, 0)` etc.; trilinear interpolation of the voxel colours on the
//!    [`SolidSynthesisOptions::trilinear_levels`] coarsest levels, nearest voxel on the
//!    finer ones, as the paper; on the [`SolidSynthesisOptions::integrate_levels`]
//!    coarsest levels the sample positions follow the field — the paper's numerical
//!    integration along the directions: unit Euler steps along the first in-plane axis
//!    from the voxel, then along the second, each step in the frame where it starts —
//!    elsewhere the centre voxel's frame spans the whole neighbourhood), projected by
//!    each plane's PCA; the candidates
//!    are the `k` best triples of the pixels predicted by the in-plane neighbours
//!    (`[T_P(v + d) − h P_P(d)]`, `d` in the 3 × 3 in-plane offsets, the paper's reduced
//!    set) plus the current triple; the one of least summed squared appearance
//!    distance wins (earliest on ties). `s³ = 8` subpasses by voxel parity, each
//!    reading the state before it.
//! 4. **Dual-grid correction** (§5.3, history windows): a level's first `⌈P/2⌉` passes
//!    run inside primary blocks of side `M` — neighbours outside the block are read at
//!    version 0 (the upsampled value) — and the last `⌊P/2⌋` inside the dual blocks
//!    (shifted by `M/2`), whose outside neighbours are read at the primary grid's final
//!    version. A block's result is therefore a pure function of its version-0 region
//!    (block + halo `r = ⌈N_h √2⌉`), and that region of the parent level's finals.
//!
//! **On demand and deterministic** (§5): a requested voxel set needs the dual blocks
//! holding it, the primary blocks under those blocks' halos, the parent level's dual
//! blocks under the primary blocks' halos, and so on to the coarsest level. Only those
//! blocks are computed (in parallel, each block sequentially), and cached
//! ([`SolidSynthesizer`] keeps them), so a voxel's triple is bit-identical whether it
//! is computed alone, in a cut, in a shell or in the whole volume, for any thread count.
//!
//! This is the 3-D lattice form of the parallel (Lefebvre & Hoppe) engine: the same
//! upsample/correct structure and exemplar stack as [`crate::parallel_synthesis`], with
//! the 2-D grid replaced by the arithmetic voxel lattice, the Jacobian by the frame,
//! and whole-level tabulation replaced by evaluation of a requested subset from its
//! dependency (block) set.

use super::candidate_triples::{CandidateHeads, Triple, wrapped};
use super::solid_exemplar::SolidExemplar;
use super::voxel_lattice::{
    FrameSource, VoxelLattice, dual_block, dual_origin, floor_div, primary_block, primary_origin,
};
use crate::SynthError;
use fieldtex_core::Progress;
use rayon::prelude::*;
use std::collections::{BTreeSet, HashMap};
use std::sync::Arc;
use std::time::Instant;

mod block_regions;
use super::integrated_init::IntegratedInit;

/// Largest grid of the integrated initialisation's solve
/// ([`SolidSynthesisOptions::integrated_init`]).
const INTEGRATED_NODES: usize = 500_000;
mod voxel_colours;
mod voxel_correction;
use block_regions::{BlockCursor, for_box, local_index, region_of};

/// Options of [`SolidSynthesizer`].
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SolidSynthesisOptions {
    /// Block side `M` of the (dual-)grid correction. Default 12 (paper: 10–15).
    pub block: usize,
    /// Correction passes per level below the coarsest (`⌈P/2⌉` primary, `⌊P/2⌋` dual).
    /// Default 2 (the paper's "2 (primary and dual) passes").
    pub passes: usize,
    /// Correction passes at the coarsest level. Default 4 (paper: 3–5).
    pub coarse_passes: usize,
    /// Per-level pass counts, finest level first, overriding `passes` / `coarse_passes`
    /// on the levels they cover (e.g. more passes only on the coarse levels, where
    /// voxels are few). Default empty.
    pub level_passes: Vec<usize>,
    /// `s³ = 8` parity subpasses per pass (default true).
    pub subpasses: bool,
    /// Candidate triples taken per predicted pixel in the correction (`k`). Default 2.
    pub k: usize,
    /// Initialisation subpart side `K`, coarsest-level voxels. Default 64 (the paper's).
    pub subpart: usize,
    /// The correction samples its neighbourhoods by trilinear interpolation on this many
    /// coarsest levels and by the nearest voxel below them (paper E §4.3). Default 3.
    pub trilinear_levels: usize,
    /// On this many coarsest levels the neighbourhood sample positions are integrated
    /// along the field (module docs); sampled trilinearly on the `trilinear_levels`
    /// coarsest, at the nearest voxel below. Default 2.
    pub integrate_levels: usize,
    /// The correction predicts a neighbour's pixel from the neighbour's actual lattice
    /// offset `D` projected into the voxel's frame (`T_P(v + D) − [h P_P(Rᵀ D)]`, paper E
    /// §4.3's `P_xy(d)`), not from the in-plane integer offset `D` was rounded from.
    /// The two agree for axis-aligned frames; for turned ones the rounded offset is up to
    /// half a voxel (`h/2` exemplar pixels per axis) off. Default false (the earlier
    /// bits): on the bent stripes box (docs/solid.md, session 13) it was neutral within
    /// the seed-to-seed spread, so it stays opt-in.
    pub projected_predictions: bool,
    /// Start from one warp of the exemplar along the frame field: the least-squares
    /// integral `U` of the frames ([`super::integrated_init`], on the finest level whose
    /// grid has at most 500 000 voxels) moves one seeded anchor triple per subpart on the
    /// coarsest level, and every upsampling step follows `U` (interpolated at the voxel
    /// centres, rounded so that steps telescope) instead of eq. 3–4 in the parent's
    /// frame. Unless [`Self::level_passes`] says otherwise no level is then corrected,
    /// and colours are read by cubic convolution at each triple moved by the warp's
    /// sub-pixel part ([`SolidSynthesizer::colors`]): a smooth warp of the exemplar,
    /// not a synthesis (with corrections, whole pixels). For layered exemplars
    /// (stripes, wood rings) whose layers should follow the sketch without breaks.
    /// Takes effect once the grid is known ([`SolidSynthesizer::with_extent`]; voxels
    /// off the grid keep the default path).
    /// Default false.
    pub integrated_init: bool,
    pub seed: u64,
}

impl Default for SolidSynthesisOptions {
    fn default() -> Self {
        Self {
            block: 12,
            passes: 2,
            coarse_passes: 4,
            level_passes: Vec::new(),
            subpasses: true,
            k: 2,
            subpart: 64,
            trilinear_levels: 3,
            integrate_levels: 2,
            projected_predictions: false,
            integrated_init: false,
            seed: 1,
        }
    }
}

/// Work done for one level by one request.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct LevelStats {
    pub level: usize,
    /// Blocks computed (not found in the cache).
    pub primary_blocks: usize,
    pub dual_blocks: usize,
    /// Voxels corrected (each once per pass) and candidate evaluations.
    pub corrections: u64,
    pub candidate_evaluations: u64,
    /// Distinct voxels whose final value this request computed (dual blocks × M³).
    pub voxels: u64,
    #[serde(skip)]
    pub seconds: f64,
}

type BlockMap = HashMap<[i32; 3], Arc<Vec<Triple>>>;

#[derive(Default)]
struct LevelCache {
    primary: BlockMap,
    dual: BlockMap,
}

/// Lazy, cached solid synthesis over a [`VoxelLattice`] (module docs).
pub struct SolidSynthesizer<'a> {
    exemplar: &'a SolidExemplar,
    lattice: VoxelLattice,
    frames: &'a dyn FrameSource,
    options: SolidSynthesisOptions,
    cache: Vec<LevelCache>,
    /// Per level and plane, the `k` candidates per pixel the correction reads.
    heads: Vec<[CandidateHeads; 3]>,
    /// Per level and plane, the PCA basis transposed (`N² · channels` rows of
    /// `pca_dims`), so that the correction's projection runs over all dimensions at
    /// once while each dimension still sums its products in the basis's order.
    bases: Vec<[Vec<f32>; 3]>,
    /// Integrated initial coordinates ([`SolidSynthesisOptions::integrated_init`]).
    init: Option<IntegratedInit>,
    /// The integrated start is left uncorrected on every level, so every voxel sits on
    /// the warp and its colour is read at the warp's sub-pixel position
    /// ([`Self::warp_residual`]).
    subpixel: bool,
}

/// The computed blocks of a [`SolidSynthesizer`], detached from its borrows
/// ([`SolidSynthesizer::into_cache`]) so that a caller that owns the exemplar and the
/// frame field can keep the work between requests and hand it to the next
/// synthesizer over the same exemplar, lattice, frames and options
/// ([`SolidSynthesizer::with_cache`]); with anything else changed, drop it.
#[derive(Default)]
pub struct SolidCache {
    levels: Vec<LevelCache>,
}

struct Counts {
    corrections: u64,
    evaluations: u64,
}

impl<'a> SolidSynthesizer<'a> {
    /// A synthesizer with an empty cache.
    pub fn new(
        exemplar: &'a SolidExemplar,
        lattice: VoxelLattice,
        frames: &'a dyn FrameSource,
        options: SolidSynthesisOptions,
    ) -> Result<Self, SynthError> {
        let bad = |name: &'static str, value: usize, reason: &'static str| {
            Err(SynthError::InvalidOption { name, value: value as f64, reason })
        };
        if !(4..=64).contains(&options.block) {
            return bad("SolidSynthesisOptions::block", options.block, "must be between 4 and 64");
        }
        if options.passes > 16 || options.coarse_passes > 32 {
            return bad("SolidSynthesisOptions::passes", options.passes, "at most 16 (32 coarse)");
        }
        if let Some(&p) = options.level_passes.iter().find(|&&p| p > 32) {
            return bad("SolidSynthesisOptions::level_passes", p, "at most 32 per level");
        }
        if options.k == 0 || options.k > exemplar.options.triples {
            return bad("SolidSynthesisOptions::k", options.k, "between 1 and the analysis's N_T");
        }
        if options.subpart == 0 {
            return bad("SolidSynthesisOptions::subpart", 0, "must be positive");
        }
        if !(lattice.spacing.is_finite() && lattice.spacing > 0.0)
            || lattice.origin.iter().any(|v| !v.is_finite())
        {
            return Err(SynthError::InvalidDomain {
                reason: "the voxel lattice needs a finite origin and a spacing > 0".into(),
            });
        }
        let levels = exemplar.options.levels;
        let heads = exemplar
            .triples
            .iter()
            .map(|row| std::array::from_fn(|p| CandidateHeads::new(&row[p], options.k)))
            .collect();
        let bases = (0..levels)
            .map(|c| {
                std::array::from_fn(|p| {
                    let lvl = &exemplar.planes[p].levels[c];
                    let dims = lvl.dims();
                    let dim = lvl.basis.len() / dims.max(1);
                    let mut t = vec![0.0f32; lvl.basis.len()];
                    for j in 0..dims {
                        for i in 0..dim {
                            t[i * dims + j] = lvl.basis[j * dim + i];
                        }
                    }
                    t
                })
            })
            .collect();
        Ok(Self {
            exemplar,
            lattice,
            frames,
            options,
            cache: (0..levels).map(|_| LevelCache::default()).collect(),
            heads,
            bases,
            init: None,
            subpixel: false,
        })
    }

    /// This synthesizer over the finest grid `[0, extent)` (voxel counts per axis): with
    /// [`SolidSynthesisOptions::integrated_init`] the initial coordinates are then
    /// integrated from the frames over the grid's coarsest voxels (voxels outside it
    /// keep the subpart pivots). Without the option it changes nothing. Call it before
    /// any request and give every synthesizer that shares a cache the same extent.
    pub fn with_extent(mut self, extent: [usize; 3]) -> Self {
        if self.options.integrated_init {
            // The finest level whose grid stays within INTEGRATED_NODES voxels (the
            // coarser, the more a turning field is cut into facets), at most the coarsest.
            let coarsest = self.cache.len().saturating_sub(1);
            // Padding in level-g voxels: the finest correction reads `halo` voxels
            // beyond the grid; voxels off the box fall back to eq. 3–4.
            let pad = self.halo() + 2;
            let nodes = |g: usize| -> usize {
                extent.iter().map(|&e| e.div_ceil(1 << g) + 2 * pad as usize).product()
            };
            let g = (0..=coarsest).find(|&g| nodes(g) <= INTEGRATED_NODES).unwrap_or(coarsest);
            self.init = Some(IntegratedInit::new(&self.lattice, self.frames, g, extent, pad));
            self.subpixel = (0..self.cache.len()).all(|c| self.level_passes(c) == 0);
        }
        self
    }

    /// The cached blocks, for [`Self::with_cache`] on a later synthesizer.
    pub fn into_cache(self) -> SolidCache {
        SolidCache { levels: self.cache }
    }

    /// This synthesizer with `cache`'s blocks, which must come from one over the same
    /// exemplar, lattice, frames and options (then every voxel keeps its value); a
    /// cache of another level count is ignored.
    pub fn with_cache(mut self, cache: SolidCache) -> Self {
        if cache.levels.len() == self.cache.len() {
            self.cache = cache.levels;
        }
        self
    }

    /// The lattice placement.
    pub fn lattice(&self) -> VoxelLattice {
        self.lattice
    }

    /// Voxels whose final value is cached, per level (dual blocks × M³).
    pub fn cached_voxels(&self) -> Vec<u64> {
        let m3 = (self.options.block as u64).pow(3);
        self.cache.iter().map(|l| l.dual.len() as u64 * m3).collect()
    }

    fn halo(&self) -> i32 {
        let half = (self.exemplar.options.neighbourhood / 2) as f64;
        ((half * std::f64::consts::SQRT_2).ceil() as i32).max(1)
    }

    /// Final (finest-level) triples of `voxels`, computing only their dependency set
    /// (module docs). Returns per-level statistics of the work done.
    pub fn triples(
        &mut self,
        voxels: &[[i32; 3]],
        progress: &dyn Progress,
    ) -> (Vec<Triple>, Vec<LevelStats>) {
        let levels = self.cache.len();
        let m = self.options.block as i32;
        let r = self.halo();
        // Backward: blocks needed per level, skipping cached ones and their dependencies.
        let mut need_dual: Vec<BTreeSet<[i32; 3]>> = vec![BTreeSet::new(); levels];
        let mut need_primary: Vec<BTreeSet<[i32; 3]>> = vec![BTreeSet::new(); levels];
        for v in voxels {
            let b = dual_block(*v, m);
            if !self.cache[0].dual.contains_key(&b) {
                need_dual[0].insert(b);
            }
        }
        for c in 0..levels {
            let mut prim = BTreeSet::new();
            for b in &need_dual[c] {
                let o = dual_origin(*b, m);
                let lo: [i32; 3] = std::array::from_fn(|a| o[a] - r);
                let hi: [i32; 3] = std::array::from_fn(|a| o[a] + m + r - 1);
                for_box(primary_block(lo, m), primary_block(hi, m), |pb| {
                    if !self.cache[c].primary.contains_key(&pb) {
                        prim.insert(pb);
                    }
                });
            }
            if c + 1 < levels {
                let mut up = BTreeSet::new();
                for b in &prim {
                    let o = primary_origin(*b, m);
                    let lo: [i32; 3] = std::array::from_fn(|a| floor_div(o[a] - r, 2));
                    let hi: [i32; 3] = std::array::from_fn(|a| floor_div(o[a] + m + r - 1, 2));
                    for_box(dual_block(lo, m), dual_block(hi, m), |db| {
                        if !self.cache[c + 1].dual.contains_key(&db) {
                            up.insert(db);
                        }
                    });
                }
                need_dual[c + 1] = up;
            }
            need_primary[c] = prim;
        }
        // Forward: coarse to fine.
        let mut stats = vec![LevelStats::default(); levels];
        for c in (0..levels).rev() {
            let t0 = Instant::now();
            let prim: Vec<[i32; 3]> = need_primary[c].iter().copied().collect();
            let dual: Vec<[i32; 3]> = need_dual[c].iter().copied().collect();
            progress.stage(&format!("solid level {c}"), (prim.len() + dual.len()) as u64);
            let mut st = LevelStats {
                level: c,
                primary_blocks: prim.len(),
                dual_blocks: dual.len(),
                ..Default::default()
            };
            self.compute_blocks(c, &prim, false, &mut st, progress);
            self.compute_blocks(c, &dual, true, &mut st, progress);
            st.voxels = dual.len() as u64 * (m as u64).pow(3);
            st.seconds = t0.elapsed().as_secs_f64();
            progress.finish_stage();
            stats[c] = st;
        }
        let mut finals = BlockCursor::new(&self.cache[0].dual, m, dual_block, dual_origin);
        let out = voxels.iter().map(|v| finals.at(*v)).collect();
        (out, stats)
    }

    /// Computes the level-`c` primary (or `dual`) `blocks` in parallel into the cache,
    /// counting the work in `st`.
    fn compute_blocks(
        &mut self,
        c: usize,
        blocks: &[[i32; 3]],
        dual: bool,
        st: &mut LevelStats,
        progress: &dyn Progress,
    ) {
        let this = &*self;
        let computed: Vec<(Vec<Triple>, Counts)> = blocks
            .par_iter()
            .map(|b| {
                let out = if dual { this.dual_block(c, *b) } else { this.primary_block(c, *b) };
                progress.advance(1);
                out
            })
            .collect();
        let level = &mut self.cache[c];
        let map = if dual { &mut level.dual } else { &mut level.primary };
        for (b, (t, n)) in blocks.iter().zip(computed) {
            st.corrections += n.corrections;
            st.candidate_evaluations += n.evaluations;
            map.insert(*b, Arc::new(t));
        }
    }

    fn frame_f32(&self, c: usize, v: [i32; 3]) -> [f32; 9] {
        self.frames.frame(self.lattice.centre(c, v)).map(|x| x as f32)
    }

    fn wrap(&self, mut t: Triple) -> Triple {
        for p in 0..3 {
            let e = &self.exemplar.planes[p];
            t[p][0] = wrapped(t[p][0], e.width) as i32;
            t[p][1] = wrapped(t[p][1], e.height) as i32;
        }
        t
    }

    /// Version 0 of voxel `v` at the coarsest level `c`: candidate slabs warped by the
    /// field in subparts (§4.1).
    fn initial(&self, c: usize, v: [i32; 3]) -> Triple {
        let n = self.exemplar.options.neighbourhood as i32;
        let h = 1i32 << c;
        let k = self.options.subpart as i32;
        let s: [i32; 3] = std::array::from_fn(|a| floor_div(v[a], k));
        let o: [f64; 3] = std::array::from_fn(|a| (s[a] * k) as f64 + 0.5 * (k - 1) as f64);
        let rm = self.frames.frame(self.lattice.centre(c, v));
        let d: [f64; 3] = std::array::from_fn(|a| v[a] as f64 - o[a]);
        // With the integrated initialisation: one seeded anchor triple per subpart moved
        // by the warp's offset on all three planes, so the xy, yz and zx coordinates
        // stay coherent across voxels (eq. 3–4's mapping of a 3-vector to the planes).
        if let Some(r) = self.init.as_ref().and_then(|u| u.offset(c, v)) {
            let key = subpart_key(s);
            let e0 = &self.exemplar.planes[0];
            let ox = (fieldtex_core::rng::hash_unit(self.options.seed, "solid-anchor-x", key)
                * e0.width as f64) as i32;
            let oy = (fieldtex_core::rng::hash_unit(self.options.seed, "solid-anchor-y", key)
                * e0.height as f64) as i32;
            return self.wrap(moved(*self.exemplar.triples[c][0].get(ox, oy, 0), r));
        }
        // Local coordinates Rᵀ d.
        let w: [i32; 3] = std::array::from_fn(|col| {
            round_f64_i32(rm[col] * d[0] + rm[3 + col] * d[1] + rm[6 + col] * d[2])
        });
        let layer = floor_div(w[2], n);
        let t = w[2] - layer * n - n / 2;
        let key = subpart_key(s) ^ (layer as u32 as u64);
        let e0 = &self.exemplar.planes[0];
        let ox = (fieldtex_core::rng::hash_unit(self.options.seed, "solid-slab-x", key)
            * e0.width as f64) as i32;
        let oy = (fieldtex_core::rng::hash_unit(self.options.seed, "solid-slab-y", key)
            * e0.height as f64) as i32;
        let table = &self.exemplar.triples[c][0];
        let mut tr = *table.get(w[0] * h + ox, w[1] * h + oy, 0);
        tr[1][1] += t * h;
        tr[2][0] += t * h;
        self.wrap(tr)
    }

    /// Version 0 of voxel `v` at level `c` below the coarsest: its parent `pv`'s final
    /// triple `parent` moved by eq. 3–4 in the parent's frame `rm`.
    fn upsampled(
        &self,
        c: usize,
        v: [i32; 3],
        pv: [i32; 3],
        parent: Triple,
        rm: &[f64; 9],
    ) -> Triple {
        let h = 1i32 << c;
        // With the integrated initialisation the step follows the one warp `U` of every
        // level (telescoping between neighbours); elsewhere eq. 3–4 in the parent's frame.
        let warp = self.init.as_ref().and_then(|u| Some((u.offset(c, v)?, u.offset(c + 1, pv)?)));
        let di: [i32; 3] = match warp {
            Some((a, b)) => std::array::from_fn(|k| a[k] - b[k]),
            None => {
                let delta: [f64; 3] = std::array::from_fn(|a| (h * (v[a] - 2 * pv[a])) as f64);
                let d: [f64; 3] = std::array::from_fn(|col| {
                    rm[col] * delta[0] + rm[3 + col] * delta[1] + rm[6 + col] * delta[2]
                });
                d.map(round_f64_i32)
            }
        };
        self.wrap(moved(parent, di))
    }

    fn primary_block(&self, c: usize, b: [i32; 3]) -> (Vec<Triple>, Counts) {
        let m = self.options.block as i32;
        let r = self.halo();
        let s = m + 2 * r;
        let o = primary_origin(b, m);
        let origin: [i32; 3] = std::array::from_fn(|a| o[a] - r);
        let mut region = if c + 1 == self.cache.len() {
            region_of(origin, s, |v| self.initial(c, v))
        } else {
            // The parents of the region: a box at level c + 1, whose frames are looked
            // up once each (eight children share one).
            let lo: [i32; 3] = origin.map(|x| floor_div(x, 2));
            // floor((o + s − 1) / 2) − floor(o / 2) + 1 ≤ s / 2 + 1 for either parity of o.
            let side = s / 2 + 1;
            let frames =
                region_of(lo, side, |pv| self.frames.frame(self.lattice.centre(c + 1, pv)));
            let mut parents = BlockCursor::new(&self.cache[c + 1].dual, m, dual_block, dual_origin);
            region_of(origin, s, |v| {
                let pv: [i32; 3] = v.map(|x| floor_div(x, 2));
                let f = &frames[local_index(pv, lo, side)];
                self.upsampled(c, v, pv, parents.at(pv), f)
            })
        };
        let passes = self.primary_passes(c);
        self.correct(c, origin, s, r, m, &mut region, passes)
    }

    fn dual_block(&self, c: usize, b: [i32; 3]) -> (Vec<Triple>, Counts) {
        let m = self.options.block as i32;
        let r = self.halo();
        let s = m + 2 * r;
        let o = dual_origin(b, m);
        let origin: [i32; 3] = std::array::from_fn(|a| o[a] - r);
        let mut primary =
            BlockCursor::new(&self.cache[c].primary, m, primary_block, primary_origin);
        let mut region = region_of(origin, s, |v| primary.at(v));
        let passes = self.dual_passes(c);
        self.correct(c, origin, s, r, m, &mut region, passes)
    }

    fn level_passes(&self, c: usize) -> usize {
        if let Some(&p) = self.options.level_passes.get(c) {
            p
        } else if self.init.is_some() {
            // The integrated start is not corrected: on the coarse levels the stack has
            // blurred thin layers away and corrections break the warp's phase (session
            // 18); on the finest they replace warp voxels by whole-pixel table triples,
            // which breaks the sub-pixel warp (session 19, docs/solid.md).
            0
        } else if c + 1 == self.cache.len() {
            self.options.coarse_passes
        } else {
            self.options.passes
        }
    }

    fn primary_passes(&self, c: usize) -> usize {
        self.level_passes(c).div_ceil(2)
    }

    fn dual_passes(&self, c: usize) -> usize {
        self.level_passes(c) / 2
    }
}

/// `x` rounded to the nearest integer, halves away from zero (as `f32::round`, without
/// the library call the baseline x86-64 target makes for it; `x` is a small offset).
/// Widening to `f64` is exact, so this is [`round_f64_i32`] of the same value.
#[inline]
fn round_i32(x: f32) -> i32 {
    round_f64_i32(x as f64)
}

/// The seed key of initialisation subpart `s`.
fn subpart_key(s: [i32; 3]) -> u64 {
    fieldtex_core::rng::mix64(
        (s[0] as u32 as u64) ^ ((s[1] as u32 as u64) << 21) ^ ((s[2] as u32 as u64) << 42),
    )
}

/// Triple `t` moved by the local 3-vector `d` (eq. 3–4's mapping to the planes: xy by
/// `(d_x, d_y)`, yz by `(d_y, d_z)`, zx by `(d_z, d_x)`), not wrapped.
fn moved(mut t: Triple, d: [i32; 3]) -> Triple {
    t[0][0] += d[0];
    t[0][1] += d[1];
    t[1][0] += d[1];
    t[1][1] += d[2];
    t[2][0] += d[2];
    t[2][1] += d[0];
    t
}

/// `x` rounded to the nearest integer, halves away from zero (as `f64::round` for
/// `|x| < 2³¹`; the difference `x − trunc(x)` is exact).
#[inline]
fn round_f64_i32(x: f64) -> i32 {
    let t = x as i32;
    let r = x - t as f64;
    if r >= 0.5 {
        t + 1
    } else if r <= -0.5 {
        t - 1
    } else {
        t
    }
}

#[cfg(test)]
mod rounding_tests {
    use super::{round_f64_i32, round_i32};

    #[test]
    fn fast_rounding_equals_the_library_rounding() {
        let mut x = -40.0f32;
        while x < 40.0 {
            for v in [x, f32::from_bits(x.to_bits() + 1), f32::from_bits(x.to_bits() - 1)] {
                assert_eq!(round_i32(v), v.round() as i32, "{v}");
                let w = v as f64 * 1.000_000_1;
                assert_eq!(round_f64_i32(w), w.round() as i32, "{w}");
            }
            x += 0.125;
        }
    }
}
