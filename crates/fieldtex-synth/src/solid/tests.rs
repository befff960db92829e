//! On-demand determinism of the solid engine: a voxel's value does not depend on what
//! else was requested, nor on the thread count.

use super::*;
use fieldtex_core::{Image, NoProgress};

/// A 32 × 32 exemplar of noisy diagonal stripes (structured, so corrections matter).
fn exemplar() -> Image {
    let mut im = Image::new(32, 32, [0.0, 0.0, 0.0, 1.0]);
    for y in 0..32 {
        for x in 0..32 {
            let s = ((x + 2 * y) % 8) as f32 / 8.0;
            let n = fieldtex_core::rng::hash_unit(7, "test-exemplar", (y * 32 + x) as u64) as f32;
            im.set(x, y, [0.2 + 0.6 * s, 0.3 + 0.2 * n, 0.8 - 0.5 * s, 1.0]);
        }
    }
    im
}

/// A bent field: rotation about z by an angle growing along x.
struct Bent;

impl FrameSource for Bent {
    fn frame(&self, p: [f64; 3]) -> [f64; 9] {
        let a = 0.08 * p[0] + 0.03 * p[2];
        let (s, c) = a.sin_cos();
        [c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0]
    }
}

fn options() -> (SolidAnalysisOptions, SolidSynthesisOptions) {
    let a = SolidAnalysisOptions { levels: 3, pool: 256, ..Default::default() };
    let s = SolidSynthesisOptions { block: 6, passes: 2, coarse_passes: 2, ..Default::default() };
    (a, s)
}

/// The test exemplar on all three planes, the default test options and a unit lattice.
fn stripes_setup() -> (SolidExemplar, SolidSynthesisOptions, VoxelLattice) {
    let img = exemplar();
    let (ao, so) = options();
    let ex = SolidExemplar::new([&img, &img, &img], &ao, &NoProgress).unwrap();
    (ex, so, VoxelLattice { origin: [0.0; 3], spacing: 1.0 })
}

/// The `n × n` voxels of the slice z = 5, x fastest.
fn slice_z5(n: i32) -> Vec<[i32; 3]> {
    (0..n * n).map(|i| [i % n, i / n, 5]).collect()
}

fn all_voxels(n: i32) -> Vec<[i32; 3]> {
    let mut v = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                v.push([x - 3, y + 1, z - 7]);
            }
        }
    }
    v
}

#[test]
fn voxels_are_identical_alone_in_subsets_and_in_the_full_volume() {
    let (ex, so, lattice) = stripes_setup();
    let full_set = all_voxels(14);
    let mut full = SolidSynthesizer::new(&ex, lattice, &Bent, so.clone()).unwrap();
    let (full_t, stats) = full.triples(&full_set, &NoProgress);
    assert!(stats.iter().all(|s| s.corrections > 0));
    // The corrections changed something: not every voxel equals its version 0.
    let distinct: std::collections::BTreeSet<_> = full_t.iter().map(|t| t[0]).collect();
    assert!(distinct.len() > 20, "only {} distinct xy coordinates", distinct.len());
    // Random subsets, each in a fresh synthesizer, and single voxels alone.
    for trial in 0..3u64 {
        let picks: Vec<usize> = (0..25)
            .map(|i| {
                (fieldtex_core::rng::hash_unit(trial, "subset", i) * full_set.len() as f64) as usize
            })
            .collect();
        let subset: Vec<[i32; 3]> = picks.iter().map(|&i| full_set[i]).collect();
        let mut fresh = SolidSynthesizer::new(&ex, lattice, &Bent, so.clone()).unwrap();
        let (t, _) = fresh.triples(&subset, &NoProgress);
        for (k, &i) in picks.iter().enumerate() {
            assert_eq!(t[k], full_t[i], "voxel {:?} differs in a subset", full_set[i]);
        }
    }
    let mut alone = SolidSynthesizer::new(&ex, lattice, &Bent, so.clone()).unwrap();
    let (t, stats_alone) = alone.triples(&[full_set[777]], &NoProgress);
    assert_eq!(t[0], full_t[777]);
    // Alone, far fewer finest voxels were computed than for the whole volume.
    assert!(stats_alone[0].voxels < stats[0].voxels);
}

