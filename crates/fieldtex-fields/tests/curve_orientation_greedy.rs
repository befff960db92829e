//! Paper A §4.1: greedy orientation behaviour and determinism across thread counts.

use fieldtex_core::NoProgress;
use fieldtex_core::vec3::{self, V3};
use fieldtex_fields::{
    CurveOrientationOptions, OrientationMode, orient_curves, surface_field_metrics,
};
use fieldtex_mesh::TriMesh;
use fieldtex_mesh::primitives::{grid, icosphere};

mod common;
use common::{line, meridian};

/// Signs, singular (or undetermined) faces and transported Dirichlet energy.
fn measure(mesh: &TriMesh, curves: &[Vec<V3>], mode: OrientationMode) -> (Vec<i8>, usize, f64) {
    let options = CurveOrientationOptions { mode, ..Default::default() };
    let r = orient_curves(mesh, curves, &options, &NoProgress).unwrap();
    let m = surface_field_metrics(mesh, &r.field.vectors, &r.solver.constraints()).unwrap();
    (r.signs, m.singularities.len() + m.undetermined_faces, m.dirichlet_energy)
}

#[test]
fn parallel_curves_on_a_plane_get_the_same_direction() {
    let mesh = grid(30, 30, 1.0, 1.0);
    // The longer curve goes first (+1, left to right); the second is given right to left.
    let curves =
        vec![line([0.1, 0.3, 0.0], [0.9, 0.3, 0.0], 8), line([0.8, 0.7, 0.0], [0.2, 0.7, 0.0], 6)];
    let options = CurveOrientationOptions::default();
    let r = orient_curves(&mesh, &curves, &options, &NoProgress).unwrap();
    assert_eq!(r.signs, vec![1, -1]);
    assert_eq!(r.steps.len(), 2);
    assert_eq!((r.steps[0].curve, r.steps[1].curve), (0, 1));
    assert!(r.steps[0].score.is_nan() && r.steps[0].factor_ms > 0.0);
    let s = r.steps[1];
    assert!(s.normalized_score > 0.9, "the second curve is consistent with the field: {s:?}");
    assert!(s.new_constraints > 10 && s.factor_ms == 0.0);
    // The field points +x everywhere between the curves.
    let v = 15 * 31 + 15;
    assert!(r.field.vectors[v][0] > 0.99, "{:?}", r.field.vectors[v]);
    let m = surface_field_metrics(&mesh, &r.field.vectors, &r.solver.constraints()).unwrap();
    assert!(m.singularities.is_empty(), "{:?}", m.singularities);
}

#[test]
fn greedy_beats_the_worst_arbitrary_orientation_on_a_sphere() {
    let mesh = icosphere(4);
    let tau = std::f64::consts::TAU;
    // Three meridian arcs, the second given north to south.
    let curves = vec![
        meridian(0.0, -1.1, 1.1, 40),
        meridian(tau / 3.0, 1.0, -1.0, 40),
        meridian(2.0 * tau / 3.0, -1.0, 1.0, 40),
    ];
    let (signs, greedy, greedy_energy) = measure(&mesh, &curves, OrientationMode::Greedy);
    assert_eq!(signs, vec![1, -1, 1], "all arcs point north");
    let (mut worst, mut worst_energy, mut inconsistent) = (0, 0.0f64, 0);
    for seed in 0..12 {
        let (s, n, e) = measure(&mesh, &curves, OrientationMode::Arbitrary { seed });
        worst = worst.max(n);
        worst_energy = worst_energy.max(e);
        if s != signs && s != [-1, 1, -1] {
            inconsistent += 1;
            assert!(
                e > 1.2 * greedy_energy,
                "inconsistent {s:?}: energy {e} vs greedy {greedy_energy}"
            );
        }
    }
    assert!(inconsistent > 0, "the seeds must include an inconsistent orientation");
    assert!(greedy <= worst, "greedy {greedy} singular faces vs worst arbitrary {worst}");
    assert!(greedy_energy < worst_energy);
}

#[test]
fn one_and_two_threads_give_identical_results() {
    let mesh = icosphere(4);
    let curves: Vec<Vec<V3>> = (0..6)
        .map(|k| {
            let lon = k as f64 * 1.1;
            if k % 2 == 0 { meridian(lon, -1.0, 0.9, 30) } else { meridian(lon, 0.8, -0.7, 30) }
        })
        .collect();
    let run = |threads: usize, mode: OrientationMode, batch: Option<f64>| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let options =
                CurveOrientationOptions { mode, batch_consistency: batch, ..Default::default() };
            let r = orient_curves(&mesh, &curves, &options, &NoProgress).unwrap();
            let m =
                surface_field_metrics(&mesh, &r.field.vectors, &r.solver.constraints()).unwrap();
            let bits: Vec<u64> = r.field.vectors.iter().flat_map(|v| v.map(f64::to_bits)).collect();
            let scores: Vec<u64> = r.steps.iter().map(|s| s.score.to_bits()).collect();
            (r.signs, bits, scores, m.dirichlet_energy.to_bits(), m.singularities)
        })
    };
    for (mode, batch) in [
        (OrientationMode::Greedy, None),
        (OrientationMode::Greedy, Some(0.8)),
        (OrientationMode::Arbitrary { seed: 7 }, None),
    ] {
        let a = run(1, mode, batch);
        let b = run(2, mode, batch);
        assert!(a == b, "{mode:?} {batch:?}: 1 and 2 threads differ");
    }
    let a = run(2, OrientationMode::Arbitrary { seed: 7 }, None);
    let b = run(2, OrientationMode::Arbitrary { seed: 8 }, None);
    assert!(a.0 != b.0 || a.1 == b.1, "seeds give streams");
}

