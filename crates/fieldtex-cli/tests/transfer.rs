//! End-to-end tests of `fieldtex transfer` (paper B): outputs, determinism across thread
//! counts, and clear errors (exit 2) for untextured sources, faceless targets and masks
//! of the wrong size.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::Duration;

mod common;
use common::{shared, transfer};
use transfer::SMALL;

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-transfer", name)
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

fn torus() -> PathBuf {
    shared().join("meshes/torus.obj")
}

fn avocado() -> PathBuf {
    shared().join("textured/avocado/avocado.obj")
}

/// A small transfer: avocado (textured OBJ) onto the torus.
fn small(out: &Path, threads: &str, extra: &[&str]) -> Output {
    let mut args = SMALL.to_vec();
    args.extend(["--threads", threads]);
    args.extend_from_slice(extra);
    transfer::run(&avocado(), &torus(), out, &args, Duration::from_secs(120))
}

#[test]
fn transfer_writes_outputs_and_is_identical_for_one_and_two_threads() {
    let a = tmp("t1");
    let b = tmp("t2");
    let oa = small(&a, "1", &["--keep", "--match", "multiscale"]);
    assert!(oa.status.success(), "{}", String::from_utf8_lossy(&oa.stderr));
    let ob = small(&b, "2", &["--keep", "--match", "multiscale"]);
    assert!(ob.status.success(), "{}", String::from_utf8_lossy(&ob.stderr));
    for f in ["model.glb", "preview.png", "guidance.ply"] {
        let x = std::fs::read(a.join(f)).unwrap();
        let y = std::fs::read(b.join(f)).unwrap();
        assert!(!x.is_empty());
        assert!(x == y, "{f} differs between 1 and 2 threads");
    }
    // The GLB passes the Khronos validator with 0 errors.
    assert_eq!(common::validator_errors(&a.join("model.glb")), 0);
    let report = transfer::report(&a);
    let g = &report["metrics"]["guidance"];
    assert_eq!(g["canonical_correlations"].as_array().unwrap().len(), 3);
    assert_eq!(g["descriptor_weights"].as_object().unwrap().len(), 12);
    let steps = report["metrics"]["feature_matching"]["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 4, "3 bands and the values");
    assert!(transfer::has_note(&report, "parametric engine: k-means"));
}

#[test]
fn untextured_source_is_a_clear_error() {
    let out = tmp("untextured");
    let o = transfer::run(&torus(), &torus(), &out, &[], Duration::from_secs(60));
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("torus.obj") && e.contains("texture"), "{e}");
}

#[test]
fn faceless_target_and_wrong_mask_are_clear_errors() {
    let dir = tmp("bad");
    let cloud = dir.join("cloud.obj");
    std::fs::write(&cloud, "v 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    let src = avocado();
    let o = transfer::run(&src, &cloud, &dir.join("o2"), &[], Duration::from_secs(60));
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("cloud.obj"), "{e}");
    // A 3×3 mask cannot match the avocado's texture.
    let mask = dir.join("mask.png");
    let img = fieldtex::Image::new(3, 3, [1.0; 4]);
    fieldtex::crates::io::write_png(&mask, &img).unwrap();
    let o = transfer::run(
        &src,
        &torus(),
        &dir.join("o3"),
        &["--mask", &s(&mask)],
        Duration::from_secs(60),
    );
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("mask") && e.contains("3×3"), "{e}");
    // Non-parametric options out of range are usage errors.
    let np = ["--engine", "nonparametric", "--neighbourhood", "4"];
    let o = transfer::run(&src, &torus(), &dir.join("o4"), &np, Duration::from_secs(60));
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("neighbourhood"));
}

/// The non-parametric engine end to end: outputs, its statistics in the report, and
/// byte-identical files for 1 and 2 threads.
#[test]
fn nonparametric_engine_runs_end_to_end_deterministically() {
    let a = tmp("np1");
    let b = tmp("np2");
    let oa = small(&a, "1", &["--engine", "nonparametric"]);
    assert!(oa.status.success(), "{}", String::from_utf8_lossy(&oa.stderr));
    let ob = small(&b, "2", &["--engine", "nonparametric"]);
    assert!(ob.status.success(), "{}", String::from_utf8_lossy(&ob.stderr));
    for f in ["model.glb", "preview.png"] {
        assert!(std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap(), "{f}");
    }
    let report = transfer::report(&a);
    let levels = report["metrics"]["nonparametric"]["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 3);
    assert!(report["metrics"].get("parametric").is_none());
    assert!(transfer::has_note(&report, "non-parametric engine"));
}

/// An OBJ with UVs but no MTL file (`spot`) is refused with a hint, and accepted with
/// `--source-texture`.
#[test]
fn obj_without_material_takes_its_texture_from_the_flag() {
    let spot = shared().join("textured/spot/spot_triangulated.obj");
    let png = shared().join("textured/spot/spot_texture.png");
    let dir = tmp("spot");
    let limit = Duration::from_secs(120);
    let o = transfer::run(&spot, &torus(), &dir.join("no-flag"), &SMALL, limit);
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("spot_triangulated.obj") && e.contains("--source-texture"), "{e}");
    let texture = s(&png);
    let args = [&SMALL[..], &["--source-texture", &texture]].concat();
    let o = transfer::run(&spot, &torus(), &dir.join("flag"), &args, limit);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = transfer::report(&dir.join("flag"));
    assert!(report["input"]["source_texture_file"].as_str().unwrap().ends_with("spot_texture.png"));
    // A texture file that does not exist names the file (exit 2).
    let missing = s(&dir.join("nope.png"));
    let args = [&SMALL[..], &["--source-texture", &missing]].concat();
    let o = transfer::run(&spot, &torus(), &dir.join("missing"), &args, limit);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nope.png"));
}

/// The Poly Haven glTF pieces (multi-mesh, JPEG textures in a sub-folder) read as
/// sources; a broken copy (its buffer missing) is exit 2 naming the missing file, never
/// a panic.
#[test]
fn gltf_sources_read_and_broken_gltf_is_a_clear_error() {
    let stool = shared().join("textured/painted_wooden_stool/painted_wooden_stool_1k.gltf");
    let out = tmp("stool");
    let o = transfer::run(&stool, &torus(), &out, &SMALL, Duration::from_secs(120));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The glTF without its .bin beside it.
    let dir = tmp("broken-gltf");
    std::fs::create_dir_all(&dir).unwrap();
    let broken = dir.join("stool.gltf");
    std::fs::copy(&stool, &broken).unwrap();
    let o = transfer::run(&broken, &torus(), &dir.join("o"), &[], Duration::from_secs(60));
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    // The message names the missing buffer the glTF refers to.
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("painted_wooden_stool.bin") && e.contains("cannot read"), "{e}");
}

/// `eval --mesh A --reference B` scores transfer fidelity: a texturing against itself
/// correlates perfectly, and `--mesh` without `--reference` is a usage error.
#[test]
fn eval_mesh_against_reference_reports_transfer_fidelity() {
    let blub = shared().join("textured/blub/blub.obj");
    let b = blub.to_str().unwrap();
    let out = common::run_limited(
        &["eval", "--mesh", b, "--reference", b, "--samples", "4000"],
        Duration::from_secs(120),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = v["pearson_luma"].as_f64().unwrap();
    assert!(r > 0.999, "self-fidelity {r}");
    let bad = common::run_limited(&["eval", "--mesh", b], Duration::from_secs(60));
    assert_eq!(bad.status.code(), Some(2));
}
