//! Crest lines on shapes whose answer is known: spheres have none (umbilic
//! everywhere), a flattened ellipsoid has one ridge along its rim, a cube has twelve
//! creases.

mod common;

use fieldtex_core::vec3;
use fieldtex_features::{CrestOptions, LineKind, LineSource, crest_lines, sharp_edge_coverage};
use fieldtex_mesh::TriMesh;
use fieldtex_mesh::primitives::{grid, icosphere, torus};

fn scaled(mut m: TriMesh, s: [f64; 3]) -> TriMesh {
    for p in &mut m.positions {
        *p = [p[0] * s[0], p[1] * s[1], p[2] * s[2]];
    }
    m
}

#[test]
fn spheres_have_no_crest_lines_at_any_scale() {
    for r in [1e-3, 1.0, 250.0] {
        let m = scaled(icosphere(4), [r; 3]);
        let c = crest_lines(&m, &CrestOptions::default()).unwrap();
        assert!(c.lines.is_empty(), "radius {r}: {} lines", c.lines.len());
        assert!(c.warnings.iter().any(|w| w.code == "no-crest-lines"));
        // Not only because the sphere counts as flat or the lines as weak: umbilics
        // are rejected by the anisotropy test.
        let loose = CrestOptions { flat_curvature: 0.0, levels: vec![0.0], ..Default::default() };
        let c = crest_lines(&m, &loose).unwrap();
        assert!(c.lines.is_empty(), "radius {r}, loose: {} lines", c.lines.len());
    }
}

/// An ellipsoid with semi-axes a = 2 > b = 1.4 > c = 0.6. Along the rim ellipse in the
/// z = 0 plane the maximal curvature runs across the rim (t_max ∥ z) and peaks there
/// by symmetry, so the rim is a ridge; the other principal sections are curvature
/// lines or minima of k_max, not ridges, and a convex surface has no valley.
#[test]
fn flattened_ellipsoid_has_its_rim_as_ridge() {
    let (a, b, c) = (2.0, 1.4, 0.6);
    let m = scaled(icosphere(5), [a, b, c]);
    let crest = crest_lines(&m, &CrestOptions::default()).unwrap();
    common::check_invariants("ellipsoid", &m, &crest);
    assert!(!crest.lines.is_empty());
    assert!(crest.lines.iter().all(|l| l.kind == LineKind::Ridge));
    let perimeter = std::f64::consts::PI * (3.0 * (a + b) - ((3.0 * a + b) * (a + 3.0 * b)).sqrt());
    let total: f64 = crest.lines.iter().map(|l| l.length).sum();
    assert!(total > 0.8 * perimeter && total < 1.2 * perimeter, "{total} vs {perimeter}");
    for l in &crest.lines {
        for p in &l.points {
            assert!(p[2].abs() < 0.05 * c, "point {p:?} off the rim plane");
            let r = (p[0] / a).powi(2) + (p[1] / b).powi(2);
            assert!((r - 1.0).abs() < 0.02, "point {p:?} off the rim ellipse");
        }
    }
}

/// The same ellipsoid seen from inside (triangles flipped, normals inward): every
/// curvature changes sign, the rim becomes a valley (a minimum of `k_min`).
#[test]
fn inside_out_ellipsoid_has_its_rim_as_valley() {
    let (a, b, c) = (2.0, 1.4, 0.6);
    let mut m = scaled(icosphere(5), [a, b, c]);
    for t in &mut m.triangles {
        t.swap(1, 2);
    }
    let crest = crest_lines(&m, &CrestOptions::default()).unwrap();
    assert!(!crest.lines.is_empty());
    assert!(crest.lines.iter().all(|l| l.kind == LineKind::Valley));
    for p in crest.lines.iter().flat_map(|l| &l.points) {
        assert!(p[2].abs() < 0.05 * c, "point {p:?} off the rim plane");
    }
}

/// On a torus the tube curvature `k_max = 1/r` is the same everywhere, so `e_max ≡ 0`
/// and any zero crossing is discretisation noise: the sharpness test removes it (and
/// a torus has no valley of `k_min` with `|k_min| > |k_max|`).
#[test]
fn torus_has_no_crest_lines() {
    for (nu, nv) in [(96, 32), (150, 40)] {
        let m = torus(2.0, 0.5, nu, nv);
        let c = crest_lines(&m, &CrestOptions::default()).unwrap();
        assert!(c.lines.is_empty(), "{nu}×{nv}: {} lines, {:?}", c.lines.len(), c.stats);
    }
    let shared = common::load("meshes/torus.obj");
    let c = crest_lines(&shared, &CrestOptions::default()).unwrap();
    assert!(c.lines.is_empty(), "shared torus: {:?}", c.stats);
}

/// A cube with 8×8 cells per side: flat faces, twelve 90° creases meeting three at a
/// time at the corners, so twelve convex crease lines (no join across a corner).
#[test]
fn cube_has_twelve_crease_ridges() {
    let face = grid(8, 8, 1.0, 1.0);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    // Six copies of the unit square mapped onto the cube's sides, outward facing.
    let maps: [fn([f64; 3]) -> [f64; 3]; 6] = [
        |p| [p[0], p[1], 1.0],
        |p| [p[1], p[0], 0.0],
        |p| [p[1], 1.0, p[0]],
        |p| [p[0], 0.0, p[1]],
        |p| [1.0, p[0], p[1]],
        |p| [0.0, p[1], p[0]],
    ];
    for map in maps {
        let base = positions.len() as u32;
        positions.extend(face.positions.iter().map(|&p| map(p)));
        triangles.extend(face.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    let raw = TriMesh::new(positions, triangles);
    let m = fieldtex_mesh::repair(&raw, &fieldtex_mesh::RepairOptions::default()).mesh;
    assert_eq!(m.n_vertices(), 6 * 81 - 12 * 9 + 8, "welded cube");
    let crest = crest_lines(&m, &CrestOptions::default()).unwrap();
    common::check_invariants("cube", &m, &crest);
    assert_eq!(crest.lines.len(), 12, "{:?}", crest.stats);
    for l in &crest.lines {
        assert_eq!(l.kind, LineKind::Ridge);
        assert_eq!(l.source, LineSource::Crease);
        assert!((l.length - 1.0).abs() < 1e-9);
        let d = vec3::sub(l.points[l.points.len() - 1], l.points[0]);
        assert!((vec3::norm(d) - 1.0).abs() < 1e-9, "a straight cube edge");
    }
    let cov = sharp_edge_coverage(&m, &crest.polylines(), 30.0, 2.0).unwrap();
    assert!((cov.sharp_covered - 1.0).abs() < 1e-12 && (cov.lines_on_sharp - 1.0).abs() < 1e-12);
    assert!((cov.sharp_length - 12.0).abs() < 1e-9);
}

/// A unit sphere with seeded radial noise of 2 % of an edge length: no dust.
#[test]
fn noisy_sphere_gives_no_dust() {
    let mut m = icosphere(5);
    let h = fieldtex_features::mean_edge_length(&m).unwrap();
    for (i, p) in m.positions.iter_mut().enumerate() {
        let u = fieldtex_core::rng::hash_unit(7, "test-noise", i as u64);
        *p = vec3::scale(*p, 1.0 + 0.02 * h * (2.0 * u - 1.0));
    }
    let c = crest_lines(&m, &CrestOptions::default()).unwrap();
    assert!(c.lines.is_empty(), "{} lines: {:?}", c.lines.len(), c.stats);
}
