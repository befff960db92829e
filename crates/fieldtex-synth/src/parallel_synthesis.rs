//! Parallel controllable texture synthesis over a [`SynthesisDomain`]
//! (Lefebvre & Hoppe 2005 "Parallel controllable texture synthesis"; 2006
//! "Appearance-space texture synthesis", anisometric synthesis §6; the 2-RoSy
//! modifications of paper D §4 "Handling orientation").
//!
//! The output is a map `S` from samples to continuous exemplar coordinates plus a flip
//! bit `I` per sample. With `F(p) = (−1)^I(p) J(p)` the *effective* frame of sample
//! `p`, one level `c` (spacing `h = 2^c`) runs:
//! 1. **Upsampling**: a child at offset `o ∈ {±½}²` from its parent `p` gets
//!    `S = S[p] + h F(p) o` (with [`SynthesisOptions::trapezoid_frames`] the mean of
//!    `F(p)` and the child's `J` sign-aligned with it replaces `F(p)`) and
//!    `I = I[p] ⊕ c(p, child)`, where the consistency
//!    `c(a, b)` is true when the representative frames of `a` and `b` point in opposite
//!    directions (Frobenius product `⟨J(a), J(b)⟩ < 0`, i.e. `u(a)·u(b) < 0` for
//!    rotations).
//! 2. **Jitter**: `S += a h ξ`, `ξ ∈ [−1, 1]²` from
//!    `hash_unit(seed, "synthesis-jitter", …)`, `a` = [`SynthesisOptions::jitter`],
//!    none on the [`SynthesisOptions::unjittered_levels`] finest levels; with
//!    [`SynthesisOptions::snap_coordinates`] the offset is rounded to whole pixels and
//!    the initial coordinates are integers (Lefebvre & Hoppe 2005 §3.2).
//! 3. **Correction** (`passes × subpasses`, 2×2 interleaved): each neighbour `q = p + δ`
//!    predicts `P = S[q] − h F(q) δ` with flip `α = I[q] ⊕ c(q, p)` — the corrected
//!    prediction `P̃` of paper D, which uses the neighbour's Jacobian and flip (with
//!    [`SynthesisOptions::trapezoid_frames`], default, `½(F(q) + (−1)^α J(p))` replaces
//!    `F(q)`: the trapezoid rule along the offset, exact to second order on a turning
//!    field). The
//!    four-corner neighbourhood of `p` averages, for each corner `Δ ∈ {±1}²`, the
//!    appearance `Ẽ_α[P + (−1)^α h Δ]` over the three neighbours whose directions are
//!    closest to the warped offset `J(p)⁻¹ Δ` (Lefebvre & Hoppe 2006 §6 use the same
//!    three predictions chosen by rounding the warped offset; choosing the three
//!    angularly nearest of the eight neighbours is our simplification, identical for
//!    `J = I`). Candidates are every prediction `(P, α)`, the k-coherence jumps
//!    `S[q] + C′ᵢ(S[q]) − h F(q) δ` with flip `α`, `p`'s current value and (with
//!    [`SynthesisOptions::own_candidates`]) its own jumps `S[p] + C′ᵢ(S[p])`; the one
//!    whose exemplar neighbourhood `Ẽ_β[u + (−1)^β h Δ]` (4 × 8 = 32-D) is closest wins
//!    (ties: the earlier candidate, the current value first) and sets `S[p]`, `I[p]`.
//!    With [`SynthesisOptions::keep_flips`] (default) only candidates with `α = I[p]`
//!    take part, so `I` changes only through the upsampling bits `c`.
//! 4. **Colours**: after the finest level, `E[S[p]]` read with
//!    [`SynthesisOptions::color_filter`] (cubic convolution by default,
//!    [`mod@crate::color_lookup`]).
//!
//! Flip indicators start combed on the initialisation level
//! ([`SynthesisOptions::comb_flips`], [`crate::flip_combing`]), so the effective frame
//! has seams only where the field's singularities force them.
//!
//! Why the 2-RoSy fix did not reduce the defect count near singularities (issue 3),
//! measured: `docs/perf/orient-synthesis.md`.
//!
//! Speed: the 32-D neighbourhood vector of every exemplar pixel (both copies) is
//! tabulated per level, so a candidate costs one 32-byte load and an exact integer
//! distance; candidates are gathered first and scored in one branch-free sweep; on CPUs
//! with AVX2 the correction runs an AVX2 build (bit-identical results). The finest
//! level holds ¾ of the samples, so [`SynthesisOptions::finest_passes`] (default 2)
//! is separate from level 1's [`SynthesisOptions::correction_passes`] (6) and the
//! cheap levels `c ≥ 2`' [`SynthesisOptions::coarse_passes`] (12).
//!
//! With [`SynthesisOptions::rosy_fix`] off, the engine is plain anisometric synthesis:
//! predictions use `J(p)`, no flips, only `Ẽ₀` (the ablation of paper D Fig. 5).
//!
//! Not implemented: the second PCA of the neighbourhood vectors (a GPU memory
//! optimisation), feature-distance channels, per-level jitter amplitudes (only
//! [`SynthesisOptions::unjittered_levels`], default 1), scale-dependent
//! stack levels (with `scale ≠ 1` level `c` still uses stack level `c`).

