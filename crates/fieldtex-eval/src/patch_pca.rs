//! A few leading principal directions of patch vectors, used only to **prune** exact
//! nearest-patch searches (any orthonormal basis keeps the search exact; a good one
//! makes it fast).
//!
//! Orthogonal (subspace) iteration on the covariance matrix from a deterministic
//! start, then a Rayleigh–Ritz step with a cyclic Jacobi eigen-solver on the small
//! `k × k` projected matrix so the directions come out sorted by variance (Golub &
//! Van Loan, "Matrix Computations", §8.2 and §8.5). Small and dependency-free; the
//! dense solver of `fieldtex-linalg` is not needed for a 147-D covariance.

/// Eigen-decomposition of a small symmetric `n × n` matrix (row-major) by cyclic
/// Jacobi rotations. Returns eigenvalues in decreasing order and the matching
/// eigenvectors as rows.
pub(crate) fn jacobi_eigen(a: &[f64], n: usize) -> (Vec<f64>, Vec<Vec<f64>>) {
    let mut m = a.to_vec();
    let mut v = vec![0f64; n * n];
    for i in 0..n {
        v[i * n + i] = 1.0;
    }
    for _sweep in 0..60 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| m[i * n + j].powi(2))
            .sum();
        let diag: f64 = (0..n).map(|i| m[i * n + i].powi(2)).sum();
        if off <= 1e-24 * diag.max(1e-300) {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = m[p * n + q];
                if apq.abs() < 1e-300 {
                    continue;
                }
                let (app, aqq) = (m[p * n + p], m[q * n + q]);
                let theta = (aqq - app) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (mkp, mkq) = (m[k * n + p], m[k * n + q]);
                    m[k * n + p] = c * mkp - s * mkq;
                    m[k * n + q] = s * mkp + c * mkq;
                }
                for k in 0..n {
                    let (mpk, mqk) = (m[p * n + k], m[q * n + k]);
                    m[p * n + k] = c * mpk - s * mqk;
                    m[q * n + k] = s * mpk + c * mqk;
                }
                for k in 0..n {
                    let (vkp, vkq) = (v[k * n + p], v[k * n + q]);
                    v[k * n + p] = c * vkp - s * vkq;
                    v[k * n + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| m[j * n + j].total_cmp(&m[i * n + i]).then(i.cmp(&j)));
    let values = order.iter().map(|&i| m[i * n + i]).collect();
    let vectors = order.iter().map(|&i| (0..n).map(|k| v[k * n + i]).collect()).collect();
    (values, vectors)
}

/// Orthonormalises the rows of `basis` in place (modified Gram–Schmidt); rows that
/// collapse are replaced by unit coordinate vectors orthogonalised in turn.
fn orthonormalize(basis: &mut [Vec<f64>]) {
    let d = basis.first().map_or(0, |b| b.len());
    for i in 0..basis.len() {
        for attempt in 0..=d {
            for j in 0..i {
                let dot: f64 = basis[i].iter().zip(&basis[j]).map(|(a, b)| a * b).sum();
                let bj = basis[j].clone();
                for (a, b) in basis[i].iter_mut().zip(&bj) {
                    *a -= dot * b;
                }
            }
            let norm = basis[i].iter().map(|a| a * a).sum::<f64>().sqrt();
            if norm > 1e-10 {
                basis[i].iter_mut().for_each(|a| *a /= norm);
                break;
            }
            // Degenerate: restart from a coordinate vector.
            basis[i] = (0..d).map(|k| if k == (i + attempt) % d { 1.0 } else { 0.0 }).collect();
        }
    }
}

/// The `k` leading principal directions (rows, unit length, mutually orthogonal) of
/// the covariance `cov` (`d × d`, row-major), largest variance first.
pub(crate) fn leading_directions(cov: &[f64], d: usize, k: usize) -> Vec<Vec<f64>> {
    let k = k.min(d).max(1);
    // Deterministic, generic start: a smooth pseudo-random pattern per row.
    let mut basis: Vec<Vec<f64>> = (0..k)
        .map(|i| {
            (0..d)
                .map(|j| ((i * 7919 + j * 104_729 + 1) as f64 * 0.618_033_988_7).fract() - 0.5)
                .collect()
        })
        .collect();
    orthonormalize(&mut basis);
    let mul = |v: &[f64]| -> Vec<f64> {
        (0..d).map(|r| cov[r * d..(r + 1) * d].iter().zip(v).map(|(a, b)| a * b).sum()).collect()
    };
    for _ in 0..40 {
        let mut next: Vec<Vec<f64>> = basis.iter().map(|b| mul(b)).collect();
        orthonormalize(&mut next);
        basis = next;
    }
    // Rayleigh–Ritz: diagonalise Bᵀ C B.
    let cb: Vec<Vec<f64>> = basis.iter().map(|b| mul(b)).collect();
    let mut small = vec![0f64; k * k];
    for i in 0..k {
        for j in 0..k {
            small[i * k + j] = basis[i].iter().zip(&cb[j]).map(|(a, b)| a * b).sum();
        }
    }
    for i in 0..k {
        for j in 0..i {
            let s = 0.5 * (small[i * k + j] + small[j * k + i]);
            small[i * k + j] = s;
            small[j * k + i] = s;
        }
    }
    let (_, vecs) = jacobi_eigen(&small, k);
    let mut out: Vec<Vec<f64>> = vecs
        .iter()
        .map(|w| (0..d).map(|t| (0..k).map(|i| w[i] * basis[i][t]).sum()).collect())
        .collect();
    orthonormalize(&mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_diagonalises() {
        let a = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 1.0];
        let (vals, vecs) = jacobi_eigen(&a, 3);
        assert!(vals[0] >= vals[1] && vals[1] >= vals[2]);
        for (l, v) in vals.iter().zip(&vecs) {
            for r in 0..3 {
                let av: f64 = (0..3).map(|c| a[r * 3 + c] * v[c]).sum();
                assert!((av - l * v[r]).abs() < 1e-10);
            }
        }
    }

    #[test]
    fn leading_directions_of_a_diagonal_covariance() {
        let d = 6;
        let mut cov = vec![0f64; d * d];
        for (i, v) in [1.0, 9.0, 4.0, 0.5, 16.0, 2.0].iter().enumerate() {
            cov[i * d + i] = *v;
        }
        let b = leading_directions(&cov, d, 3);
        let expect = [4, 1, 2];
        for (row, &axis) in b.iter().zip(&expect) {
            assert!((row[axis].abs() - 1.0).abs() < 1e-6, "{row:?}");
        }
    }
}
