//! Invariants of the parallel synthesis engine on small procedural exemplars.

use std::f32::consts::PI;

mod common;

use common::stripes;
use fieldtex_core::{Image, NoProgress};
use fieldtex_synth::{
    AnalysisOptions, ColorFilter, ExemplarAnalysis, ImageDomain, SynthError, SynthesisDomain,
    SynthesisOptions, synthesize,
};

/// A small non-square, non-power-of-two, non-periodic exemplar.
fn blotches(w: usize, h: usize) -> Image {
    Image::from_fn(w, h, |x, y| {
        let (fx, fy) = (x as f32, y as f32);
        [
            0.5 + 0.5 * (fx * 0.9 + (fy * 0.4).sin() * 2.0).sin(),
            0.5 + 0.5 * (fy * 0.7 - fx * 0.2).cos(),
            ((x * 7 + y * 13) % 11) as f32 / 11.0,
            1.0,
        ]
    })
}

/// Analysis treating the procedural exemplar as tileable.
fn analyse(im: &Image) -> ExemplarAnalysis {
    let opts = AnalysisOptions { tileable: true, coherence_scan: usize::MAX, ..Default::default() };
    ExemplarAnalysis::new(im, &opts, &NoProgress).unwrap()
}

/// Dominant stripe orientation (radians mod π, 0 = along +x) of a luminance image via
/// the structure tensor, and its coherence in [0, 1].
fn stripe_orientation(im: &Image) -> (f32, f32) {
    let lum = im.luminance();
    let (w, h) = (im.width, im.height);
    let (mut jxx, mut jyy, mut jxy) = (0.0f64, 0.0f64, 0.0f64);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let gx = (lum[y * w + x + 1] - lum[y * w + x - 1]) as f64;
            let gy = (lum[(y + 1) * w + x] - lum[(y - 1) * w + x]) as f64;
            jxx += gx * gx;
            jyy += gy * gy;
            jxy += gx * gy;
        }
    }
    let grad = 0.5 * (2.0 * jxy).atan2(jxx - jyy);
    let coherence = ((jxx - jyy).powi(2) + 4.0 * jxy * jxy).sqrt() / (jxx + jyy).max(1e-12);
    (
        ((grad + std::f64::consts::FRAC_PI_2).rem_euclid(std::f64::consts::PI)) as f32,
        coherence as f32,
    )
}

fn angle_diff_mod_pi(a: f32, b: f32) -> f32 {
    let d = (a - b).rem_euclid(PI);
    d.min(PI - d)
}

#[test]
fn coords_are_valid_and_colours_match_the_exemplar() {
    let ex = blotches(20, 13);
    let an = analyse(&ex);
    assert_eq!(an.level_count(), 5);
    let dom = ImageDomain::constant(37, 29, 0.7, 1.0).unwrap();
    let opts = SynthesisOptions { color_filter: ColorFilter::Nearest, ..Default::default() };
    let r = synthesize(&an, &dom, &opts, &NoProgress).unwrap();
    assert_eq!((r.colors.width, r.colors.height), (37, 29));
    assert_eq!(r.coords.len(), 37 * 29);
    assert_eq!(r.flips.len(), 37 * 29);
    assert_eq!(r.level_timings_ms.len(), 5);
    for (i, u) in r.coords.iter().enumerate() {
        assert!(u[0] >= 0.0 && u[0] < 20.0 && u[1] >= 0.0 && u[1] < 13.0, "{i}: {u:?}");
        let (x, y) = (u[0] as usize, u[1] as usize);
        assert_eq!(r.colors.pixels[i], ex.get(x, y), "pixel {i}");
    }
}