/// Per-level pass counts (`level_passes`) are used (the triples differ from the
/// default counts') and keep the on-demand equality: a few voxels alone equal the same
/// voxels of the full volume.
#[test]
fn per_level_passes_keep_the_on_demand_equality() {
    let (ex, so, lattice) = stripes_setup();
    let voxels = all_voxels(10);
    let run = |level_passes: Vec<usize>, voxels: &[[i32; 3]]| {
        let o = SolidSynthesisOptions { level_passes, ..so.clone() };
        SolidSynthesizer::new(&ex, lattice, &Bent, o).unwrap().triples(voxels, &NoProgress)
    };
    let (plain, _) = run(Vec::new(), &voxels);
    let (more, stats) = run(vec![4, 5, 6], &voxels);
    assert_ne!(plain, more, "the per-level counts changed nothing");
    assert!(stats[2].corrections > 0);
    let few = [voxels[3], voxels[500], voxels[999]];
    let (t, _) = run(vec![4, 5, 6], &few);
    assert_eq!(t, [more[3], more[500], more[999]]);
}

/// A constant field: the identity frame everywhere.
struct Axes;

impl FrameSource for Axes {
    fn frame(&self, _p: [f64; 3]) -> [f64; 9] {
        [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    }
}

/// Predictions from the neighbours' projected lattice offsets
/// (`SolidSynthesisOptions::projected_predictions`) equal the in-plane integer offsets
/// for axis-aligned frames (same triples), are used for turned ones (the triples
/// differ), and keep the on-demand equality.
#[test]
fn projected_predictions_change_only_turned_frames() {
    let (ex, so, lattice) = stripes_setup();
    let voxels = all_voxels(10);
    let run = |projected: bool, frames: &dyn FrameSource, voxels: &[[i32; 3]]| {
        let o = SolidSynthesisOptions { projected_predictions: projected, ..so.clone() };
        SolidSynthesizer::new(&ex, lattice, frames, o).unwrap().triples(voxels, &NoProgress).0
    };
    assert_eq!(run(true, &Axes, &voxels), run(false, &Axes, &voxels));
    let turned = run(true, &Bent, &voxels);
    assert_ne!(turned, run(false, &Bent, &voxels), "the projected offsets changed nothing");
    let few = [voxels[7], voxels[432], voxels[998]];
    assert_eq!(run(true, &Bent, &few), [turned[7], turned[432], turned[998]]);
}

#[test]
fn one_and_two_threads_give_the_same_voxels() {
    let img = exemplar();
    let (ao, so) = options();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let ex = SolidExemplar::new([&img, &img, &img], &ao, &NoProgress).unwrap();
            let lattice = VoxelLattice { origin: [0.5, 0.0, -2.0], spacing: 0.7 };
            let mut s = SolidSynthesizer::new(&ex, lattice, &Bent, so.clone()).unwrap();
            s.colors(&all_voxels(10), &NoProgress).0
        })
    };
    let a = run(1);
    let b = run(2);
    assert!(a.iter().zip(&b).all(|(x, y)| x.map(f32::to_bits) == y.map(f32::to_bits)));
}

#[test]
fn candidate_triples_agree_along_their_crossbars() {
    let img = exemplar();
    let (ao, _) = options();
    let ex = SolidExemplar::new([&img, &img, &img], &ao, &NoProgress).unwrap();
    let table = &ex.triples[0][0];
    // The best triple's crossbar error is no larger than a random triple's on average.
    let n = ao.neighbourhood as i32;
    let err = |t: &Triple| {
        let mut e = 0.0f32;
        for j in 0..3 {
            let k = (j + 1) % 3;
            for s in -(n / 2)..=n / 2 {
                let a = ex.color(j, 0, t[j][0], t[j][1] + s);
                let b = ex.color(k, 0, t[k][0] + s, t[k][1]);
                e += (0..3).map(|ch| (a[ch] - b[ch]).powi(2)).sum::<f32>();
            }
        }
        e
    };
    let (mut best, mut random) = (0.0, 0.0);
    for p in 0..64i32 {
        let t = *table.get(p % 32, p / 2, 0);
        assert_eq!(t[0], [p % 32, (p / 2) % 32]);
        best += err(&t);
        let q = |i: u64| {
            (fieldtex_core::rng::hash_unit(3, "rand-triple", p as u64 * 8 + i) * 32.0) as i32
        };
        random += err(&[t[0], [q(0), q(1)], [q(2), q(3)]]);
    }
    assert!(best < 0.5 * random, "best {best} vs random {random}");
    // The turned tables index their own plane.
    assert_eq!(ex.triples[0][1].get(5, 9, 0)[1], [5, 9]);
    assert_eq!(ex.triples[0][2].get(5, 9, 0)[2], [5, 9]);
}

