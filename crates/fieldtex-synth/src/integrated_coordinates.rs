//! Initial exemplar coordinates integrated from the synthesis frames — the option
//! [`crate::SynthesisOptions::integrated_init`] of the parallel synthesis's
//! initialisation (our variant; the solid pipeline's twin is
//! `solid::integrated_init`).
//!
//! Lefebvre & Hoppe (2005, §3.1) start from arbitrary coordinates on the initialisation
//! level, so each of its samples begins as a patch of its own. Where the field turns,
//! neighbouring patches meet with their structure out of phase, and with a periodic
//! exemplar (stripes, weaves) the corrections leave some of those seams as stripe
//! endings. Here the initial coordinates are instead the least-squares integral `U` of
//! the effective frames `F = (−1)^I J` over the initialisation lattice:
//!
//! `U = argmin Σ |U(q) − U(p) − h ½(F(p) + F(q)) δ|²`
//!
//! over the axis edges `(p, q = p + δ)` whose effective frames agree (`⟨F(p), F(q)⟩ > 0`:
//! the seams that the singularities force are left out), `h` the lattice spacing in
//! exemplar pixels. The two coordinates are two Poisson problems with one graph
//! Laplacian ([`fieldtex_linalg::conjugate_gradients`], from zero, so `U` has zero mean
//! on every connected part). For a constant frame `U` is the exemplar tiled along it;
//! where the stripe normal of the field is a gradient (parallel curves) `U` follows it
//! exactly; elsewhere the misfit is spread as a smooth stretch instead of seams.
//!
//! Shapes: `nbr[p]` the neighbours of sample `p` in the stencil's slot order
//! (`u32::MAX`: none), `jac[p]` its representative Jacobian (exemplar pixels per lattice
//! step, option scale included), `flips[p]` its flip indicator; the result has one
//! `[x, y]` per sample, in exemplar pixels, not wrapped.

use fieldtex_linalg::conjugate_gradients;

use crate::lattice_domain::{Dim, Jacobian, Stencil, frobenius, mat_vec, mean, negated};

/// Iteration cap of the two solves (the initialisation level has a few hundred to a few
/// thousand samples).
const MAX_ITERATIONS: usize = 4000;

/// `U` of the module docs and its misfit for one lattice level with spacing `spacing`
/// (exemplar pixels per lattice step before the Jacobian), solved from zero.
pub(crate) fn integrated_coordinates<const D: usize, const S: usize>(
    nbr: &[[u32; S]],
    jac: &[Jacobian<D>],
    flips: &[bool],
    spacing: f32,
) -> Integrated
where
    Dim<D>: Stencil<D, S>,
{
    let start = vec![[0.0f64; 2]; jac.len()];
    refine_integrated_coordinates::<D, S>(nbr, jac, flips, spacing, start, MAX_ITERATIONS)
}

/// `U` per sample (exemplar pixels, not wrapped) and its misfit: per sample the largest
/// `|U(q) − U(p) − h F̄ δ| / |h F̄ δ|` over its axis edges, infinite next to a forced seam
/// (an axis neighbour whose effective frame disagrees).
pub(crate) struct Integrated {
    pub(crate) u: Vec<[f64; 2]>,
    pub(crate) misfit: Vec<f32>,
}