#[test]
fn output_is_identical_for_one_and_two_threads() {
    let an =
        ExemplarAnalysis::new(&blotches(24, 24), &AnalysisOptions::default(), &NoProgress).unwrap();
    let field: Vec<f32> = (0..48 * 40)
        .flat_map(|i| {
            let (x, y) = ((i % 48) as f32 - 20.0, (i / 48) as f32 - 17.0);
            [-y, x] // a vortex: the representative flips nowhere, rotates everywhere
        })
        .collect();
    let dom = ImageDomain::from_direction_field(48, 40, &field, 1.0).unwrap();
    let run = |threads: usize| {
        let an = an.clone();
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
            let a =
                ExemplarAnalysis::new(&blotches(24, 24), &AnalysisOptions::default(), &NoProgress)
                    .unwrap();
            assert_eq!(a.level(0), an.level(0));
            let opts = SynthesisOptions { seed: 9, ..Default::default() };
            synthesize(&a, &dom, &opts, &NoProgress).unwrap()
        })
    };
    let (a, b) = (run(1), run(2));
    let bits = |r: &fieldtex_synth::SynthesisResult| {
        r.coords.iter().flat_map(|u| [u[0].to_bits(), u[1].to_bits()]).collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.flips, b.flips);
    assert_eq!(a.colors, b.colors);
    // A different seed gives a different texture.
    let c =
        synthesize(&an, &dom, &SynthesisOptions { seed: 10, ..Default::default() }, &NoProgress)
            .unwrap();
    assert_ne!(bits(&a), bits(&c));
}

#[test]
fn stripes_follow_a_constant_field() {
    let an = analyse(&stripes(32));
    for deg in [0.0f32, 45.0, 120.0] {
        let dom = ImageDomain::constant(64, 64, deg.to_radians(), 1.0).unwrap();
        let r = synthesize(&an, &dom, &SynthesisOptions::default(), &NoProgress).unwrap();
        let (theta, coherence) = stripe_orientation(&r.colors);
        let err = angle_diff_mod_pi(theta, deg.to_radians()).to_degrees();
        assert!(
            err < 8.0,
            "field {deg}°: stripes at {}° (coherence {coherence})",
            theta.to_degrees()
        );
        assert!(coherence > 0.6, "field {deg}°: weak orientation, coherence {coherence}");
    }
}

#[test]
fn neighbouring_samples_are_mostly_coherent() {
    let an = analyse(&blotches(32, 32));
    let angle = 0.5f32;
    let dom = ImageDomain::constant(64, 64, angle, 1.0).unwrap();
    let r = synthesize(&an, &dom, &SynthesisOptions::default(), &NoProgress).unwrap();
    let (w, h) = (64usize, 64usize);
    let (mut ok, mut total) = (0usize, 0usize);
    for y in 0..h {
        for x in 0..w - 1 {
            let (p, q) = (y * w + x, y * w + x + 1);
            let j = dom.jacobian(0, p);
            let sign = if r.flips[p] { -1.0 } else { 1.0 };
            // Expected exemplar step for the domain offset (1, 0).
            let e = [sign * j[0], sign * j[2]];
            let wrap = |d: f32| (d + 16.0).rem_euclid(32.0) - 16.0;
            let dx = wrap(r.coords[q][0] - r.coords[p][0] - e[0]);
            let dy = wrap(r.coords[q][1] - r.coords[p][1] - e[1]);
            total += 1;
            if dx.abs() < 0.5 && dy.abs() < 0.5 {
                ok += 1;
            }
        }
    }
    let frac = ok as f32 / total as f32;
    eprintln!("coherent fraction {frac}");
    assert!(frac > 0.5, "only {:.0}% of neighbouring samples are coherent", 100.0 * frac);
}