#[test]
fn batched_rounds_orient_consistent_curves_together() {
    let mesh = grid(30, 30, 1.0, 1.0);
    // Four parallel curves, alternately given in opposite directions.
    let curves: Vec<Vec<V3>> = (0..4)
        .map(|k| {
            let y = 0.2 + 0.2 * k as f64;
            let len = 0.8 - 0.05 * k as f64;
            let (a, b) = ([0.1, y, 0.0], [0.1 + len, y, 0.0]);
            if k % 2 == 0 { line(a, b, 8) } else { line(b, a, 8) }
        })
        .collect();
    let exact =
        orient_curves(&mesh, &curves, &CurveOrientationOptions::default(), &NoProgress).unwrap();
    assert_eq!(exact.signs, vec![1, -1, 1, -1]);
    assert_eq!(exact.steps.iter().map(|s| s.round).collect::<Vec<_>>(), vec![0, 1, 2, 3]);
    let options = CurveOrientationOptions { batch_consistency: Some(0.9), ..Default::default() };
    let batched = orient_curves(&mesh, &curves, &options, &NoProgress).unwrap();
    assert_eq!(batched.signs, exact.signs);
    // Round 0: the longest curve alone; round 1: the other three at once, one solve.
    assert_eq!(batched.steps.iter().map(|s| s.round).collect::<Vec<_>>(), vec![0, 1, 1, 1]);
    assert_eq!(batched.steps.iter().filter(|s| s.solve_ms > 0.0).count(), 2);
    let max_diff = batched
        .field
        .vectors
        .iter()
        .zip(&exact.field.vectors)
        .map(|(a, b)| vec3::norm(vec3::sub(*a, *b)))
        .fold(0.0, f64::max);
    assert!(max_diff < 1e-9, "same signs give the same field: {max_diff:e}");
    for tau in [0.0, -1.0, 1.5, f64::NAN] {
        let o = CurveOrientationOptions { batch_consistency: Some(tau), ..Default::default() };
        assert!(orient_curves(&mesh, &curves, &o, &NoProgress).is_err(), "τ = {tau}");
    }
}

#[test]
fn given_signs_in_one_factorisation_reproduce_the_greedy_field() {
    let mesh = icosphere(4);
    let tau = std::f64::consts::TAU;
    let curves = vec![
        meridian(0.0, -1.1, 1.1, 40),
        meridian(tau / 3.0, 1.1, -1.1, 40),
        meridian(2.0 * tau / 3.0, -0.9, 0.9, 30),
    ];
    let options = CurveOrientationOptions::default();
    let greedy = orient_curves(&mesh, &curves, &options, &NoProgress).unwrap();
    assert!(greedy.steps.iter().skip(1).all(|s| s.factor_ms == 0.0 && s.update_ms > 0.0));
    let given =
        fieldtex_fields::orient_curves_with_signs(&mesh, &curves, &greedy.signs, &options.field)
            .unwrap();
    assert_eq!(given.signs, greedy.signs);
    assert_eq!(given.steps.len(), 1);
    let step = given.steps[0];
    assert!(step.factor_ms > 0.0 && step.update_ms == 0.0, "one factorisation: {step:?}");
    assert_eq!(step.new_constraints, greedy.solver.constraints().len());
    // Rank-1 updates per curve vs all penalties in one factorisation: the same solution.
    let (a, b) = (greedy.solver.raw_solution(), given.solver.raw_solution());
    let scale = a.iter().map(|v| vec3::norm(*v)).fold(0.0, f64::max);
    let diff = a.iter().zip(b).map(|(x, y)| vec3::norm(vec3::sub(*x, *y))).fold(0.0, f64::max);
    assert!(scale > 0.0 && diff <= 1e-9 * scale, "diff {diff:e}, scale {scale:e}");
    // Flipping every sign flips the field; a wrong sign count is an error.
    let flipped: Vec<i8> = greedy.signs.iter().map(|s| -s).collect();
    let f = fieldtex_fields::orient_curves_with_signs(&mesh, &curves, &flipped, &options.field)
        .unwrap();
    let v = greedy.solver.constraints()[0].0 as usize;
    let (p, q) = (greedy.field.vectors[v], f.field.vectors[v]);
    assert!(vec3::dot(p, q) < -0.99, "{p:?} vs {q:?}");
    assert!(
        fieldtex_fields::orient_curves_with_signs(&mesh, &curves, &[1], &options.field).is_err()
    );
}
