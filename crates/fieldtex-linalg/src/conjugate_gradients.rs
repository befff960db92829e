//! Conjugate gradients on a matrix-free operator: `apply(x, y)` writes `y = A x` for a
//! symmetric positive (semi-)definite `A` (Hestenes & Stiefel 1952). Sequential, so the
//! result does not depend on the thread count. Starting from zero, the iterates of a
//! singular but consistent system (a graph Laplacian with a right-hand side summing to
//! zero) stay orthogonal to its null space, so the solution has zero mean there.

/// Solves `A x = rhs` from `x = 0` until `‖r‖ ≤ tolerance ‖rhs‖` or `max_iterations`.
pub fn conjugate_gradients(
    apply: &dyn Fn(&[f64], &mut [f64]),
    rhs: &[f64],
    max_iterations: usize,
    tolerance: f64,
) -> Vec<f64> {
    let n = rhs.len();
    let mut x = vec![0.0; n];
    let mut r = rhs.to_vec();
    let mut p = r.clone();
    let mut ap = vec![0.0; n];
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut rr = dot(&r, &r);
    let stop = tolerance * tolerance * rr.max(f64::MIN_POSITIVE);
    for _ in 0..max_iterations {
        if rr <= stop {
            break;
        }
        apply(&p, &mut ap);
        let alpha = rr / dot(&p, &ap);
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        let next = dot(&r, &r);
        let beta = next / rr;
        rr = next;
        for i in 0..n {
            p[i] = r[i] + beta * p[i];
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_path_laplacian_with_zero_mean() {
        // Path graph 0-1-2-3 with unit edges; rhs sums to zero (consistent).
        let apply = |x: &[f64], y: &mut [f64]| {
            let n = x.len();
            for i in 0..n {
                let mut v = 0.0;
                if i > 0 {
                    v += x[i] - x[i - 1];
                }
                if i + 1 < n {
                    v += x[i] - x[i + 1];
                }
                y[i] = v;
            }
        };
        let rhs = [-1.0, 0.0, 0.0, 1.0];
        let x = conjugate_gradients(&apply, &rhs, 100, 1e-12);
        // x is the linear ramp with slope 1 per edge (each inner node balanced), mean zero.
        let mean: f64 = x.iter().sum::<f64>() / 4.0;
        assert!(mean.abs() < 1e-9, "{x:?}");
        for w in x.windows(2) {
            assert!((w[1] - w[0] - 1.0).abs() < 1e-9, "{x:?}");
        }
    }
}
