//! Regression tests for the gaps `tools/robustness_sweep.sh` found in the newer
//! commands (conformal, solid, transfer, eval --mesh, atlas, render, inspect, repair):
//! each test is named after the bug it pins. `docs/first-hour.md` lists them.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::Duration;

mod common;
use common::{code, shared, stderr};

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-robustness-sweep", name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn run(args: &[&str]) -> Output {
    common::run_limited(args, Duration::from_secs(120))
}

/// A `w`×`h` exemplar with a deterministic colour pattern, written as `dir/name`.
fn exemplar(dir: &Path, name: &str, w: usize, h: usize) -> PathBuf {
    let im = fieldtex::Image::from_fn(w, h, |x, y| {
        let v = ((x * 37 + y * 91) % 256) as f32 / 255.0;
        [v, 1.0 - v, ((x ^ y) % 7) as f32 / 6.0, 1.0]
    });
    let p = dir.join(name);
    fieldtex::crates::io::write_png(&p, &im).unwrap();
    p
}

/// Exit 2 with a message naming `has`, free of internal-failure wording, panics and
/// the library's option names (`…Options::field`) or Rust debug structures.
fn assert_input_error(o: &Output, has: &str) {
    let e = stderr(o);
    assert_eq!(code(o), 2, "{e}");
    assert!(e.contains(has), "message should name {has:?}: {e}");
    for bad in ["internal", "panicked", "Options::", "{", "Some("] {
        assert!(!e.contains(bad), "message contains {bad:?}: {e}");
    }
}

/// `solid --mesh torus --exemplar E --out OUT --resolution 32 --atlas-size 64 --levels 2 EXTRA…`.
fn solid_small(dir: &Path, extra: &[&str]) -> Output {
    let ex = exemplar(dir, "ex.png", 32, 32);
    let torus = shared().join("meshes/torus.obj");
    let out = dir.join("out");
    let mut args = vec!["solid", "--mesh", s(&torus), "--exemplar", s(&ex), "--out", s(&out)];
    args.extend_from_slice(&["--resolution", "32", "--atlas-size", "64", "--levels", "2"]);
    args.extend_from_slice(&["--quiet"]);
    let mut all: Vec<&str> = args;
    all.extend_from_slice(extra);
    run(&all)
}

#[test]
fn conformal_non_square_exemplar_panicked() {
    // A 64×8 exemplar passed the "one patch on each side" check (patch 8) and then
    // panicked in `f64::clamp` (min 2 > max 1) when choosing the exemplar levels.
    let d = tmp("conformal_non_square");
    let torus = shared().join("meshes/torus.obj");
    for (name, w, h) in [("wide.png", 64, 8), ("tall.png", 8, 64)] {
        let ex = exemplar(&d, name, w, h);
        let out = d.join(format!("out-{name}"));
        let o = run(&[
            "conformal",
            "--mesh",
            s(&torus),
            "--exemplar",
            s(&ex),
            "--out",
            s(&out),
            "--size",
            "64",
            "--levels",
            "2",
            "--patch-size",
            "8",
            "--quiet",
        ]);
        assert_eq!(code(&o), 0, "{name}: {}", stderr(&o));
        assert!(out.join("model.glb").is_file(), "{name}: no model.glb");
    }
}

#[test]
fn corrupt_png_printed_decoder_debug_text() {
    // A PNG signature followed by junk: the PNG decoder's message carried
    // `ChunkType { type: …, critical: false, … }`.
    let d = tmp("corrupt_png");
    let bad = d.join("garbage.png");
    std::fs::write(&bad, b"\x89PNG\r\n\x1a\nthis is not a png at all").unwrap();
    let good = exemplar(&d, "good.png", 32, 32);
    let o = run(&["eval", s(&good), "--exemplar", s(&bad), "--quiet"]);
    assert_input_error(&o, "garbage.png");
    assert!(stderr(&o).contains("malformed"), "{}", stderr(&o));
}