/// The transpose of `im` (the yz exemplar a single `--exemplar` implies).
fn transpose(im: &Image) -> Image {
    let mut t = Image::new(im.height, im.width, [0.0; 4]);
    for y in 0..im.height {
        for x in 0..im.width {
            t.set(y, x, im.get(x, y));
        }
    }
    t
}

#[test]
fn partner_search_finds_exact_partners_off_the_pool_grid() {
    // xy = I, yz = Iᵀ, zx weight 0: pixel (x, y) of I has an exact partner (y, x) in Iᵀ
    // (its column equals that pixel's row). A pool of stride 4 holds only 1/16 of those
    // partners; the full-resolution refinement must find (nearly) all of them. A smooth
    // exemplar with unique sticks, so pool hits land next to the exact partner.
    let a = std::f32::consts::TAU / 32.0;
    let mut img = Image::new(32, 32, [0.0, 0.0, 0.0, 1.0]);
    for y in 0..32 {
        for x in 0..32 {
            let (xf, yf) = (x as f32, y as f32);
            let r = 0.5 + 0.35 * (a * xf).sin();
            let g = 0.5 + 0.35 * (a * yf + 0.7).sin();
            let b = 0.5 + 0.35 * (a * (xf + yf)).cos();
            img.set(x, y, [r, g, b, 1.0]);
        }
    }
    let tr = transpose(&img);
    let ao = SolidAnalysisOptions {
        levels: 1,
        pool: 64,
        plane_weights: [1.0, 1.0, 0.0],
        ..Default::default()
    };
    let ex = SolidExemplar::new([&img, &tr, &img], &ao, &NoProgress).unwrap();
    let table = &ex.triples[0][0];
    let mut exact = 0;
    for y in 0..32 {
        for x in 0..32 {
            exact += (table.get(x, y, 0)[1] == [y, x]) as usize;
        }
    }
    assert!(exact >= 1024 * 9 / 10, "{exact} of 1024 pixels have their exact partner");
}

/// A 64 × 64 running-bond brick exemplar whose mortar is hard to see in RGB (bricks of
/// per-brick greys around the mortar's grey, strong per-pixel noise), and its feature
/// mask (1 on the mortar, 0 on the bricks): bricks 16 × 8 with 2-pixel joints.
fn bricks() -> (Image, Image) {
    let mut im = Image::new(64, 64, [0.0, 0.0, 0.0, 1.0]);
    let mut mask = Image::new(64, 64, [0.0, 0.0, 0.0, 1.0]);
    for y in 0..64usize {
        for x in 0..64usize {
            let row = y / 8;
            let shift = if row % 2 == 1 { 8 } else { 0 };
            let bx = (x + shift) % 64 / 16;
            let mortar = y % 8 < 2 || (x + shift) % 16 < 2;
            let n = fieldtex_core::rng::hash_unit(11, "brick-noise", (y * 64 + x) as u64) as f32;
            let b = fieldtex_core::rng::hash_unit(11, "brick-tone", (row * 4 + bx) as u64) as f32;
            let base = if mortar { 0.5 } else { 0.38 + 0.24 * b };
            let v = base + 0.3 * (n - 0.5);
            im.set(x, y, [v, v * 0.95, v * 0.9, 1.0]);
            let m = if mortar { 1.0 } else { 0.0 };
            mask.set(x, y, [m, m, m, 1.0]);
        }
    }
    (im, mask)
}

/// Share of the mortar pixels (mask ≥ 0.5) of a `w × h` mask image that lie in its
/// largest 4-connected mortar component: 1 for an unbroken mortar network.
fn mortar_connectivity(mask: &[f32], w: usize, h: usize) -> f64 {
    let mut label = vec![usize::MAX; w * h];
    let (mut total, mut largest) = (0usize, 0usize);
    for start in 0..w * h {
        if mask[start] < 0.5 || label[start] != usize::MAX {
            continue;
        }
        let mut stack = vec![start];
        label[start] = start;
        let mut size = 0;
        while let Some(i) = stack.pop() {
            size += 1;
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            for (nx, ny) in [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)] {
                if nx < 0 || ny < 0 || nx >= w as isize || ny >= h as isize {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if mask[j] >= 0.5 && label[j] == usize::MAX {
                    label[j] = start;
                    stack.push(j);
                }
            }
        }
        total += size;
        largest = largest.max(size);
    }
    if total == 0 { 0.0 } else { largest as f64 / total as f64 }
}

