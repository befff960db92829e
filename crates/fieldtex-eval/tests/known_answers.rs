//! Metrics on inputs whose answers are known in advance.

use fieldtex_eval::*;
use std::f64::consts::PI;

/// A grey image `f(x, y)` sampled at pixel centres, as 1 channel.
fn grey(w: usize, h: usize, f: impl Fn(f64, f64) -> f64) -> Vec<f32> {
    let mut v = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            v.push(f(x as f64 + 0.5, y as f64 + 0.5) as f32);
        }
    }
    v
}

/// Stripes running along direction `theta_deg` (x right, y down), period `period`.
fn stripes(w: usize, h: usize, theta_deg: f64, period: f64) -> Vec<f32> {
    let t = theta_deg.to_radians();
    let k = 2.0 * PI / period;
    grey(w, h, |x, y| 0.5 + 0.4 * (k * (-t.sin() * x + t.cos() * y)).cos())
}

/// A colourful, non-repetitive test exemplar (RGB).
fn exemplar(w: usize, h: usize) -> Vec<f32> {
    let mut v = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let (xf, yf) = (x as f64, y as f64);
            let n = |s: &str, i: u64| fieldtex_core::rng::hash_unit(5, s, i);
            let i = (y * w + x) as u64;
            v.push((0.5 + 0.3 * (xf * 0.41 + yf * 0.13).sin() + 0.2 * n("r", i)) as f32 * 0.8);
            v.push((0.4 + 0.3 * (yf * 0.37).cos() + 0.2 * n("g", i)) as f32);
            v.push((0.3 + 0.2 * ((xf - yf) * 0.23).sin() + 0.3 * n("b", i)) as f32);
        }
    }
    v
}

#[test]
fn exemplar_against_itself_is_perfect() {
    let (w, h) = (40, 36);
    let e = exemplar(w, h);
    let v = ImageView::new(&e, w, h, 3).unwrap();
    let opts = PatchDistanceOptions::default();
    let c = coherence(&v, &v, &opts).unwrap();
    let m = completeness(&v, &v, &opts).unwrap();
    assert_eq!(c.mean, 0.0);
    assert_eq!(m.mean, 0.0);
    assert_eq!(c.queries, 34 * 30);
    let sw = color_sliced_wasserstein(&v, &v, &SlicedWassersteinOptions::default()).unwrap();
    assert!(sw.distance < 1e-7, "{sw:?}");
}

#[test]
fn coherence_and_completeness_see_the_difference() {
    let (w, h) = (40, 36);
    let e = exemplar(w, h);
    let ev = ImageView::new(&e, w, h, 3).unwrap();
    // A crop is perfectly coherent but incomplete.
    let (cw, ch) = (16, 14);
    let mut crop = Vec::new();
    for y in 5..5 + ch {
        crop.extend_from_slice(&e[(y * w + 7) * 3..(y * w + 7 + cw) * 3]);
    }
    let cv = ImageView::new(&crop, cw, ch, 3).unwrap();
    let opts = PatchDistanceOptions::default();
    assert_eq!(coherence(&cv, &ev, &opts).unwrap().mean, 0.0);
    let incomplete = completeness(&cv, &ev, &opts).unwrap();
    assert!(incomplete.mean > 1e-3, "{incomplete:?}");
    // A constant image is neither.
    let flat = vec![0.5f32; 30 * 30 * 3];
    let fv = ImageView::new(&flat, 30, 30, 3).unwrap();
    let c = coherence(&fv, &ev, &opts).unwrap();
    assert!(c.mean > 1e-3 && c.rms > 0.03, "{c:?}");
    // Wrapping the exemplar gives more candidates.
    let wrapped = coherence(&cv, &ev, &opts.clone().with_wrap_exemplar(true)).unwrap();
    assert_eq!(wrapped.candidates, w * h);
    assert_eq!(wrapped.mean, 0.0);
}