use std::time::Instant;

use fieldtex_core::rng::hash_unit;
use fieldtex_core::{Image, Progress};
use rayon::prelude::*;

use crate::color_lookup::color_lookup;
use crate::exemplar_analysis::{APPEARANCE_DIMS, ExemplarAnalysis};
use crate::exemplar_level::{ExemplarLevel, NV, NvEntry, dist_nv};
use crate::flip_combing::comb_flips;
use crate::integrated_coordinates::IntegratedStart;
use crate::lattice_domain::{
    Dim, LatticeDomain, PlanarDomain, Stencil, frobenius, mat_vec, mean, negated,
};
use crate::level_tables::{LevelTables, NONE, tabulate};
pub use crate::synthesis_options::SynthesisOptions;
use crate::synthesis_options::{MAX_K, validate};
use crate::synthesis_subset::SubsetPlan;
use crate::warped_neighbourhood::{corner_map, inverse_frame, warped_corner};
use crate::{SynthError, SynthesisDomain};

/// Result of [`synthesize`]: per finest-level sample (row-major over
/// [`SynthesisDomain::output_size`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SynthesisResult {
    /// Exemplar colour at each sample's coordinate ([`SynthesisOptions::color_filter`]).
    pub colors: Image,
    /// Exemplar coordinate of each sample, in `[0, W) × [0, H)`.
    pub coords: Vec<[f32; 2]>,
    /// Flip indicator of each sample (the sample shows the exemplar turned by 180°).
    pub flips: Vec<bool>,
    /// Wall time per synthesis level, coarsest first, milliseconds.
    pub level_timings_ms: Vec<f64>,
}

/// Candidates of one correction at most on a lattice with `s` neighbours: per neighbour
/// its prediction and k jumps, and p's own k jumps.
pub(crate) const fn max_candidates(s: usize) -> usize {
    s * (1 + MAX_K) + MAX_K
}
/// Per-level synthesis context on a `D`-dimensional lattice with `S` neighbours and room
/// for `C` ([`max_candidates`]`(S)`) candidates.
struct Pass<'a, const D: usize, const S: usize, const C: usize> {
    ex: ExemplarLevel,
    t: &'a LevelTables<D, S>,
    spacing: f32,
    k: usize,
    rosy: bool,
    own: bool,
    /// [`SynthesisOptions::keep_flips`] (with the 2-RoSy fix).
    keep_flips: bool,
    /// Whether the CPU supports AVX2 (the correction then runs the AVX2 build).
    avx2: bool,
    /// [`SynthesisOptions::trapezoid_frames`] (with the 2-RoSy fix).
    trapezoid: bool,
    /// [`SynthesisOptions::warped_corners`] (with the 2-RoSy fix): the appearance
    /// images `[Ẽ₀, Ẽ₁]` the warped corners read.
    warp: Option<[&'a [[i8; APPEARANCE_DIMS]]; 2]>,
}

