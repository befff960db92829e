//! Benchmark of the sparse SPD solver layer on a penalty system like the ones of the
//! field pipelines: a 2-D grid graph Laplacian (448 × 448 = 200,704 unknowns) plus a
//! penalty `α = 1e8` on 2 % of the diagonal.
//!
//! Run: `cargo run --release -p fieldtex-linalg --example bench_linalg [-- GRID_SIDE]`
//!
//! Prints one line per measurement, `BENCH <name> median_ms=<x>` (median over several
//! runs), plus `BENCH refactor_over_update ratio=<x>` and `INFO` lines, so a script can
//! parse it. Target (issue 2): one rank-1 update ≥ 100× faster than a refactorisation.

use std::time::Instant;

use fieldtex_linalg::{Cholesky, SparseMatrix, SymbolicCholesky};

const ALPHA: f64 = 1e8;

// The tests' grid fixtures (grid Laplacian plus penalty diagonal).
#[path = "../tests/common/mod.rs"]
mod common;

/// The `side × side` grid Laplacian with `ALPHA` on every 50th diagonal entry, and which
/// entries are constrained.
fn grid_penalty_system(side: usize) -> (SparseMatrix, Vec<bool>) {
    let n = side * side;
    let picked = common::every(n, 50);
    let mut constrained = vec![false; n];
    for &i in &picked {
        constrained[i] = true;
    }
    (common::penalty_system(side, side, &picked, ALPHA), constrained)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let m = v.len() / 2;
    if v.len() % 2 == 1 { v[m] } else { 0.5 * (v[m - 1] + v[m]) }
}

fn time_ms<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t0 = Instant::now();
    let r = f();
    (r, t0.elapsed().as_secs_f64() * 1e3)
}

fn report(name: &str, samples: Vec<f64>) -> f64 {
    let m = median(samples);
    println!("BENCH {name} median_ms={m:.4}");
    m
}

