//! Times each metric of `fieldtex orient`'s default report on a real orient output:
//! `profile_orient_metrics OUT_DIR EXEMPLAR.png [--exact]` where `OUT_DIR` holds the
//! `texture.png` and `field.npy` of an orient run at the exemplar's own size (no
//! reduction; its `coords.npy` too, if present, for the source coverage). Prints one `STAGE name ms` line per metric in the facade's order
//! (`crates/fieldtex/src/pipelines/eval.rs::image_metrics`, plus the exemplar's own
//! orientation of `orient.rs`). Used for `docs/perf/orient.md`.

#[path = "common/mod.rs"]
mod common;
use common::*;

use fieldtex_eval::*;
use std::time::Instant;

/// CPU seconds (user + system) of this process so far (`/proc/self/stat`, 100 Hz).
fn cpu_s() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let f: Vec<&str> = s.rsplit(')').next().unwrap_or("").split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (tick(11) + tick(12)) / 100.0
}

fn stage<T>(name: &str, f: impl FnOnce() -> T) -> T {
    let (t, c) = (Instant::now(), cpu_s());
    let r = f();
    println!(
        "STAGE {name:28} {:8.1} ms wall {:8.0} ms cpu",
        t.elapsed().as_secs_f64() * 1e3,
        (cpu_s() - c) * 1e3
    );
    r
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let exact = a.iter().any(|s| s == "--exact");
    let run = OrientRun::read(&a[1], &a[2]);
    let (ov, ev, fv) = run.views();
    // `--search DIMS,RERANK,CHECKS` tries other approximate-search options.
    let search = a.iter().position(|s| s == "--search").map(|i| {
        let v: Vec<usize> = a[i + 1].split(',').map(|x| x.parse().unwrap()).collect();
        ApproximateSearchOptions {
            pca_dims: v[0],
            rerank: v[1],
            max_checks: v[2],
            ..Default::default()
        }
    });
    // `--samples N` (0 = every query / the stride grid) and `--seed S`: the query sample.
    let arg =
        |name: &str| a.iter().position(|s| s == name).map(|i| a[i + 1].parse::<u64>().unwrap());
    let mut search = search.unwrap_or_default();
    if let Some(n) = arg("--samples") {
        search.sampled_queries = n as usize;
    }
    if let Some(s) = arg("--seed") {
        search.seed = s;
    }
    let approximate = (!exact).then(|| search.clone());
    let t0 = Instant::now();
    let angle = stage("exemplar_orientation", || {
        let (angle, _) = dominant_orientation(&ev).unwrap();
        let r = OrientationReference::ConstantDeg(angle);
        orientation_error(&ev, &r, &Default::default()).unwrap();
        angle
    });
    let popts = PatchDistanceOptions::default()
        .with_wrap_exemplar(true)
        .with_approximate(approximate.clone());
    let (c, p) =
        stage("coherence+completeness", || coherence_and_completeness(&ov, &ev, &popts).unwrap());
    if std::env::args().any(|s| s == "--split") {
        stage("  coherence only", || coherence(&ov, &ev, &popts).unwrap());
        stage("  completeness only", || completeness(&ov, &ev, &popts).unwrap());
    }
    // Orient's default completeness: the source coverage of its coords.npy (no search).
    let coords_path = format!("{}/coords.npy", a[1]);
    if std::path::Path::new(&coords_path).exists() {
        let coords = npy(&coords_path);
        let r = stage("source_coverage", || {
            source_coverage(&coords, [ev.width, ev.height], &SourceCoverageOptions::default())
                .unwrap()
        });
        println!(
            "source coverage {:.4} (copied {:.4}, mean distance {:.2} px, max {:.1} px)",
            r.covered_share, r.copied_share, r.mean_distance_px, r.max_distance_px
        );
    }
    let sw = stage("color_sliced_wasserstein", || {
        color_sliced_wasserstein(
            &ov,
            &ev,
            &SlicedWassersteinOptions {
                seed: 1,
                max_pixels: (!exact).then_some(color_sliced_wasserstein::SAMPLED_PIXELS),
                ..Default::default()
            },
        )
        .unwrap()
    });
    let g = stage("guided_coherence", || {
        // `--guided-stride S` tries another query step.
        let stride =
            arg("--guided-stride").map_or(GuidedCoherenceOptions::default().stride, |s| s as usize);
        // The facade's default samples query pixels (`--guided-samples N`, 0 = the grid).
        let default_samples = if exact { 0 } else { guided_coherence::SAMPLED_QUERIES };
        let sampled_queries = arg("--guided-samples").map_or(default_samples, |s| s as usize);
        let o = GuidedCoherenceOptions {
            approximate: approximate.clone(),
            stride,
            sampled_queries,
            seed: 1,
            ..Default::default()
        };
        guided_coherence(&ov, &ev, &fv, &o).unwrap()
    });
    // The facade computes one orientation map for both (same σ).
    let map = stage("orientation_map", || {
        image_orientation(&ov, &OrientationOptions::default()).unwrap()
    });
    let oe = stage("orientation_error", || {
        let o = OrientationErrorOptions { exemplar_angle_deg: angle, ..Default::default() };
        orientation_error_of_map(&map, &OrientationReference::Field(fv), &o).unwrap()
    });
    let s = stage("singularities", || singularities(&map, &SingularityOptions::default()));
    // The facade's default counts phase defects on the image reduced 2×.
    let pd = stage("phase_defects", || {
        let o = PhaseDefectOptions::default();
        if exact { phase_defects(&ov, &o) } else { coarse_phase_defects(&ov, &o) }.unwrap()
    });
    println!(
        "STAGE {:28} {:8.1} ms wall {:8.0} ms cpu",
        "total",
        t0.elapsed().as_secs_f64() * 1e3,
        cpu_s() * 1e3
    );
    println!(
        "coherence {:.6} (se {:.6}, {} queries) completeness {:.6} (se {:.6}, {} queries) \
         sw {:.6} guided {:.6} orient_err {:.3} sing {} pd {}",
        c.mean,
        c.standard_error.unwrap_or(0.0),
        c.queries,
        p.mean,
        p.standard_error.unwrap_or(0.0),
        p.queries,
        sw.distance,
        g.mean,
        oe.mean_error_deg,
        s.merged.len(),
        pd.count
    );
}
