//! Helpers shared by the CLI's end-to-end tests: the binary, the shared data folder, a
//! fresh scratch folder per test, and a run with a wall-clock limit (a hang fails the
//! test instead of stalling the suite).

#![allow(dead_code)] // each test file uses a subset

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The `fieldtex` binary under test.
pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_fieldtex")
}

pub mod golden;
mod paths;
pub use paths::{shared, tmp_in};

/// Runs the binary with `args`, failing the test when it runs past `limit`.
pub fn run_limited(args: &[&str], limit: Duration) -> Output {
    let mut child = Command::new(bin())
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn fieldtex");
    let t0 = Instant::now();
    loop {
        if child.try_wait().expect("wait").is_some() {
            return child.wait_with_output().expect("output");
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            panic!("fieldtex {args:?} did not finish within {limit:?} (hang?)");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Runs `fieldtex CMD --mesh MESH --exemplar EXEMPLAR --out OUT EXTRA…` within `limit`
/// (the argument head of every mesh pipeline: atlas-based ones, conformal, solid).
pub fn run_on_mesh(
    cmd: &str,
    mesh: &Path,
    exemplar: &Path,
    out: &Path,
    extra: &[&str],
    limit: Duration,
) -> Output {
    let (mesh, exemplar, out) =
        (mesh.to_str().unwrap(), exemplar.to_str().unwrap(), out.to_str().unwrap());
    let mut args = vec![cmd, "--mesh", mesh, "--exemplar", exemplar, "--out", out];
    args.extend_from_slice(extra);
    run_limited(&args, limit)
}

/// The exit code (−1 when killed by a signal).
pub fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or(-1)
}

/// Standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Number of errors the Khronos glTF validator (installed into `tools/gltf-validator`
/// by `scripts/test`) reports for `glb`; the validator's report is printed on failure.
pub fn validator_errors(glb: &Path) -> u64 {
    let validator = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/gltf-validator");
    assert!(
        validator.join("node_modules/gltf-validator").is_dir(),
        "glTF validator missing: run `npm ci --prefix tools/gltf-validator` (scripts/test does it)"
    );
    let o = Command::new("node").arg(validator.join("validate.js")).arg(glb).output().unwrap();
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("validator JSON");
    let errors = report["issues"]["numErrors"].as_u64().unwrap_or(u64::MAX);
    if errors != 0 {
        eprintln!("{}", String::from_utf8_lossy(&o.stdout));
    }
    errors
}

/// `orient --preset PRESET` on the stripes exemplar at 128² (field grid 32) into
/// `dir`, with `extra` flags; asserts exit 0 and returns the output.
pub fn orient_small(dir: &Path, preset: &str, extra: &[&str], limit: Duration) -> Output {
    let ex = shared().join("exemplars/stripes_Fabric071.png");
    let mut args = vec![
        "orient",
        "--preset",
        preset,
        "--exemplar",
        ex.to_str().unwrap(),
        "--size",
        "128",
        "--grid",
        "32",
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
    ];
    args.extend_from_slice(extra);
    let o = run_limited(&args, limit);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    o
}

/// A JSON file's value (panics with the path on a missing or malformed file).
pub fn read_json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A 4×4 exemplar written by the tool itself (`render` of the shared torus at 4 px) as
/// `dir/tiny.png`: below every engine's minimum size.
pub fn tiny_exemplar(dir: &Path) -> PathBuf {
    let tiny = dir.join("tiny.png");
    let torus = shared().join("meshes/torus.obj");
    let (torus, out) = (torus.to_str().unwrap(), tiny.to_str().unwrap());
    let args = ["render", torus, "--out", out, "--size", "4", "--quiet"];
    let o = run_limited(&args, Duration::from_secs(60));
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    tiny
}

pub mod transfer;
