//! `DynamicFactor::from_faer` reads faer's numeric factor in place, relying on faer's
//! private storage (supernodal column-major blocks with each column's diagonal first,
//! simplicial CSC with the diagonal first). faer is pinned to an exact version in the
//! workspace `Cargo.toml` for that reason; these tests rebuild `L` from the row-index
//! description and check `L Lᵀ = P A Pᵀ`, so a faer upgrade that changes the layout
//! fails here, naming the cause, instead of corrupting updates silently.

use crate::cholesky::{Cholesky, FactorLayout, SymbolicCholesky};
use crate::test_support::penalised_grid;

fn check_layout(layout: FactorLayout) {
    let a = penalised_grid(24, 7);
    let n = a.nrows();
    let sym = SymbolicCholesky::analyze_with(&a, layout).unwrap();
    let mut chol = Cholesky::factor_with(&sym, &a).unwrap();
    let d = chol.ensure_dynamic().unwrap().clone();
    // Dense L of P A Pᵀ from the in-place description.
    let mut l = vec![0.0f64; n * n];
    for j in 0..n {
        let s = d.start[j];
        assert_eq!(
            d.rows[s] as usize, j,
            "faer layout changed: column {j} does not start with its diagonal \
             (update cholesky_update.rs::from_faer for the new faer version)"
        );
        for t in 0..d.len[j] {
            let i = d.rows[s + t] as usize;
            assert!(i >= j && i < n, "faer layout changed: row {i} in column {j}");
            l[i * n + j] = d.vals[s + t];
        }
    }
    let dense_a = |r: usize, c: usize| {
        let (cp, ri, v) = (a.col_ptr(), a.row_idx(), a.values());
        (cp[c]..cp[c + 1]).find(|&k| ri[k] == r).map_or(0.0, |k| v[k])
    };
    let mut worst = 0.0f64;
    for i in 0..n {
        for j in 0..=i {
            let llt: f64 = (0..=j).map(|k| l[i * n + k] * l[j * n + k]).sum();
            let pap = dense_a(d.perm[i], d.perm[j]);
            worst = worst.max((llt - pap).abs() / (1.0 + pap.abs()));
        }
    }
    assert!(
        worst < 1e-8,
        "faer layout changed: L Lᵀ differs from P A Pᵀ by {worst:e} \
         (update cholesky_update.rs::from_faer for the new faer version)"
    );
}

#[test]
fn supernodal_factor_is_read_in_place_correctly() {
    check_layout(FactorLayout::Supernodal);
}

#[test]
fn simplicial_factor_is_read_in_place_correctly() {
    check_layout(FactorLayout::Simplicial);
}
