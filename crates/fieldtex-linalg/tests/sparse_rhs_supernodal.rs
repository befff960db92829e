//! `Cholesky::solve_sparse_with_residual` on the supernodal layout (forward pass over
//! the supernodes on the reach of the nonzeros, backward pass over all): equal to the
//! ordinary solve and to a fresh factor's solve after multiple-rank updates and
//! downdates, for right-hand sides at leaves, at the root and spread out; bit-identical
//! for 1 and 2 threads. `Cholesky::clone_from` gives the same factor as a clone.

mod common;
use common::*;
use fieldtex_linalg::{Cholesky, FactorLayout, SymbolicCholesky};

fn rel_diff(x: &[f64], y: &[f64]) -> f64 {
    max_abs_diff(x, y) / max_abs(y)
}

/// Right-hand sides with few nonzeros: one entry, a local cluster, a spread set, the
/// last unknowns (root separator side) and repeated structure.
fn sparse_rhs(n: usize) -> Vec<Vec<f64>> {
    let mut rng = Lcg(17);
    let mut out = Vec::new();
    let sets: [Vec<usize>; 4] = [
        vec![n / 3],
        (n / 2..n / 2 + 40).collect(),
        (0..n).step_by(n / 30).collect(),
        (n - 25..n).chain(0..5).collect(),
    ];
    for set in sets {
        let mut b = vec![0.0; n];
        for i in set {
            b[i] = rng.next_f64() * 2.0 - 1.0 + 1e-3;
        }
        out.push(b);
    }
    out
}

fn supernodal_factor(side: usize, penalties: &[(usize, f64)]) -> (Cholesky, Cholesky) {
    let a = penalty_system(side, side, &every(side * side, 11), 2.0);
    let sym = SymbolicCholesky::analyze_with(&a, FactorLayout::Supernodal).unwrap();
    let mut f = Cholesky::factor_with(&sym, &a).unwrap();
    f.prepare_updates().unwrap();
    f.add_diagonal_penalties(penalties).unwrap();
    let mut d = vec![0.0; side * side];
    for &(i, w) in penalties {
        d[i] += w;
    }
    let fresh = Cholesky::factor_with(&sym, &a.add_diagonal(&d)).unwrap();
    (f, fresh)
}

#[test]
fn supernodal_sparse_solve_matches_ordinary_and_fresh_solves() {
    let side = 48;
    let n = side * side;
    let penalties: Vec<(usize, f64)> = (0..60).map(|k| (700 + 13 * k, 0.5 + k as f64)).collect();
    let (mut f, fresh) = supernodal_factor(side, &penalties);
    for (t, b) in sparse_rhs(n).iter().enumerate() {
        let (x, r) = f.solve_sparse_with_residual(b).unwrap();
        let (ordinary, _) = f.solve_with_residual(b).unwrap();
        let (reference, _) = fresh.solve_with_residual(b).unwrap();
        assert!(r < 1e-11, "rhs {t}: residual {r:e}");
        assert!(rel_diff(&x, &ordinary) < 1e-11, "rhs {t}: {:e}", rel_diff(&x, &ordinary));
        assert!(rel_diff(&x, &reference) < 1e-9, "rhs {t}: {:e}", rel_diff(&x, &reference));
    }
    // after a downdate of half of the penalties
    f.remove_diagonal_penalties(&penalties[..30]).unwrap();
    let (_, fresh) = supernodal_factor(side, &penalties[30..]);
    for b in sparse_rhs(n) {
        let (x, _) = f.solve_sparse_with_residual(&b).unwrap();
        let (reference, _) = fresh.solve_with_residual(&b).unwrap();
        assert!(rel_diff(&x, &reference) < 1e-9, "{:e}", rel_diff(&x, &reference));
    }
}