#[test]
fn sliced_wasserstein_of_a_colour_shift() {
    let (w, h) = (32, 32);
    let a = exemplar(w, h);
    let b: Vec<f32> = a.iter().map(|v| v + 0.1).collect();
    let (va, vb) = (ImageView::new(&a, w, h, 3).unwrap(), ImageView::new(&b, w, h, 3).unwrap());
    let opts = SlicedWassersteinOptions { directions: 256, seed: 3, max_pixels: None };
    let r = color_sliced_wasserstein(&va, &vb, &opts).unwrap();
    // E[(θ·s)²] = |s|²/3 for uniform θ: SW = 0.1.
    assert!((r.distance - 0.1).abs() < 0.01, "{r:?}");
    // Different sizes of the same distribution: a 2×2 tiling of an image.
    let mut tiled = Vec::new();
    for y in 0..2 * h {
        for x in 0..2 * w {
            let i = ((y % h) * w + (x % w)) * 3;
            tiled.extend_from_slice(&a[i..i + 3]);
        }
    }
    let vt = ImageView::new(&tiled, 2 * w, 2 * h, 3).unwrap();
    assert!(color_sliced_wasserstein(&va, &vt, &opts).unwrap().distance < 1e-6);
    // Seeded: identical twice.
    assert_eq!(color_sliced_wasserstein(&va, &vb, &opts).unwrap(), r);
}

#[test]
fn rotated_stripes_orientation_within_one_degree() {
    let (w, h) = (96, 96);
    for theta in [0.0, 17.0, 30.0, 45.0, 60.0, 90.0, 123.0, 160.0] {
        let img = stripes(w, h, theta, 8.0);
        let v = ImageView::new(&img, w, h, 1).unwrap();
        let opts = OrientationErrorOptions::default();
        let r = orientation_error(&v, &OrientationReference::ConstantDeg(theta), &opts).unwrap();
        let d = (r.mean_texture_angle_deg - theta).rem_euclid(180.0);
        assert!(d.min(180.0 - d) < 1.0, "θ={theta}: measured {}", r.mean_texture_angle_deg);
        assert!(r.mean_error_deg < 1.0, "θ={theta}: {r:?}");
        assert!(r.mean_coherence > 0.9);
        let off =
            orientation_error(&v, &OrientationReference::ConstantDeg(theta + 30.0), &opts).unwrap();
        assert!((off.mean_error_deg - 30.0).abs() < 1.0, "θ={theta}: {off:?}");
        // The same as a per-pixel field (with arbitrary signs and lengths).
        let (c, s) = (theta.to_radians().cos() as f32, theta.to_radians().sin() as f32);
        let field: Vec<f32> = (0..w * h)
            .flat_map(|i| if i % 3 == 0 { [-2.0 * c, -2.0 * s] } else { [c, s] })
            .collect();
        let f = FieldView::new(&field, w, h).unwrap();
        let rf = orientation_error(&v, &OrientationReference::Field(f), &opts).unwrap();
        assert!((rf.mean_error_deg - r.mean_error_deg).abs() < 1e-4);
        let (dom, coh) = dominant_orientation(&v).unwrap();
        let d = (dom - theta).rem_euclid(180.0);
        assert!(d.min(180.0 - d) < 1.0 && coh > 0.9, "{dom} {coh}");
    }
}

#[test]
fn exemplar_angle_offsets_the_expected_direction() {
    let img = stripes(64, 64, 90.0, 8.0);
    let v = ImageView::new(&img, 64, 64, 1).unwrap();
    let opts = OrientationErrorOptions { exemplar_angle_deg: 90.0, ..Default::default() };
    let r = orientation_error(&v, &OrientationReference::ConstantDeg(0.0), &opts).unwrap();
    assert!(r.mean_error_deg < 1.0, "{r:?}");
}

fn half_winding_field(w: usize, h: usize, x0: f64, y0: f64, sign: f64) -> Vec<f32> {
    let mut f = Vec::with_capacity(w * h * 2);
    for y in 0..h {
        for x in 0..w {
            let a = sign * 0.5 * (y as f64 + 0.5 - y0).atan2(x as f64 + 0.5 - x0) + 0.3;
            f.push(a.cos() as f32);
            f.push(a.sin() as f32);
        }
    }
    f
}

#[test]
fn one_half_singularities_of_a_designed_field() {
    let (w, h) = (64, 48);
    for (sign, x0, y0) in [(1.0, 30.3, 20.7), (-1.0, 12.8, 33.1)] {
        let f = half_winding_field(w, h, x0, y0, sign);
        let map = OrientationMap::from_field(&FieldView::new(&f, w, h).unwrap());
        let r = singularities(&map, &SingularityOptions::default());
        assert_eq!(r.raw.len(), 1, "{r:?}");
        let s = r.raw[0];
        assert_eq!(s.index, 0.5 * sign);
        assert!((s.x - x0).abs() <= 0.5 && (s.y - y0).abs() <= 0.5, "{s:?} vs ({x0}, {y0})");
        assert_eq!(r.merged.len(), 1);
        assert_eq!(r.index_sum, 0.5 * sign);
        let designed = [ExpectedSingularity { x: x0, y: y0, index: 0.5 * sign }];
        let m = match_singularities(&r.merged, &designed, 1.0);
        assert_eq!((m.matched, m.missed, m.spurious), (1, 0, 0));
    }
}

