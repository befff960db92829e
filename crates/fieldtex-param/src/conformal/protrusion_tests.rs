//! Tests of the genus-0 protrusion slits, the similarity ghosts across seams, the
//! chart-by-chart relaxation of patch layouts and the rejection of garbage maps
//! (session 15); the other constructions are tested in `tests.rs`.

use super::tests::{distortion, genus_two_slab};
use super::*;
use fieldtex_core::NoProgress;
use fieldtex_mesh::primitives;

/// A sphere with four long fingers along the tetrahedron's directions (radius
/// `1 + 4 Σ max(0, d·aᵢ)²⁴`): genus 0, a shape the two-point cylinder squeezes.
fn four_fingers() -> fieldtex_mesh::TriMesh {
    let mut mesh = primitives::icosphere(4);
    let s = 1.0 / 3f64.sqrt();
    let dirs = [[s, s, s], [s, -s, -s], [-s, s, -s], [-s, -s, s]];
    for p in &mut mesh.positions {
        let r: f64 =
            dirs.iter().map(|a| (p[0] * a[0] + p[1] * a[1] + p[2] * a[2]).max(0.0).powi(24)).sum();
        *p = p.map(|x| x * (1.0 + 4.0 * r));
    }
    mesh
}

#[test]
fn protrusions_get_slits_and_a_double_cover_that_evens_the_area_scale() {
    let mesh = four_fingers();
    let (comps, _) = global_conformal(&mesh, &NoProgress).unwrap();
    let c = &comps[0];
    assert_eq!(c.genus, 0);
    let p = c.protrusion_slits.as_ref().expect("the fingers get slits");
    assert_eq!(p.tips.len(), 4, "{p:?}");
    assert_eq!(c.double_cover_genus, Some(3));
    assert_eq!(c.method, ConformalMethod::CriticalTrajectoryPatches);
    // The two-point cylinder squeezes two fingers by orders of magnitude.
    assert!(p.log_area_std < 0.5 * p.cylinder_log_area_std, "{p:?}");
    assert!(c.corner_uv.iter().flatten().flatten().all(|x| x.is_finite()));
    let d = distortion(c);
    assert_eq!(d.flipped, 0);
    assert!(
        (d.log_area_std - p.log_area_std).abs() < 1e-9 || d.log_area_std < p.cylinder_log_area_std
    );
    // Every tip is a finger's end: far from the centre.
    for &t in &p.tips {
        assert!(fieldtex_core::vec3::norm(mesh.positions[t as usize]) > 2.5, "tip {t}");
    }
}

#[test]
fn protrusion_slits_are_the_same_for_one_and_two_threads() {
    let mesh = four_fingers();
    let run = |t: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap();
        pool.install(|| global_conformal(&mesh, &NoProgress).unwrap().0.remove(0))
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(
        a.protrusion_slits.as_ref().map(|p| p.tips.clone()),
        b.protrusion_slits.map(|p| p.tips)
    );
    assert!(
        a.corner_uv
            .iter()
            .flatten()
            .flatten()
            .zip(b.corner_uv.iter().flatten().flatten())
            .all(|(x, y)| x.to_bits() == y.to_bits())
    );
}

#[test]
fn slit_ghosts_continue_each_chart_across_its_slit() {
    let (comps, _) = global_conformal(&four_fingers(), &NoProgress).unwrap();
    let c = &comps[0];
    let slit: Vec<&Ghost> = c.map.ghosts.iter().filter(|g| g.corners.is_some()).collect();
    assert!(!slit.is_empty());
    let len = |p: [f64; 2], q: [f64; 2]| ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
    for g in &slit {
        // A similarity of the face's own chart: same orientation, same edge ratios.
        let (gc, rc) = (g.corners.unwrap(), c.map.corner[g.face as usize]);
        assert!(periodic_uv::signed_area(&gc) * periodic_uv::signed_area(&rc) > 0.0);
        let s = len(gc[0], gc[1]) / len(rc[0], rc[1]);
        for (i, j) in [(1, 2), (2, 0)] {
            assert!((len(gc[i], gc[j]) / len(rc[i], rc[j]) / s - 1.0).abs() < 1e-6, "{g:?}");
        }
    }
    // The geometry image links more margin texels with the slit ghosts than without.
    let with = GeometryImage::new(c, 256).margin_copies.len();
    let mut without = c.clone();
    without.map.ghosts.retain(|g| g.corners.is_none());
    assert!(with > GeometryImage::new(&without, 256).margin_copies.len() + 10);
}

