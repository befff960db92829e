//! Blocked multi-RHS solves against single solves, and multiple-rank penalty updates
//! against sequential rank-1 updates and refactorisations of the assembled matrix.

mod common;
use common::*;
use fieldtex_linalg::{
    Cholesky, FactorLayout, LinalgError, MAX_BLOCK, SparseMatrix, SymbolicCholesky, UpdateSign,
};

const LAYOUTS: [FactorLayout; 2] = [FactorLayout::Simplicial, FactorLayout::Supernodal];
const ALPHA: f64 = 1e8;

fn factor(a: &SparseMatrix, layout: FactorLayout) -> Cholesky {
    let sym = SymbolicCholesky::analyze_with(a, layout).unwrap();
    Cholesky::factor_with(&sym, a).unwrap()
}

fn rel_diff(x: &[f64], y: &[f64]) -> f64 {
    max_abs_diff(x, y) / max_abs(y)
}

fn rhs_set(n: usize, k: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = Lcg(seed);
    (0..k).map(|c| if c == 1 { vec![0.0; n] } else { rng.vec(n) }).collect()
}

fn check_blocked_equals_single(chol: &Cholesky, bs: &[Vec<f64>]) {
    let xs = chol.solve_many(bs).unwrap();
    let worst = chol.last_residual();
    let mut max_single = 0.0f64;
    for (b, x) in bs.iter().zip(&xs) {
        let (single, r) = chol.solve_with_residual(b).unwrap();
        max_single = max_single.max(r);
        if b.iter().all(|&v| v == 0.0) {
            assert!(x.iter().all(|&v| v == 0.0), "zero right-hand side gives x = 0");
            continue;
        }
        let d = rel_diff(x, &single);
        assert!(d < 1e-12, "blocked vs single solve: {d:e}");
    }
    assert!(worst < 1e-10, "worst residual {worst:e}");
    // caller buffers
    let refs: Vec<&[f64]> = bs.iter().map(Vec::as_slice).collect();
    let mut out: Vec<Vec<f64>> = bs.iter().map(|b| vec![f64::NAN; b.len()]).collect();
    let mut outs: Vec<&mut [f64]> = out.iter_mut().map(Vec::as_mut_slice).collect();
    let r = chol.solve_many_into(&refs, &mut outs).unwrap();
    assert_eq!(r, worst);
    assert_eq!(out, xs);
}

#[test]
fn blocked_solves_match_single_solves() {
    let (w, h) = (30, 25);
    let n = w * h;
    let a = penalty_system(w, h, &every(n, 29), ALPHA);
    for layout in LAYOUTS {
        let mut chol = factor(&a, layout);
        for k in [1, 3, MAX_BLOCK, MAX_BLOCK + 3] {
            check_blocked_equals_single(&chol, &rhs_set(n, k, 5 + k as u64));
        }
        // rank-1 update with fill: the factor leaves faer's layout (own blocked loops)
        chol.update(&[(3, 0.7), (n / 2, 1.1), (n - 5, -0.4)], UpdateSign::Up).unwrap();
        // downdate: forced refinement step on every column
        chol.add_diagonal_penalty(17, ALPHA).unwrap();
        chol.remove_diagonal_penalty(17, ALPHA).unwrap();
        for k in [3, MAX_BLOCK + 1] {
            check_blocked_equals_single(&chol, &rhs_set(n, k, 40 + k as u64));
        }
    }
}

#[test]
fn blocked_solve_input_errors() {
    let a = penalty_system(6, 6, &[0, 20], ALPHA);
    let chol = Cholesky::factor(&a).unwrap();
    assert!(matches!(
        chol.solve_many(&[vec![1.0; 36], vec![1.0; 35]]),
        Err(LinalgError::Dimension { .. })
    ));
    let mut bad = vec![1.0; 36];
    bad[7] = f64::NAN;
    assert!(matches!(
        chol.solve_many(&[vec![1.0; 36], bad]),
        Err(LinalgError::NonFinite { index: 7, .. })
    ));
    let b = vec![1.0; 36];
    let mut x = vec![0.0; 36];
    assert!(matches!(
        chol.solve_many_into(&[&b, &b], &mut [&mut x]),
        Err(LinalgError::Dimension { .. })
    ));
    assert!(chol.solve_many(&[]).unwrap().is_empty());
}

/// Solution of `a x = b` by a fresh factorisation.
fn reference(a: &SparseMatrix, b: &[f64]) -> Vec<f64> {
    Cholesky::factor(a).unwrap().solve(b).unwrap()
}

fn with_penalties(a: &SparseMatrix, p: &[(usize, f64)], sign: f64) -> SparseMatrix {
    let mut d = vec![0.0; a.nrows()];
    for &(i, alpha) in p {
        d[i] += sign * alpha;
    }
    a.add_diagonal(&d)
}

