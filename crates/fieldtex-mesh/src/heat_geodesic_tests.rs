//! Tests of the heat method against exact distances and on defective input.

use super::*;
use crate::primitives::{grid, icosphere};
use crate::test_meshes::{defective_patch, load_obj, two_components};

#[test]
fn sphere_distance_is_arc_length() {
    let m = icosphere(5);
    let hg = HeatGeodesic::new(&m, &HeatGeodesicOptions::default()).unwrap();
    let d = hg.distance(&[0]).unwrap();
    let p0 = m.positions[0];
    let (mut err_sum, mut err_max) = (0.0f64, 0.0f64);
    for (v, p) in m.positions.iter().enumerate() {
        let exact = vec3::dot(p0, *p).clamp(-1.0, 1.0).acos();
        let e = (d[v] - exact).abs();
        err_sum += e;
        err_max = err_max.max(e);
    }
    let mean = err_sum / m.n_vertices() as f64;
    assert_eq!(d[0], 0.0);
    assert!(mean < 0.01 * std::f64::consts::PI, "mean error {mean}");
    assert!(err_max < 0.05 * std::f64::consts::PI, "max error {err_max}");
}

#[test]
fn plane_distance_is_euclidean_for_every_boundary_mode() {
    let m = grid(40, 40, 1.0, 1.0);
    let centre = 20 * 41 + 20;
    for boundary in [HeatBoundary::Average, HeatBoundary::Neumann, HeatBoundary::Dirichlet] {
        let opts = HeatGeodesicOptions { boundary, ..Default::default() };
        let hg = HeatGeodesic::new(&m, &opts).unwrap();
        let d = hg.distance(&[centre]).unwrap();
        let c = m.positions[centre];
        let mut max_err = 0.0f64;
        for (v, p) in m.positions.iter().enumerate() {
            let exact = vec3::norm(vec3::sub(*p, c));
            max_err = max_err.max((d[v] - exact).abs());
        }
        let tol = if boundary == HeatBoundary::Average { 0.03 } else { 0.08 };
        assert!(max_err < tol, "{boundary:?}: max error {max_err}");
    }
}

#[test]
fn reusable_across_source_sets_and_deterministic() {
    let m = icosphere(3);
    let hg = HeatGeodesic::new(&m, &HeatGeodesicOptions::default()).unwrap();
    let sets = vec![vec![0], vec![5, 17], vec![100]];
    let batch = hg.distances(&sets).unwrap();
    for (s, d) in sets.iter().zip(&batch) {
        assert_eq!(&hg.distance(s).unwrap(), d);
        for &v in s {
            assert_eq!(d[v], 0.0);
        }
    }
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let single = pool.install(|| {
        HeatGeodesic::new(&m, &HeatGeodesicOptions::default()).unwrap().distance(&[5, 17]).unwrap()
    });
    assert_eq!(single, batch[1]);
}

#[test]
fn point_sources_match_vertex_sources() {
    let m = icosphere(3);
    let hg = HeatGeodesic::new(&m, &HeatGeodesicOptions::default()).unwrap();
    let t = m.triangles[0];
    let by_vertex = hg.distance(&[t[1] as usize]).unwrap();
    let by_point = hg.distance_from_points(&[(0, [0.0, 1.0, 0.0])]).unwrap();
    assert_eq!(by_vertex, by_point);
    // A point in the middle of the triangle is close to its corners.
    let mid = hg.distance_from_points(&[(0, [1.0, 1.0, 1.0])]).unwrap();
    for &v in &t {
        assert!(mid[v as usize] < 0.2, "{}", mid[v as usize]);
    }
    assert!(hg.distance_from_points(&[(0, [f64::NAN, 0.0, 0.0])]).is_err());
    assert!(hg.distance_from_points(&[(99_999, [1.0, 0.0, 0.0])]).is_err());
    assert!(hg.distance(&[m.n_vertices()]).is_err());
}