#[test]
fn a_coarse_plank_whose_map_is_garbage_falls_back_to_the_atlas() {
    // A 30 × 1 × 0.2 box of 48 triangles: long thin triangles, negative cotan weights,
    // a cylinder map with a mean angle distortion in the hundreds.
    let mut mesh = primitives::cube(2);
    for p in &mut mesh.positions {
        p[0] *= 30.0;
        p[2] *= 0.2;
    }
    let (comps, warnings) = global_conformal(&mesh, &NoProgress).unwrap();
    let c = &comps[0];
    assert_eq!(c.method, ConformalMethod::Failed);
    assert!(!c.has_uv());
    assert!(c.note.as_deref().is_some_and(|n| n.contains("chart atlas")), "{:?}", c.note);
    assert!(warnings.iter().any(|w| w.code == "conformal-map-rejected"), "{warnings:?}");
}

#[test]
fn patch_layouts_relax_chart_by_chart_without_flips() {
    for mesh in [four_fingers(), genus_two_slab(4)] {
        let (mut comps, _) = global_conformal(&mesh, &NoProgress).unwrap();
        let c = &mut comps[0];
        assert_eq!(c.method, ConformalMethod::CriticalTrajectoryPatches);
        // The coarse fingers' map is itself at a mean σ1/σ2 near 1.4 over all faces (the
        // faces next to its zero points): the bound sits above it.
        let opts = MassSpringOptions { max_angle_distortion: 1.6, ..Default::default() };
        let st = c.relax_quasi_isometric(&opts).expect("patch layouts relax");
        assert_eq!((st.after.flipped, distortion(c).flipped), (0, 0), "{st:?}");
        assert!(st.after.log_area_std < 0.9 * st.before.log_area_std, "{st:?}");
        assert!(st.after.angle_mean <= opts.max_angle_distortion + 1e-9, "{st:?}");
        // Every seam's margin is drawn by similarity now, and the image links it.
        assert!(!c.map.ghosts.is_empty() && c.map.ghosts.iter().all(|g| g.corners.is_some()));
        assert!(!GeometryImage::new(c, 256).margin_copies.is_empty());
        // Repacked charts do not overlap: no two faces of different charts share area.
        let n = c.faces.len();
        let mut boxes: Vec<(u32, [f64; 4])> = Vec::new();
        for f in 0..n {
            let cu = c.map.corner[f];
            let b = cu.iter().fold(
                [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY],
                |b, p| [b[0].min(p[0]), b[1].min(p[1]), b[2].max(p[0]), b[3].max(p[1])],
            );
            boxes.push((c.map.patch[f], b));
        }
        let mut chart_box: std::collections::BTreeMap<u32, [f64; 4]> = Default::default();
        for (p, b) in boxes {
            let e = chart_box.entry(p).or_insert(b);
            *e = [e[0].min(b[0]), e[1].min(b[1]), e[2].max(b[2]), e[3].max(b[3])];
        }
        let v: Vec<[f64; 4]> = chart_box.into_values().collect();
        for i in 0..v.len() {
            for j in i + 1..v.len() {
                let (a, b) = (v[i], v[j]);
                let apart = a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1];
                assert!(apart, "charts {i} and {j} overlap: {a:?} {b:?}");
            }
        }
    }
}
