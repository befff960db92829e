//! Incremental solves of the curve-constrained diffusion (`CurveFieldSolver::solve_at`)
//! against full solves, and the greedy orientation with and without them.

use fieldtex_core::NoProgress;
use fieldtex_core::vec3::{self, V3};
use fieldtex_fields::harmonic_diffusion::{CurveFieldOptions, CurveFieldSolver};
use fieldtex_fields::{CurveOrientationOptions, FieldsError, orient_curves};
use fieldtex_mesh::primitives::icosphere;

mod common;
use common::meridian;

fn curves() -> Vec<Vec<V3>> {
    (0..7)
        .map(|i| meridian(0.9 * i as f64, -1.0 + 0.1 * i as f64, 0.8 - 0.05 * i as f64, 40))
        .collect()
}

#[test]
fn incremental_solve_matches_full_solve_at_needed_vertices() {
    let mesh = icosphere(4);
    let opts = CurveFieldOptions::default();
    let mut inc = CurveFieldSolver::new(&mesh, &opts).unwrap();
    let mut full = CurveFieldSolver::new(&mesh, &opts).unwrap();
    let sampled: Vec<_> = curves().iter().map(|c| inc.sample_curve(c)).collect();
    for (k, c) in sampled.iter().enumerate() {
        let sign = if k % 3 == 1 { -1.0 } else { 1.0 };
        inc.add_constraints(c, sign).unwrap();
        full.add_constraints(c, sign).unwrap();
        let needed: Vec<u32> = sampled[k + 1..].iter().flat_map(|c| c.vertices.clone()).collect();
        let r = inc.solve_at(&needed).unwrap();
        full.solve().unwrap();
        assert_eq!(r.incremental, usize::from(k > 0), "step {k}: first solve is full");
        let scale = full.raw_solution().iter().map(|v| vec3::norm(*v)).fold(0.0, f64::max);
        for &v in &needed {
            let d = vec3::norm(vec3::sub(
                inc.raw_solution()[v as usize],
                full.raw_solution()[v as usize],
            ));
            assert!(d <= 1e-9 * scale, "step {k}, vertex {v}: {d:e}");
            assert_eq!(
                inc.tangent_at(v as usize),
                full.tangent_at(v as usize).map(|_| inc.tangent_at(v as usize).unwrap())
            );
        }
    }
}

#[test]
fn stale_vertices_have_no_tangent_and_field_needs_a_full_solve() {
    let mesh = icosphere(3);
    let mut s = CurveFieldSolver::new(&mesh, &CurveFieldOptions::default()).unwrap();
    let cs: Vec<_> = curves().iter().map(|c| s.sample_curve(c)).collect();
    s.add_constraints(&cs[0], 1.0).unwrap();
    s.solve().unwrap();
    s.add_constraints(&cs[1], 1.0).unwrap();
    let needed = cs[2].vertices.clone();
    assert_eq!(s.solve_at(&needed).unwrap().incremental, 1);
    let outside = (0..mesh.n_vertices()).find(|v| !needed.contains(&(*v as u32))).unwrap();
    assert!(s.tangent_at(outside).is_none());
    assert!(s.tangent_at(needed[0] as usize).is_some());
    assert!(matches!(s.field(), Err(FieldsError::StaleSolution { .. })));
    // asking for stale vertices without a change re-solves fully
    let r = s.solve_at(&[outside as u32]).unwrap();
    assert_eq!((r.components_solved, r.incremental), (1, 0));
    assert!(s.tangent_at(outside).is_some());
    s.add_constraints(&cs[3], 1.0).unwrap();
    assert_eq!(s.solve_at(&needed).unwrap().incremental, 1);
    s.solve().unwrap();
    assert!(s.field().is_ok());
}

#[test]
fn greedy_with_incremental_solves_orients_like_full_solves() {
    let mesh = icosphere(4);
    let run = |incremental_solves| {
        let o = CurveOrientationOptions { incremental_solves, ..Default::default() };
        orient_curves(&mesh, &curves(), &o, &NoProgress).unwrap()
    };
    let (a, b) = (run(true), run(false));
    assert_eq!(a.signs, b.signs);
    let order = |r: &fieldtex_fields::CurveOrientationResult| {
        r.steps.iter().map(|s| s.curve).collect::<Vec<_>>()
    };
    assert_eq!(order(&a), order(&b));
    assert!(a.steps.iter().any(|s| s.incremental));
    assert!(b.steps.iter().all(|s| !s.incremental));
    for (x, y) in a.field.vectors.iter().zip(&b.field.vectors) {
        assert!(vec3::norm(vec3::sub(*x, *y)) < 1e-9);
    }
}