#[test]
fn supernodal_sparse_solve_is_identical_for_one_and_two_threads() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
            let (mut f, _) = supernodal_factor(40, &[(100, 1.0), (900, 2.0), (1500, 0.5)]);
            sparse_rhs(1600)
                .iter()
                .map(|b| f.solve_sparse_with_residual(b).unwrap().0)
                .collect::<Vec<_>>()
        })
    };
    let (one, two) = (run(1), run(2));
    for (p, q) in one.iter().zip(&two) {
        assert!(p.iter().zip(q).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}

/// Bit patterns of the solutions of `f` for the sparse right-hand sides.
fn solution_bits(f: &mut Cholesky, n: usize) -> Vec<u64> {
    let mut out = Vec::new();
    for b in sparse_rhs(n) {
        out.extend(f.solve_sparse_with_residual(&b).unwrap().0.iter().map(|v| v.to_bits()));
        out.extend(f.solve(&b).unwrap().iter().map(|v| v.to_bits()));
    }
    out
}

#[test]
fn copy_from_equals_a_clone_and_stays_updatable() {
    let side = 32;
    let n = side * side;
    let (src, _) = supernodal_factor(side, &[(40, 1.0), (500, 2.0), (1000, 0.5)]);
    // into an updatable factor of the same analysis with other values (values copied)
    let (mut dst, _) = supernodal_factor(side, &[(7, 3.0), (300, 4.0)]);
    dst.clone_from(&src);
    let mut reference = src.clone();
    assert_eq!(solution_bits(&mut dst, n), solution_bits(&mut reference, n));
    // both keep updating alike
    dst.add_diagonal_penalties(&[(600, 1.5), (601, 1.5)]).unwrap();
    reference.add_diagonal_penalties(&[(600, 1.5), (601, 1.5)]).unwrap();
    assert_eq!(solution_bits(&mut dst, n), solution_bits(&mut reference, n));
    // into factors of another layout or not yet updatable: a clone
    let a = penalty_system(side, side, &every(n, 11), 2.0);
    for layout in [FactorLayout::Simplicial, FactorLayout::Supernodal] {
        let sym = SymbolicCholesky::analyze_with(&a, layout).unwrap();
        let mut other = Cholesky::factor_with(&sym, &a).unwrap();
        other.clone_from(&src);
        let mut reference = src.clone();
        assert_eq!(solution_bits(&mut other, n), solution_bits(&mut reference, n));
    }
    // from a factor never updated
    let fresh = Cholesky::factor(&a).unwrap();
    let mut dst2 = src.clone();
    dst2.clone_from(&fresh);
    assert_eq!(dst2.solve(&vec![1.0; n]).unwrap(), fresh.solve(&vec![1.0; n]).unwrap());
}

#[test]
fn copy_changed_from_equals_a_full_copy() {
    let side = 40;
    let n = side * side;
    let (base, _) = supernodal_factor(side, &[(40, 1.0)]);
    let nnz = base.symbolic().factor_nnz();
    let mut cur = base.clone();
    // a cluster of penalties (like a stroke), part of it removed again, one more added
    let ups: Vec<(usize, f64)> = (0..40).map(|t| (620 + t, 0.5 + t as f64 * 0.01)).collect();
    cur.add_diagonal_penalties(&ups).unwrap();
    cur.remove_diagonal_penalties(&ups[..10]).unwrap();
    cur.add_diagonal_penalty(777, 2.0).unwrap();
    let changed: Vec<usize> = ups.iter().map(|p| p.0).chain([777, 620]).collect();
    // back to the base: only the paths of `changed` are copied
    let mut restored = cur.clone();
    let copied = restored.copy_changed_from(&base, &changed);
    assert!(copied > 0 && copied < nnz / 2, "{copied} of {nnz} values copied");
    assert_eq!(solution_bits(&mut restored, n), solution_bits(&mut base.clone(), n));
    // and the other way: a copy of the base brought to the current state
    let mut forward = base.clone();
    forward.copy_changed_from(&cur, &changed);
    assert_eq!(solution_bits(&mut forward, n), solution_bits(&mut cur.clone(), n));
    // the test can fail: leaving indices out leaves their paths stale (the solve then
    // fails its residual check or differs)
    let mut partial = cur.clone();
    partial.copy_changed_from(&base, &changed[..5]);
    let b = vec![1.0; n];
    let (x, _) = base.solve_with_residual(&b).unwrap();
    match partial.solve_with_residual(&b) {
        Ok((y, _)) => assert_ne!(x, y),
        Err(e) => assert!(e.to_string().contains("residual"), "{e}"),
    }
    // into a factor that is not updatable: a full copy
    let a = penalty_system(side, side, &every(n, 11), 2.0);
    let mut other = Cholesky::factor(&a).unwrap();
    other.copy_changed_from(&cur, &changed);
    assert_eq!(solution_bits(&mut other, n), solution_bits(&mut cur.clone(), n));
}
