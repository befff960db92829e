//! Bad input from each crate reachable from the CLI exits 2 (issue 12: each crate error
//! says its kind, the facade maps it through `Error::classify`). Covered elsewhere:
//! `fieldtex-transfer` (tests/transfer.rs), `fieldtex-eval` (robustness.rs, a tiny
//! exemplar). Not reachable from the CLI as bad input: `fieldtex-features`,
//! `fieldtex-mesh`, `fieldtex-param`, `fieldtex-texopt` (the readers, the repair stage
//! and the facade's own option checks refuse such input first, also with exit 2);
//! `fieldtex-linalg` errors are always internal.

use std::path::{Path, PathBuf};
use std::time::Duration;

mod common;
use common::{code, shared, stderr};

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("fieldtex-error-kinds", name)
}

fn quick(args: &[&str]) -> std::process::Output {
    common::run_limited(args, Duration::from_secs(60))
}

/// `orient --preset PRESET` of `exemplar` at 64² into `out`.
fn orient(preset: &str, exemplar: &Path, out: &Path) -> std::process::Output {
    let (ex, out) = (exemplar.to_str().unwrap(), out.to_str().unwrap());
    quick(&[
        "orient",
        "--preset",
        preset,
        "--exemplar",
        ex,
        "--size",
        "64",
        "--out",
        out,
        "--quiet",
    ])
}

#[test]
fn io_an_unparsable_mesh_exits_2() {
    let d = tmp("io");
    let mesh = d.join("garbage.obj");
    std::fs::write(&mesh, "v 0 0 zero\nf 1 2 3\n").unwrap();
    let o = quick(&["inspect", mesh.to_str().unwrap()]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("garbage.obj"), "{}", stderr(&o));
}

#[test]
fn fields_an_unknown_preset_exits_2() {
    let d = tmp("fields");
    let ex = shared().join("exemplars/stripes_Fabric071.png");
    let o = orient("no-such-preset", &ex, &d.join("o"));
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("unknown preset"), "{}", stderr(&o));
}

#[test]
fn synth_an_exemplar_below_the_stack_minimum_exits_2() {
    let d = tmp("synth");
    let tiny = common::tiny_exemplar(&d);
    let o = orient("whorl", &tiny, &d.join("o"));
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("tiny.png") && e.contains("synthesis needs at least"), "{e}");
}
