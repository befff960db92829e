//! Synthesis against a pre-rotated exemplar copy (`rotated_exemplar.rs`): a rotated
//! constant design copies whole pixels of the copy, the 0° case is the plain engine, the
//! coordinates stay those of the original exemplar.

mod common;

use std::collections::HashSet;

use common::stripes;

use fieldtex_core::{Image, NoProgress};
use fieldtex_eval as ev;
use fieldtex_synth::rotated_exemplar::{RotatedExemplar, synthesize_rotated};
use fieldtex_synth::{
    AnalysisOptions, ColorFilter, ExemplarAnalysis, ImageDomain, SynthesisOptions, color_lookup,
    synthesize,
};

fn setup(angle_deg: f32) -> (Image, AnalysisOptions, ExemplarAnalysis, ImageDomain) {
    let ex = stripes(48);
    let aopts = AnalysisOptions { tileable: true, ..Default::default() };
    let analysis = ExemplarAnalysis::new(&ex, &aopts, &NoProgress).unwrap();
    let dom = ImageDomain::constant(96, 96, angle_deg.to_radians(), 1.0).unwrap();
    (ex, aopts, analysis, dom)
}

fn bits(c: &[f32; 4]) -> [u32; 3] {
    [c[0].to_bits(), c[1].to_bits(), c[2].to_bits()]
}

/// Share of `colors` equal, bit for bit, to some pixel of `image`.
fn exact_share(colors: &Image, image: &Image) -> f64 {
    let set: HashSet<[u32; 3]> = image.pixels.iter().map(bits).collect();
    let hits = colors.pixels.iter().filter(|c| set.contains(&bits(c))).count();
    hits as f64 / colors.pixels.len() as f64
}

#[test]
fn rotated_design_copies_pixels_of_the_rotated_copy() {
    let (_, aopts, analysis, dom) = setup(30.0);
    let opts = SynthesisOptions { seed: 3, ..Default::default() };
    let copy = RotatedExemplar::new(&analysis, 30f32.to_radians(), opts.color_filter);
    let rotated =
        synthesize_rotated(&analysis, &aopts, &dom, 30f32.to_radians(), 1.0, &opts, &NoProgress)
            .unwrap();
    let plain = synthesize(&analysis, &dom, &opts, &NoProgress).unwrap();
    let (r, p) =
        (exact_share(&rotated.colors, &copy.image), exact_share(&plain.colors, &copy.image));
    assert!(r > 0.95, "pre-rotated: {r} of the pixels are copy pixels");
    assert!(p < 0.5, "plain: {p} of the pixels are copy pixels");
    // The coordinates are the original exemplar's: reading them there gives the colour.
    let close = rotated
        .coords
        .iter()
        .zip(&rotated.colors.pixels)
        .filter(|(u, c)| {
            let d = color_lookup(&analysis, **u, ColorFilter::Cubic);
            (0..3).all(|i| (d[i] - c[i]).abs() < 1e-4)
        })
        .count();
    assert!(close as f64 > 0.95 * rotated.coords.len() as f64, "{close} coordinates agree");
}

#[test]
fn rotated_design_is_more_coherent_than_the_plain_engine() {
    let (ex, aopts, analysis, dom) = setup(30.0);
    let (s, c) = 30f32.to_radians().sin_cos();
    let field: Vec<f32> = (0..96 * 96).flat_map(|_| [c, s]).collect();
    let eb = ev::rgb_buffer(&ex);
    let exv = ev::ImageView::new(&eb, ex.width, ex.height, 3).unwrap();
    let fv = ev::FieldView::new(&field, 96, 96).unwrap();
    let gopts = ev::GuidedCoherenceOptions { stride: 4, ..Default::default() };
    let score = |im: &Image| {
        let b = ev::rgb_buffer(im);
        let v = ev::ImageView::new(&b, im.width, im.height, 3).unwrap();
        ev::guided_coherence(&v, &exv, &fv, &gopts).unwrap().mean
    };
    let (mut rot, mut plain) = (0.0, 0.0);
    for seed in 1..=3 {
        let opts = SynthesisOptions { seed, ..Default::default() };
        let a = 30f32.to_radians();
        rot += score(
            &synthesize_rotated(&analysis, &aopts, &dom, a, 1.0, &opts, &NoProgress)
                .unwrap()
                .colors,
        );
        plain += score(&synthesize(&analysis, &dom, &opts, &NoProgress).unwrap().colors);
    }
    eprintln!("guided coherence, sum of 3 seeds: pre-rotated {rot}, plain {plain}");
    assert!(rot < plain, "guided coherence pre-rotated {rot} vs plain {plain} (sum of 3 seeds)");
}

#[test]
fn zero_angle_is_the_plain_engine() {
    let (_, aopts, analysis, dom) = setup(0.0);
    let opts = SynthesisOptions { seed: 5, ..Default::default() };
    let rotated =
        synthesize_rotated(&analysis, &aopts, &dom, 0.0, 1.0, &opts, &NoProgress).unwrap();
    let plain = synthesize(&analysis, &dom, &opts, &NoProgress).unwrap();
    assert_eq!(rotated.colors, plain.colors);
    assert_eq!(rotated.coords, plain.coords);
    assert_eq!(rotated.flips, plain.flips);
}

#[test]
fn rotated_synthesis_is_deterministic_across_thread_counts() {
    let (_, aopts, analysis, dom) = setup(30.0);
    let opts = SynthesisOptions { seed: 9, ..Default::default() };
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
            synthesize_rotated(&analysis, &aopts, &dom, 0.7, 1.0, &opts, &NoProgress).unwrap()
        })
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.colors, b.colors);
    assert_eq!(a.coords, b.coords);
}