#[test]
fn the_feature_channel_keeps_the_mortar_connected() {
    // Paper E §4: for a regular exemplar the feature mask, matched as a fourth channel,
    // keeps the feature curves (mortar) continuous where RGB alone loses them. An xy
    // slice of a constant-field solid; the mortar it shows is the mask at each voxel's
    // final triple (plane-weighted like its colour).
    let (img, mask) = bricks();
    let (ti, tm) = (transpose(&img), transpose(&mask));
    let ao = SolidAnalysisOptions {
        levels: 3,
        pool: 256,
        plane_weights: [1.0, 1.0, 0.0],
        ..Default::default()
    };
    let so = SolidSynthesisOptions { block: 8, passes: 2, coarse_passes: 3, ..Default::default() };
    let identity = ConstantFrame([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    let lattice = VoxelLattice { origin: [0.0; 3], spacing: 1.0 };
    let side = 48usize;
    let slice: Vec<[i32; 3]> =
        (0..side * side).map(|i| [(i % side) as i32, (i / side) as i32, 5]).collect();
    let shown_mortar = |ex: &SolidExemplar, masked: &SolidExemplar| {
        let mut synth = SolidSynthesizer::new(ex, lattice, &identity, so.clone()).unwrap();
        let (t, _) = synth.triples(&slice, &NoProgress);
        // Mortar shown at each voxel: the plane-weighted mask at its triple (read from
        // the masked analysis's matched channel, whose planes index the same pixels).
        t.iter()
            .map(|t| {
                (masked.matched(0, 0, t[0][0], t[0][1])[3]
                    + masked.matched(1, 0, t[1][0], t[1][1])[3])
                    / 2.0
            })
            .collect::<Vec<f32>>()
    };
    let plain = SolidExemplar::new([&img, &ti, &img], &ao, &NoProgress).unwrap();
    let masked = SolidExemplar::with_features(
        [&img, &ti, &img],
        [Some(&mask), Some(&tm), Some(&mask)],
        &ao,
        &NoProgress,
    )
    .unwrap();
    assert_eq!((plain.channels(), masked.channels()), (3, 4));
    let without = mortar_connectivity(&shown_mortar(&plain, &masked), side, side);
    let with = mortar_connectivity(&shown_mortar(&masked, &masked), side, side);
    let exemplar: Vec<f32> = mask.pixels.iter().map(|p| p[0]).collect();
    assert_eq!(mortar_connectivity(&exemplar, 64, 64), 1.0);
    eprintln!("mortar in the largest component: with the channel {with:.3}, without {without:.3}");
    assert!(
        with > without + 0.1 && with > 0.8,
        "mortar in the largest component: {with:.3} with the feature channel, {without:.3} without"
    );
}

#[test]
fn feature_masks_are_all_or_none_and_exemplar_sized() {
    let (img, mask) = bricks();
    let ao = SolidAnalysisOptions { levels: 2, pool: 64, ..Default::default() };
    let some = SolidExemplar::with_features(
        [&img, &img, &img],
        [Some(&mask), None, Some(&mask)],
        &ao,
        &NoProgress,
    );
    assert!(matches!(some, Err(crate::SynthError::InvalidOption { .. })));
    let small = Image::new(32, 64, [1.0; 4]);
    let wrong = SolidExemplar::with_features(
        [&img, &img, &img],
        [Some(&small), Some(&small), Some(&small)],
        &ao,
        &NoProgress,
    );
    assert!(matches!(wrong, Err(crate::SynthError::FeatureMaskSize { plane: "xy", .. })));
}

/// The integrated initialisation (opt-in) changes the triples of a bent field and keeps
/// the on-demand equality: a few voxels alone equal the same voxels of the full volume
/// (all voxels here lie at negative and positive lattice indices, inside and outside
/// the grid the coordinates were integrated over).
#[test]
fn integrated_initialisation_keeps_the_on_demand_equality() {
    let (ex, so, lattice) = stripes_setup();
    let voxels = all_voxels(10);
    let run = |integrated_init: bool, voxels: &[[i32; 3]]| {
        let o = SolidSynthesisOptions { integrated_init, ..so.clone() };
        SolidSynthesizer::new(&ex, lattice, &Bent, o)
            .unwrap()
            .with_extent([12, 12, 12])
            .triples(voxels, &NoProgress)
            .0
    };
    let plain = run(false, &voxels);
    let integrated = run(true, &voxels);
    assert_ne!(plain, integrated, "the integrated initialisation changed nothing");
    for i in [0, 137, 512, voxels.len() - 1] {
        assert_eq!(run(true, &voxels[i..i + 1])[0], integrated[i], "voxel {:?}", voxels[i]);
    }
}

/// With the integrated start the xy coordinates of neighbouring voxels follow the bent
/// field's step (one warp) far more often than from the default slabs.
#[test]
fn integrated_start_follows_a_bent_field() {
    let (ex, so, lattice) = stripes_setup();
    let n = 24;
    let slice = slice_z5(n);
    let share = |integrated_init: bool| {
        let o = SolidSynthesisOptions { integrated_init, ..so.clone() };
        let t = SolidSynthesizer::new(&ex, lattice, &Bent, o)
            .unwrap()
            .with_extent([n as usize, n as usize, 12])
            .triples(&slice, &NoProgress)
            .0;
        let mut ok = 0;
        for y in 0..n {
            for x in 0..n - 1 {
                let (a, b) = (t[(y * n + x) as usize][0], t[(y * n + x + 1) as usize][0]);
                let r = Bent.frame(lattice.centre(0, [x, y, 5]));
                // One voxel along world x moves the local coordinates by Rᵀ e_x.
                let wrap = |d: i32| (d + 16).rem_euclid(32) - 16;
                let e = [wrap(b[0] - a[0]) as f64 - r[0], wrap(b[1] - a[1]) as f64 - r[1]];
                ok += (e[0].hypot(e[1]) <= 1.0) as usize;
            }
        }
        ok as f64 / (n * (n - 1)) as f64
    };
    let (plain, integrated) = (share(false), share(true));
    eprintln!("coherent steps: default {plain:.3}, integrated {integrated:.3}");
    assert!(integrated > plain + 0.1, "default {plain:.3}, integrated {integrated:.3}");
}

/// The uncorrected integrated start reads its colours at the warp's sub-pixel position:
/// on a constant frame that is every triple's own pixels (the warp's constant is
/// rounded away), on a bent field the colours step less between neighbours than the
/// whole-pixel colours of the same triples (the staircase of a rounded warp is gone).
#[test]
fn integrated_colours_follow_the_warp_below_a_pixel() {
    let (ex, so, lattice) = stripes_setup();
    let n = 24;
    let slice = slice_z5(n);
    let o = SolidSynthesisOptions { integrated_init: true, ..so };
    let run = |frames: &dyn FrameSource| {
        let mut s = SolidSynthesizer::new(&ex, lattice, frames, o.clone())
            .unwrap()
            .with_extent([n as usize, n as usize, 12]);
        let (colours, stats) = s.colors(&slice, &NoProgress);
        assert!(stats.iter().all(|l| l.corrections == 0), "the integrated start was corrected");
        let whole: Vec<[f32; 3]> =
            s.triples(&slice, &NoProgress).0.iter().map(|t| s.triple_color(0, t)).collect();
        (colours, whole)
    };
    let (colours, whole) = run(&ConstantFrame([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]));
    assert_eq!(colours, whole, "a constant frame reads whole pixels");
    let (colours, whole) = run(&Bent);
    let moved = colours.iter().zip(&whole).filter(|(a, b)| a != b).count();
    assert!(moved * 2 > colours.len(), "{moved} of {} colours read between pixels", colours.len());
    let step = |c: &[[f32; 3]]| {
        let mut sum = 0.0f64;
        for y in 0..n {
            for x in 0..n - 1 {
                let (a, b) = (c[(y * n + x) as usize], c[(y * n + x + 1) as usize]);
                sum += (0..3).map(|k| (a[k] - b[k]).abs() as f64).sum::<f64>();
            }
        }
        sum / (n * (n - 1)) as f64
    };
    let (sub, px) = (step(&colours), step(&whole));
    eprintln!("mean neighbour step: sub-pixel {sub:.4}, whole pixels {px:.4}");
    assert!(sub < 0.95 * px, "sub-pixel {sub:.4}, whole pixels {px:.4}");
}