/// Fraction of horizontal neighbour pairs in columns `x0..x1` whose coordinates differ by
/// the effective frame `(−1)^I J` applied to (1, 0), within half a pixel.
fn coherent_fraction(
    r: &fieldtex_synth::SynthesisResult,
    dom: &ImageDomain,
    ex_size: f32,
    x0: usize,
    x1: usize,
) -> f32 {
    let (w, h) = (dom.width, dom.height);
    let (mut ok, mut total) = (0usize, 0usize);
    let wrap = |d: f32| (d + ex_size / 2.0).rem_euclid(ex_size) - ex_size / 2.0;
    for y in 0..h {
        for x in x0..x1.min(w - 1) {
            let (p, q) = (y * w + x, y * w + x + 1);
            let j = dom.jacobian(0, p);
            let sign = if r.flips[p] { -1.0 } else { 1.0 };
            let dx = wrap(r.coords[q][0] - r.coords[p][0] - sign * j[0]);
            let dy = wrap(r.coords[q][1] - r.coords[p][1] - sign * j[2]);
            total += 1;
            if dx.abs() < 0.5
                && dy.abs() < 0.5
                && r.flips[p] == r.flips[q] ^ (dom.jacobian(0, q)[0] * j[0] < 0.0)
            {
                ok += 1;
            }
        }
    }
    ok as f32 / total.max(1) as f32
}

#[test]
fn rosy_fix_keeps_patches_coherent_across_a_representative_flip() {
    // Representative points right on the left half and left on the right half: the same
    // orientation field everywhere (horizontal), a 180° jump in the vector field.
    let an = analyse(&blotches(32, 32));
    let (w, h) = (64usize, 48usize);
    let field: Vec<f32> =
        (0..w * h).flat_map(|i| if i % w < w / 2 { [1.0, 0.0] } else { [-1.0, 0.0] }).collect();
    let dom = ImageDomain::from_direction_field(w, h, &field, 1.0).unwrap();
    let (mut seam_fixed, mut seam_plain, mut away) = (0.0, 0.0, 0.0);
    for seed in 0..4 {
        let fixed =
            synthesize(&an, &dom, &SynthesisOptions { seed, ..Default::default() }, &NoProgress)
                .unwrap();
        let opts = SynthesisOptions { seed, rosy_fix: false, ..Default::default() };
        let plain = synthesize(&an, &dom, &opts, &NoProgress).unwrap();
        assert!(plain.flips.iter().all(|&f| !f));
        // Pairs straddling the jump (columns 31 | 32) and pairs well inside the left half.
        seam_fixed += coherent_fraction(&fixed, &dom, 32.0, 31, 32) / 4.0;
        seam_plain += coherent_fraction(&plain, &dom, 32.0, 31, 32) / 4.0;
        away += coherent_fraction(&fixed, &dom, 32.0, 4, 24) / 4.0;
    }
    eprintln!("seam fixed {seam_fixed} plain {seam_plain} away {away}");
    assert!(seam_fixed > seam_plain + 0.2, "fixed {seam_fixed} vs plain {seam_plain}");
    assert!(seam_fixed > 0.5 * away, "seam {seam_fixed} vs away {away}");
}

#[test]
fn bad_exemplars_and_options_are_refused() {
    let opts = AnalysisOptions::default();
    assert!(matches!(
        ExemplarAnalysis::new(&Image::new(7, 30, [0.5; 4]), &opts, &NoProgress),
        Err(SynthError::ExemplarTooSmall { width: 7, height: 30, .. })
    ));
    assert!(matches!(
        ExemplarAnalysis::new(&Image::new(2100, 9, [0.5; 4]), &opts, &NoProgress),
        Err(SynthError::ExemplarTooLarge { .. })
    ));
    let mut nan = blotches(10, 10);
    nan.pixels[23][1] = f32::NAN;
    assert!(matches!(
        ExemplarAnalysis::new(&nan, &opts, &NoProgress),
        Err(SynthError::NonFiniteExemplar { index: 23, x: 3, y: 2, .. })
    ));
    let mut short = blotches(10, 10);
    short.pixels.pop();
    assert!(ExemplarAnalysis::new(&short, &opts, &NoProgress).is_err());
    // A flat exemplar must not panic (degenerate PCA).
    let flat = analyse(&Image::new(12, 12, [0.3, 0.3, 0.3, 1.0]));
    let dom = ImageDomain::constant(16, 16, 0.0, 1.0).unwrap();
    assert!(synthesize(&flat, &dom, &SynthesisOptions::default(), &NoProgress).is_ok());
    let an = analyse(&blotches(12, 12));
    for o in [
        SynthesisOptions { subpasses: 3, ..Default::default() },
        SynthesisOptions { k: 5, ..Default::default() },
        SynthesisOptions { jitter: f32::NAN, ..Default::default() },
        SynthesisOptions { scale: 0.0, ..Default::default() },
        SynthesisOptions { finest_passes: Some(17), ..Default::default() },
        SynthesisOptions { coarse_passes: Some(33), ..Default::default() },
    ] {
        assert!(matches!(
            synthesize(&an, &dom, &o, &NoProgress),
            Err(SynthError::InvalidOption { .. })
        ));
    }
    assert!(ImageDomain::new(2, 2, vec![[0.0; 4]; 4]).is_err());
}