impl<const D: usize, const S: usize, const C: usize> Pass<'_, D, S, C>
where
    Dim<D>: Stencil<D, S>,
{
    /// [`Self::correct_impl`] compiled for AVX2 (integer distances and the same IEEE
    /// float operations without FMA contraction: bit-identical to the baseline build).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn correct_avx2<const WARP: bool>(
        &self,
        p: usize,
        s: &[[f32; 2]],
        fl: &[bool],
    ) -> ([f32; 2], bool) {
        self.correct_impl::<WARP>(p, s, fl)
    }

    /// New `(S, I)` of sample `p` from the current state.
    #[inline]
    fn correct(&self, p: usize, s: &[[f32; 2]], fl: &[bool]) -> ([f32; 2], bool) {
        // The warped corner reads are compiled as a separate instance so that the
        // default path keeps the plain loop (no per-neighbour corner maps).
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is true only when the CPU reports AVX2 support.
            return unsafe {
                if self.warp.is_some() {
                    self.correct_avx2::<true>(p, s, fl)
                } else {
                    self.correct_avx2::<false>(p, s, fl)
                }
            };
        }
        if self.warp.is_some() {
            self.correct_impl::<true>(p, s, fl)
        } else {
            self.correct_impl::<false>(p, s, fl)
        }
    }

    /// `WARP`: [`Self::warp`] is set (the warped corner reads).
    #[inline(always)]
    fn correct_impl<const WARP: bool>(
        &self,
        p: usize,
        s: &[[f32; 2]],
        fl: &[bool],
    ) -> ([f32; 2], bool) {
        let ex = &self.ex;
        let h = self.spacing;
        let jp = self.t.jac[p];
        let nb = &self.t.nbr[p];
        // Predictions of p's coordinate by each neighbour: (coordinate, flip, the
        // neighbour's effective offset h F(q) δ).
        let mut pred = [([0.0f32; 2], false, [0.0f32; 2]); S];
        let mut valid = [false; S];
        // Corner maps of the warped reads (warped_neighbourhood.rs), per neighbour.
        let jinv = if WARP { self.warp.and_then(|_| inverse_frame(&jp)) } else { None };
        let mut corner_maps = [None; S];
        for k in 0..S {
            let q = nb[k];
            if q == NONE {
                continue;
            }
            let q = q as usize;
            if self.k > 0 {
                ex.prefetch_coherence(s[q]);
            }
            let (mut fq, alpha) = if self.rosy {
                let jq = self.t.jac[q];
                let cons = frobenius(&jq, &jp) < 0.0;
                let fq = if fl[q] { negated(&jq) } else { jq };
                (fq, fl[q] ^ cons)
            } else {
                (jp, false)
            };
            if self.trapezoid {
                // Trapezoid rule: the mean of q's effective frame and p's frame with the
                // candidate's flip (sign-aligned with it by the choice of α).
                let fpa = if alpha { negated(&jp) } else { jp };
                fq = mean(&fq, &fpa);
            }
            if WARP && let Some(ji) = &jinv {
                let fpa = if alpha { negated(&jp) } else { jp };
                corner_maps[k] = corner_map(&fq, &fpa, ji, h);
            }
            let d = <Dim<D> as Stencil<D, S>>::OFFSETS[k];
            let off = mat_vec(&fq, d.map(|c| c as f32 * h));
            pred[k] = (ex.wrap([s[q][0] - off[0], s[q][1] - off[1]]), alpha, off);
            valid[k] = true;
        }
        // Four-corner neighbourhood of p, averaged over three predictions per corner.
        // Targets are kept as 6 × the mean (6 = lcm of the possible counts 1, 2, 3), so
        // the whole comparison is exact integer arithmetic. Corners without any
        // prediction (domain border) are masked out.
        let mut target = [0i16; NV];
        let mut mask = [0i16; NV];
        for (ci, slots) in self.t.corner_slots[p].iter().enumerate() {
            let lanes = ci * APPEARANCE_DIMS..(ci + 1) * APPEARANCE_DIMS;
            let tc = &mut target[lanes.clone()];
            let mut count = 0i16;
            for &t in slots {
                let t = t as usize;
                if !valid[t] {
                    continue;
                }
                let (u, a, _) = pred[t];
                let v = match (WARP, &corner_maps[t], self.warp) {
                    (true, Some(m), Some(app)) => &warped_corner(ex, app[a as usize], u, m, ci)[..],
                    _ => &ex.nv[a as usize][ex.pixel(u)].0[lanes.clone()],
                };
                for (o, &x) in tc.iter_mut().zip(v) {
                    *o += x as i16;
                }
                count += 1;
            }
            if count > 0 {
                let f = 6 / count;
                tc.iter_mut().for_each(|x| *x *= f);
                mask[lanes].fill(-1);
            }
        }
        // The current value first: when its neighbourhood is exactly its exemplar
        // neighbourhood (inside a coherent patch) no candidate can beat it.
        let current = (s[p], fl[p] && self.rosy);
        let current_d = {
            let (x, y) = ex.cell(current.0);
            if x >= ex.x_lo && x < ex.x_hi && y >= ex.y_lo && y < ex.y_hi {
                let d = dist_nv(&ex.nv[current.1 as usize][y * ex.w + x].0, &target, &mask);
                if d == 0 {
                    return current;
                }
                d
            } else {
                i32::MAX
            }
        };
        // Gather the eligible candidates (coordinates outside the level's margin band
        // are not), then score them in one branch-free sweep whose table loads overlap.
        let mut cand_u = [[0.0f32; 2]; C];
        let mut cand_nv: [&NvEntry; C] = [&ex.nv[0][0]; C];
        let mut cand_b = [false; C];
        let mut n = 0usize;
        let mut push = |u: [f32; 2], b: bool| {
            let (x, y) = ex.cell(u);
            if x >= ex.x_lo && x < ex.x_hi && y >= ex.y_lo && y < ex.y_hi {
                cand_u[n] = u;
                cand_nv[n] = &ex.nv[b as usize][y * ex.w + x];
                cand_b[n] = b;
                n += 1;
            }
        };
        for k in 0..S {
            if !valid[k] {
                continue;
            }
            let (u, a, off) = pred[k];
            if self.keep_flips && a != current.1 {
                continue;
            }
            push(u, a);
            if self.k == 0 {
                continue;
            }
            let sq = s[nb[k] as usize];
            // Coordinates are wrapped (non-negative): truncation is the floor.
            let frac = [sq[0] - (sq[0] as i32) as f32, sq[1] - (sq[1] as i32) as f32];
            let base = ex.pixel(sq) * ex.k_store;
            for v in &ex.coherence[base..base + self.k] {
                push(ex.wrap([v[0] + frac[0] - off[0], v[1] + frac[1] - off[1]]), a);
            }
        }
        if self.own {
            // The k-coherence jumps of p's own coordinate (δ = 0 of the 3×3 set).
            let (sp, b) = current;
            let frac = [sp[0] - (sp[0] as i32) as f32, sp[1] - (sp[1] as i32) as f32];
            let base = ex.pixel(sp) * ex.k_store;
            for v in &ex.coherence[base..base + self.k] {
                push(ex.wrap([v[0] + frac[0], v[1] + frac[1]]), b);
            }
        }
        let mut dist = [0i32; C];
        for (d, a) in dist[..n].iter_mut().zip(&cand_nv[..n]) {
            *d = dist_nv(&a.0, &target, &mask);
        }
        // The smallest distance wins; ties keep the earlier candidate (the current
        // value first), so repeated candidates change nothing.
        let (mut best, mut best_d) = (current, current_d);
        for i in 0..n {
            if dist[i] < best_d {
                best_d = dist[i];
                best = (cand_u[i], cand_b[i]);
            }
        }
        best
    }
}

