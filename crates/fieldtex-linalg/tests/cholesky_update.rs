//! Rank-1 update/downdate of the sparse Cholesky factor, checked against full
//! refactorisations of the independently assembled matrix.

mod common;
use common::*;
use fieldtex_linalg::{
    Cholesky, FactorLayout, LinalgError, SparseMatrix, SymbolicCholesky, UpdateSign,
};

const LAYOUTS: [FactorLayout; 2] = [FactorLayout::Simplicial, FactorLayout::Supernodal];

/// Factor with a forced layout (both storage paths of the update code are tested).
fn factor(a: &SparseMatrix, layout: FactorLayout) -> Cholesky {
    let sym = SymbolicCholesky::analyze_with(a, layout).unwrap();
    assert_eq!(sym.is_supernodal(), layout == FactorLayout::Supernodal);
    Cholesky::factor_with(&sym, a).unwrap()
}

const ALPHA: f64 = 1e8;

/// `a + sign · w wᵀ`, assembled independently of the solver.
fn add_outer(a: &SparseMatrix, w: &[(usize, f64)], sign: f64) -> SparseMatrix {
    let t: Vec<_> =
        w.iter().flat_map(|&(i, x)| w.iter().map(move |&(j, y)| (i, j, x * y))).collect();
    a.add_scaled(&SparseMatrix::from_triplets(a.nrows(), a.ncols(), &t).unwrap(), sign)
}

fn rel_residual(a: &SparseMatrix, x: &[f64], b: &[f64]) -> f64 {
    let ax = a.mul_vec(x);
    let r: f64 = ax.iter().zip(b).map(|(p, q)| (p - q) * (p - q)).sum::<f64>().sqrt();
    r / b.iter().map(|v| v * v).sum::<f64>().sqrt()
}

fn rel_diff(x: &[f64], y: &[f64]) -> f64 {
    max_abs_diff(x, y) / max_abs(y)
}

#[test]
fn sixteen_random_updates_match_refactorisation() {
    for layout in LAYOUTS {
        sixteen_random_updates_match_refactorisation_with(layout);
    }
}

fn sixteen_random_updates_match_refactorisation_with(layout: FactorLayout) {
    let (w, h) = (40, 30);
    let n = w * h;
    let a0 = penalty_system(w, h, &every(n, 37), ALPHA);
    let mut chol = factor(&a0, layout);
    let mut a_ref = a0.clone();
    let mut rng = Lcg(2024);
    let mut penalties: Vec<usize> = Vec::new();
    let mut general: Vec<Vec<(usize, f64)>> = Vec::new();
    for step in 0..16 {
        match step % 4 {
            0 | 2 => {
                let i = rng.below(n);
                chol.add_diagonal_penalty(i, ALPHA).unwrap();
                a_ref = add_outer(&a_ref, &[(i, ALPHA.sqrt())], 1.0);
                penalties.push(i);
            }
            1 => {
                // three entries in different places of the grid: creates fill in L
                let wv: Vec<(usize, f64)> =
                    (0..3).map(|_| (rng.below(n), rng.next_f64() + 0.5)).collect();
                chol.update(&wv, UpdateSign::Up).unwrap();
                let mut merged = wv.clone();
                merged.sort_by_key(|e| e.0);
                a_ref = add_outer(&a_ref, &wv, 1.0);
                general.push(wv);
            }
            _ => {
                if step % 8 == 3 {
                    let i = penalties.remove(0);
                    chol.remove_diagonal_penalty(i, ALPHA).unwrap();
                    a_ref = add_outer(&a_ref, &[(i, ALPHA.sqrt())], -1.0);
                } else {
                    let wv = general.remove(0);
                    chol.update(&wv, UpdateSign::Down).unwrap();
                    a_ref = add_outer(&a_ref, &wv, -1.0);
                }
            }
        }
    }
    assert!(chol.is_updated());
    let b = rng.vec(n);
    let x_up = chol.solve(&b).unwrap();
    let x_full = Cholesky::factor(&a_ref).unwrap().solve(&b).unwrap();
    assert!(
        rel_residual(&a_ref, &x_up, &b) < 1e-12,
        "residual {}",
        rel_residual(&a_ref, &x_up, &b)
    );
    assert!(rel_diff(&x_up, &x_full) < 1e-11, "solutions differ by {}", rel_diff(&x_up, &x_full));
    // the matrix tracked for residual checks is the assembled one
    let cur = chol.current_matrix();
    let diff = cur.add_scaled(&a_ref, -1.0);
    assert!(max_abs(diff.values()) < 1e-6, "tracked matrix drift {}", max_abs(diff.values()));
}

