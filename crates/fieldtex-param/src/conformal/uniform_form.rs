//! The holomorphic 1-form with the most uniform conformal factor (after Jin, Wang, Yau &
//! Gu 2004, "Optimal global conformal surface parameterization", used by Wang et al.
//! 2005 §3 to pick the form to cut along).
//!
//! Every holomorphic form is `φ_a = Σ_k a_k (ω_k + i ⋆ω_k)` with real `a ∈ ℝ^{2g}`, and
//! its area stretching per face is `|φ_a|² = |Σ_k a_k X_k|²` (`X_k` the face vectors of
//! `ω_k`). We minimise the area-weighted coefficient of variation of `|φ_a|²` over the
//! unit sphere of `a` — scale-free, so the sphere loses nothing — by a deterministic
//! compass (pattern) search started from the best basis form: try `a ± s e_k` for every
//! `k`, keep the best improvement, halve `s` when none improves. Substitute: Jin et al.
//! state the problem as an energy over the form space and minimise it with their own
//! solver; the compass search reaches a local minimum of the same kind of objective
//! (uniformity of the conformal factor) and is named as a substitute in the notes.

use fieldtex_core::vec3;

/// The optimised coefficients (unit length) and the objective before (best basis form)
/// and after.
#[derive(Debug, Clone)]
pub struct UniformForm {
    pub coefficients: Vec<f64>,
    pub cv_basis: f64,
    pub cv: f64,
}

/// Area-weighted coefficient of variation of `|Σ a_k X_k|²`.
pub fn stretch_cv(x: &[Vec<[f64; 3]>], areas: &[f64], a: &[f64]) -> f64 {
    let (mut s, mut s2, mut w) = (0.0, 0.0, 0.0);
    for f in 0..areas.len() {
        let mut v = [0.0; 3];
        for (k, xk) in x.iter().enumerate() {
            v = vec3::add(v, vec3::scale(xk[f], a[k]));
        }
        let m = vec3::norm2(v);
        s += areas[f] * m;
        s2 += areas[f] * m * m;
        w += areas[f];
    }
    let mean = s / w.max(f64::MIN_POSITIVE);
    ((s2 / w.max(f64::MIN_POSITIVE) - mean * mean).max(0.0)).sqrt() / mean.max(f64::MIN_POSITIVE)
}

/// Compass search for the most uniform form (see the module docs); at most `max_evals`
/// objective evaluations.
pub fn most_uniform_form(x: &[Vec<[f64; 3]>], areas: &[f64], max_evals: usize) -> UniformForm {
    let m = x.len();
    let unit = |k: usize| (0..m).map(|j| if j == k { 1.0 } else { 0.0 }).collect::<Vec<f64>>();
    let mut best_k = 0;
    let mut best = f64::INFINITY;
    for k in 0..m {
        let cv = stretch_cv(x, areas, &unit(k));
        if cv < best {
            best = cv;
            best_k = k;
        }
    }
    let cv_basis = best;
    let mut a = unit(best_k);
    let mut step = 0.5;
    let mut evals = m;
    while step > 1e-3 && evals < max_evals {
        let mut improved: Option<(Vec<f64>, f64)> = None;
        for k in 0..m {
            for s in [step, -step] {
                let mut b = a.clone();
                b[k] += s;
                let n = b.iter().map(|v| v * v).sum::<f64>().sqrt();
                if n <= 1e-12 {
                    continue;
                }
                for v in b.iter_mut() {
                    *v /= n;
                }
                let cv = stretch_cv(x, areas, &b);
                evals += 1;
                if cv < improved.as_ref().map_or(best, |i| i.1) {
                    improved = Some((b, cv));
                }
            }
        }
        match improved {
            Some((b, cv)) => {
                a = b;
                best = cv;
            }
            None => step *= 0.5,
        }
    }
    UniformForm { coefficients: a, cv_basis, cv: best }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn search_finds_the_uniform_combination() {
        // Two "forms" on 4 faces: X0 large on faces 0–1, X1 on faces 2–3; their sum is
        // uniform (CV 0), each alone is not.
        let x = vec![
            vec![[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.0, 0.0]],
            vec![[0.0, 0.1, 0.0], [0.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        ];
        let areas = [1.0; 4];
        let r = most_uniform_form(&x, &areas, 500);
        assert!(r.cv_basis > 0.9, "{r:?}");
        assert!(r.cv < 1e-3, "{r:?}");
        assert!(r.cv <= r.cv_basis);
    }
}
