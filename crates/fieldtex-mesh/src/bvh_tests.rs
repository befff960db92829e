//! BVH tests against brute force.

use super::*;
use crate::primitives::{icosphere, torus};
use crate::test_meshes::{categories, load_obj};
use fieldtex_core::rng::hash_unit;

fn brute_hit(mesh: &TriMesh, o: V3, d: V3, tmax: f64) -> Option<(u32, f64)> {
    let mut best: Option<(u32, f64)> = None;
    for (f, t) in mesh.triangles.iter().enumerate() {
        let c = t.map(|i| mesh.positions[i as usize]);
        let e1 = vec3::sub(c[1], c[0]);
        let e2 = vec3::sub(c[2], c[0]);
        let pv = vec3::cross(d, e2);
        let det = vec3::dot(e1, pv);
        if det.abs() < 1e-14 {
            continue;
        }
        let tv = vec3::sub(o, c[0]);
        let u = vec3::dot(tv, pv) / det;
        let qv = vec3::cross(tv, e1);
        let v = vec3::dot(d, qv) / det;
        let tt = vec3::dot(e2, qv) / det;
        if u >= 0.0
            && v >= 0.0
            && u + v <= 1.0
            && tt >= 0.0
            && tt <= tmax
            && best.is_none_or(|b| tt < b.1)
        {
            best = Some((f as u32, tt));
        }
    }
    best
}

fn random_unit(seed: u64, i: u64) -> V3 {
    let z = 2.0 * hash_unit(seed, "bvh-test-z", i) - 1.0;
    let a = 2.0 * std::f64::consts::PI * hash_unit(seed, "bvh-test-a", i);
    let r = (1.0 - z * z).sqrt();
    [r * a.cos(), r * a.sin(), z]
}

/// Rays from a sphere of radius 3 around the mesh towards random inner points.
/// `intersect_many` and `occluded_many` of `rays` in a pool of `threads` threads.
fn batches_on(bvh: &Bvh, rays: &[Ray], threads: usize) -> (Vec<Option<Hit>>, Vec<bool>) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| (bvh.intersect_many(rays), bvh.occluded_many(rays)))
}

fn rays(mesh: &TriMesh, n: u64) -> Vec<Ray> {
    let bb = mesh.bounding_box().unwrap();
    let (c, r) = (bb.center(), bb.diagonal());
    (0..n)
        .map(|i| {
            let o = vec3::add(c, vec3::scale(random_unit(1, i), 1.5 * r));
            let target = vec3::add(c, vec3::scale(random_unit(2, i), 0.3 * r));
            Ray::new(o, vec3::sub(target, o))
        })
        .collect()
}

#[test]
fn closest_hits_match_brute_force() {
    let mut meshes = vec![icosphere(3), torus(2.0, 0.7, 40, 16)];
    meshes.extend(load_obj("fandisk.obj"));
    for m in &meshes {
        let bvh = Bvh::build(m).unwrap();
        let rs = rays(m, 300);
        let hits = bvh.intersect_many(&rs);
        let mut n_hits = 0;
        for (r, h) in rs.iter().zip(&hits) {
            let bf = brute_hit(m, r.origin, r.dir, f64::INFINITY);
            match (h, bf) {
                (Some(h), Some((_, t))) => {
                    n_hits += 1;
                    assert!((h.t - t).abs() < 1e-6 * t.max(1.0), "t {} vs {t}", h.t);
                    let c = m.triangle_positions(h.triangle as usize);
                    let p: V3 = (0..3).fold([0.0; 3], |acc, k| {
                        vec3::add(acc, vec3::scale(c[k], h.barycentric[k]))
                    });
                    let q = vec3::add(r.origin, vec3::scale(r.dir, h.t));
                    assert!(vec3::norm(vec3::sub(p, q)) < 1e-6 * vec3::norm(r.dir) * h.t.max(1.0));
                }
                (None, None) => {}
                (h, bf) => panic!("bvh {h:?} vs brute force {bf:?}"),
            }
            assert_eq!(h.is_some(), bvh.occluded(r));
        }
        assert!(n_hits > 100);
    }
}