#[test]
fn downdate_of_update_restores_original() {
    for layout in LAYOUTS {
        downdate_of_update_restores_original_with(layout);
    }
}

fn downdate_of_update_restores_original_with(layout: FactorLayout) {
    let (w, h) = (30, 30);
    let n = w * h;
    let a0 = penalty_system(w, h, &every(n, 23), ALPHA);
    let mut chol = factor(&a0, layout);
    let b = Lcg(1).vec(n);
    let x0 = chol.solve(&b).unwrap();
    let wv = [(5, 0.7), (n - 3, -1.3), (n / 2, 0.25)];
    chol.add_diagonal_penalty(417, ALPHA).unwrap();
    chol.update(&wv, UpdateSign::Up).unwrap();
    let x_mid = chol.solve(&b).unwrap();
    assert!(rel_diff(&x_mid, &x0) > 1e-3, "the update must change the solution");
    chol.update(&wv, UpdateSign::Down).unwrap();
    chol.remove_diagonal_penalty(417, ALPHA).unwrap();
    let x1 = chol.solve(&b).unwrap();
    assert!(rel_diff(&x1, &x0) < 1e-11, "restored solution differs by {}", rel_diff(&x1, &x0));
    // the factor itself (no refinement) is restored up to the ε·α rounding of the round trip
    let raw = chol.clone().with_options(fieldtex_linalg::CholeskyOptions {
        max_refinement_steps: 0,
        refine_after_downdate: false,
        ..Default::default()
    });
    let x_raw = raw.solve(&b).unwrap();
    assert!(
        rel_diff(&x_raw, &x0) < 1e-7,
        "unrefined restored solution differs by {}",
        rel_diff(&x_raw, &x0)
    );
    assert!(rel_residual(&a0, &x1, &b) < 1e-11);
}

#[test]
fn indefinite_downdate_is_refused_and_factor_kept() {
    for layout in LAYOUTS {
        indefinite_downdate_is_refused_and_factor_kept_with(layout);
    }
}

fn indefinite_downdate_is_refused_and_factor_kept_with(layout: FactorLayout) {
    let (w, h) = (20, 20);
    let n = w * h;
    let cons = every(n, 19);
    let a0 = penalty_system(w, h, &cons, ALPHA);
    let mut chol = factor(&a0, layout);
    chol.add_diagonal_penalty(7, 1.0).unwrap(); // make sure we are in the updatable form
    let b = Lcg(4).vec(n);
    let x_before = chol.solve(&b).unwrap();
    // node 1 is unconstrained: removing 1e8 from a diagonal of ~3 is indefinite
    let err = chol.remove_diagonal_penalty(1, ALPHA).unwrap_err();
    assert!(matches!(err, LinalgError::UpdateFailed { column: 1, .. }), "{err}");
    // a general downdate larger than the matrix along a direction
    let err = chol.update(&[(3, 10.0), (4, 10.0)], UpdateSign::Down).unwrap_err();
    assert!(matches!(err, LinalgError::UpdateFailed { .. }), "{err}");
    // removing a penalty that is not there, in a single step, to exactly zero pivot
    let x_after = chol.solve(&b).unwrap();
    assert_eq!(x_before, x_after, "a refused downdate must leave the factor bit-identical");
    // a legitimate downdate still works afterwards
    chol.remove_diagonal_penalty(7, 1.0).unwrap();
    chol.remove_diagonal_penalty(cons[2], ALPHA).unwrap();
    let a_ref = add_outer(&a0, &[(cons[2], ALPHA.sqrt())], -1.0);
    let x = chol.solve(&b).unwrap();
    let x_full = Cholesky::factor(&a_ref).unwrap().solve(&b).unwrap();
    assert!(rel_diff(&x, &x_full) < 1e-11, "{}", rel_diff(&x, &x_full));
}

#[test]
fn penalty_constraints_on_a_grid_laplacian() {
    for layout in LAYOUTS {
        penalty_constraints_on_a_grid_laplacian_with(layout);
    }
}

