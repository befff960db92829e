//! Crest lines on every shared mesh: no failure, no NaN, invariants hold; smooth scans
//! give a moderate number of long lines (no dust); CAD parts give lines of both kinds.

mod common;

use fieldtex_features::{CrestOptions, LineKind, crest_lines};

/// Every mesh file under `meshes/` (and its `defects/`), plus the blub fish.
fn all_meshes() -> Vec<String> {
    let mut out = Vec::new();
    for dir in ["meshes", "meshes/defects"] {
        let mut names: Vec<String> = std::fs::read_dir(common::data_dir().join(dir))
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".obj") || n.ends_with(".ply"))
            .map(|n| format!("{dir}/{n}"))
            .collect();
        names.sort();
        out.extend(names);
    }
    out.push("textured/blub/blub.obj".into());
    out
}

#[test]
fn every_shared_mesh_after_repair_gives_valid_lines() {
    let meshes = all_meshes();
    assert!(meshes.len() >= 16, "{meshes:?}");
    for name in &meshes {
        let mesh = common::load(name);
        if mesh.triangles.is_empty() {
            continue;
        }
        let crest =
            crest_lines(&mesh, &CrestOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
        common::check_invariants(name, &mesh, &crest);
        let h = crest.stats.mean_edge_length;
        for l in &crest.lines {
            assert!(l.length >= 5.0 * h - 1e-12, "{name}: a line of {} edges", l.length / h);
        }
    }
}

/// Unrepaired defective input (non-manifold, inconsistent orientation, slivers, soup,
/// Möbius) must not panic: an error or a valid result.
#[test]
fn raw_defective_meshes_do_not_panic() {
    for name in all_meshes().iter().filter(|n| n.contains("defects")) {
        let mesh = common::load_raw(name);
        if let Ok(crest) = crest_lines(&mesh, &CrestOptions::default()) {
            common::check_invariants(name, &mesh, &crest);
        }
    }
}

#[test]
fn smooth_scans_give_few_long_lines() {
    for name in [
        "meshes/stanford-bunny.obj",
        "meshes/armadillo.obj",
        "meshes/horse.ply",
        "textured/blub/blub.obj",
    ] {
        let mesh = common::load(name);
        let crest = crest_lines(&mesh, &CrestOptions::default()).unwrap();
        let h = crest.stats.mean_edge_length;
        let n = crest.lines.len();
        let short = crest.lines.iter().filter(|l| l.length < 5.0 * h).count();
        assert_eq!(short, 0, "{name}");
        assert!((5..=120).contains(&n), "{name}: {n} lines, {:?}", crest.stats);
        let mut lengths: Vec<f64> = crest.lines.iter().map(|l| l.length / h).collect();
        lengths.sort_by(f64::total_cmp);
        let median = lengths[n / 2];
        assert!(median >= 6.5, "{name}: median line length {median} edges");
        // Most of the raw linked pieces were joined or dropped.
        assert!(crest.stats.raw_lines > 3 * n, "{name}: {:?}", crest.stats);
    }
}

#[test]
fn rocker_arm_gives_ridges_and_valleys() {
    let mesh = common::load("meshes/rocker-arm.obj");
    let crest = crest_lines(&mesh, &CrestOptions::default()).unwrap();
    common::check_invariants("rocker-arm", &mesh, &crest);
    assert!(crest.lines.len() >= 10, "{:?}", crest.stats);
    assert!(crest.lines.iter().any(|l| l.kind == LineKind::Ridge));
    assert!(crest.lines.iter().any(|l| l.kind == LineKind::Valley));
}