fn load_exemplar(name: &str) -> Image {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/exemplars")
        .join(name);
    let img = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba32f();
    let (w, h) = img.dimensions();
    Image { width: w as usize, height: h as usize, pixels: img.pixels().map(|p| p.0).collect() }
}

#[test]
fn real_non_power_of_two_exemplar_follows_the_field() {
    // stripes_Fabric071 is 116×116, not tileable (default analysis options).
    let ex = load_exemplar("stripes_Fabric071.png");
    assert_eq!((ex.width, ex.height), (116, 116));
    let an = ExemplarAnalysis::new(&ex, &AnalysisOptions::default(), &NoProgress).unwrap();
    assert_eq!(an.level_count(), 7);
    let margin = an.level(0).margin as f32;
    let deg = 30.0f32;
    let dom = ImageDomain::constant(96, 96, deg.to_radians(), 1.0).unwrap();
    let r = synthesize(&an, &dom, &SynthesisOptions::default(), &NoProgress).unwrap();
    let (theta, coherence) = stripe_orientation(&r.colors);
    let err = angle_diff_mod_pi(theta, deg.to_radians()).to_degrees();
    eprintln!("real stripes: error {err}°, coherence {coherence}");
    assert!(
        err < 5.0 && coherence > 0.6,
        "stripes at {}°, coherence {coherence}",
        theta.to_degrees()
    );
    // Almost every coordinate keeps clear of the (non-tileable) exemplar border.
    let inside =
        r.coords.iter().filter(|u| u.iter().all(|&v| v >= margin && v < 116.0 - margin)).count();
    assert!(inside as f32 > 0.99 * r.coords.len() as f32, "{inside} of {}", r.coords.len());
}

/// Horizontal and vertical neighbour pairs whose effective frames `(−1)^I J` point in
/// opposite directions.
fn effective_seams(r: &fieldtex_synth::SynthesisResult, dom: &ImageDomain) -> usize {
    let (w, h) = (dom.width, dom.height);
    let eff = |p: usize| dom.jacobian(0, p).map(|v| if r.flips[p] { -v } else { v });
    let mut seams = 0;
    for y in 0..h {
        for x in 0..w {
            let a = eff(y * w + x);
            for (qx, qy) in [(x + 1, y), (x, y + 1)] {
                if qx < w && qy < h {
                    let b = eff(qy * w + qx);
                    seams += (a[0] * b[0] + a[1] * b[1] < 0.0) as usize;
                }
            }
        }
    }
    seams
}

