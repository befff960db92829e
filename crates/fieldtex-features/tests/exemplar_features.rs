//! Exemplar feature lines: synthetic lines with known positions, user polylines, and
//! the real striped exemplars.

use fieldtex_core::Image;
use fieldtex_features::{
    ExemplarFeatureOptions, FeaturesError, LinePolarity, detect_exemplar_feature_lines,
    exemplar_features_from_polylines,
};
use std::path::Path;

/// Distance from `p` to segment `a b`.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    ((p[0] - a[0] - t * dx).powi(2) + (p[1] - a[1] - t * dy).powi(2)).sqrt()
}

/// White image with dark anti-aliased lines (Gaussian profile, σ = 1 px) along `segments`.
fn draw(w: usize, h: usize, segments: &[([f64; 2], [f64; 2])]) -> Image {
    let mut im = Image::new(w, h, [1.0; 4]);
    for y in 0..h {
        for x in 0..w {
            let p = [x as f64, y as f64];
            let d =
                segments.iter().map(|(a, b)| segment_distance(p, *a, *b)).fold(f64::MAX, f64::min);
            let v = (1.0 - 0.8 * (-d * d / 2.0).exp()) as f32;
            im.set(x, y, [v, v, v, 1.0]);
        }
    }
    im
}

fn length(line: &[[f32; 2]]) -> f64 {
    line.windows(2)
        .map(|s| (((s[1][0] - s[0][0]).powi(2) + (s[1][1] - s[0][1]).powi(2)) as f64).sqrt())
        .sum()
}

#[test]
fn finds_drawn_dark_lines_within_one_pixel_and_nothing_else() {
    let segments = [
        ([10.0, 30.0], [110.0, 30.0]),
        ([20.0, 50.0], [100.0, 85.0]),
        ([60.0, 10.0], [75.0, 90.0]),
    ];
    let im = draw(128, 100, &segments);
    let options = ExemplarFeatureOptions { toroidal: false, ..Default::default() };
    let f = detect_exemplar_feature_lines(&im, &options).unwrap();
    assert!(!f.lines.is_empty());
    // Every detected point lies within 1 px of a drawn line (no spurious lines). Lines
    // run on past the drawn ends by about the scale (the blurred end still looks like
    // a line), so the segments are prolonged by 3 px for this check.
    let prolonged: Vec<([f64; 2], [f64; 2])> = segments
        .iter()
        .map(|(a, b)| {
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let l = (dx * dx + dy * dy).sqrt();
            let (ux, uy) = (3.0 * dx / l, 3.0 * dy / l);
            ([a[0] - ux, a[1] - uy], [b[0] + ux, b[1] + uy])
        })
        .collect();
    for (k, line) in f.lines.iter().enumerate() {
        for p in line {
            let p = [p[0] as f64, p[1] as f64];
            let d =
                prolonged.iter().map(|(a, b)| segment_distance(p, *a, *b)).fold(f64::MAX, f64::min);
            assert!(d < 1.0, "line {k} point {p:?} is {d:.2} px from every drawn line");
        }
    }
    // Each drawn line is covered: points along it, away from ends and crossings, have a
    // detected line pixel within 1.5 px in the distance map.
    for (a, b) in &segments {
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        let (mut covered, mut total) = (0, 0);
        for k in 0..=len as usize {
            let t = k as f64 / len;
            let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            if k < 4 || k + 4 > len as usize {
                continue;
            }
            total += 1;
            if f.distance_at(p[0], p[1]) <= 1.5 {
                covered += 1;
            }
        }
        assert!(covered as f64 >= 0.9 * total as f64, "{covered}/{total} covered on {a:?}–{b:?}");
    }
    let drawn: f64 =
        segments.iter().map(|(a, b)| ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt()).sum();
    let detected: f64 = f.lines.iter().map(|l| length(l)).sum();
    assert!(detected > 0.85 * drawn && detected < 1.05 * drawn, "{detected} vs {drawn}");
    assert!(f.lines.len() <= 8, "{} pieces", f.lines.len());
    // Bright polarity on the inverted image finds the same lines.
    let mut inverted = im.clone();
    inverted.pixels.iter_mut().for_each(|p| *p = [1.0 - p[0], 1.0 - p[1], 1.0 - p[2], 1.0]);
    let bright = ExemplarFeatureOptions { polarity: LinePolarity::Bright, ..options };
    let fb = detect_exemplar_feature_lines(&inverted, &bright).unwrap();
    assert_eq!(fb.lines.len(), f.lines.len());
    let bright_len: f64 = fb.lines.iter().map(|l| length(l)).sum();
    assert!((bright_len - detected).abs() < 1e-2, "{bright_len} vs {detected}");
    assert_eq!(fb.distance, f.distance);
}

