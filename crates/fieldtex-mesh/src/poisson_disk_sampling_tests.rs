//! Poisson-disk sampling tests: true minimum distance (checked with an independent grid
//! hash), coverage, determinism, target counts and bad input.

use super::*;
use crate::primitives::{grid, icosphere};
use crate::test_meshes::categories_and;

/// The smallest pairwise distance below `r` (else infinity), through the static
/// [`crate::SpatialGrid`] (not the incremental grid the sampler uses).
fn min_distance(points: &[V3], r: f64) -> f64 {
    let grid = crate::SpatialGrid::new(points, r);
    let mut best = f64::INFINITY;
    for (i, p) in points.iter().enumerate() {
        grid.for_each_within(points, *p, r, |j, d2| {
            if j as usize != i {
                best = best.min(d2.sqrt());
            }
        });
    }
    best
}

fn check(name: &str, mesh: &TriMesh, s: &PoissonDiskSamples) {
    let pts: Vec<V3> = s.samples.iter().map(|x| x.position).collect();
    if pts.len() > 1 {
        let d = min_distance(&pts, s.radius);
        assert!(d >= s.radius, "{name}: two samples {d} apart, radius {}", s.radius);
    }
    for x in &s.samples {
        let t = mesh.triangle_positions(x.triangle as usize);
        let b = x.barycentric;
        assert!(
            b.iter().all(|v| (0.0..=1.0).contains(v))
                && (b.iter().sum::<f64>() - 1.0).abs() < 1e-12
        );
        let q = (0..3).fold([0.0; 3], |a, k| vec3::add(a, vec3::scale(t[k], b[k])));
        assert!(vec3::norm(vec3::sub(q, x.position)) < 1e-12, "{name}");
    }
}

#[test]
fn minimum_distance_holds_over_categories_and_fixtures() {
    let all =
        categories_and(&["stanford-bunny.obj", "fertility.obj", "defects/narrow_triangles.obj"]);
    for (name, m) in &all {
        // About 1750 samples whatever the size (the defective patch's needle is huge).
        let r = 0.02 * crate::areas::total_area(m).sqrt();
        let opts = PoissonDiskOptions { radius: Some(r), seed: 3, ..Default::default() };
        let (s, _) = poisson_disk_sampling(m, &opts).unwrap();
        assert!(s.samples.len() > 50, "{name}: {}", s.samples.len());
        check(name, m, &s);
    }
}

#[test]
fn sphere_samples_cover_the_surface() {
    let m = icosphere(4);
    let r = 0.05;
    let opts = PoissonDiskOptions { radius: Some(r), ..Default::default() };
    let (s, w) = poisson_disk_sampling(&m, &opts).unwrap();
    assert!(w.is_empty());
    check("sphere", &m, &s);
    // Near-maximal: a maximal set on the unit sphere has roughly 0.7 · 4π / r² samples.
    let n = s.samples.len() as f64;
    let expect = 0.7 * 4.0 * std::f64::consts::PI / (r * r);
    assert!(n > 0.8 * expect && n < 1.2 * expect, "{n} vs {expect}");
    // Every vertex of the sphere mesh has a sample within 2r.
    let bvh_free: Vec<V3> = s.samples.iter().map(|x| x.position).collect();
    let far = m
        .positions
        .iter()
        .filter(|p| bvh_free.iter().all(|q| vec3::norm(vec3::sub(**p, *q)) >= 2.0 * r))
        .count();
    assert!(far * 200 < m.n_vertices(), "{far} uncovered vertices");
}

#[test]
fn deterministic_for_any_thread_count_and_seed_dependent() {
    let m = crate::test_meshes::two_components();
    let opts = PoissonDiskOptions { radius: Some(0.1), seed: 11, ..Default::default() };
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| poisson_disk_sampling(&m, &opts).unwrap().0)
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a, b);
    let other = poisson_disk_sampling(&m, &PoissonDiskOptions { seed: 12, ..opts }).unwrap().0;
    assert_ne!(a.samples, other.samples);
}

#[test]
fn target_count_is_approached() {
    let m = grid(20, 20, 2.0, 1.0);
    for target in [200, 1500] {
        let opts = PoissonDiskOptions { target_count: Some(target), ..Default::default() };
        let (s, _) = poisson_disk_sampling(&m, &opts).unwrap();
        let n = s.samples.len() as f64;
        assert!((n / target as f64 - 1.0).abs() < 0.05, "{n} for {target}");
        check("grid", &m, &s);
    }
}

#[test]
fn bad_options_and_arealess_meshes() {
    let m = icosphere(1);
    for bad in [Some(0.0), Some(-1.0), Some(f64::NAN), Some(f64::INFINITY)] {
        let o = PoissonDiskOptions { radius: bad, ..Default::default() };
        assert!(poisson_disk_sampling(&m, &o).is_err());
    }
    assert!(poisson_disk_sampling(&m, &PoissonDiskOptions::default()).is_err());
    let flat = TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], vec![[0, 1, 2]]);
    let (s, w) = poisson_disk_sampling(
        &flat,
        &PoissonDiskOptions { radius: Some(0.1), ..Default::default() },
    )
    .unwrap();
    assert!(s.samples.is_empty());
    assert_eq!(w[0].code, "sampling-no-area");
    // A radius far too small is capped, not a hang or an allocation failure.
    let o =
        PoissonDiskOptions { radius: Some(1e-6), max_candidates: 100_000, ..Default::default() };
    let (s, w) = poisson_disk_sampling(&m, &o).unwrap();
    assert!(w.iter().any(|w| w.code == "sampling-candidates-capped"));
    check("capped", &m, &s);
}

#[test]
fn nested_levels_are_prefixes_and_keep_their_radius() {
    let m = icosphere(3);
    let radii = [0.4, 0.2, 0.1];
    let (levels, w) =
        poisson_disk_sampling_nested(&m, &radii, &PoissonDiskOptions::default()).unwrap();
    assert!(w.is_empty(), "{w:?}");
    assert_eq!(levels.len(), 3);
    for k in 0..3 {
        check("nested", &m, &levels[k]);
        assert_eq!(levels[k].radius, radii[k]);
        if k > 0 {
            let (prev, cur) = (&levels[k - 1].samples, &levels[k].samples);
            assert!(cur.len() > 2 * prev.len(), "{} vs {}", cur.len(), prev.len());
            assert_eq!(&cur[..prev.len()], &prev[..]);
        }
    }
    // The coarsest level is the single-radius sampling with the same seed.
    let opts = PoissonDiskOptions { radius: Some(0.4), ..Default::default() };
    assert_eq!(poisson_disk_sampling(&m, &opts).unwrap().0.samples, levels[0].samples);
    let bad = poisson_disk_sampling_nested(&m, &[0.1, 0.2], &PoissonDiskOptions::default());
    assert!(bad.is_err());
}
