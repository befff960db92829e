//! Calibration and contract tests of `guided_coherence`.

use fieldtex_eval::{
    FieldView, GuidedCoherenceOptions, ImageView, PatchDistanceOptions, coherence, guided_coherence,
};
use std::path::Path;

mod common;
use common::{constant_field, rotated_copy};

/// An RGB exemplar from the shared test data as `(data, width, height)`.
fn exemplar(name: &str) -> (Vec<f32>, usize, usize) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/exemplars").join(name);
    let img = image::open(&path).expect("test exemplar").to_rgb8();
    let (w, h) = (img.width() as usize, img.height() as usize);
    (img.as_raw().iter().map(|&v| v as f32 / 255.0).collect(), w, h)
}

fn guided(out: &[f32], size: usize, ex: &[f32], ew: usize, eh: usize, field: &[f32]) -> f64 {
    let o = ImageView::new(out, size, size, 3).unwrap();
    let e = ImageView::new(ex, ew, eh, 3).unwrap();
    let f = FieldView::new(field, size, size).unwrap();
    guided_coherence(&o, &e, &f, &GuidedCoherenceOptions { stride: 4, ..Default::default() })
        .unwrap()
        .mean
}

fn exemplar_view(ex: &[f32], ew: usize, eh: usize) -> ImageView<'_> {
    ImageView::new(ex, ew, eh, 3).unwrap()
}

/// Guided coherence of rotated copies (patchworks when `patchwork`) at each angle in
/// `degs`, each under its own constant field, and the plain coherence of the 45° copy.
fn rotated_scores(
    ex: &[f32],
    ew: usize,
    eh: usize,
    size: usize,
    degs: &[f64],
    patchwork: bool,
) -> (Vec<(f64, f64)>, f64) {
    let scores = degs
        .iter()
        .map(|&deg| {
            let out = rotated_copy(ex, ew, eh, size, deg, patchwork);
            (deg, guided(&out, size, ex, ew, eh, &constant_field(size, deg)))
        })
        .collect();
    let out45 = rotated_copy(ex, ew, eh, size, 45.0, patchwork);
    let plain45 = coherence(
        &ImageView::new(&out45, size, size, 3).unwrap(),
        &exemplar_view(ex, ew, eh),
        &PatchDistanceOptions::default().with_wrap_exemplar(true),
    )
    .unwrap()
    .mean;
    (scores, plain45)
}

#[test]
fn exact_rotated_copies_score_near_zero_and_noise_scores_high() {
    let (ex, ew, eh) = exemplar("stripes_Fabric071.png");
    let size = 96;
    let (scores, plain45) = rotated_scores(&ex, ew, eh, size, &[0.0, 30.0, 45.0, 90.0], false);
    let noise: Vec<f32> = (0..size * size * 3)
        .map(|i| fieldtex_core::rng::hash_unit(7, "guided-noise", i as u64) as f32)
        .collect();
    let noise_score = guided(&noise, size, &ex, ew, eh, &constant_field(size, 30.0));
    eprintln!("exact copies: guided {scores:?}, plain 45° {plain45}, noise {noise_score}");
    // 0° and 90° frames sample exactly what the exemplar patches hold.
    assert!(scores[0].1 < 1e-9 && scores[3].1 < 1e-9, "{scores:?}");
    // Oblique frames only pay for the pixel-copy jaggies: far below the plain metric
    // and below a typical synthesis' 0° coherence on this exemplar (≈ 1.5e-3).
    for &(deg, v) in &scores {
        assert!(v < 0.05 * plain45 && v < 1.5e-3, "{deg}°: {v} vs plain 45° {plain45}");
    }
    assert!(noise_score > 50.0 * scores[2].1, "noise {noise_score}");
}