#[test]
fn flat_image_gives_no_line_and_a_warning() {
    let im = Image::new(40, 30, [0.5, 0.5, 0.5, 1.0]);
    let f = detect_exemplar_feature_lines(&im, &ExemplarFeatureOptions::default()).unwrap();
    assert!(f.lines.is_empty());
    assert!(f.distance.iter().all(|d| d.is_infinite()));
    assert_eq!(f.warnings[0].code, "exemplar-no-feature-lines");
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let tiny = Image::new(2, 5, [0.0; 4]);
    assert!(matches!(
        detect_exemplar_feature_lines(&tiny, &ExemplarFeatureOptions::default()),
        Err(FeaturesError::InvalidOption { name: "exemplar width", .. })
    ));
    let bad = ExemplarFeatureOptions { low_threshold: 0.9, ..Default::default() };
    assert!(detect_exemplar_feature_lines(&Image::new(8, 8, [0.0; 4]), &bad).is_err());
    let mut nan = draw(32, 32, &[([4.0, 16.0], [28.0, 16.0])]);
    nan.set(3, 3, [f32::NAN; 4]);
    let f = detect_exemplar_feature_lines(&nan, &ExemplarFeatureOptions::default()).unwrap();
    assert!(f.warnings.iter().any(|w| w.code == "exemplar-non-finite-pixels"));
    let e = exemplar_features_from_polylines(10, 10, &[vec![[1.0, 1.0], [f32::NAN, 2.0]]], true);
    assert_eq!(e, Err(FeaturesError::NonFiniteCurvePoint { curve: 0, point: 1 }));
}

#[test]
fn user_polylines_give_exact_distances() {
    // A vertical line at x = 3 on a 20 × 10 torus: distance |x − 3| wrapped.
    let f =
        exemplar_features_from_polylines(20, 10, &[vec![[3.0, 0.0], [3.0, 9.0]]], true).unwrap();
    for y in 0..10 {
        for x in 0..20i64 {
            let dx = (x - 3).rem_euclid(20).min((3 - x).rem_euclid(20)) as f32;
            assert_eq!(f.distance[y * 20 + x as usize], dx, "({x}, {y})");
        }
    }
    assert_eq!(f.distance_at(3.5, 4.0), 0.5);
    assert_eq!(f.distance_at(-0.5, 4.0), 3.5);
    // Not toroidal: no wrap.
    let g =
        exemplar_features_from_polylines(20, 10, &[vec![[3.0, 0.0], [3.0, 9.0]]], false).unwrap();
    assert_eq!(g.distance[19], 16.0);
    let out =
        exemplar_features_from_polylines(20, 10, &[vec![[30.0, 0.0], [40.0, 9.0]]], false).unwrap();
    assert_eq!(out.warnings[0].code, "exemplar-lines-outside");
}

fn exemplar(name: &str) -> Image {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/exemplars").join(name);
    fieldtex_io::read_image(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Mean absolute direction (degrees from the x axis, mod 180) of a line's segments,
/// length-weighted.
fn mean_abs_angle_deg(line: &[[f32; 2]]) -> f64 {
    let (mut s, mut l) = (0.0, 0.0);
    for seg in line.windows(2) {
        let (dx, dy) = ((seg[1][0] - seg[0][0]) as f64, (seg[1][1] - seg[0][1]) as f64);
        let len = (dx * dx + dy * dy).sqrt();
        let a = dy.atan2(dx).to_degrees().rem_euclid(180.0);
        s += len * a.min(180.0 - a);
        l += len;
    }
    s / l
}

#[test]
fn finds_the_horizontal_stripes_of_the_real_exemplars() {
    // stripes: five dark navy stripes across the whole width.
    let im = exemplar("stripes_Fabric071.png");
    let f = detect_exemplar_feature_lines(&im, &ExemplarFeatureOptions::default()).unwrap();
    let long: Vec<_> = f.lines.iter().filter(|l| length(l) > 0.4 * im.width as f64).collect();
    assert!(long.len() >= 4, "stripes: {} long lines of {}", long.len(), f.lines.len());
    for l in &long {
        let a = mean_abs_angle_deg(l);
        assert!(a < 5.0, "stripes: a long line runs at {a:.1}° from horizontal");
    }
    let total: f64 = f.lines.iter().map(|l| length(l)).sum();
    assert!(total > 4.0 * im.width as f64, "stripes: total length {total}");
    assert!(f.distance.iter().all(|d| d.is_finite() && *d >= 0.0));
    assert_eq!(f, detect_exemplar_feature_lines(&im, &ExemplarFeatureOptions::default()).unwrap());

    // woodgrain: low-contrast grain, many shorter lines, mostly horizontal.
    let im = exemplar("woodgrain_Wood022.png");
    let f = detect_exemplar_feature_lines(&im, &ExemplarFeatureOptions::default()).unwrap();
    let total: f64 = f.lines.iter().map(|l| length(l)).sum();
    assert!(total > 3.0 * im.width as f64, "woodgrain: total length {total}");
    let weighted: f64 =
        f.lines.iter().map(|l| length(l) * mean_abs_angle_deg(l)).sum::<f64>() / total;
    assert!(weighted < 20.0, "woodgrain: lines run at {weighted:.1}° from horizontal on average");
    assert!(f.distance.iter().all(|d| d.is_finite() && *d >= 0.0));
}

#[test]
fn same_result_for_any_thread_count() {
    let im = exemplar("woodgrain_Wood022.png");
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
            detect_exemplar_feature_lines(&im, &ExemplarFeatureOptions::default()).unwrap()
        })
    };
    assert_eq!(run(1), run(3));
}