#[test]
fn ranges_inside_rays_and_bad_queries() {
    let m = icosphere(3);
    let bvh = Bvh::build(&m).unwrap();
    // From the centre every direction hits the sphere near t = 1 (back faces count).
    let h = bvh.closest_hit([0.0; 3], [0.3, -0.2, 0.9], f64::INFINITY).unwrap();
    let len = vec3::norm([0.3, -0.2, 0.9]);
    assert!((h.t * len - 1.0).abs() < 0.02);
    assert!(bvh.closest_hit([0.0; 3], [0.3, -0.2, 0.9], 0.5 / len).is_none());
    assert!(!bvh.any_hit([0.0; 3], [0.3, -0.2, 0.9], 0.5 / len));
    assert!(bvh.any_hit([0.0; 3], [0.3, -0.2, 0.9], 2.0 / len));
    // tmin skips the first surface: from outside, tmin past the near side hits the far side.
    // Along the z axis, through vertices (0, 0, ±1) of the icosphere: watertight.
    let r = Ray::new([0.0, 0.0, 5.0], [0.0, 0.0, -1.0]);
    let near = bvh.intersect(&r).unwrap();
    let far = bvh.intersect(&r.with_range(near.t + 0.1, f64::INFINITY)).unwrap();
    assert!((near.t - 4.0).abs() < 0.02 && (far.t - 6.0).abs() < 0.02);
    // Degenerate queries.
    assert!(bvh.closest_hit([0.0; 3], [0.0; 3], 1.0).is_none());
    assert!(bvh.closest_hit([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], 1.0).is_none());
    assert!(bvh.closest_point([f64::INFINITY, 0.0, 0.0]).is_none());
    let empty = Bvh::build(&TriMesh::default()).unwrap();
    assert!(empty.closest_hit([0.0; 3], [1.0, 0.0, 0.0], 1.0).is_none());
    assert!(empty.closest_point([0.0; 3]).is_none());
}

#[test]
fn closest_points_match_brute_force_over_categories() {
    let mut all = categories();
    all.extend(load_obj("defects/narrow_triangles.obj").map(|m| ("narrow", m)));
    for (name, m) in &all {
        let bvh = Bvh::build(m).unwrap();
        let bb = m.bounding_box().unwrap();
        let (c, r) = (bb.center(), bb.diagonal().min(10.0));
        for i in 0..100u64 {
            let p = vec3::add(c, vec3::scale(random_unit(3, i), r * hash_unit(4, "len", i)));
            let got = bvh.closest_point(p).unwrap();
            let mut best = f64::INFINITY;
            for f in 0..m.n_triangles() {
                let (q, _) = closest_point_on_triangle(p, m.triangle_positions(f));
                best = best.min(vec3::norm(vec3::sub(q, p)));
            }
            assert!(
                (got.distance - best).abs() <= 1e-9 * (1.0 + best),
                "{name}: {got:?} vs {best}"
            );
            let t = m.triangle_positions(got.triangle as usize);
            let q: V3 =
                (0..3).fold([0.0; 3], |a, k| vec3::add(a, vec3::scale(t[k], got.barycentric[k])));
            assert!(vec3::norm(vec3::sub(q, got.point)) < 1e-9 * (1.0 + r), "{name}");
        }
    }
}

#[test]
fn far_from_origin_and_deterministic() {
    let mut m = torus(2.0, 0.7, 40, 16);
    for p in &mut m.positions {
        *p = vec3::add(*p, [1.0e6, -2.0e6, 3.0e5]);
    }
    let bvh = Bvh::build(&m).unwrap();
    let rs = rays(&m, 200);
    for r in &rs {
        let bf = brute_hit(&m, r.origin, r.dir, f64::INFINITY);
        let h = bvh.intersect(r);
        assert_eq!(h.is_some(), bf.is_some());
        if let (Some(h), Some((_, t))) = (h, bf) {
            assert!((h.t - t).abs() < 1e-9 * vec3::norm(r.dir).recip() + 1e-7);
        }
    }
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| Bvh::build(&m).unwrap().intersect_many(&rs))
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn non_finite_triangles_are_skipped() {
    let mut m = icosphere(2);
    m.positions[0] = [f64::NAN, 0.0, 0.0];
    let bvh = Bvh::build(&m).unwrap();
    assert_eq!(bvh.n_skipped(), m.triangles.iter().filter(|t| t.contains(&0)).count());
    assert!(bvh.closest_hit([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], f64::INFINITY).is_some());
    assert!(bvh.closest_point([0.0, 0.0, 5.0]).is_some());
    let mut bad = m.clone();
    bad.triangles.push([0, 1, 1000]);
    assert!(Bvh::build(&bad).is_err());
}

#[test]
fn watertight_on_shared_edges_and_vertices() {
    // A flat grid hit exactly through its inner vertices and edge midpoints: never a
    // miss (the outermost boundary is excluded: see the module docs).
    let m = crate::primitives::grid(8, 8, 1.0, 1.0);
    let bvh = Bvh::build(&m).unwrap();
    let mut n = 0;
    for i in 1..16 {
        for j in 1..16 {
            let (x, y) = (i as f64 / 16.0, j as f64 / 16.0);
            let h = bvh.closest_hit([x, y, 1.0], [0.0, 0.0, -1.0], f64::INFINITY);
            assert!(h.is_some_and(|h| (h.t - 1.0).abs() < 1e-12), "miss at ({x}, {y})");
            assert!(bvh.any_hit([x, y, 1.0], [0.0, 0.0, -1.0], 2.0));
            n += 1;
        }
    }
    assert_eq!(n, 225);
}