/// Synthesises a texture over `domain` from the analysed exemplar. Deterministic for a
/// given seed, independent of the rayon thread count.
pub fn synthesize(
    analysis: &ExemplarAnalysis,
    domain: &dyn SynthesisDomain,
    options: &SynthesisOptions,
    progress: &dyn Progress,
) -> Result<SynthesisResult, SynthError> {
    let (out_w, out_h) = check_output_size(domain)?;
    let run = synthesize_planar(analysis, domain, options, progress, None)?;
    let filter = options.color_filter;
    let pixels = run.coords.par_iter().map(|&u| color_lookup(analysis, u, filter)).collect();
    Ok(SynthesisResult {
        colors: Image { width: out_w, height: out_h, pixels },
        coords: run.coords,
        flips: run.flips,
        level_timings_ms: run.level_timings_ms,
    })
}

/// Result of [`synthesize_subset`] and [`crate::synthesize_volume`]: the requested
/// finest samples, in the order given.
#[derive(Clone, Debug, PartialEq)]
pub struct SubsetSynthesis {
    /// The requested sample indices (row-major over [`SynthesisDomain::output_size`];
    /// for a volume x fastest, then y, then z).
    pub samples: Vec<usize>,
    /// Exemplar colour of each requested sample.
    pub colors: Vec<[f32; 4]>,
    /// Exemplar coordinate of each requested sample.
    pub coords: Vec<[f32; 2]>,
    /// Flip indicator of each requested sample.
    pub flips: Vec<bool>,
    /// Samples computed per level, finest first (the dependency sets' sizes).
    pub evaluated_per_level: Vec<usize>,
}

