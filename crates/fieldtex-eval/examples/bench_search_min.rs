//! Least time over repetitions of each of orient's default metrics on one thread (the
//! minimum filters out a loaded machine's noise):
//! `bench_search_min OUT_DIR EXEMPLAR.png [REPS]` with `OUT_DIR` an orient output
//! (`texture.png`, `field.npy`). Used for `docs/perf/orient.md`.

#[path = "common/mod.rs"]
mod common;
use common::*;

use fieldtex_eval::*;
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let reps: usize = a.get(3).map_or(15, |s| s.parse().unwrap());
    let run = OrientRun::read(&a[1], &a[2]);
    let (ov, ev, fv) = run.views();
    let approximate = Some(ApproximateSearchOptions::default());
    let popts = PatchDistanceOptions::default()
        .with_wrap_exemplar(true)
        .with_approximate(approximate.clone());
    let gopts = GuidedCoherenceOptions {
        approximate,
        sampled_queries: guided_coherence::SAMPLED_QUERIES,
        ..Default::default()
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let best = |name: &str, f: &(dyn Fn() -> f64 + Sync)| {
        let mut t_min = f64::INFINITY;
        let mut v = 0.0;
        for _ in 0..reps {
            let t = Instant::now();
            v = pool.install(f);
            t_min = t_min.min(t.elapsed().as_secs_f64());
        }
        println!("{name:12} min {:7.1} ms over {reps} (value {v:.9})", t_min * 1e3);
    };
    best("coherence", &|| coherence(&ov, &ev, &popts).unwrap().mean);
    best("guided", &|| guided_coherence(&ov, &ev, &fv, &gopts).unwrap().mean);
    let swo = SlicedWassersteinOptions {
        seed: 1,
        max_pixels: Some(color_sliced_wasserstein::SAMPLED_PIXELS),
        ..Default::default()
    };
    best("colour_sw", &|| color_sliced_wasserstein(&ov, &ev, &swo).unwrap().distance);
    best("orient_map", &|| {
        image_orientation(&ov, &OrientationOptions::default()).unwrap().coherence[0] as f64
    });
    best("period", &|| estimate_stripe_period(&ov).unwrap());
    best("phase", &|| {
        coarse_phase_defects(&ov, &PhaseDefectOptions::default()).unwrap().count as f64
    });
}
