//! Tests of principal curvatures on surfaces with known curvature and on defects.

use super::*;
use crate::Topology;
use crate::primitives::{grid, icosphere, torus};
use crate::test_meshes::{categories, load_obj};

/// An open cylinder of radius `r` around the z axis, height `h`.
fn cylinder(r: f64, h: f64, nu: usize, nz: usize) -> TriMesh {
    let mut m = grid(nu, nz, 1.0, 1.0);
    // Wrap the grid: column nu coincides with column 0; merge by index remapping.
    let w = nu + 1;
    for p in &mut m.positions {
        let a = 2.0 * std::f64::consts::PI * p[0];
        *p = [r * a.cos(), r * a.sin(), h * p[1]];
    }
    for t in &mut m.triangles {
        for i in t.iter_mut() {
            if (*i as usize) % w == nu {
                *i -= nu as u32;
            }
        }
    }
    // Outward normals: the grid is CCW seen from +z; after wrapping, faces point outward
    // iff (∂/∂u × ∂/∂z) points out, which holds for this parameterisation.
    m
}

fn check_frames(name: &str, c: &PrincipalCurvatures) {
    for v in 0..c.k_max.len() {
        assert!(c.k_max[v].is_finite() && c.k_min[v].is_finite(), "{name}: vertex {v}");
        assert!(c.k_max[v] >= c.k_min[v], "{name}: vertex {v}");
        let (d1, d2, n) = (c.dir_max[v], c.dir_min[v], c.normals[v]);
        assert!((vec3::norm(d1) - 1.0).abs() < 1e-9, "{name}: dir_max not unit at {v}");
        assert!((vec3::norm(d2) - 1.0).abs() < 1e-9, "{name}: dir_min not unit at {v}");
        assert!(vec3::dot(d1, n).abs() < 1e-9 && vec3::dot(d1, d2).abs() < 1e-9, "{name}");
    }
}

#[test]
fn sphere_has_curvature_one_over_r() {
    let mut m = icosphere(4);
    for p in &mut m.positions {
        *p = vec3::scale(*p, 2.0);
    }
    let (c, w) = principal_curvatures(&m, &CurvatureOptions::default()).unwrap();
    assert!(w.is_empty());
    check_frames("sphere", &c);
    for v in 0..m.n_vertices() {
        assert!((c.k_max[v] - 0.5).abs() < 0.01, "k_max {}", c.k_max[v]);
        assert!((c.k_min[v] - 0.5).abs() < 0.01, "k_min {}", c.k_min[v]);
    }
}

#[test]
fn cylinder_curves_around_its_axis() {
    let r = 1.5;
    let m = cylinder(r, 3.0, 96, 24);
    let topo = Topology::build(m.n_vertices(), &m.triangles);
    let boundary = topo.boundary_vertices();
    let (c, _) = principal_curvatures(&m, &CurvatureOptions::default()).unwrap();
    check_frames("cylinder", &c);
    let mut checked = 0;
    for (v, &on_boundary) in boundary.iter().enumerate() {
        if on_boundary || topo.vertex_faces(v).is_empty() {
            continue;
        }
        checked += 1;
        assert!((c.k_max[v] - 1.0 / r).abs() < 0.02 / r, "k_max {} at {v}", c.k_max[v]);
        assert!(c.k_min[v].abs() < 0.02 / r, "k_min {} at {v}", c.k_min[v]);
        // k_max direction: horizontal (around the axis), k_min: along the axis.
        assert!(c.dir_max[v][2].abs() < 0.05, "dir_max {:?}", c.dir_max[v]);
        assert!(c.dir_min[v][2].abs() > 0.99, "dir_min {:?}", c.dir_min[v]);
    }
    assert!(checked > 1000);
}

#[test]
fn torus_equators() {
    let (big, small) = (2.0, 0.5);
    let m = torus(big, small, 180, 60);
    let (c, _) = principal_curvatures(&m, &CurvatureOptions::default()).unwrap();
    check_frames("torus", &c);
    let (mut outer, mut inner) = (0, 0);
    for (v, p) in m.positions.iter().enumerate() {
        if p[2].abs() > 1e-9 {
            continue;
        }
        let rho = p[0].hypot(p[1]);
        if (rho - (big + small)).abs() < 1e-9 {
            // Outer equator: 1/r around the tube, 1/(R + r) around the axis.
            assert!((c.k_max[v] - 1.0 / small).abs() < 0.03, "outer k_max {}", c.k_max[v]);
            assert!((c.k_min[v] - 1.0 / (big + small)).abs() < 0.02, "outer k_min {}", c.k_min[v]);
            outer += 1;
        } else if (rho - (big - small)).abs() < 1e-9 {
            assert!((c.k_max[v] - 1.0 / small).abs() < 0.03, "inner k_max {}", c.k_max[v]);
            assert!((c.k_min[v] + 1.0 / (big - small)).abs() < 0.03, "inner k_min {}", c.k_min[v]);
            inner += 1;
        }
    }
    assert_eq!((outer, inner), (180, 180));
}

#[test]
fn plane_is_flat_with_valid_frames() {
    let m = grid(6, 5, 1.0, 1.0);
    let (c, w) = principal_curvatures(&m, &CurvatureOptions::default()).unwrap();
    assert!(w.is_empty());
    check_frames("plane", &c);
    assert!(c.k_max.iter().chain(&c.k_min).all(|k| k.abs() < 1e-12));
}

#[test]
fn categories_and_fixtures_stay_finite() {
    let mut all = categories();
    for name in
        ["fandisk.obj", "fertility.obj", "stanford-bunny.obj", "defects/narrow_triangles.obj"]
    {
        if let Some(m) = load_obj(name) {
            all.push((name, m));
        }
    }
    assert!(all.len() >= 8, "fixture meshes not found");
    for (name, m) in &all {
        for smoothing in [0, 2] {
            let opts = CurvatureOptions { smoothing_iterations: smoothing, ..Default::default() };
            let (c, _) = principal_curvatures(m, &opts).unwrap();
            check_frames(name, &c);
        }
    }
}

#[test]
fn defects_fall_back_with_a_warning() {
    let m = crate::test_meshes::defective_patch();
    let (c, w) = principal_curvatures(&m, &CurvatureOptions::default()).unwrap();
    check_frames("defective", &c);
    assert_eq!(w.len(), 1, "{w:?}");
    // The unreferenced last vertex has nothing to borrow from: zero curvature.
    let last = m.n_vertices() - 1;
    assert_eq!((c.k_max[last], c.k_min[last]), (0.0, 0.0));
    // A vertex that is only on a degenerate triangle borrows from its neighbours:
    // the flap midpoint (index 25) sits on the flat grid, so it borrows zero.
    assert!(c.k_max[25].abs() < 1e-9);
}

#[test]
fn smoothing_keeps_the_sphere_and_is_deterministic() {
    let m = icosphere(3);
    let opts = CurvatureOptions { smoothing_iterations: 2, ..Default::default() };
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| principal_curvatures(&m, &opts).unwrap().0)
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a, b);
    assert!(a.k_max.iter().all(|k| (k - 1.0).abs() < 0.03));
}
