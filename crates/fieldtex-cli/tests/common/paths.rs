//! Where test data and scratch folders are: shared by the CLI's end-to-end tests
//! (through `common`) and the facade's integration tests (which include this file by
//! path; both crates sit at `crates/NAME`).

#![allow(dead_code)] // each test file uses a subset

use std::path::{Path, PathBuf};

/// `../shared/data` beside the repository (meshes, exemplars, textured meshes).
pub fn shared() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// An empty scratch folder `suite/name` under Cargo's per-target temporary folder.
pub fn tmp_in(suite: &str, name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(suite).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
