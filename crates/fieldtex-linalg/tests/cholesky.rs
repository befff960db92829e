//! Sparse Cholesky: solves, symbolic reuse, residual checks and bad input.

mod common;
use common::*;
use fieldtex_linalg::{Cholesky, FactorLayout, LinalgError, SparseMatrix, SymbolicCholesky};

#[test]
fn penalty_grid_solves_with_small_residual() {
    let (w, h) = (60, 50);
    let a = penalty_system(w, h, &every(w * h, 50), 1e8);
    let chol = Cholesky::factor(&a).unwrap();
    let mut rng = Lcg(7);
    let x_true = rng.vec(w * h);
    let b = a.mul_vec(&x_true);
    let x = chol.solve(&b).unwrap();
    assert!(chol.last_residual() < 1e-12, "residual {}", chol.last_residual());
    // forward error is bounded by cond · residual; the penalty system is stiff but the
    // recovered x must still be close.
    assert!(max_abs_diff(&x, &x_true) < 1e-6, "err {}", max_abs_diff(&x, &x_true));
}

#[test]
fn symbolic_is_reused_for_new_values() {
    let (w, h) = (30, 20);
    let cons = every(w * h, 17);
    let a = penalty_system(w, h, &cons, 1e8);
    let sym = SymbolicCholesky::analyze(&a).unwrap();
    assert_eq!(sym.size(), w * h);
    let mut a2 = a.clone();
    a2.values_mut().iter_mut().for_each(|v| *v *= 3.0);
    let c1 = Cholesky::factor_with(&sym, &a).unwrap();
    let c2 = Cholesky::factor_with(&sym, &a2).unwrap();
    let b = Lcg(3).vec(w * h);
    let x1 = c1.solve(&b).unwrap();
    let x2 = c2.solve(&b).unwrap();
    for (p, q) in x1.iter().zip(&x2) {
        assert!((p - 3.0 * q).abs() < 1e-9 * p.abs().max(1.0));
    }
    // another pattern is refused
    let other = penalty_system(w, h, &every(w * h, 13), 1e8);
    let other = other.add_scaled(&grid_laplacian(w, h), 0.0);
    let bigger = grid_laplacian(w + 1, h).add_diagonal(&vec![1.0; (w + 1) * h]);
    assert!(matches!(Cholesky::factor_with(&sym, &bigger), Err(LinalgError::Dimension { .. })));
    let _ = other; // same pattern (diagonal always stored): accepted
    let mut t = a.triplets();
    t.push((0, w * h - 1, 0.0));
    t.push((w * h - 1, 0, 0.0));
    let extra = SparseMatrix::from_triplets(w * h, w * h, &t).unwrap();
    assert!(matches!(
        Cholesky::factor_with(&sym, &extra),
        Err(LinalgError::PatternMismatch { .. })
    ));
}

#[test]
fn solve_many_matches_single_solves() {
    let (w, h) = (40, 40);
    let a = penalty_system(w, h, &every(w * h, 31), 1e8);
    let chol = Cholesky::factor(&a).unwrap();
    let mut rng = Lcg(11);
    let bs: Vec<Vec<f64>> = (0..3).map(|_| rng.vec(w * h)).collect();
    let xs = chol.solve_many(&bs).unwrap();
    for (b, x) in bs.iter().zip(&xs) {
        let single = chol.solve(b).unwrap();
        let d = max_abs_diff(&single, x) / max_abs(&single);
        assert!(d < 1e-13, "blocked vs single solve: {d:e}");
    }
    assert!(chol.solve_many(&[]).unwrap().is_empty());
}

#[test]
fn laplacian_without_constraints_is_not_spd() {
    // a pure graph Laplacian is singular (constants in the kernel)
    let err = Cholesky::factor(&grid_laplacian(10, 10)).unwrap_err();
    assert!(matches!(err, LinalgError::FactorizationFailed { size: 100, .. }), "{err}");
}

#[test]
fn zero_row_is_an_error_not_a_panic() {
    let a = penalty_system(8, 8, &every(64, 5), 1e8);
    // drop every entry of row/column 9
    let t: Vec<_> = a.triplets().into_iter().filter(|&(i, j, _)| i != 9 && j != 9).collect();
    let z = SparseMatrix::from_triplets(64, 64, &t).unwrap();
    let err = Cholesky::factor(&z).unwrap_err();
    assert!(matches!(err, LinalgError::FactorizationFailed { .. }), "{err}");
    // explicit zero diagonal too
    let mut t2 = a.triplets();
    t2.retain(|&(i, j, _)| i != 9 && j != 9);
    t2.push((9, 9, 0.0));
    let z2 = SparseMatrix::from_triplets(64, 64, &t2).unwrap();
    assert!(matches!(Cholesky::factor(&z2), Err(LinalgError::FactorizationFailed { .. })));
}

