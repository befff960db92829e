//! Helpers of the `fieldtex transfer` end-to-end tests: one command line builder, the
//! small-run flags and the report reader.

use super::run_limited;
use std::path::Path;
use std::process::Output;
use std::time::Duration;

/// Flags of a small, fast transfer (4000 samples, 1500 descriptor samples, 10 clusters,
/// a 128² atlas).
pub const SMALL: [&str; 8] =
    ["--samples", "4000", "--descriptor-samples", "1500", "--clusters", "10", "--size", "128"];

/// `fieldtex transfer --source S --target T --out O --quiet` followed by `extra`, killed
/// after `limit`.
pub fn run(source: &Path, target: &Path, out: &Path, extra: &[&str], limit: Duration) -> Output {
    let paths = [source, target, out].map(|p| p.display().to_string());
    let mut args = vec![
        "transfer", "--source", &paths[0], "--target", &paths[1], "--out", &paths[2], "--quiet",
    ];
    args.extend_from_slice(extra);
    run_limited(&args, limit)
}

/// The `report.json` of an output folder.
pub fn report(out: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap()
}

/// Whether one of the report's `notes` contains `text`.
pub fn has_note(report: &serde_json::Value, text: &str) -> bool {
    report["notes"].as_array().unwrap().iter().any(|n| n.as_str().unwrap().contains(text))
}