#[test]
fn solid_sketch_weight_1e300_was_an_internal_failure() {
    // A finite but huge curve weight overflowed the field design system: exit 1
    // "internal failure: … non-finite value in matrix". 10⁶ failed the same way.
    let d = tmp("solid_huge_weight");
    for w in ["1e300", "1e6"] {
        let sketch = d.join(format!("sketch-{w}.json"));
        let text =
            format!(r#"{{"curves": [{{"points": [[1.25, 0, 0], [0, 1.25, 0]], "weight": {w}}}]}}"#);
        std::fs::write(&sketch, text).unwrap();
        let o = solid_small(&d, &["--sketch", s(&sketch)]);
        assert_input_error(&o, &format!("sketch-{w}.json"));
        assert!(stderr(&o).contains("weight"), "{}", stderr(&o));
        // The value is shown as written, not as 300 digits.
        assert!(!stderr(&o).contains("0000000000"), "{}", stderr(&o));
    }
}

#[test]
fn solid_option_errors_named_library_fields() {
    // `--levels 0` said "exemplar: invalid option SolidAnalysisOptions::levels = 0",
    // `--atlas-size 3` said "--size must be …", `--feature-weight NaN` blamed the mask
    // file, `--block 1` and `--passes 100` named `SolidSynthesisOptions` fields.
    let d = tmp("solid_option_names");
    let mask = exemplar(&d, "mask.png", 32, 32);
    let cases: [(&[&str], &str); 7] = [
        (&["--levels", "0"], "--levels"),
        (&["--levels", "99"], "--levels"),
        (&["--atlas-size", "3"], "--atlas-size"),
        (&["--neighbourhood", "4"], "--neighbourhood"),
        (&["--feature-weight", "NaN", "--feature-mask", s(&mask)], "--feature-weight"),
        (&["--block", "1"], "--block"),
        (&["--passes", "100"], "--passes"),
    ];
    for (extra, flag) in cases {
        let o = solid_small(&d, extra);
        assert_input_error(&o, flag);
        assert!(!d.join("out").exists(), "{extra:?}: the output folder was created");
    }
}

#[test]
fn conformal_scale_1e_30_hung() {
    // `--scale` was only required to be > 0; 10⁻⁶ and below ran for minutes. `--levels 0`
    // was told about `--scale` as well.
    let d = tmp("conformal_tiny_scale");
    let ex = exemplar(&d, "ex.png", 32, 32);
    let torus = shared().join("meshes/torus.obj");
    let out = d.join("out");
    let base = ["conformal", "--mesh", s(&torus), "--exemplar", s(&ex), "--out", s(&out)];
    for (extra, flag) in [(["--scale", "1e-30"], "--scale"), (["--levels", "0"], "--levels")] {
        let mut args = base.to_vec();
        args.extend_from_slice(&extra);
        let o = run(&args);
        assert_input_error(&o, flag);
        assert!(!stderr(&o).contains("0000000000"), "{}", stderr(&o));
        let other = if flag == "--scale" { "--levels" } else { "--scale" };
        assert!(!stderr(&o).contains(other), "{}", stderr(&o));
    }
}

#[test]
fn transfer_option_errors_named_library_fields_or_passed_silently() {
    // `--coherence NaN` and `--neighbourhood 4` were accepted with the default engine,
    // `--descriptor-samples 0` with any;
    // `--samples 0` said "invalid option samples", `--clusters 0` "invalid option
    // parametric engine: clusters ≥ 1, iterations ≤ 100, quantiles ≥ 2"; a negative
    // `--coherence` was taken for a flag by the argument parser.
    let d = tmp("transfer_option_names");
    let torus = shared().join("meshes/torus.obj");
    let out = d.join("out");
    let base = ["transfer", "--source", s(&torus), "--target", s(&torus), "--out", s(&out)];
    let cases: [(&[&str], &str); 7] = [
        (&["--coherence", "NaN"], "--coherence"),
        (&["--descriptor-samples", "0"], "--descriptor-samples"),
        (&["--coherence", "-1"], "--coherence"),
        (&["--neighbourhood", "4"], "--neighbourhood"),
        (&["--samples", "0"], "--samples"),
        (&["--clusters", "0"], "--clusters"),
        (&["--engine", "nonparametric", "--neighbourhood", "11"], "--neighbourhood"),
    ];
    for (extra, flag) in cases {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        let o = run(&args);
        assert_input_error(&o, flag);
        assert!(!out.exists(), "{extra:?}: the output folder was created");
    }
}

#[test]
fn eval_mesh_samples_0_scored_15_points_and_1e8_hung() {
    // `eval --mesh --samples 0` reported a correlation over 15 points (clamped in
    // silence); `--samples 100000000` did not finish within a minute.
    let blub = shared().join("textured/blub/blub.obj");
    for n in ["0", "100000000"] {
        let o = run(&["eval", "--mesh", s(&blub), "--reference", s(&blub), "--samples", n]);
        assert_input_error(&o, "--samples");
    }
}

#[test]
fn solid_small_exemplar_was_not_named() {
    // "exemplar: exemplar is 8×64 pixels; synthesis needs at least 10 …" named no file;
    // with per-plane exemplars the user could not tell which one.
    let d = tmp("solid_small_exemplar");
    let good = exemplar(&d, "good.png", 32, 32);
    let thin = exemplar(&d, "thin.png", 8, 64);
    let torus = shared().join("meshes/torus.obj");
    let out = d.join("out");
    let (t, g, th, o) = (s(&torus), s(&good), s(&thin), s(&out));
    let single = ["solid", "--mesh", t, "--exemplar", th, "--out", o, "--resolution", "32"];
    assert_input_error(&run(&single), "thin.png");
    let planes = [
        "solid",
        "--mesh",
        t,
        "--exemplar-xy",
        g,
        "--exemplar-yz",
        th,
        "--exemplar-zx",
        g,
        "--out",
        o,
        "--resolution",
        "32",
    ];
    assert_input_error(&run(&planes), "thin.png");
}