#[test]
fn singularities_of_striped_textures() {
    let (w, h) = (128, 128);
    let (x0, y0) = (64.0, 64.0);
    let k = 2.0 * PI / 8.0;
    // Confocal parabolas: level sets of r + x have a +1/2 core at the focus.
    let loop_core = grey(w, h, |x, y| {
        let (dx, dy) = (x - x0, y - y0);
        0.5 + 0.4 * (k * ((dx * dx + dy * dy).sqrt() + dx)).cos()
    });
    // Level sets of Re(z^{3/2}) meet in a −1/2 trisector.
    let delta = grey(w, h, |x, y| {
        let (dx, dy) = (x - x0, y - y0);
        let r = (dx * dx + dy * dy).sqrt();
        let a = dy.atan2(dx);
        0.5 + 0.4 * (0.18 * r.powf(1.5) * (1.5 * a).cos()).cos()
    });
    for (img, sign) in [(loop_core, 1.0), (delta, -1.0)] {
        let v = ImageView::new(&img, w, h, 1).unwrap();
        let map = image_orientation(&v, &OrientationOptions::default()).unwrap();
        let r = singularities(&map, &SingularityOptions::default());
        let near: Vec<_> = r.merged.iter().filter(|c| (c.x - x0).hypot(c.y - y0) < 8.0).collect();
        assert_eq!(near.len(), 1, "sign {sign}: {:?}", r.merged);
        assert_eq!(near[0].index, 0.5 * sign);
    }
}

#[test]
fn singular_cores_are_not_phase_defects() {
    let (w, h) = (160, 160);
    let (x0, y0) = (80.0, 80.0);
    let k = 2.0 * PI / 8.0;
    // Uniformly spaced loop: straight stripes on one side, half circles around the core.
    let loop_core = grey(w, h, |x, y| {
        let (dx, dy) = (x - x0, y - y0);
        let d = if dx >= 0.0 { dy.abs() } else { dx.hypot(dy) };
        0.5 + 0.4 * (k * d).cos()
    });
    let delta = grey(w, h, |x, y| {
        let (dx, dy) = (x - x0, y - y0);
        0.5 + 0.4 * (0.12 * dx.hypot(dy).powf(1.5) * (1.5 * dy.atan2(dx)).cos()).cos()
    });
    for img in [loop_core, delta] {
        let v = ImageView::new(&img, w, h, 1).unwrap();
        let r = phase_defects(&v, &PhaseDefectOptions::default()).unwrap();
        assert_eq!(r.count, 0, "{r:?}");
    }
}

#[test]
fn period_estimate_of_stripes() {
    for (theta, period) in [(0.0, 8.0), (35.0, 11.0), (100.0, 6.0)] {
        let img = stripes(96, 96, theta, period);
        let v = ImageView::new(&img, 96, 96, 1).unwrap();
        let t = estimate_stripe_period(&v).unwrap();
        assert!((t - period).abs() / period < 0.1, "θ={theta}: {t} vs {period}");
    }
}

#[test]
fn clean_stripes_have_no_phase_defects() {
    for theta in [0.0, 30.0, 75.0, 90.0, 140.0] {
        let img = stripes(128, 128, theta, 8.0);
        let v = ImageView::new(&img, 128, 128, 1).unwrap();
        let r = phase_defects(&v, &PhaseDefectOptions::default()).unwrap();
        assert_eq!(r.count, 0, "θ={theta}: {r:?}");
        assert!(r.striped_fraction > 0.9);
    }
}

