//! The blend step: each carrier's colour minimises the weighted patch energy for fixed
//! matches (Kwatra et al. 2005 eq. 3, one IRLS step of eq. 2).
//!
//! With matches `z_p` fixed, `Σ_p ω_p |x_p − z_p|²` is minimised per carrier by the
//! weighted average of the colours the overlapping matched patches assign it:
//! `x(c) = Σ_p ω_p z_p(c) / Σ_p ω_p`, where `z_p(c)` is the (filtered) exemplar
//! sampled bilinearly at the carrier's patch coordinates mapped into the match. The
//! weights are `ω_p = λ_p · max(e_p, 1/255)^(r−2)` with `e_p` the RMS patch error,
//! which turns the quadratic energy into the robust `Σ λ_p |x_p − z_p|^r` (IRLS).
//!
//! The blend is a gather over carriers (each carrier looks up the samples whose
//! footprint contains it), so it runs in parallel without write conflicts and is
//! deterministic. Each patch pixel's contribution is further weighted by a Gaussian
//! falloff `exp(−ρ²/(2σ²))` (`ρ` = distance from the patch centre in grid units,
//! `σ` = [`TexOptOptions::blend_falloff`](crate::TexOptOptions::blend_falloff)): fewer
//! patches disagree at each carrier, so the result is sharper than the plain average
//! (`σ = ∞` gives Kwatra 2005 exactly). The carrier's *source* is the exemplar
//! coordinate it receives from the patch with the largest weight, so centres win over
//! borders. Carriers outside every footprint keep their colour and source.
//!
//! [`BlendMode::Crisp`] is the final pass of [`optimise`](crate::optimise) (when
//! [`TexOptOptions::crisp`](crate::TexOptOptions::crisp)): each carrier takes the colour
//! of the one covering patch that agrees best with the average instead of the average
//! itself, the usual cure for the softness of least-squares blending (a texel shows an
//! exemplar pixel; seams between patches stay where the average put its transitions).

use crate::CrispChoice;
use crate::exemplar_patches::HALF;
use crate::texture_optimisation::LevelContext;
use rayon::prelude::*;

/// Robust IRLS weight `λ · max(e, 1/255)^(r−2)` of a sample whose squared 192-D patch
/// error is `d2` (`e = sqrt(d2 / 192)`, the RMS error per colour component).
#[inline]
pub fn robust_weight(lambda: f64, d2: f32, exponent: f64) -> f64 {
    let rms = (d2 as f64 / crate::exemplar_patches::DIM as f64).sqrt().max(1.0 / 255.0);
    lambda * rms.powf(exponent - 2.0)
}

/// How a carrier's colour is formed from the patches covering it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BlendMode {
    /// The robust weighted average (Kwatra et al. 2005 eq. 3).
    Average,
    /// The crisp final pass: the exemplar pixel (nearest to the coordinate) that one
    /// covering patch assigns, with its exemplar coordinate as source; which patch is
    /// [`TexOptOptions::crisp_choice`](crate::TexOptOptions::crisp_choice). Every
    /// carrier then shows an exemplar pixel, not a mix.
    Crisp,
    /// The colour of the covering patch with the largest weight (the one whose centre
    /// is nearest, at equal IRLS weights): a mosaic of whole patches. Used for the
    /// random initialisation, where averaging unrelated patches would give flat grey.
    Winner,
}

/// Most covering patches considered by the crisp choice (the average uses all).
const MAX_CRISP_CANDIDATES: usize = 64;

/// Blends the carriers `which` (all when `None`) from the matches; returns the number
/// of those left uncovered.
pub(crate) fn blend(
    ctx: &LevelContext,
    which: Option<&[u32]>,
    matches: &[crate::patch_search::Placement],
    weights: &[f64],
    colors: &mut [[f32; 4]],
    source: &mut [[f32; 2]],
    mode: BlendMode,
) -> usize {
    if let Some(list) = which {
        let results: Vec<Option<([f32; 4], [f32; 2])>> = list
            .par_iter()
            .with_min_len(1024)
            .map(|&c| blend_carrier(ctx, c as usize, matches, weights, mode))
            .collect();
        let mut uncovered = 0;
        for (&c, r) in list.iter().zip(results) {
            match r {
                Some((col, src)) => {
                    colors[c as usize] = col;
                    source[c as usize] = src;
                }
                None => uncovered += 1,
            }
        }
        return uncovered;
    }
    colors
        .par_iter_mut()
        .zip(source.par_iter_mut())
        .enumerate()
        .with_min_len(1024)
        .map(|(c, (col, src))| match blend_carrier(ctx, c, matches, weights, mode) {
            Some((a, b)) => {
                *col = a;
                *src = b;
                0
            }
            None => 1,
        })
        .sum()
}