fn main() {
    let side: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(448);
    let runs = 5;
    let (a, constrained) = grid_penalty_system(side);
    let n = a.nrows();
    println!(
        "INFO unknowns={n} nnz={} constrained={} threads={}",
        a.nnz(),
        constrained.iter().filter(|&&c| c).count(),
        rayon::current_num_threads()
    );

    let mut t_sym = Vec::new();
    let mut symbolic = None;
    for _ in 0..runs {
        let (s, ms) = time_ms(|| SymbolicCholesky::analyze(&a).expect("analysis"));
        t_sym.push(ms);
        symbolic = Some(s);
    }
    let symbolic = symbolic.unwrap();
    println!("INFO factor_nnz={} supernodal={}", symbolic.factor_nnz(), symbolic.is_supernodal());
    report("symbolic_analysis", t_sym);

    let mut t_full = Vec::new();
    for _ in 0..runs {
        let (_, ms) = time_ms(|| Cholesky::factor(&a).expect("factor"));
        t_full.push(ms);
    }
    report("symbolic_plus_numeric", t_full);

    let mut t_num = Vec::new();
    let mut chol = None;
    for _ in 0..runs {
        let (c, ms) = time_ms(|| Cholesky::factor_with(&symbolic, &a).expect("factor"));
        t_num.push(ms);
        chol = Some(c);
    }
    report("numeric_factorisation", t_num);

    // refactorisation with new values (same pattern), symbolic reused
    let mut a2 = a.clone();
    a2.values_mut().iter_mut().for_each(|v| *v *= 1.5);
    let mut t_re = Vec::new();
    for _ in 0..runs {
        let (_, ms) = time_ms(|| Cholesky::factor_with(&symbolic, &a2).expect("refactor"));
        t_re.push(ms);
    }
    let refactor = report("numeric_refactorisation", t_re);

    let mut chol = chol.unwrap();
    let rhs: Vec<Vec<f64>> = (0..3)
        .map(|k| {
            (0..n)
                .map(|i| if constrained[i] { ALPHA * ((i * (k + 1)) % 7) as f64 } else { 0.0 })
                .collect()
        })
        .collect();
    let mut t_one = Vec::new();
    for _ in 0..runs {
        let (x, ms) = time_ms(|| chol.solve(&rhs[0]).expect("solve"));
        std::hint::black_box(x);
        t_one.push(ms);
    }
    report("solve_1rhs", t_one);
    let mut t_solve = Vec::new();
    for _ in 0..runs {
        let (x, ms) = time_ms(|| chol.solve_many(&rhs).expect("solve"));
        std::hint::black_box(x);
        t_solve.push(ms);
    }
    println!("INFO solve_residual={:e}", chol.last_residual());
    report("solve_3rhs", t_solve);

    // rank-1 updates: penalties on unconstrained unknowns, spread over the grid
    let free: Vec<usize> = (0..n).filter(|&i| !constrained[i]).collect();
    let pick = |k: usize| free[(k * 7919 + 13) % free.len()];
    let (_, first) = time_ms(|| chol.add_diagonal_penalty(pick(0), ALPHA).expect("update"));
    println!("BENCH first_rank1_update median_ms={first:.4}");
    println!("INFO updatable_factor_nnz={}", chol.updated_factor_nnz().unwrap_or(0));
    let updates = 64;
    let mut t_up = Vec::new();
    for k in 1..=updates {
        let (_, ms) = time_ms(|| chol.add_diagonal_penalty(pick(k), ALPHA).expect("update"));
        t_up.push(ms);
    }
    let update = report("rank1_update", t_up);
    let costs: Vec<(usize, usize)> =
        (1..=updates).filter_map(|k| chol.update_path_cost(pick(k))).collect();
    let mean = |f: fn(&(usize, usize)) -> usize| {
        costs.iter().map(f).sum::<usize>() as f64 / costs.len().max(1) as f64
    };
    println!(
        "INFO update_path_columns_mean={:.0} update_path_entries_mean={:.0}",
        mean(|c| c.0),
        mean(|c| c.1)
    );
    let mut t_down = Vec::new();
    for k in 1..=updates {
        let (_, ms) = time_ms(|| chol.remove_diagonal_penalty(pick(k), ALPHA).expect("downdate"));
        t_down.push(ms);
    }
    report("rank1_downdate", t_down);

    // one "curve" of 61 neighbouring unknowns (a staircase across the grid): 61 rank-1
    // updates in turn vs one multiple-rank update, then back by one multiple-rank downdate
    let curves: Vec<Vec<(usize, f64)>> = (0..runs)
        .map(|r| {
            let (mut x, mut y) = (side / 4 + 7 * r, side / 3 + 5 * r);
            let mut c = Vec::new();
            while c.len() < 61 {
                if !constrained[y * side + x] {
                    c.push((y * side + x, ALPHA));
                }
                if c.len() % 2 == 0 { y += 1 } else { x += 1 }
            }
            c
        })
        .collect();
    let mut t_seq = Vec::new();
    let mut t_multi = Vec::new();
    let mut t_multi_down = Vec::new();
    for c in &curves {
        let mut copy = chol.clone();
        let (_, ms) = time_ms(|| {
            for &(i, a) in c {
                copy.add_diagonal_penalty(i, a).expect("update");
            }
        });
        t_seq.push(ms);
        let (_, ms) = time_ms(|| chol.add_diagonal_penalties(c).expect("multiple-rank update"));
        t_multi.push(ms);
        let (_, ms) =
            time_ms(|| chol.remove_diagonal_penalties(c).expect("multiple-rank downdate"));
        t_multi_down.push(ms);
    }
    let seq = report("curve61_sequential_rank1", t_seq);
    let multi = report("curve61_multiple_rank_update", t_multi);
    report("curve61_multiple_rank_downdate", t_multi_down);
    println!("INFO curve61_sequential_over_multiple_rank ratio={:.1}", seq / multi);
    println!("BENCH refactor_over_curve61_update ratio={:.1}", refactor / multi);

    let mut t_solve_up = Vec::new();
    for _ in 0..runs {
        let (x, ms) = time_ms(|| chol.solve_many(&rhs).expect("solve after updates"));
        std::hint::black_box(x);
        t_solve_up.push(ms);
    }
    println!("INFO solve_after_updates_residual={:e}", chol.last_residual());
    report("solve_3rhs_after_updates", t_solve_up);

    // accuracy: the updated factor against a refactorisation of the assembled matrix
    let current = chol.current_matrix();
    let x_up = chol.solve(&rhs[0]).expect("solve");
    let x_full = Cholesky::factor(&current).expect("factor").solve(&rhs[0]).expect("solve");
    let err = x_up.iter().zip(&x_full).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max)
        / x_full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    println!("INFO updated_vs_refactored_rel_diff={err:e} updates={}", 2 * updates + 1);
    println!("BENCH refactor_over_update ratio={:.1}", refactor / update);
}