#[test]
fn planted_dislocation_is_found() {
    let (w, h) = (128, 128);
    let k = 2.0 * PI / 8.0;
    for (x0, y0, rot) in [(64.3, 60.7, 0.0), (50.0, 70.0, 0.6)] {
        let img = grey(w, h, |x, y| {
            let (dx, dy) = (x - x0, y - y0);
            let (c, s) = (f64::cos(rot), f64::sin(rot));
            let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
            0.5 + 0.4 * (k * u + v.atan2(u)).cos()
        });
        let v = ImageView::new(&img, w, h, 1).unwrap();
        let r = phase_defects(&v, &PhaseDefectOptions::default()).unwrap();
        assert!(r.count >= 1, "{r:?}");
        assert_eq!(count_defects_near(&r.defects, &[[x0, y0]], 8.0), 1, "{r:?}");
        assert_eq!(r.count, 1, "{r:?}");
        assert!((r.per_10k_px - 1e4 / r.evaluated_pixels as f64).abs() < 1e-9);
    }
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    assert!(ImageView::new(&[0.0; 5], 2, 2, 1).is_err());
    assert!(ImageView::new(&[f32::NAN; 4], 2, 2, 1).is_err());
    assert!(ImageView::new(&[0.0; 4], usize::MAX, 2, 1).is_err());
    let tiny = [0.5f32; 4 * 4 * 3];
    let t = ImageView::new(&tiny, 4, 4, 3).unwrap();
    assert!(matches!(
        coherence(&t, &t, &PatchDistanceOptions::default()),
        Err(EvalError::TooSmall { .. })
    ));
    assert!(coherence(&t, &t, &PatchDistanceOptions::default().with_patch_size(0)).is_err());
    let e = exemplar(40, 36);
    let ev = ImageView::new(&e, 40, 36, 3).unwrap();
    let capped = PatchDistanceOptions { max_pairs: 1000, ..Default::default() };
    assert!(matches!(coherence(&ev, &ev, &capped), Err(EvalError::TooLarge { .. })));
    let grey1 = [0.5f32; 16];
    let g = ImageView::new(&grey1, 4, 4, 1).unwrap();
    assert!(matches!(
        color_sliced_wasserstein(&t, &g, &Default::default()),
        Err(EvalError::ChannelMismatch { .. })
    ));
    assert!(phase_defects(&t, &PhaseDefectOptions::default()).is_err());
    let big = vec![0.5f32; 32 * 32];
    let b = ImageView::new(&big, 32, 32, 1).unwrap();
    let field = vec![1.0f32; 31 * 32 * 2];
    let f = FieldView::new(&field, 31, 32).unwrap();
    assert!(matches!(
        orientation_error(&b, &OrientationReference::Field(f), &Default::default()),
        Err(EvalError::SizeMismatch { .. })
    ));
    // A flat image: nothing to measure, but no panic and no defects.
    let r = phase_defects(&b, &PhaseDefectOptions::default()).unwrap();
    assert_eq!(r.count, 0);
    let o = orientation_error(&b, &OrientationReference::ConstantDeg(0.0), &Default::default())
        .unwrap();
    assert!(o.mean_error_deg.is_nan() && o.mean_coherence == 0.0);
    let bad = PhaseDefectOptions { period_px: Some(f64::NAN), ..Default::default() };
    assert!(phase_defects(&b, &bad).is_err());
}

#[test]
fn results_do_not_depend_on_thread_count() {
    let (w, h) = (48, 40);
    let e = exemplar(w, h);
    let ev = ImageView::new(&e, w, h, 3).unwrap();
    let o: Vec<f32> =
        e.iter().enumerate().map(|(i, v)| v * 0.9 + 0.05 * ((i % 11) as f32 / 11.0)).collect();
    let ov = ImageView::new(&o, w, h, 3).unwrap();
    let s = stripes(96, 96, 25.0, 7.0);
    let sv = ImageView::new(&s, 96, 96, 1).unwrap();
    let run = || {
        (
            coherence(&ov, &ev, &PatchDistanceOptions::default()).unwrap(),
            completeness(&ov, &ev, &PatchDistanceOptions::default()).unwrap(),
            color_sliced_wasserstein(&ov, &ev, &Default::default()).unwrap(),
            format!(
                "{:?}",
                orientation_error(
                    &sv,
                    &OrientationReference::ConstantDeg(20.0),
                    &Default::default()
                )
                .unwrap()
            ),
            phase_defects(&sv, &Default::default()).unwrap(),
        )
    };
    let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
    let a = pool(1).install(run);
    let b = pool(3).install(run);
    assert_eq!(a, b);
    assert!(a.0.mean > 0.0);
}