#[test]
fn batches_in_coherent_order_match_single_queries() {
    // Large enough to take the sorted path of `bvh_ray_order`, with odd rays mixed in.
    let m = torus(2.0, 0.7, 40, 16);
    let bvh = Bvh::build(&m).unwrap();
    let mut rs = rays(&m, 12_000);
    for (i, r) in rs.iter_mut().enumerate().step_by(97) {
        match i % 6 {
            0 => r.dir = [0.0; 3],
            1 => r.origin[1] = f64::NAN,
            2 => *r = r.with_range(5.0, 1.0),
            3 => r.origin = [0.1, 2.0, 0.05], // inside the box
            4 => r.dir = [0.0, 0.0, -1.0],    // axis-parallel
            _ => r.dir = [f64::INFINITY, 0.0, 0.0],
        }
    }
    let run = |threads| batches_on(&bvh, &rs, threads);
    let (hits, occ) = run(2);
    assert_eq!((hits.clone(), occ.clone()), run(1));
    let mut n_hits = 0;
    for (i, r) in rs.iter().enumerate() {
        assert_eq!(hits[i], bvh.intersect(r), "ray {i}");
        assert_eq!(occ[i], bvh.occluded(r), "ray {i}");
        n_hits += usize::from(occ[i]);
    }
    assert!(n_hits > 3000 && n_hits < 11_000, "{n_hits}");
}

#[test]
fn rays_aimed_at_vertices_and_edge_midpoints_never_miss() {
    // Every ray coming from the outside, roughly along the normal, aimed exactly at a
    // vertex or an edge midpoint of a closed mesh hits at or before it: no slipping
    // through shared corners and edges. (Grazing silhouette rays may rightly miss.)
    let meshes = [(torus(2.0, 0.7, 24, 12), 2.0), (icosphere(2), 0.0)];
    for (m, ring) in meshes {
        let bvh = Bvh::build(&m).unwrap();
        // Outward normal of the torus with this ring radius (or of the unit sphere).
        let normal = |p: V3| {
            let r = (p[0] * p[0] + p[1] * p[1]).sqrt().max(1e-12);
            let c = [p[0] * ring / r, p[1] * ring / r, 0.0];
            vec3::normalize(vec3::sub(p, c)).unwrap()
        };
        let mut targets: Vec<V3> = m.positions.clone();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (m.positions[t[k] as usize], m.positions[t[(k + 1) % 3] as usize]);
                targets.push(vec3::scale(vec3::add(a, b), 0.5));
            }
        }
        for (i, &p) in targets.iter().enumerate() {
            let off = vec3::add(normal(p), vec3::scale(random_unit(5, i as u64), 0.4));
            let o = vec3::add(p, off);
            let d = vec3::sub(p, o);
            let h = bvh.closest_hit(o, d, f64::INFINITY);
            assert!(h.is_some_and(|h| h.t <= 1.0 + 1e-6), "target {i} {p:?}: {h:?}");
            assert!(bvh.any_hit(o, d, 1.0 + 1e-6), "target {i}");
        }
    }
}

