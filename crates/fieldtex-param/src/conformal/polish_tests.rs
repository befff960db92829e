//! Tests of the conformal polish of slit cylinders and patch layouts and of the seam
//! feathering of geometry images (session 16).

use super::conformal_polish::PolishOptions;
use super::*;
use fieldtex_core::NoProgress;
use fieldtex_mesh::primitives;

/// A coarse lumpy sphere (icosphere level 2, radius `1 + 0.25 sin 3x sin 2y sin 2z`):
/// its slit cylinder is visibly non-conformal per triangle.
fn lumpy_sphere() -> fieldtex_mesh::TriMesh {
    let mut mesh = primitives::icosphere(2);
    for p in &mut mesh.positions {
        let r = 1.0 + 0.25 * (3.0 * p[0]).sin() * (2.0 * p[1]).sin() * (2.0 * p[2]).sin();
        *p = p.map(|x| x * r);
    }
    mesh
}

fn away(c: &ConformalComponent) -> f64 {
    let near = c.near_singularity.clone();
    mass_spring::map_distortion(&c.local_mesh, c.faces.len(), &c.corner_uv, &|f| near[f]).angle_mean
}

#[test]
fn polish_lowers_the_angle_distortion_of_a_coarse_cylinder_without_flips() {
    let (comps, _) = global_conformal(&lumpy_sphere(), &NoProgress).unwrap();
    let mut c = comps[0].clone();
    assert_eq!(c.method, ConformalMethod::SlitCylinder);
    let before = away(&c);
    let area_before: f64 = c.corner_uv.iter().map(periodic_uv::signed_area).sum();
    let options = PolishOptions { above: 1.0, ..Default::default() };
    let stats = c.polish_conformal(&options).expect("a cylinder is polished");
    assert!(stats.applied, "{stats:?}");
    assert_eq!(stats.charts, 1);
    assert!((stats.away_before - before).abs() < 1e-12);
    let after = away(&c);
    assert!((stats.away_after - after).abs() < 1e-12);
    assert!(after < before - 0.005, "σ1/σ2 away from singularities {before} → {after}");
    assert_eq!(tests::distortion(&c).flipped, 0);
    // The cylinder is one chart now: no period, its seam drawn by similarity ghosts, and
    // its size kept by the similarity fit.
    assert!(c.lattice.a.is_none() && c.lattice.b.is_none());
    assert!(!c.map.ghosts.is_empty() && c.map.ghosts.iter().all(|g| g.corners.is_some()));
    let area_after: f64 = c.corner_uv.iter().map(periodic_uv::signed_area).sum();
    assert!((area_after / area_before - 1.0).abs() < 0.1, "{area_before} → {area_after}");
    // The geometry image of the polished map links its margins across the old seam.
    assert!(GeometryImage::new(&c, 128).margin_copies.len() > 50);
}

#[test]
fn polish_leaves_maps_within_the_threshold_alone() {
    let (comps, _) = global_conformal(&lumpy_sphere(), &NoProgress).unwrap();
    let mut c = comps[0].clone();
    let options = PolishOptions { above: 10.0, ..Default::default() };
    let stats = c.polish_conformal(&options).unwrap();
    assert!(!stats.applied && stats.charts == 0);
    assert_eq!(c.corner_uv, comps[0].corner_uv);
    assert_eq!(c.lattice, comps[0].lattice);
    // The torus image is never polished (its seams are periods).
    let torus = primitives::torus(1.0, 0.3, 24, 12);
    let (comps, _) = global_conformal(&torus, &NoProgress).unwrap();
    let mut t = comps[0].clone();
    assert!(t.polish_conformal(&PolishOptions { above: 1.0, ..Default::default() }).is_none());
}

#[test]
fn polished_patch_layouts_are_the_same_for_one_and_two_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let (comps, _) = global_conformal(&tests::genus_two_slab(6), &NoProgress).unwrap();
            let mut c = comps[0].clone();
            let stats = c.polish_conformal(&PolishOptions { above: 1.0, ..Default::default() });
            (stats, c.corner_uv, c.map.ghosts.len())
        })
    };
    let (a, b) = (run(1), run(2));
    let stats = a.0.expect("a patch layout is polished");
    assert!(stats.charts >= 1);
    assert_eq!(stats.after.flipped, 0);
    assert!(stats.away_after <= stats.away_before);
    assert_eq!(a.0, b.0);
    assert_eq!(a.1, b.1);
    assert_eq!(a.2, b.2);
}

#[test]
fn feathering_closes_the_colour_steps_across_cuts_and_leaves_the_rest() {
    let (comps, _) = global_conformal(&tests::genus_two_slab(6), &NoProgress).unwrap();
    let img = GeometryImage::new(&comps[0], 256);
    assert!(!img.margin_copies.is_empty());
    // Each real texel a colour of its own (a hash), the margins copied: the two sides of
    // every cut differ.
    let n = img.width * img.height;
    let mut px: Vec<[f32; 4]> = (0..n)
        .map(|i| {
            let h = fieldtex_core::rng::hash_unit(7, "feather-test", i as u64) as f32;
            [h, 1.0 - h, 0.5 * h, 1.0]
        })
        .collect();
    img.copy_margins(&mut px);
    let before = px.clone();
    let mut margin = vec![false; n];
    for &(g, _, _) in &img.margin_copies {
        margin[g as usize] = true;
    }
    let real = |i: usize| !img.tau[i].is_nan() && !margin[i];
    // Pairs of real texels that are neighbours across a cut.
    let w = img.width;
    let mut across = Vec::new();
    for &(g, r, _) in &img.margin_copies {
        let g = g as usize;
        for a in [g.wrapping_sub(1), g + 1, g.wrapping_sub(w), g + w] {
            if a < n && real(a) && a != r as usize {
                across.push((a, r as usize));
            }
        }
    }
    let step = |p: &[[f32; 4]]| {
        across.iter().map(|&(a, b)| (p[a][0] - p[b][0]).abs() as f64).sum::<f64>()
            / across.len() as f64
    };
    let pairs = img.feather_seams(&mut px, 4);
    assert!(pairs >= across.len());
    assert!(step(&px) < 0.6 * step(&before), "{} → {}", step(&before), step(&px));
    // Texels farther than the band from every cut keep their colour; margins still match.
    let mut near = vec![false; n];
    for &(a, b) in &across {
        for t in [a, b] {
            let (x, y) = ((t % w) as i64, (t / w) as i64);
            for dy in -6i64..=6 {
                for dx in -6i64..=6 {
                    let (u, v) = (x + dx, y + dy);
                    if u >= 0 && v >= 0 && (u as usize) < w && (v as usize) < img.height {
                        near[v as usize * w + u as usize] = true;
                    }
                }
            }
        }
    }
    for &(a, b) in &img.seam_pairs {
        near[a as usize] = true;
        near[b as usize] = true;
    }
    let far = (0..n).filter(|&i| real(i) && !near[i]).collect::<Vec<_>>();
    assert!(!far.is_empty());
    assert!(far.iter().all(|&i| px[i] == before[i]));
    assert!(img.margin_copies.iter().all(|&(g, r, _)| px[g as usize] == px[r as usize]));
}
