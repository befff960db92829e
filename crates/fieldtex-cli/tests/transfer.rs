//! End-to-end tests of `fieldtex transfer` (paper B): outputs, determinism across thread
//! counts, and clear errors (exit 2) for untextured sources, faceless targets and masks
//! of the wrong size.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::Duration;

mod common;
use common::shared;

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-transfer", name)
}

fn run(args: &[&str], limit: Duration) -> Output {
    common::run_limited(args, limit)
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// A small transfer: avocado (textured OBJ) onto the torus.
fn small(out: &Path, threads: &str, extra: &[&str]) -> Output {
    let src = shared().join("textured/avocado/avocado.obj");
    let tgt = shared().join("meshes/torus.obj");
    let mut args = vec![
        "transfer".to_string(),
        "--source".into(),
        s(&src),
        "--target".into(),
        s(&tgt),
        "--out".into(),
        s(out),
        "--samples".into(),
        "4000".into(),
        "--descriptor-samples".into(),
        "1500".into(),
        "--clusters".into(),
        "10".into(),
        "--size".into(),
        "128".into(),
        "--threads".into(),
        threads.into(),
        "--quiet".into(),
    ];
    args.extend(extra.iter().map(|x| x.to_string()));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    run(&refs, Duration::from_secs(120))
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
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("report.json")).unwrap()).unwrap();
    let g = &report["metrics"]["guidance"];
    assert_eq!(g["canonical_correlations"].as_array().unwrap().len(), 3);
    assert_eq!(g["descriptor_weights"].as_object().unwrap().len(), 12);
    let steps = report["metrics"]["feature_matching"]["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 4, "3 bands and the values");
    assert!(
        report["notes"]
            .as_array()
            .unwrap()
            .iter()
            .any(|n| n.as_str().unwrap().contains("parametric engine: k-means"))
    );
}

#[test]
fn untextured_source_is_a_clear_error() {
    let out = tmp("untextured");
    let o = run(
        &[
            "transfer",
            "--source",
            &s(&shared().join("meshes/torus.obj")),
            "--target",
            &s(&shared().join("meshes/torus.obj")),
            "--out",
            &s(&out),
            "--quiet",
        ],
        Duration::from_secs(60),
    );
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("torus.obj") && e.contains("texture"), "{e}");
}

#[test]
fn faceless_target_and_wrong_mask_are_clear_errors() {
    let dir = tmp("bad");
    let cloud = dir.join("cloud.obj");
    std::fs::write(&cloud, "v 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    let src = shared().join("textured/avocado/avocado.obj");
    let o = run(
        &[
            "transfer",
            "--source",
            &s(&src),
            "--target",
            &s(&cloud),
            "--out",
            &s(&dir.join("o2")),
            "--quiet",
        ],
        Duration::from_secs(60),
    );
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("cloud.obj"), "{e}");
    // A 3×3 mask cannot match the avocado's texture.
    let mask = dir.join("mask.png");
    let img = fieldtex::Image::new(3, 3, [1.0; 4]);
    fieldtex::crates::io::write_png(&mask, &img).unwrap();
    let png = mask.clone();
    let o = run(
        &[
            "transfer",
            "--source",
            &s(&src),
            "--target",
            &s(&shared().join("meshes/torus.obj")),
            "--mask",
            &s(&png),
            "--out",
            &s(&dir.join("o3")),
            "--quiet",
        ],
        Duration::from_secs(60),
    );
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("mask") && e.contains("3×3"), "{e}");
    // Non-parametric options out of range are usage errors.
    let o = run(
        &[
            "transfer",
            "--source",
            &s(&src),
            "--target",
            &s(&shared().join("meshes/torus.obj")),
            "--engine",
            "nonparametric",
            "--neighbourhood",
            "4",
            "--out",
            &s(&dir.join("o4")),
            "--quiet",
        ],
        Duration::from_secs(60),
    );
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
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("report.json")).unwrap()).unwrap();
    let levels = report["metrics"]["nonparametric"]["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 3);
    assert!(report["metrics"].get("parametric").is_none());
    assert!(
        report["notes"]
            .as_array()
            .unwrap()
            .iter()
            .any(|n| n.as_str().unwrap().contains("non-parametric engine"))
    );
}

/// An OBJ with UVs but no MTL file (`spot`) is refused with a hint, and accepted with
/// `--source-texture`.
#[test]
fn obj_without_material_takes_its_texture_from_the_flag() {
    let spot = shared().join("textured/spot/spot_triangulated.obj");
    let png = shared().join("textured/spot/spot_texture.png");
    let torus = shared().join("meshes/torus.obj");
    let dir = tmp("spot");
    let base = |out: &Path| {
        vec![
            "transfer".to_string(),
            "--source".into(),
            s(&spot),
            "--target".into(),
            s(&torus),
            "--out".into(),
            s(out),
            "--samples".into(),
            "4000".into(),
            "--descriptor-samples".into(),
            "1500".into(),
            "--clusters".into(),
            "10".into(),
            "--size".into(),
            "128".into(),
            "--quiet".into(),
        ]
    };
    let args = base(&dir.join("no-flag"));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = run(&refs, Duration::from_secs(60));
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("spot_triangulated.obj") && e.contains("--source-texture"), "{e}");
    let mut args = base(&dir.join("flag"));
    args.extend(["--source-texture".to_string(), s(&png)]);
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = run(&refs, Duration::from_secs(120));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("flag/report.json")).unwrap()).unwrap();
    assert!(report["input"]["source_texture_file"].as_str().unwrap().ends_with("spot_texture.png"));
    // A texture file that does not exist names the file (exit 2).
    let mut args = base(&dir.join("missing"));
    args.extend(["--source-texture".to_string(), s(&dir.join("nope.png"))]);
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = run(&refs, Duration::from_secs(60));
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
    let o = run(
        &[
            "transfer",
            "--source",
            &s(&stool),
            "--target",
            &s(&shared().join("meshes/torus.obj")),
            "--out",
            &s(&out),
            "--samples",
            "4000",
            "--descriptor-samples",
            "1500",
            "--clusters",
            "10",
            "--size",
            "128",
            "--quiet",
        ],
        Duration::from_secs(120),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The glTF without its .bin beside it.
    let dir = tmp("broken-gltf");
    std::fs::create_dir_all(&dir).unwrap();
    let broken = dir.join("stool.gltf");
    std::fs::copy(&stool, &broken).unwrap();
    let o = run(
        &[
            "transfer",
            "--source",
            &s(&broken),
            "--target",
            &s(&shared().join("meshes/torus.obj")),
            "--out",
            &s(&dir.join("o")),
            "--quiet",
        ],
        Duration::from_secs(60),
    );
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
    let out = run(
        &["eval", "--mesh", b, "--reference", b, "--samples", "4000"],
        Duration::from_secs(120),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = v["pearson_luma"].as_f64().unwrap();
    assert!(r > 0.999, "self-fidelity {r}");
    let bad = run(&["eval", "--mesh", b], Duration::from_secs(60));
    assert_eq!(bad.status.code(), Some(2));
}