/// `U` of the module docs improved from `start` by at most `iterations` conjugate-gradient
/// steps (the cascade of [`crate::SynthesisOptions::integrated_init`]: each finer level
/// starts from its parents' `U` carried down and only smooths what the parents' frames
/// could not say).
pub(crate) fn refine_integrated_coordinates<const D: usize, const S: usize>(
    nbr: &[[u32; S]],
    jac: &[Jacobian<D>],
    flips: &[bool],
    spacing: f32,
    start: Vec<[f64; 2]>,
    iterations: usize,
) -> Integrated
where
    Dim<D>: Stencil<D, S>,
{
    let n = jac.len();
    let frame = |p: usize| if flips[p] { negated(&jac[p]) } else { jac[p] };
    let mut b = vec![[0.0f64; 2]; n];
    let mut degree = vec![0.0f64; n];
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(D * n);
    let mut steps: Vec<[f64; 2]> = Vec::with_capacity(D * n);
    let mut misfit = vec![0.0f32; n];
    for p in 0..n {
        let fp = frame(p);
        for &k in <Dim<D> as Stencil<D, S>>::AXES {
            let d = <Dim<D> as Stencil<D, S>>::OFFSETS[k];
            // Each edge once: from the sample on its negative side.
            if d.iter().sum::<i32>() < 0 {
                continue;
            }
            let q = nbr[p][k];
            if q == u32::MAX {
                continue;
            }
            let fq = frame(q as usize);
            if frobenius(&fp, &fq) <= 0.0 {
                misfit[p] = f32::INFINITY;
                misfit[q as usize] = f32::INFINITY;
                continue;
            }
            let g = mat_vec(&mean(&fp, &fq), d.map(|c| c as f32 * spacing));
            steps.push([g[0] as f64, g[1] as f64]);
            for c in 0..2 {
                b[q as usize][c] += g[c] as f64;
                b[p][c] -= g[c] as f64;
            }
            degree[p] += 1.0;
            degree[q as usize] += 1.0;
            edges.push((p as u32, q));
        }
    }
    let apply = |x: &[f64], y: &mut [f64]| {
        for (i, yi) in y.iter_mut().enumerate() {
            *yi = degree[i] * x[i];
        }
        for &(p, q) in &edges {
            let (p, q) = (p as usize, q as usize);
            y[p] -= x[q];
            y[q] -= x[p];
        }
    };
    let mut u = start;
    // The two coordinates are independent solves (each sequential, so the result does
    // not depend on the thread count): side by side.
    let solve = |c: usize| {
        // Solve A (x0 + e) = b for the correction e from zero.
        let x0: Vec<f64> = u.iter().map(|v| v[c]).collect();
        let mut ax0 = vec![0.0; n];
        apply(&x0, &mut ax0);
        let rhs: Vec<f64> = b.iter().zip(&ax0).map(|(v, a)| v[c] - a).collect();
        conjugate_gradients(&apply, &rhs, iterations, 1e-10)
    };
    let (ex, ey) = rayon::join(|| solve(0), || solve(1));
    for ((ui, x), y) in u.iter_mut().zip(ex).zip(ey) {
        ui[0] += x;
        ui[1] += y;
    }
    for (&(p, q), g) in edges.iter().zip(&steps) {
        let (p, q) = (p as usize, q as usize);
        let r = [u[q][0] - u[p][0] - g[0], u[q][1] - u[p][1] - g[1]];
        let m = (r[0].hypot(r[1]) / g[0].hypot(g[1]).max(1e-12)) as f32;
        misfit[p] = misfit[p].max(m);
        misfit[q] = misfit[q].max(m);
    }
    Integrated { u, misfit }
}

/// Samples whose own misfit and whose neighbours' are all below `tau` (the warp is
/// trusted there; elsewhere the synthesis starts as without it).
pub(crate) fn trusted<const S: usize>(nbr: &[[u32; S]], misfit: &[f32], tau: f32) -> Vec<bool> {
    (0..misfit.len())
        .map(|p| {
            misfit[p] < tau && nbr[p].iter().all(|&q| q == u32::MAX || misfit[q as usize] < tau)
        })
        .collect()
}

/// Conjugate-gradient steps per finer level of the cascade.
const LEVEL_ITERATIONS: usize = 40;

/// The integrated start of the parallel synthesis
/// ([`crate::SynthesisOptions::integrated_init`]): the parent level's `U`, carried from
/// the initialisation level down to the finest.
pub(crate) struct IntegratedStart {
    parent: Integrated,
    tau: f32,
}