fn penalty_constraints_on_a_grid_laplacian_with(layout: FactorLayout) {
    // The intended use: L + P with 2 % constrained, then move constraints around.
    let (w, h) = (50, 40);
    let n = w * h;
    let mut cons = every(n, 50);
    let a0 = penalty_system(w, h, &cons, ALPHA);
    let mut chol = factor(&a0, layout);
    let mut rng = Lcg(77);
    for _ in 0..5 {
        let i = rng.below(n);
        chol.add_diagonal_penalty(i, ALPHA).unwrap();
        cons.push(i);
    }
    for _ in 0..3 {
        let i = cons.remove(0);
        chol.remove_diagonal_penalty(i, ALPHA).unwrap();
    }
    let direct = penalty_system(w, h, &cons, ALPHA);
    // boundary values: b = α · target at constrained nodes
    let mut b = vec![0.0; n];
    for &i in &cons {
        b[i] += ALPHA * ((i % w) as f64 / w as f64);
    }
    let x = chol.solve(&b).unwrap();
    assert!(chol.last_residual() < 1e-12, "{}", chol.last_residual());
    let x_full = Cholesky::factor(&direct).unwrap().solve(&b).unwrap();
    assert!(rel_diff(&x, &x_full) < 1e-11, "{}", rel_diff(&x, &x_full));
    assert!(rel_residual(&direct, &x, &b) < 1e-12);
    // multi-RHS after updates
    let xs = chol.solve_many(&[b.clone(), rng.vec(n)]).unwrap();
    assert!(rel_diff(&xs[0], &x) < 1e-13, "{}", rel_diff(&xs[0], &x));
}

#[test]
fn tiny_tridiagonal_system_updates() {
    for layout in LAYOUTS {
        tiny_tridiagonal_system_updates_with(layout);
    }
}

fn tiny_tridiagonal_system_updates_with(layout: FactorLayout) {
    // 1-D chain: faer picks a simplicial factor here
    let n = 6;
    let mut t = Vec::new();
    for i in 0..n {
        t.push((i, i, 2.5));
        if i + 1 < n {
            t.push((i, i + 1, -1.0));
            t.push((i + 1, i, -1.0));
        }
    }
    let a0 = SparseMatrix::from_triplets(n, n, &t).unwrap();
    let mut chol = factor(&a0, layout);
    let wv = [(0, 1.0), (5, 2.0)];
    chol.update(&wv, UpdateSign::Up).unwrap();
    let a1 = add_outer(&a0, &wv, 1.0);
    let b = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let x = chol.solve(&b).unwrap();
    assert!(rel_residual(&a1, &x, &b) < 1e-14);
    let x_full = Cholesky::factor(&a1).unwrap().solve(&b).unwrap();
    assert!(rel_diff(&x, &x_full) < 1e-13);
}

#[test]
fn bad_update_input_is_an_error() {
    let a0 = penalty_system(5, 5, &[0], ALPHA);
    let mut chol = Cholesky::factor(&a0).unwrap();
    assert!(matches!(
        chol.update(&[(25, 1.0)], UpdateSign::Up),
        Err(LinalgError::IndexOutOfRange { .. })
    ));
    assert!(matches!(
        chol.update(&[(2, f64::NAN)], UpdateSign::Up),
        Err(LinalgError::NonFinite { .. })
    ));
    assert!(matches!(
        chol.update(&[(2, 1e200)], UpdateSign::Up),
        Err(LinalgError::NonFinite { .. })
    ));
    assert!(matches!(chol.add_diagonal_penalty(2, -1.0), Err(LinalgError::InvalidArgument { .. })));
    assert!(matches!(
        chol.add_diagonal_penalty(2, f64::INFINITY),
        Err(LinalgError::InvalidArgument { .. })
    ));
    // empty / zero vectors are no-ops
    chol.update(&[], UpdateSign::Down).unwrap();
    chol.update(&[(3, 0.0)], UpdateSign::Down).unwrap();
    assert!(!chol.is_updated());
    // duplicates are summed: (2, 1) + (2, 1) = 2 e₂ → +4 on the diagonal
    chol.update(&[(2, 1.0), (2, 1.0)], UpdateSign::Up).unwrap();
    assert_eq!(chol.current_matrix().get(2, 2), a0.get(2, 2) + 4.0);
}
