//! The approximate nearest-patch search (PCA + kd-tree) against the exact scan on the
//! shared test exemplars: the bound stated in `docs/first-hour.md`.
//!
//! Each "output" is a patchwork of the exemplar (16×16 blocks copied from seeded random
//! positions, with a little seeded noise), the typical structure of a synthesised
//! texture: most output patches have a near copy in the exemplar, those across block
//! seams do not.

use fieldtex_eval::*;
use std::path::Path;

fn load(name: &str) -> (Vec<f32>, usize, usize) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/exemplars").join(name);
    let im = image::open(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display())).to_rgb32f();
    let (w, h) = (im.width() as usize, im.height() as usize);
    (im.into_raw(), w, h)
}

fn patchwork(ex: &[f32], w: usize, h: usize, size: usize, seed: u64) -> Vec<f32> {
    let mut out = vec![0f32; size * size * 3];
    let block = 16;
    for by in (0..size).step_by(block) {
        for bx in (0..size).step_by(block) {
            let k = (by / block * 1000 + bx / block) as u64;
            let sx = (fieldtex_core::rng::hash_unit(seed, "pw-x", k) * w as f64) as usize;
            let sy = (fieldtex_core::rng::hash_unit(seed, "pw-y", k) * h as f64) as usize;
            for y in by..(by + block).min(size) {
                for x in bx..(bx + block).min(size) {
                    let (ex_x, ex_y) = ((sx + x - bx) % w, (sy + y - by) % h);
                    for c in 0..3 {
                        let n = 0.02
                            * (fieldtex_core::rng::hash_unit(
                                seed,
                                "pw-n",
                                ((y * size + x) * 3 + c) as u64,
                            ) - 0.5) as f32;
                        out[(y * size + x) * 3 + c] = ex[(ex_y * w + ex_x) * 3 + c] + n;
                    }
                }
            }
        }
    }
    out
}

/// Relative gap of the approximate means over the exact ones, on four exemplars.
#[test]
fn approximate_coherence_and_completeness_stay_within_the_stated_bound() {
    let size = 128;
    let mut worst: f64 = 0.0;
    for name in [
        "stripes_Fabric071.png",
        "bricks_Bricks012.png",
        "pebbles_Rocks002.png",
        "bands-fingerprint-like_Onyx013.png",
    ] {
        let (ex, w, h) = load(name);
        let out = patchwork(&ex, w, h, size, 3);
        let o = ImageView::new(&out, size, size, 3).unwrap();
        let e = ImageView::new(&ex, w, h, 3).unwrap();
        let exact_opts = PatchDistanceOptions::default().with_wrap_exemplar(true);
        let (ec, ep) = coherence_and_completeness(&o, &e, &exact_opts).unwrap();
        // Query stride 1 isolates the search error; the default stride adds the
        // sampling error.
        for stride in [1, ApproximateSearchOptions::default().query_stride] {
            let a = ApproximateSearchOptions { query_stride: stride, ..Default::default() };
            let approx_opts = exact_opts.clone().with_approximate(Some(a));
            let (ac, ap) = coherence_and_completeness(&o, &e, &approx_opts).unwrap();
            assert_eq!((ac.search.as_str(), ap.search.as_str()), ("approximate", "approximate"));
            let gap_c = (ac.mean - ec.mean) / ec.mean;
            let gap_p = (ap.mean - ep.mean) / ep.mean.max(1e-12);
            eprintln!(
                "{name} stride {stride}: coherence exact {:.6} approx {:.6} ({:+.2} %), \
                 completeness exact {:.6} approx {:.6} ({:+.2} %)",
                ec.mean,
                ac.mean,
                100.0 * gap_c,
                ep.mean,
                ap.mean,
                100.0 * gap_p
            );
            if stride == 1 {
                // Every approximate distance is a true distance: never below the exact.
                assert!(gap_c >= -1e-4 && gap_p >= -1e-4, "{name}: below the exact minimum");
            }
            worst = worst.max(gap_c.abs()).max(gap_p.abs());
        }
    }
    let bound = fieldtex_eval::approximate_nearest_patch::ERROR_BOUND_PERCENT;
    assert!(
        100.0 * worst <= bound,
        "approximate metrics {:.1} % from the exact ones (bound {bound} %)",
        100.0 * worst
    );
}

/// The approximate search gives bit-identical reports on 1 and 2 threads.
#[test]
fn approximate_metrics_do_not_depend_on_the_thread_count() {
    let (ex, w, h) = load("bricks_Bricks012.png");
    let out = patchwork(&ex, w, h, 96, 5);
    let o = ImageView::new(&out, 96, 96, 3).unwrap();
    let e = ImageView::new(&ex, w, h, 3).unwrap();
    let opts = PatchDistanceOptions::default()
        .with_wrap_exemplar(true)
        .with_approximate(Some(ApproximateSearchOptions::default()));
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| coherence_and_completeness(&o, &e, &opts).unwrap())
    };
    assert_eq!(run(1), run(2));
    // The sampled sliced Wasserstein distance too (a sample of 2 000 of 9 216 pixels).
    let sw = SlicedWassersteinOptions { seed: 4, max_pixels: Some(2_000), ..Default::default() };
    let run_sw = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| color_sliced_wasserstein(&o, &e, &sw).unwrap())
    };
    assert_eq!(run_sw(1), run_sw(2));
}

/// The sampled colour sliced Wasserstein distance of the default reports against all
/// pixels, on 384² patchworks of four exemplars (a near-identical distribution) and on
/// the same patchworks 0.05 brighter (a distinct one).
#[test]
fn sampled_sliced_wasserstein_stays_within_the_stated_bound() {
    use fieldtex_eval::color_sliced_wasserstein::{
        SAMPLED_ERROR_BOUND_ABS, SAMPLED_ERROR_BOUND_PERCENT, SAMPLED_PIXELS,
    };
    let size = 384;
    for name in [
        "stripes_Fabric071.png",
        "bricks_Bricks012.png",
        "pebbles_Rocks002.png",
        "bands-fingerprint-like_Onyx013.png",
    ] {
        let (ex, w, h) = load(name);
        for shift in [0.0f32, 0.05] {
            let out: Vec<f32> =
                patchwork(&ex, w, h, size, 7).iter().map(|v| (v + shift).min(1.0)).collect();
            let o = ImageView::new(&out, size, size, 3).unwrap();
            let e = ImageView::new(&ex, w, h, 3).unwrap();
            let all = SlicedWassersteinOptions { seed: 1, ..Default::default() };
            let sampled =
                SlicedWassersteinOptions { max_pixels: Some(SAMPLED_PIXELS), ..all.clone() };
            let (a, s) = (
                color_sliced_wasserstein(&o, &e, &all).unwrap().distance,
                color_sliced_wasserstein(&o, &e, &sampled).unwrap().distance,
            );
            eprintln!(
                "{name} +{shift}: sliced Wasserstein all {a:.6} sampled {s:.6} ({:+.6}, {:+.2} %)",
                s - a,
                100.0 * (s - a) / a
            );
            let bound = SAMPLED_ERROR_BOUND_ABS + SAMPLED_ERROR_BOUND_PERCENT / 100.0 * a;
            assert!((s - a).abs() <= bound, "{name} +{shift}: sampled {s} vs all {a}");
        }
    }
}