#[test]
fn indefinite_matrix_is_an_error() {
    let a =
        SparseMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, 1.0), (0, 1, 2.0), (1, 0, 2.0)])
            .unwrap();
    assert!(matches!(Cholesky::factor(&a), Err(LinalgError::FactorizationFailed { .. })));
}

#[test]
fn bad_values_are_errors() {
    let a = penalty_system(6, 6, &[0], 1e8);
    let chol = Cholesky::factor(&a).unwrap();
    let mut b = vec![1.0; 36];
    b[4] = f64::NAN;
    assert!(matches!(chol.solve(&b), Err(LinalgError::NonFinite { index: 4, .. })));
    assert!(matches!(chol.solve(&[1.0; 5]), Err(LinalgError::Dimension { .. })));
    // NaN introduced through arithmetic on a valid matrix
    let nan = a.add_scaled(&a, f64::NAN);
    assert!(matches!(Cholesky::factor(&nan), Err(LinalgError::NonFinite { .. })));
    // asymmetric
    let mut t = a.triplets();
    t.push((0, 1, 0.5));
    let asym = SparseMatrix::from_triplets(36, 36, &t).unwrap();
    assert!(matches!(Cholesky::factor(&asym), Err(LinalgError::NotSymmetric { .. })));
    // not square
    let rect = SparseMatrix::from_triplets(3, 2, &[(0, 0, 1.0)]).unwrap();
    assert!(matches!(Cholesky::factor(&rect), Err(LinalgError::Dimension { .. })));
    // zero rhs
    assert_eq!(chol.solve(&[0.0; 36]).unwrap(), vec![0.0; 36]);
}

#[test]
fn empty_matrix() {
    let a = SparseMatrix::from_triplets(0, 0, &[]).unwrap();
    let chol = Cholesky::factor(&a).unwrap();
    assert!(chol.solve(&[]).unwrap().is_empty());
}

#[test]
fn tight_tolerance_reports_solve_failed() {
    let a = penalty_system(30, 30, &every(900, 20), 1e8);
    let opts = fieldtex_linalg::CholeskyOptions {
        residual_tolerance: 0.0,
        refine_above: 0.0,
        max_refinement_steps: 1,
        ..Default::default()
    };
    let chol = Cholesky::factor(&a).unwrap().with_options(opts);
    let b = Lcg(5).vec(900);
    match chol.solve(&b) {
        Err(LinalgError::SolveFailed { residual, .. }) => {
            assert!(residual > 0.0 && residual < 1e-10)
        }
        other => panic!("expected SolveFailed, got {other:?}"),
    }
}

#[test]
fn factor_and_solve_are_thread_count_independent() {
    let a = penalty_system(120, 100, &every(12000, 50), 1e8);
    let b = Lcg(9).vec(12000);
    for layout in
        [fieldtex_linalg::FactorLayout::Simplicial, fieldtex_linalg::FactorLayout::Supernodal]
    {
        let run = |t| {
            rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap().install(|| {
                let s = SymbolicCholesky::analyze_with(&a, layout).unwrap();
                let mut c = Cholesky::factor_with(&s, &a).unwrap();
                let x = c.solve_many(&[b.clone(), b.clone()]).unwrap();
                c.add_diagonal_penalty(77, 1e8).unwrap();
                (x, c.solve(&b).unwrap())
            })
        };
        assert_eq!(run(1), run(2));
        assert_eq!(run(1), run(3));
    }
}

#[test]
fn public_types_are_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<Cholesky>();
    check::<SymbolicCholesky>();
    check::<SparseMatrix>();
    check::<fieldtex_linalg::Pca>();
    check::<LinalgError>();
}

#[test]
fn given_ordering_factors_and_rejects_non_permutations() {
    let (w, h) = (30, 20);
    let n = w * h;
    let a = penalty_system(w, h, &every(n, 23), 1e8);
    let reversed: Vec<usize> = (0..n).rev().collect();
    let sym = SymbolicCholesky::analyze_with_ordering(&a, FactorLayout::Auto, &reversed).unwrap();
    assert_eq!(sym.permutation(), reversed);
    let b = Lcg(3).vec(n);
    let x = Cholesky::factor_with(&sym, &a).unwrap().solve(&b).unwrap();
    let reference = Cholesky::factor(&a).unwrap().solve(&b).unwrap();
    assert!(max_abs_diff(&x, &reference) <= 1e-9 * max_abs(&reference));
    let mut dup = reversed.clone();
    dup[0] = dup[1];
    assert!(SymbolicCholesky::analyze_with_ordering(&a, FactorLayout::Auto, &dup).is_err());
    assert!(
        SymbolicCholesky::analyze_with_ordering(&a, FactorLayout::Auto, &reversed[1..]).is_err()
    );
}
