//! The crest-line target of issue 4 on fandisk (a CAD part): sharp edges (dihedral
//! angle > 30°) covered by detected lines, and detected lines lying on sharp edges.

mod common;

use fieldtex_features::{CrestOptions, LineKind, LineSource, crest_lines, sharp_edge_coverage};

#[test]
fn fandisk_meets_the_coverage_and_precision_target() {
    let mesh = common::load("meshes/fandisk.obj");
    let crest = crest_lines(&mesh, &CrestOptions::default()).unwrap();
    common::check_invariants("fandisk", &mesh, &crest);
    let cov = sharp_edge_coverage(&mesh, &crest.polylines(), 30.0, 2.0).unwrap();
    assert!(cov.sharp_edges > 500, "{cov:?}");
    assert!(cov.sharp_covered >= 0.90, "sharp-edge coverage {cov:?}");
    assert!(cov.lines_on_sharp >= 0.80, "precision {cov:?}");
    // Creases of both convexities are found.
    assert!(crest.lines.iter().any(|l| l.kind == LineKind::Ridge));
    assert!(crest.lines.iter().any(|l| l.kind == LineKind::Valley));
    assert!(crest.warnings.iter().all(|w| w.code != "no-crest-lines"));
}

/// The curvature half of the detector alone (creases switched off) also finds the
/// fandisk creases: evidence that the extremality tracing works on CAD input and is
/// not merely hidden behind the crease detector.
#[test]
fn fandisk_curvature_extrema_alone_follow_the_creases() {
    let mesh = common::load("meshes/fandisk.obj");
    let options = CrestOptions { sharp_angle_deg: 180.0, ..Default::default() };
    let crest = crest_lines(&mesh, &options).unwrap();
    common::check_invariants("fandisk curvature only", &mesh, &crest);
    assert!(crest.lines.iter().all(|l| l.source == LineSource::Curvature));
    assert_eq!(crest.stats.sharp_edges, 0);
    let cov = sharp_edge_coverage(&mesh, &crest.polylines(), 30.0, 2.0).unwrap();
    assert!(cov.sharp_covered >= 0.85, "{cov:?}");
    assert!(cov.lines_on_sharp >= 0.80, "{cov:?}");
}

#[test]
fn levels_are_nested_subsets_by_strength() {
    let mesh = common::load("meshes/fandisk.obj");
    let options = CrestOptions::default();
    let crest = crest_lines(&mesh, &options).unwrap();
    for l in &crest.lines {
        assert!(l.strength >= options.levels[l.level]);
        if let Some(&next) = options.levels.get(l.level + 1) {
            assert!(l.strength < next);
        }
    }
    let counts: Vec<usize> = (0..3).map(|k| crest.at_level(k).count()).collect();
    assert!(counts[0] >= counts[1] && counts[1] >= counts[2] && counts[2] >= 1, "{counts:?}");
    // A higher first threshold returns exactly the lines that passed it before.
    let coarse = CrestOptions { levels: vec![options.levels[1]], ..options.clone() };
    let c2 = crest_lines(&mesh, &coarse).unwrap();
    assert_eq!(c2.lines.len(), counts[1]);
}

#[test]
fn same_result_for_any_thread_count() {
    let mesh = common::load("meshes/fandisk.obj");
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| crest_lines(&mesh, &CrestOptions::default()).unwrap())
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a, b);
}