#[test]
fn kept_flips_leave_fewer_effective_frame_seams_than_free_flips() {
    // Two +1/2 wedges: the representative field jumps along cuts from each, and a
    // 180°-symmetric exemplar (stripes) lets free flips wander.
    let an = analyse(&stripes(32));
    let n = 96usize;
    let field: Vec<f32> = (0..n * n)
        .flat_map(|i| {
            let (x, y) = ((i % n) as f32 + 0.5, (i / n) as f32 + 0.5);
            let a = 0.5 * (y - 48.0).atan2(x - 30.0) + 0.5 * (y - 48.0).atan2(x - 66.0);
            [a.cos(), a.sin()]
        })
        .collect();
    let dom = ImageDomain::from_direction_field(n, n, &field, 1.0).unwrap();
    let (mut kept, mut free) = (0, 0);
    for seed in 0..3 {
        let opts = SynthesisOptions { seed, ..Default::default() };
        kept += effective_seams(&synthesize(&an, &dom, &opts, &NoProgress).unwrap(), &dom);
        let opts = SynthesisOptions { seed, keep_flips: false, ..Default::default() };
        free += effective_seams(&synthesize(&an, &dom, &opts, &NoProgress).unwrap(), &dom);
    }
    eprintln!("effective-frame seam pairs: kept {kept}, free {free}");
    assert!(kept * 2 < free, "kept flips {kept} vs free flips {free}");
}

#[test]
fn snapped_coordinates_copy_exemplar_pixels_for_an_axis_aligned_field() {
    // With snapping (default) and no finest-level jitter, a 0° field puts every finest
    // coordinate on a pixel centre, so the cubic colours are exemplar pixels.
    let ex = blotches(24, 20);
    let an = analyse(&ex);
    let dom = ImageDomain::constant(40, 36, 0.0, 1.0).unwrap();
    let r = synthesize(&an, &dom, &SynthesisOptions::default(), &NoProgress).unwrap();
    for (i, u) in r.coords.iter().enumerate() {
        assert_eq!(u.map(|v| v.fract()), [0.5, 0.5], "sample {i}: {u:?}");
        assert_eq!(r.colors.pixels[i], ex.get(u[0] as usize, u[1] as usize), "sample {i}");
    }
    // Without snapping the phases are arbitrary and the colours interpolate.
    let opts = SynthesisOptions { snap_coordinates: false, ..Default::default() };
    let r = synthesize(&an, &dom, &opts, &NoProgress).unwrap();
    assert!(r.coords.iter().any(|u| u[0].fract() != 0.5));
}

#[test]
fn trapezoid_frames_change_nothing_where_the_orientation_is_constant() {
    // One horizontal orientation whose representatives jump by 180° at the middle: the
    // sign-aligned mean of two frames is the frame itself (bit for bit), so the
    // trapezoid rule must leave the result unchanged; a sign error would average
    // opposite frames to zero across the jump.
    let an = analyse(&blotches(32, 32));
    let (w, h) = (64usize, 48usize);
    let flip: Vec<f32> =
        (0..w * h).flat_map(|i| if i % w < w / 2 { [1.0, 0.0] } else { [-1.0, 0.0] }).collect();
    let dom = ImageDomain::from_direction_field(w, h, &flip, 1.0).unwrap();
    let opts = SynthesisOptions { seed: 5, ..Default::default() };
    let off = SynthesisOptions { trapezoid_frames: false, ..opts.clone() };
    let a = synthesize(&an, &dom, &opts, &NoProgress).unwrap();
    let b = synthesize(&an, &dom, &off, &NoProgress).unwrap();
    assert!(a.flips.iter().any(|&f| f), "the jump needs flipped samples");
    assert_eq!(a.coords, b.coords);
    assert_eq!(a.flips, b.flips);
    // On a turning field the rule is active: the results differ.
    let swirl: Vec<f32> = (0..w * h)
        .flat_map(|i| {
            let a = 0.05 * (i % w) as f32 + 0.03 * (i / w) as f32;
            [a.cos(), a.sin()]
        })
        .collect();
    let dom = ImageDomain::from_direction_field(w, h, &swirl, 1.0).unwrap();
    let a = synthesize(&an, &dom, &opts, &NoProgress).unwrap();
    let b = synthesize(&an, &dom, &off, &NoProgress).unwrap();
    assert_ne!(a.coords, b.coords);
}