/// The blended colour and source of carrier `c`, `None` when no patch covers it.
fn blend_carrier(
    ctx: &LevelContext,
    c: usize,
    matches: &[crate::patch_search::Placement],
    weights: &[f64],
    mode: BlendMode,
) -> Option<([f32; 4], [f32; 2])> {
    let lvl = ctx.level;
    let s = lvl.step as f64;
    let pos = ctx.domain.positions();
    let mut acc = [0.0f64; 4];
    let mut wsum = 0.0f64;
    let mut win = (f64::NEG_INFINITY, [0.0f64; 2]);
    let mut cands = [(0.0f64, [0.0f32; 4], [0.0f64; 2]); MAX_CRISP_CANDIDATES];
    let mut n_cands = 0usize;
    let mut win_color = [0.0f32; 4];
    ctx.sample_grid.for_each_within(&ctx.sample_positions, pos[c], ctx.radius, |p, _| {
        let p = p as usize;
        let Some((u, v)) = ctx.footprint_coords(p, c) else {
            return;
        };
        let [ox, oy] = lvl.origin(matches[p].position);
        let [fx, fy] = matches[p].offset;
        let (ex, ey) = (ox as f64 + fx as f64 + u * s, oy as f64 + fy as f64 + v * s);
        let z = lvl.sample(ex, ey);
        let rho2 = (u - HALF).powi(2) + (v - HALF).powi(2);
        let g = if ctx.falloff > 0.0 { (-rho2 * ctx.falloff).exp() } else { 1.0 };
        let w = weights[p] * g;
        for k in 0..4 {
            acc[k] += w * z[k] as f64;
        }
        wsum += w;
        if w > win.0 {
            win = (w, [ex, ey]);
            win_color = z;
        }
        if mode == BlendMode::Crisp
            && ctx.crisp_choice == CrispChoice::Consensus
            && n_cands < MAX_CRISP_CANDIDATES
        {
            cands[n_cands] = (w, z, [ex, ey]);
            n_cands += 1;
        }
    });
    if !(wsum > 0.0 && wsum.is_finite()) {
        return None;
    }
    let mut col = [0, 1, 2, 3].map(|k| (acc[k] / wsum) as f32);
    if mode == BlendMode::Winner {
        col = win_color;
    }
    if mode == BlendMode::Crisp && ctx.crisp_choice == CrispChoice::BestMatch {
        // The exemplar pixel under the best-matching covering patch (largest robust
        // weight times falloff), nearest, not bilinear.
        col = lvl.sample(win.1[0].round(), win.1[1].round());
    } else if mode == BlendMode::Crisp {
        let mut best = (f32::INFINITY, f64::NEG_INFINITY, usize::MAX);
        for (i, (w, z, _)) in cands[..n_cands].iter().enumerate() {
            // Only patches near their centre here (weight at least half the largest):
            // their placement is what the search (and §5.2's constraint) decided.
            if *w < 0.5 * win.0 {
                continue;
            }
            let e: f32 = (0..3).map(|k| (z[k] - col[k]) * (z[k] - col[k])).sum();
            if e < best.0 || (e == best.0 && *w > best.1) {
                best = (e, *w, i);
            }
        }
        if best.2 != usize::MAX {
            // The exemplar pixel under the chosen source (nearest, not bilinear: a
            // bilinear lookup at half-pixel offsets would halve fine grain).
            let [ex, ey] = cands[best.2].2;
            col = lvl.sample(ex.round(), ey.round());
            win.1 = [ex, ey];
        }
    }
    let (w, h) = (lvl.width as f64, lvl.height as f64);
    let wrap = |v: f64, n: f64| if lvl.toroidal { v.rem_euclid(n) } else { v.clamp(0.0, n - 1.0) };
    Some((col, [wrap(win.1[0], w) as f32, wrap(win.1[1], h) as f32]))
}