#[test]
fn rotated_patchworks_score_within_twice_the_unrotated_one() {
    let (ex, ew, eh) = exemplar("stripes_Fabric071.png");
    let size = 96;
    let zero = guided(
        &rotated_copy(&ex, ew, eh, size, 0.0, true),
        size,
        &ex,
        ew,
        eh,
        &constant_field(size, 0.0),
    );
    let (scores, plain45) = rotated_scores(&ex, ew, eh, size, &[30.0, 45.0, 90.0], true);
    eprintln!("patchworks: 0° {zero}, {scores:?}, plain 45° {plain45}");
    assert!(zero > 1e-5, "the seams must cost something: {zero}");
    for &(deg, v) in &scores {
        assert!(v <= 2.0 * zero && v >= 0.5 * zero, "{deg}°: {v} vs 0°: {zero}");
    }
    assert!(scores[1].1 < 0.5 * plain45, "45°: {} vs plain {plain45}", scores[1].1);
}

#[test]
fn bit_identical_for_any_thread_count() {
    let (ex, ew, eh) = exemplar("woodgrain_Wood022.png");
    let size = 64;
    let out = rotated_copy(&ex, ew, eh, size, 37.0, true);
    // A rotating field: every query has its own frame.
    let field: Vec<f32> = (0..size * size)
        .flat_map(|i| {
            let a = (i % size) as f32 * 0.05 + (i / size) as f32 * 0.02;
            [a.cos(), a.sin()]
        })
        .collect();
    let run = |threads: usize, opts: &GuidedCoherenceOptions| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
            let o = ImageView::new(&out, size, size, 3).unwrap();
            let f = FieldView::new(&field, size, size).unwrap();
            guided_coherence(&o, &exemplar_view(&ex, ew, eh), &f, opts).unwrap()
        })
    };
    let grid = GuidedCoherenceOptions { stride: 3, ..Default::default() };
    let (a, b) = (run(1, &grid), run(3, &grid));
    assert_eq!(a, b);
    assert!(a.queries > 100 && a.mean > 0.0, "{a:?}");
    // The pipelines' default: the approximate search on a seeded sample of pixels.
    let sampled = GuidedCoherenceOptions {
        approximate: Some(fieldtex_eval::ApproximateSearchOptions::default()),
        sampled_queries: 300,
        seed: 4,
        ..Default::default()
    };
    let (a, b) = (run(1, &sampled), run(3, &sampled));
    assert_eq!(a, b);
    assert_eq!((a.queries, a.sampled_queries, a.skipped_border), (300, 300, 0), "{a:?}");
    assert!(a.standard_error.is_some_and(|se| se > 0.0), "{a:?}");
}

#[test]
fn bad_inputs_are_errors() {
    let (ex, ew, eh) = exemplar("stripes_Fabric071.png");
    let out = vec![0.5f32; 32 * 32 * 3];
    let o = ImageView::new(&out, 32, 32, 3).unwrap();
    let e = exemplar_view(&ex, ew, eh);
    let small = constant_field(16, 0.0);
    let f_small = FieldView::new(&small, 16, 16).unwrap();
    let opts = GuidedCoherenceOptions { stride: 4, ..Default::default() };
    assert!(guided_coherence(&o, &e, &f_small, &opts).is_err(), "field size");
    let field = constant_field(32, 0.0);
    let f = FieldView::new(&field, 32, 32).unwrap();
    let bad_stride = GuidedCoherenceOptions { stride: 0, ..Default::default() };
    assert!(guided_coherence(&o, &e, &f, &bad_stride).is_err(), "stride 0");
    let grey = vec![0.5f32; 32 * 32];
    let g = ImageView::new(&grey, 32, 32, 1).unwrap();
    assert!(guided_coherence(&g, &e, &f, &opts).is_err(), "channels");
    // Zero vectors are skipped, not failed.
    let zeros = vec![0f32; 32 * 32 * 2];
    let fz = FieldView::new(&zeros, 32, 32).unwrap();
    let r = guided_coherence(&o, &e, &fz, &opts).unwrap();
    assert_eq!(r.queries, 0);
    assert_eq!(r.skipped_no_direction, 64);
}