/// Multiple-rank update == the same rank-1 updates in turn == refactorisation, then the
/// downdate back to the original.
fn check_multiple_rank(a0: &SparseMatrix, layout: FactorLayout, pens: &[(usize, f64)], b: &[f64]) {
    let mut multi = factor(a0, layout);
    let mut seq = factor(a0, layout);
    let x0 = multi.solve(b).unwrap();
    multi.add_diagonal_penalties(pens).unwrap();
    for &(i, alpha) in pens {
        seq.add_diagonal_penalty(i, alpha).unwrap();
    }
    assert_eq!(multi.current_matrix(), seq.current_matrix());
    let a1 = with_penalties(a0, pens, 1.0);
    let dm = rel_diff(multi.current_matrix().values(), a1.values());
    assert!(dm < 1e-14, "tracked matrix vs assembled: {dm:e}");
    let xm = multi.solve(b).unwrap();
    let xs = seq.solve(b).unwrap();
    let d = rel_diff(&xm, &xs);
    assert!(d < 1e-13, "multiple-rank vs sequential rank-1: {d:e}");
    let d = rel_diff(&xm, &reference(&a1, b));
    assert!(d < 1e-10, "multiple-rank vs refactorisation: {d:e}");
    // downdate back (in another order)
    let rev: Vec<_> = pens.iter().rev().copied().collect();
    multi.remove_diagonal_penalties(&rev).unwrap();
    let d = rel_diff(&multi.solve(b).unwrap(), &x0);
    assert!(d < 1e-10, "downdated back vs original: {d:e}");
    assert!(multi.last_residual() < 1e-12);
}

#[test]
fn multiple_rank_random_penalties() {
    let (w, h) = (36, 28);
    let n = w * h;
    let a0 = penalty_system(w, h, &every(n, 41), ALPHA);
    let mut rng = Lcg(77);
    let b = rng.vec(n);
    for layout in LAYOUTS {
        for k in [1, 5, 8, 23] {
            let mut pens: Vec<(usize, f64)> =
                (0..k).map(|_| (rng.below(n), 10f64.powf(8.0 * rng.next_f64()))).collect();
            if k > 2 {
                pens.push(pens[1]); // an index twice
            }
            check_multiple_rank(&a0, layout, &pens, &b);
        }
    }
}

#[test]
fn multiple_rank_curve_penalties() {
    // a "curve": a diagonal staircase of 60 neighbouring grid nodes, α = 1e8 each
    let (w, h) = (50, 40);
    let n = w * h;
    let a0 = penalty_system(w, h, &every(n, 97), ALPHA);
    let mut curve = Vec::new();
    let (mut x, mut y) = (5usize, 3usize);
    while curve.len() < 60 {
        curve.push((y * w + x, ALPHA));
        if curve.len() % 2 == 0 { y += 1 } else { x += 1 }
    }
    let mut b = vec![0.0; n];
    for (k, &(i, _)) in curve.iter().enumerate() {
        b[i] = ALPHA * (k as f64 / 60.0);
    }
    for layout in LAYOUTS {
        check_multiple_rank(&a0, layout, &curve, &b);
        // a second curve on top of a first one, as the greedy orientation does
        let mut chol = factor(&a0, layout);
        chol.add_diagonal_penalties(&curve[..30]).unwrap();
        chol.add_diagonal_penalties(&curve[30..]).unwrap();
        let d =
            rel_diff(&chol.solve(&b).unwrap(), &reference(&with_penalties(&a0, &curve, 1.0), &b));
        assert!(d < 1e-10, "two curves vs refactorisation: {d:e}");
    }
}

#[test]
fn indefinite_multiple_rank_downdate_is_refused() {
    let (w, h) = (20, 20);
    let n = w * h;
    let a0 = penalty_system(w, h, &[0, 150, 399], 10.0);
    let b = Lcg(3).vec(n);
    for layout in LAYOUTS {
        let mut chol = factor(&a0, layout);
        chol.add_diagonal_penalties(&[(5, ALPHA), (200, ALPHA)]).unwrap();
        let before = chol.solve(&b).unwrap();
        let matrix = chol.current_matrix();
        // removing more than is there at 150 (a negative diagonal entry): indefinite
        let err = chol
            .remove_diagonal_penalties(&[(5, ALPHA), (0, 10.0), (150, 20.0), (399, 10.0)])
            .unwrap_err();
        assert!(matches!(err, LinalgError::UpdateFailed { .. }), "{err}");
        assert_eq!(chol.current_matrix(), matrix, "matrix unchanged");
        assert_eq!(chol.solve(&b).unwrap(), before, "factor restored exactly");
    }
}

#[test]
fn multiple_rank_input_errors_change_nothing() {
    let a0 = penalty_system(6, 6, &[0], ALPHA);
    let mut chol = Cholesky::factor(&a0).unwrap();
    assert!(matches!(
        chol.add_diagonal_penalties(&[(1, ALPHA), (36, ALPHA)]),
        Err(LinalgError::IndexOutOfRange { .. })
    ));
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            chol.add_diagonal_penalties(&[(1, ALPHA), (2, bad)]),
            Err(LinalgError::InvalidArgument { .. })
        ));
    }
    chol.add_diagonal_penalties(&[]).unwrap();
    assert!(!chol.is_updated());
    assert_eq!(chol.current_matrix(), a0);
}

#[test]
fn multiple_rank_update_is_thread_count_independent() {
    // long root columns × many penalties: the update splits columns into parallel halves
    let (w, h) = (160, 150);
    let n = w * h;
    let a0 = penalty_system(w, h, &every(n, 211), ALPHA);
    let pens: Vec<(usize, f64)> = (0..240).map(|k| ((k * 7919 + 13) % n, ALPHA)).collect();
    let b = Lcg(5).vec(n);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut chol = factor(&a0, FactorLayout::Supernodal);
            chol.add_diagonal_penalties(&pens).unwrap();
            chol.solve(&b).unwrap()
        })
    };
    let (x1, x2) = (run(1), run(2));
    assert!(x1.iter().zip(&x2).all(|(p, q)| p.to_bits() == q.to_bits()));
    let d = rel_diff(&x2, &reference(&with_penalties(&a0, &pens, 1.0), &b));
    assert!(d < 1e-9, "vs refactorisation: {d:e}");
}
