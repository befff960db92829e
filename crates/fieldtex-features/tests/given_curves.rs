//! User curves on a mesh: located, snapped, preprocessed.

mod common;

use fieldtex_core::vec3;
use fieldtex_features::{
    CrestOptions, FeaturesError, GivenCurvesOptions, LineKind, LineSource, crest_lines,
    given_curves, sharp_edge_coverage,
};

#[test]
fn offset_crest_lines_snap_back_onto_fandisk() {
    let mesh = common::load("meshes/fandisk.obj");
    let crest = crest_lines(&mesh, &CrestOptions::default()).unwrap();
    let h = crest.stats.mean_edge_length;
    let offset = vec3::scale([0.48, -0.6, 0.64], 0.3 * h);
    let curves: Vec<Vec<[f64; 3]>> = crest
        .lines
        .iter()
        .map(|l| l.points.iter().map(|&p| vec3::add(p, offset)).collect())
        .collect();
    let given = given_curves(&mesh, &curves, &GivenCurvesOptions::default()).unwrap();
    common::check_invariants("given fandisk", &mesh, &given);
    assert!(given.lines.iter().all(|l| l.kind == LineKind::Given && l.source == LineSource::User));
    assert!(given.lines.len() >= crest.lines.len() / 2, "{:?}", given.stats);
    assert!(given.warnings.iter().all(|w| w.code != "curves-off-surface"));
    let cov = sharp_edge_coverage(&mesh, &given.polylines(), 30.0, 2.0).unwrap();
    assert!(cov.sharp_covered >= 0.9 && cov.lines_on_sharp >= 0.8, "{cov:?}");
}

#[test]
fn unsnapped_curves_keep_their_points() {
    let mesh = fieldtex_mesh::primitives::icosphere(3);
    let curve: Vec<[f64; 3]> = (0..=20)
        .map(|i| {
            let a = i as f64 * 0.1;
            [1.02 * a.cos(), 1.02 * a.sin(), 0.0]
        })
        .collect();
    let options = GivenCurvesOptions { snap_to_surface: false, preprocess: None };
    let given = given_curves(&mesh, std::slice::from_ref(&curve), &options).unwrap();
    assert_eq!(given.lines.len(), 1);
    assert_eq!(given.lines[0].points, curve);
    assert_eq!(given.lines[0].faces.len(), curve.len());
    // Snapped, the same curve lies on the (inscribed) polyhedron.
    let snapped = given_curves(&mesh, &[curve], &GivenCurvesOptions::default()).unwrap();
    common::check_invariants("snapped", &mesh, &snapped);
    assert!(snapped.lines[0].points.iter().all(|p| vec3::norm(*p) <= 1.0 + 1e-12));
}

#[test]
fn far_curves_warn_and_bad_points_fail() {
    let mesh = fieldtex_mesh::primitives::icosphere(3);
    let far = vec![(0..10).map(|i| [5.0 + i as f64 * 0.2, 0.0, 0.0]).collect::<Vec<_>>()];
    let given = given_curves(&mesh, &far, &GivenCurvesOptions::default()).unwrap();
    assert!(given.warnings.iter().any(|w| w.code == "curves-off-surface"));
    let bad = vec![vec![[0.0; 3], [0.0, f64::INFINITY, 0.0]]];
    assert!(matches!(
        given_curves(&mesh, &bad, &GivenCurvesOptions::default()),
        Err(FeaturesError::NonFiniteCurvePoint { curve: 0, point: 1 })
    ));
    let empty = fieldtex_mesh::TriMesh::default();
    assert!(matches!(
        given_curves(&empty, &far, &GivenCurvesOptions::default()),
        Err(FeaturesError::EmptyMesh)
    ));
}