impl IntegratedStart {
    /// `U` of the initialisation level (`nbr`, `jac`, `flips`, lattice spacing
    /// `spacing`); the coordinates `s` of its trusted samples (misfit below `tau`,
    /// [`trusted`]) become `U + offset` wrapped into the exemplar of `size` pixels
    /// (floored with `snap`), the others keep theirs.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn begin<const D: usize, const S: usize>(
        nbr: &[[u32; S]],
        jac: &[Jacobian<D>],
        flips: &[bool],
        spacing: f32,
        tau: f32,
        offset: [f64; 2],
        size: (usize, usize),
        snap: bool,
        s: &mut [[f32; 2]],
    ) -> Self
    where
        Dim<D>: Stencil<D, S>,
    {
        let r = integrated_coordinates::<D, S>(nbr, jac, flips, spacing);
        let (w, h) = (size.0 as f64, size.1 as f64);
        for ((si, v), _) in s.iter_mut().zip(&r.u).zip(trusted(nbr, &r.misfit, tau)).filter(|x| x.1)
        {
            let x = (v[0] + offset[0]).rem_euclid(w);
            let y = (v[1] + offset[1]).rem_euclid(h);
            let (x, y) = if snap { (x.floor(), y.floor()) } else { (x, y) };
            *si = [(x as f32).min((w as f32).next_down()), (y as f32).min((h as f32).next_down())];
        }
        Self { parent: r, tau }
    }

    /// One finer level: `U` carried down from the parents (`parent[i].0`, the child's
    /// upsampling offset `h F o` from `offset(i)`) and smoothed on this level; per
    /// sample its step from the parent (`None`: the default path, for untrusted samples)
    /// and whether it is trusted. This level's `U` becomes the next level's parent.
    pub(crate) fn level<const D: usize, const S: usize>(
        &mut self,
        nbr: &[[u32; S]],
        jac: &[Jacobian<D>],
        flips: &[bool],
        parent: &[(u32, [f32; D])],
        offset: impl Fn(usize) -> [f32; 2],
        spacing: f32,
    ) -> (Vec<Option<[f32; 2]>>, Vec<bool>)
    where
        Dim<D>: Stencil<D, S>,
    {
        let u_par = &self.parent.u;
        let start: Vec<[f64; 2]> = (0..jac.len())
            .map(|i| {
                let (par, o) = (parent[i].0 as usize, offset(i));
                [u_par[par][0] + o[0] as f64, u_par[par][1] + o[1] as f64]
            })
            .collect();
        let r = refine_integrated_coordinates::<D, S>(
            nbr,
            jac,
            flips,
            spacing,
            start,
            LEVEL_ITERATIONS,
        );
        let trust = trusted(nbr, &r.misfit, self.tau);
        let steps = (0..jac.len())
            .map(|i| {
                let par = parent[i].0 as usize;
                trust[i].then(|| {
                    [(r.u[i][0] - u_par[par][0]) as f32, (r.u[i][1] - u_par[par][1]) as f32]
                })
            })
            .collect();
        self.parent = r;
        (steps, trust)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice_domain::OFFS8;

    /// 8-neighbour table of a `w × h` grid (row-major).
    fn grid(w: usize, h: usize) -> Vec<[u32; 8]> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i32, (i / w) as i32);
                OFFS8.map(|[dx, dy]| {
                    let (qx, qy) = (x + dx, y + dy);
                    if qx < 0 || qy < 0 || qx >= w as i32 || qy >= h as i32 {
                        u32::MAX
                    } else {
                        (qy as usize * w + qx as usize) as u32
                    }
                })
            })
            .collect()
    }

    #[test]
    fn a_constant_frame_integrates_to_the_tiling_along_it() {
        let (w, h) = (7, 5);
        let (c, s) = (0.6f32, 0.8f32);
        let jac = vec![[[c, -s], [s, c]]; w * h];
        // Half the samples carry the opposite representative and a flip: the same
        // effective frame.
        let (jac, flips): (Vec<_>, Vec<_>) = jac
            .iter()
            .enumerate()
            .map(|(i, j)| if i % 3 == 0 { (negated(j), true) } else { (*j, false) })
            .unzip();
        let r = integrated_coordinates::<2, 8>(&grid(w, h), &jac, &flips, 4.0);
        assert!(r.misfit.iter().all(|&m| m < 1e-6));
        let u = r.u;
        let at = |x: usize, y: usize| u[y * w + x];
        for y in 0..h {
            for x in 0..w - 1 {
                let (a, b) = (at(x, y), at(x + 1, y));
                // One step along +x is 4 · J e_x = 4 (c, s).
                assert!((b[0] - a[0] - 2.4).abs() < 1e-6 && (b[1] - a[1] - 3.2).abs() < 1e-6);
            }
        }
        let mean_x: f64 = u.iter().map(|v| v[0]).sum::<f64>() / u.len() as f64;
        assert!(mean_x.abs() < 1e-6);
    }

    #[test]
    fn a_forced_seam_is_left_out() {
        // Left half frame I, right half −I without flips: the effective frames disagree
        // across the middle, so each half integrates on its own.
        let (w, h) = (6, 4);
        let jac: Vec<Jacobian<2>> = (0..w * h)
            .map(|i| if i % w < 3 { [[1.0, 0.0], [0.0, 1.0]] } else { [[-1.0, 0.0], [0.0, -1.0]] })
            .collect();
        let r = integrated_coordinates::<2, 8>(&grid(w, h), &jac, &vec![false; w * h], 1.0);
        assert!(r.misfit[2].is_infinite() && r.misfit[3].is_infinite() && r.misfit[0] < 1e-6);
        let u = r.u;
        let at = |x: usize, y: usize| u[y * w + x];
        assert!((at(1, 0)[0] - at(0, 0)[0] - 1.0).abs() < 1e-6);
        assert!((at(4, 0)[0] - at(3, 0)[0] + 1.0).abs() < 1e-6);
        assert!((at(1, 1)[1] - at(1, 0)[1] - 1.0).abs() < 1e-6);
    }
}