#[test]
fn components_without_source_are_infinite() {
    let m = two_components();
    let hg = HeatGeodesic::new(&m, &HeatGeodesicOptions::default()).unwrap();
    assert!(hg.warnings().iter().any(|w| w.code == "geodesic-components"));
    let sphere_vertices = icosphere(2).n_vertices();
    let d = hg.distance(&[0]).unwrap();
    assert!(d[..sphere_vertices].iter().all(|x| x.is_finite()));
    assert!(d[sphere_vertices..].iter().all(|x| x.is_infinite()));
    // Sources in both components: both finite.
    let d = hg.distance(&[0, sphere_vertices + 3]).unwrap();
    assert!(d.iter().all(|x| x.is_finite() && *x >= 0.0));
}

#[test]
fn defective_mesh_gives_finite_distances_where_connected() {
    let m = defective_patch();
    let hg = HeatGeodesic::new(&m, &HeatGeodesicOptions::default()).unwrap();
    let d = hg.distance(&[0]).unwrap();
    assert!(d.iter().all(|x| !x.is_nan()));
    // Grid vertices (0..25) and the attached flap and needles (25..28) are connected.
    assert!(d[..28].iter().all(|x| x.is_finite()), "{:?}", &d[..28]);
    // The coincident triangle's corners and the unreferenced vertex are not.
    assert!(d[28..].iter().all(|x| x.is_infinite()), "{:?}", &d[28..]);
    // A source on an isolated vertex is 0 there and infinite elsewhere.
    let iso = hg.distance(&[31]).unwrap();
    assert_eq!(iso[31], 0.0);
    assert!(iso[..31].iter().all(|x| x.is_infinite()));
    // The needles distort the global solve, but grid distances stay plausible (the
    // exact ones lie in [0, √2]).
    for (v, dv) in d[..25].iter().enumerate() {
        assert!(*dv <= 1.6, "vertex {v}: {dv}");
    }
    assert!(d[24] > 1.0, "{}", d[24]);
}

#[test]
fn high_genus_fixture_is_roughly_lipschitz() {
    let Some(m) = load_obj("fertility.obj") else { return };
    let hg = HeatGeodesic::new(&m, &HeatGeodesicOptions::default()).unwrap();
    let d = hg.distance(&[0]).unwrap();
    assert!(d.iter().all(|x| x.is_finite() && *x >= 0.0));
    let topo = Topology::build(m.n_vertices(), &m.triangles);
    let mut bad = 0;
    for e in &topo.edges {
        let (a, b) = (e[0] as usize, e[1] as usize);
        let len = vec3::norm(vec3::sub(m.positions[a], m.positions[b]));
        if (d[a] - d[b]).abs() > 1.5 * len + 1e-9 {
            bad += 1;
        }
    }
    assert!(bad * 100 < topo.n_edges(), "{bad} of {} edges", topo.n_edges());
}

#[test]
fn bunny_with_holes_and_unreferenced_vertices() {
    let Some(m) = load_obj("stanford-bunny.obj") else { return };
    let hg = HeatGeodesic::new(&m, &HeatGeodesicOptions::default()).unwrap();
    let d = hg.distance(&[m.triangles[0][0] as usize]).unwrap();
    let mut used = vec![false; m.n_vertices()];
    for t in &m.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    for (v, &u) in used.iter().enumerate() {
        assert!(!d[v].is_nan());
        assert_eq!(u, d[v].is_finite(), "vertex {v}: used {u}, distance {}", d[v]);
    }
    // Narrow slivers: finite everywhere.
    if let Some(n) = load_obj("defects/narrow_triangles.obj") {
        let d =
            HeatGeodesic::new(&n, &HeatGeodesicOptions::default()).unwrap().distance(&[0]).unwrap();
        assert!(d.iter().all(|x| x.is_finite() && *x >= 0.0), "{d:?}");
    }
}
