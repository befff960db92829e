//! `align` with a 512² structured exemplar on a flat mesh (no crest lines): the
//! exemplar's characteristic scale sets the coarsest patch, the smoothest-field fallback
//! (or `--direction`) steers it, and the baked texels keep the exemplar's contrast and
//! crispness.

use fieldtex::crates::{io, mesh};
use fieldtex::{AlignOptions, Image, NoProgress, align};
use std::path::PathBuf;

// The CLI tests' data and scratch-folder helpers.
#[path = "../../fieldtex-cli/tests/common/paths.rs"]
mod common;

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-align-real", name)
}

// The brick exemplar of texopt's structured-exemplar test.
#[path = "../../fieldtex-texopt/tests/common/bricks.rs"]
mod bricks;
use bricks::bricks;

#[test]
fn structured_512_exemplar_on_a_flat_mesh() {
    let d = tmp("flat");
    let plane = mesh::primitives::grid(24, 24, 1.0, 1.0);
    let mesh_path = d.join("plane.obj");
    io::write_obj(&mesh_path, &plane, None).unwrap();
    let ex_path = d.join("bricks.png");
    io::write_png(&ex_path, &bricks(512)).unwrap();
    let mut opts = AlignOptions {
        mesh: mesh_path,
        exemplar: ex_path,
        size: 256,
        feature_align: false,
        ..Default::default()
    };
    let report = align(&d.join("out"), &opts, &NoProgress).unwrap();
    let r = serde_json::to_value(&report).unwrap();
    let m = &r["metrics"];
    let scale = m["exemplar_scale"]["pixels"].as_f64().unwrap();
    assert!((80.0..=120.0).contains(&scale), "characteristic scale {scale}");
    let levels: Vec<u64> = m["texopt"]["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["patch_size"].as_u64().unwrap())
        .collect();
    assert_eq!(levels, vec![128, 64, 32, 16, 8]);
    let fallback = report.warnings.iter().any(|w| w.message.contains("smoothest"));
    assert!(fallback, "{:?}", report.warnings);
    let contrast = m["contrast"]["contrast_ratio"].as_f64().unwrap();
    let gradient = m["contrast"]["gradient_ratio"].as_f64().unwrap();
    eprintln!("contrast {contrast:.3} gradient {gradient:.3}");
    assert!(contrast >= 0.6, "contrast ratio {contrast}");
    assert!(gradient >= 0.7, "gradient ratio {gradient}");
    // The flat plane's smoothest field is constant: the texture's dominant orientation
    // follows it (surface orientation error against the field).
    let error = m["orientation_error"]["surface"]["mean_deg"].as_f64().unwrap();
    assert!(error < 20.0, "orientation error {error}°");
    // --direction: a global direction is accepted and used where no curve constrains.
    opts.direction = Some([0.0, 1.0, 0.0]);
    let report = align(&d.join("out-dir"), &opts, &NoProgress).unwrap();
    assert!(report.warnings.iter().any(|w| w.message.contains("given direction")));
    opts.direction = Some([0.0, 0.0, 0.0]);
    assert!(align(&d.join("out-bad"), &opts, &NoProgress).is_err());
}