/// The requested finest samples of [`synthesize`] computed from their dependency sets
/// only ([`crate::synthesis_subset`]): the same bits as the same samples of a full
/// synthesis with the same options and seed, for any thread count. Errors as
/// [`synthesize`], and on a requested index outside the finest level.
pub fn synthesize_subset(
    analysis: &ExemplarAnalysis,
    domain: &dyn SynthesisDomain,
    options: &SynthesisOptions,
    requested: &[usize],
    progress: &dyn Progress,
) -> Result<SubsetSynthesis, SynthError> {
    let n0 = domain.sample_count(0);
    if let Some(&bad) = requested.iter().find(|&&r| r >= n0) {
        return Err(SynthError::InvalidDomain {
            reason: format!("requested sample {bad} ≥ finest sample count {n0}"),
        });
    }
    check_output_size(domain)?;
    let run = synthesize_planar(analysis, domain, options, progress, Some(requested))?;
    Ok(run.subset(analysis, requested.to_vec(), options.color_filter))
}

impl EngineRun {
    /// The samples `samples` of this run, with their colours.
    pub(crate) fn subset(
        self,
        analysis: &ExemplarAnalysis,
        samples: Vec<usize>,
        filter: crate::ColorFilter,
    ) -> SubsetSynthesis {
        SubsetSynthesis {
            colors: samples
                .par_iter()
                .map(|&r| color_lookup(analysis, self.coords[r], filter))
                .collect(),
            coords: samples.iter().map(|&r| self.coords[r]).collect(),
            flips: samples.iter().map(|&r| self.flips[r]).collect(),
            samples,
            evaluated_per_level: self.evaluated_per_level,
        }
    }
}

/// Whether the correction can run its AVX2 build on this CPU.
pub(crate) fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// The engine over a 2-D [`SynthesisDomain`] (8 neighbours, 4 subpass classes).
fn synthesize_planar(
    analysis: &ExemplarAnalysis,
    domain: &dyn SynthesisDomain,
    options: &SynthesisOptions,
    progress: &dyn Progress,
    requested: Option<&[usize]>,
) -> Result<EngineRun, SynthError> {
    let avx2 = avx2_available();
    let planar = PlanarDomain(domain);
    synthesize_with::<2, 8, { max_candidates(8) }>(
        analysis, &planar, options, progress, avx2, requested,
    )
}

/// The finest level's output image size, checked against its sample count.
fn check_output_size(domain: &dyn SynthesisDomain) -> Result<(usize, usize), SynthError> {
    let n0 = domain.sample_count(0);
    let (out_w, out_h) = domain.output_size();
    if n0 == 0 || out_w * out_h != n0 {
        return Err(SynthError::InvalidDomain {
            reason: format!("{n0} finest samples but output size {out_w}×{out_h}"),
        });
    }
    Ok((out_w, out_h))
}

/// Finest-level state after the last level (full, or right at the planned samples).
pub(crate) struct EngineRun {
    pub(crate) coords: Vec<[f32; 2]>,
    pub(crate) flips: Vec<bool>,
    pub(crate) level_timings_ms: Vec<f64>,
    pub(crate) evaluated_per_level: Vec<usize>,
}

