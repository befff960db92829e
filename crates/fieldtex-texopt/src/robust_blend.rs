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
//! deterministic. The carrier's *source* is the exemplar coordinate it receives from
//! the winning patch: the largest `ω_p · exp(−ρ²/8)` (`ρ` = distance from the patch
//! centre in grid units), so centres win over borders. Carriers outside every
//! footprint keep their colour and source.

use crate::exemplar_patches::{GRID, HALF};
use crate::texture_optimisation::LevelContext;
use fieldtex_core::vec3::{dot, sub};
use rayon::prelude::*;

/// Robust IRLS weight `λ · max(e, 1/255)^(r−2)` of a sample whose squared 192-D patch
/// error is `d2` (`e = sqrt(d2 / 192)`, the RMS error per colour component).
#[inline]
pub fn robust_weight(lambda: f64, d2: f32, exponent: f64) -> f64 {
    let rms = (d2 as f64 / crate::exemplar_patches::DIM as f64).sqrt().max(1.0 / 255.0);
    lambda * rms.powf(exponent - 2.0)
}

/// Blends all carriers from the matches; returns the number of uncovered carriers.
pub(crate) fn blend(
    ctx: &LevelContext,
    matches: &[u32],
    weights: &[f64],
    colors: &mut [[f32; 4]],
    source: &mut [[f32; 2]],
) -> usize {
    let lvl = ctx.level;
    let s = lvl.step as f64;
    let pos = ctx.domain.positions();
    let nrm = ctx.domain.normals();
    let lim = GRID as f64 - 0.5;
    colors
        .par_iter_mut()
        .zip(source.par_iter_mut())
        .enumerate()
        .with_min_len(1024)
        .map(|(c, (col, src))| {
            let mut acc = [0.0f64; 4];
            let mut wsum = 0.0f64;
            let mut win = (f64::NEG_INFINITY, [0.0f64; 2]);
            ctx.sample_grid.for_each_within(&ctx.sample_positions, pos[c], ctx.radius, |p, _| {
                let p = p as usize;
                let f = &ctx.frames[p];
                if dot(nrm[c], f.n) < ctx.normal_cosine {
                    return;
                }
                let d = sub(pos[c], f.pos);
                let u = dot(d, f.tx) + HALF;
                let v = dot(d, f.ty) + HALF;
                if !(-0.5..lim).contains(&u) || !(-0.5..lim).contains(&v) {
                    return;
                }
                let [ox, oy] = lvl.origin(matches[p]);
                let (ex, ey) = (ox as f64 + u * s, oy as f64 + v * s);
                let z = lvl.sample(ex, ey);
                let w = weights[p];
                for k in 0..4 {
                    acc[k] += w * z[k] as f64;
                }
                wsum += w;
                let rho2 = (u - HALF).powi(2) + (v - HALF).powi(2);
                let score = w * (-rho2 / 8.0).exp();
                if score > win.0 {
                    win = (score, [ex, ey]);
                }
            });
            if wsum > 0.0 && wsum.is_finite() {
                for k in 0..4 {
                    col[k] = (acc[k] / wsum) as f32;
                }
                let (w, h) = (lvl.width as f64, lvl.height as f64);
                let wrap = |v: f64, n: f64| {
                    if lvl.toroidal { v.rem_euclid(n) } else { v.clamp(0.0, n - 1.0) }
                };
                *src = [wrap(win.1[0], w) as f32, wrap(win.1[1], h) as f32];
                0
            } else {
                1
            }
        })
        .sum()
}