#[test]
fn random_rays_with_ranges_and_duplicates_match_brute_force() {
    // Every triangle twice (same corners): hits must go to the lower index. Random
    // ranges, axis-parallel directions (zero components) and tiny or huge direction
    // lengths; batches must equal single queries for 1 and 2 threads.
    let orig = torus(2.0, 0.7, 30, 12);
    let n = orig.triangles.len() as u32;
    let mut m = orig.clone();
    let scale = |i: u64| if i.is_multiple_of(2) { 1e-35 } else { 1e35 };
    let dup: Vec<[u32; 3]> = m.triangles.clone();
    m.triangles.extend(dup);
    let bvh = Bvh::build(&m).unwrap();
    let mut rs = rays(&m, 9000);
    for (i, r) in rs.iter_mut().enumerate() {
        let i = i as u64;
        match i % 5 {
            1 => r.dir[(i / 5 % 3) as usize] = 0.0,
            2 => {
                let k = (i / 5 % 3) as usize;
                r.dir = [0.0; 3];
                r.dir[k] = if i.is_multiple_of(2) { 1.0 } else { -1.0 };
                r.origin[k] = if i.is_multiple_of(2) { -5.0 } else { 5.0 };
            }
            3 => r.dir = vec3::scale(r.dir, scale(i)),
            _ => {}
        }
        if i.is_multiple_of(3) {
            let len = vec3::norm(r.dir);
            let a = 4.0 * hash_unit(6, "tmin", i) / len;
            *r = r.with_range(a, a + 3.0 * hash_unit(6, "tlen", i) / len);
        }
    }
    let run = |threads| batches_on(&bvh, &rs, threads);
    let (hits, occ) = run(1);
    assert_eq!((hits.clone(), occ.clone()), run(2));
    let mut n_hits = 0;
    for (i, r) in rs.iter().enumerate() {
        assert_eq!(hits[i], bvh.intersect(r), "ray {i}");
        assert_eq!(occ[i], hits[i].is_some(), "ray {i}");
        if i % 5 == 3 {
            // Same as the ray with its usual length.
            let r0 = Ray { dir: vec3::scale(r.dir, 1.0 / scale(i as u64)), ..*r };
            let h0 = bvh.intersect(&r0);
            assert_eq!(hits[i].map(|h| h.triangle), h0.map(|h| h.triangle), "ray {i}");
            if let (Some(h), Some(h0)) = (hits[i], h0) {
                assert!((h.t * scale(i as u64) - h0.t).abs() < 1e-9 * h0.t, "ray {i}");
            }
        } else if i % 3 != 0 {
            // Brute force over the originals only (the copies tie).
            let bf = brute_hit(&orig, r.origin, r.dir, r.tmax);
            match (hits[i], bf) {
                (Some(h), Some((_, t))) => {
                    assert!(h.triangle < n, "ray {i}: the copy {} won", h.triangle);
                    assert!((h.t - t).abs() <= 1e-6 * t.max(1.0 / vec3::norm(r.dir)), "ray {i}");
                    n_hits += 1;
                }
                (None, None) => {}
                (h, bf) => {
                    // Only a ray grazing an edge may disagree with the non-watertight
                    // brute force; its hit must then lie on a triangle's border.
                    let h = h.unwrap_or_else(|| panic!("ray {i}: missed {bf:?}"));
                    assert!(h.barycentric.iter().any(|&b| b < 1e-7), "ray {i}: {h:?}");
                }
            }
        } else if let Some(h) = hits[i] {
            assert!(h.triangle < n && h.t >= r.tmin && h.t <= r.tmax * (1.0 + 1e-12), "ray {i}");
        }
    }
    assert!(n_hits > 1500, "{n_hits}");
}

#[test]
fn grid_boundary_is_hit_by_axis_parallel_rays() {
    // Rays along -z in the bounding-box faces of a flat grid (x or y at its extremes).
    let m = crate::primitives::grid(4, 4, 1.0, 1.0);
    let bvh = Bvh::build(&m).unwrap();
    for j in 0..=8 {
        let s = j as f64 / 8.0;
        for (x, y) in [(0.0, s), (1.0, s), (s, 0.0), (s, 1.0)] {
            let h = bvh.closest_hit([x, y, 1.0], [0.0, 0.0, -1.0], f64::INFINITY);
            assert!(h.is_some_and(|h| (h.t - 1.0).abs() < 1e-12), "miss at ({x}, {y})");
            assert!(bvh.any_hit([x, y, 1.0], [0.0, 0.0, -1.0], 2.0), "({x}, {y})");
        }
    }
}

#[test]
fn avx2_and_portable_traversals_agree() {
    // The 4-lane (portable) traversal must give exactly the AVX2 one's results, as it is
    // the one taken on CPUs without AVX2; axis-parallel and grazing rays included.
    if !bvh_wide::has_avx2() {
        return;
    }
    let m = torus(2.0, 0.7, 60, 24);
    let bvh = Bvh::build(&m).unwrap();
    let mut rs = rays(&m, 3000);
    for (i, r) in rs.iter_mut().enumerate().step_by(7) {
        r.dir[i % 3] = 0.0;
    }
    let mut n_hits = 0;
    for r in &rs {
        let Some((oray, _)) = bvh.oray(r) else { continue };
        let rb = RayBoxes::new(oray.origin, oray.direction, oray.tmin, bvh.scene_half);
        let shear = Shear::new(&oray);
        let (mut s0, mut s1) = (shear, shear);
        let a = bvh.wide.closest_impl::<false, _>(
            &rb,
            &mut s0,
            &bvh.prim_tris,
            &bvh.prim_ids,
            &bvh.corners,
        );
        let b = bvh.wide.closest_impl::<true, _>(
            &rb,
            &mut s1,
            &bvh.prim_tris,
            &bvh.prim_ids,
            &bvh.corners,
        );
        assert_eq!(a.map(|(p, t)| (p, t.to_bits())), b.map(|(p, t)| (p, t.to_bits())));
        let any0 = bvh.wide.any_impl::<false>(&rb, &shear, &bvh.prim_tris);
        assert_eq!(any0, bvh.wide.any_impl::<true>(&rb, &shear, &bvh.prim_tris));
        assert_eq!(any0, a.is_some());
        n_hits += usize::from(any0);
    }
    assert!(n_hits > 1000 && n_hits < 2900, "{n_hits}");
}