/// The engine with the AVX2 build of the correction on or off (`avx2` only when the CPU
/// supports it), over every sample or only the dependency sets of `requested`, on a
/// `D`-dimensional lattice with `S` neighbours (`C` = [`max_candidates`]`(S)`).
pub(crate) fn synthesize_with<const D: usize, const S: usize, const C: usize>(
    analysis: &ExemplarAnalysis,
    domain: &dyn LatticeDomain<D>,
    options: &SynthesisOptions,
    progress: &dyn Progress,
    avx2: bool,
    requested: Option<&[usize]>,
) -> Result<EngineRun, SynthError>
where
    Dim<D>: Stencil<D, S>,
{
    const { assert!(C >= max_candidates(S)) };
    validate(options, analysis)?;
    let n0 = domain.sample_count(0);
    if n0 == 0 {
        return Err(SynthError::InvalidDomain { reason: "the domain has no samples".into() });
    }
    if domain.level_count() < 2 {
        return Err(SynthError::InvalidDomain {
            reason: "the domain needs at least 2 levels (one for initialisation)".into(),
        });
    }
    let levels = analysis.level_count().min(domain.level_count() - 1).max(1);
    let (w, h) = (analysis.width(), analysis.height());
    let (wf, hf) = (w as f32, h as f32);
    progress.stage("parallel synthesis", levels as u64);

    // Initialisation level: combed flips; random coordinates, or the frames integrated.
    let mut parent_tables = tabulate::<D, S>(domain, levels, options.scale, 1, false)?;
    let n_init = domain.sample_count(levels);
    let m = analysis.level(levels - 1).margin.min(w.min(h) / 2) as f64;
    let mut fl = if options.rosy_fix && options.comb_flips {
        comb_flips(&parent_tables.nbr, &parent_tables.jac, <Dim<D> as Stencil<D, S>>::AXES)
    } else {
        vec![false; n_init]
    };
    if options.integrated_init && requested.is_some() {
        return Err(SynthError::InvalidOption {
            name: "integrated_init",
            value: 1.0,
            reason: "needs the whole domain (not a subset synthesis)",
        });
    }
    let mut s: Vec<[f32; 2]> = (0..n_init)
        .map(|i| {
            let i = i as u64;
            let ux = m + hash_unit(options.seed, "synthesis-init", 2 * i) * (w as f64 - 2.0 * m);
            let uy =
                m + hash_unit(options.seed, "synthesis-init", 2 * i + 1) * (h as f64 - 2.0 * m);
            let (ux, uy) =
                if options.snap_coordinates { (ux.floor(), uy.floor()) } else { (ux, uy) };
            [(ux as f32).min(wf.next_down()), (uy as f32).min(hf.next_down())]
        })
        .collect();
    // The integrated start: the frames integrated over the initialisation level
    // (spacing: twice the coarsest synthesised level's), placed by one seeded offset.
    let mut integrated = options.integrated_init.then(|| {
        let offset = [
            hash_unit(options.seed, "synthesis-init-offset", 0) * w as f64,
            hash_unit(options.seed, "synthesis-init-offset", 1) * h as f64,
        ];
        IntegratedStart::begin::<D, S>(
            &parent_tables.nbr,
            &parent_tables.jac,
            &fl,
            2.0 * analysis.level(levels - 1).spacing as f32,
            options.integrated_trust,
            offset,
            (w, h),
            options.snap_coordinates,
            &mut s,
        )
    });
    let mut level_timings_ms = Vec::with_capacity(levels);
    let passes_of = |level: usize| {
        if level == 0 {
            options.finest_passes.unwrap_or(options.correction_passes)
        } else if level >= 2 {
            options.coarse_passes.unwrap_or(options.correction_passes)
        } else {
            options.correction_passes
        }
    };
    // Subset mode: every level tabulated first, then the dependency sets planned.
    let (plan, mut planned_tables) = match requested {
        None => (None, Vec::new()),
        Some(r) => {
            let all = (0..levels)
                .map(|l| tabulate(domain, l, options.scale, options.subpasses, true))
                .collect::<Result<Vec<_>, _>>()?;
            let plan = SubsetPlan::new(&all, n_init, passes_of, r);
            (Some(plan), all.into_iter().map(Some).collect::<Vec<_>>())
        }
    };

    for level in (0..levels).rev() {
        let start = Instant::now();
        let tables = match planned_tables.get_mut(level).and_then(Option::take) {
            Some(t) => t,
            None => tabulate(domain, level, options.scale, options.subpasses, true)?,
        };
        let start_mask = plan.as_ref().map(|p| &p.start[level]);
        let an = analysis.level(level);
        let ex = ExemplarLevel::new(analysis, level, options.rosy_fix);
        let spacing = an.spacing as f32;
        let n = tables.jac.len();
        // 1. Upsampling with the parent's effective frame; 2. jitter.
        let amp = if level < options.unjittered_levels { 0.0 } else { options.jitter * spacing };
        let seed = options.seed;
        let (ps, pf, pj) = (&s, &fl, &parent_tables.jac);
        let rosy = options.rosy_fix;
        let snap = options.snap_coordinates;
        let trapezoid = rosy && options.trapezoid_frames;
        // Per sample: the upsampling offset `h F o`, the jitter and the flip.
        let up: Vec<([f32; 2], [f32; 2], bool)> = (0..n)
            .into_par_iter()
            .map(|i| {
                if let Some(m) = start_mask
                    && !m[i]
                {
                    return ([0.0; 2], [0.0; 2], false);
                }
                let (par, off) = tables.parent[i];
                let par = par as usize;
                let jpar = pj[par];
                let flip_par = rosy && pf[par];
                let mut f = if flip_par { negated(&jpar) } else { jpar };
                if trapezoid {
                    // Trapezoid rule: the mean of the parent's effective frame and the
                    // child's representative frame sign-aligned with it.
                    let jc = tables.jac[i];
                    let jc = if frobenius(&f, &jc) < 0.0 { negated(&jc) } else { jc };
                    f = mean(&f, &jc);
                }
                let o = mat_vec(&f, off.map(|v| v * spacing));
                let idx = ((level * n0 + i) as u64) * 2;
                let mut jx = (2.0 * hash_unit(seed, "synthesis-jitter", idx) - 1.0) as f32 * amp;
                let mut jy =
                    (2.0 * hash_unit(seed, "synthesis-jitter", idx + 1) - 1.0) as f32 * amp;
                if snap {
                    (jx, jy) = (jx.round(), jy.round());
                }
                let flip = rosy && (flip_par ^ (frobenius(&jpar, &tables.jac[i]) < 0.0));
                (o, [jx, jy], flip)
            })
            .collect();
        let mut nf: Vec<bool> = up.iter().map(|v| v.2).collect();
        // With the integrated start a trusted child steps from its parent by the
        // difference of the integrated coordinates, without jitter, and is corrected only
        // on the finest levels.
        let (steps, trust) = match integrated.as_mut() {
            Some(start) => {
                let (st, t) = start.level::<D, S>(
                    &tables.nbr,
                    &tables.jac,
                    &nf,
                    &tables.parent,
                    |i| up[i].0,
                    spacing,
                );
                (Some(st), Some(t))
            }
            None => (None, None),
        };
        let mut ns: Vec<[f32; 2]> = (0..n)
            .into_par_iter()
            .map(|i| {
                if let Some(m) = start_mask
                    && !m[i]
                {
                    return [0.0; 2];
                }
                let par = tables.parent[i].0 as usize;
                let (o, j, _) = up[i];
                let (o, j) = match steps.as_ref().and_then(|st| st[i]) {
                    Some(step) => (step, [0.0; 2]),
                    None => (o, j),
                };
                ex.wrap([ps[par][0] + o[0] + j[0], ps[par][1] + o[1] + j[1]])
            })
            .collect();
        // 3. Correction passes with subpasses.
        let pass = Pass::<D, S, C> {
            ex,
            t: &tables,
            spacing,
            k: options.k,
            rosy,
            own: options.own_candidates,
            avx2,
            keep_flips: rosy && options.keep_flips,
            trapezoid: rosy && options.trapezoid_frames,
            warp: (rosy && options.warped_corners).then(|| {
                let d = &an.appearance_q.data;
                [&d[0][..], &d[1][..]]
            }),
        };
        let n_classes = tables.classes.len();
        let skip = trust.as_ref().filter(|_| level >= options.integrated_free_levels);
        for pass_index in 0..passes_of(level) {
            for (c, class) in tables.classes.iter().enumerate() {
                let step = plan.as_ref().map(|p| &p.steps[level][pass_index * n_classes + c]);
                let updates: Vec<(u32, ([f32; 2], bool))> = class
                    .par_iter()
                    .filter(|&&p| step.is_none_or(|m| m[p as usize]))
                    .filter(|&&p| skip.is_none_or(|t| !t[p as usize]))
                    .map(|&p| (p, pass.correct(p as usize, &ns, &nf)))
                    .collect();
                for (p, (u, f)) in updates {
                    ns[p as usize] = u;
                    nf[p as usize] = f;
                }
            }
        }
        s = ns;
        fl = nf;
        parent_tables = tables;
        level_timings_ms.push(start.elapsed().as_secs_f64() * 1e3);
        progress.advance(1);
    }
    progress.finish_stage();
    let evaluated_per_level = plan.map_or_else(|| vec![n0; 1], |p| p.evaluated());
    Ok(EngineRun { coords: s, flips: fl, level_timings_ms, evaluated_per_level })
}

#[cfg(test)]
#[path = "parallel_synthesis_tests.rs"]
mod tests;
