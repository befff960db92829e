use super::mass_spring::map_distortion;
use super::*;
use fieldtex_core::NoProgress;
use fieldtex_mesh::primitives;

fn distortion(c: &ConformalComponent) -> mass_spring::MapDistortion {
    let slit = c.near_singularity.clone();
    map_distortion(&c.local_mesh, c.faces.len(), &c.corner_uv, &move |f| slit[f])
}

#[test]
fn torus_has_one_image_without_zero_points_or_flips() {
    let mesh = primitives::torus(1.0, 0.4, 64, 32);
    let (comps, warnings) = global_conformal(&mesh, &NoProgress).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(comps.len(), 1);
    let c = &comps[0];
    assert_eq!(c.genus, 1);
    assert_eq!(c.method, ConformalMethod::HolomorphicTorus);
    assert_eq!(c.zero_points.len(), 0, "{:?}", c.zero_points);
    let d = distortion(c);
    assert_eq!(d.flipped, 0);
    assert!(d.angle_mean < 1.05, "angle distortion {}", d.angle_mean);
    assert!(c.conjugate_residual < 0.1, "conjugate residual {}", c.conjugate_residual);
    // Every face centroid lies in the fundamental domain.
    let b = c.lattice.b.unwrap();
    for cu in &c.corner_uv {
        let g = [(cu[0][0] + cu[1][0] + cu[2][0]) / 3.0, (cu[0][1] + cu[1][1] + cu[2][1]) / 3.0];
        assert!(
            g[0] >= -1e-9
                && g[0] <= c.lattice.a.unwrap() + 1e-9
                && g[1] >= -1e-9
                && g[1] <= b[1] + 1e-9
        );
    }
}

#[test]
fn sphere_maps_to_one_cylinder_without_flips() {
    let mesh = primitives::icosphere(3);
    let (comps, _) = global_conformal(&mesh, &NoProgress).unwrap();
    let c = &comps[0];
    assert_eq!((c.genus, c.method), (0, ConformalMethod::SlitCylinder));
    let d = distortion(c);
    assert_eq!(d.flipped, 0);
    assert!(d.angle_mean < 1.1, "angle distortion {}", d.angle_mean);
    assert!(c.conjugate_residual < 0.3, "conjugate residual {}", c.conjugate_residual);
    let n_slit = c.slit.iter().filter(|s| **s).count();
    assert!((10..=12).contains(&n_slit), "{n_slit} slit triangles"); // two fans
}

#[test]
fn open_surfaces_are_capped_and_mapped() {
    // An open tube: a torus with one ring of quads removed (two boundary loops).
    let torus = primitives::torus(1.0, 0.3, 40, 16);
    let keep: Vec<[u32; 3]> = torus
        .triangles
        .iter()
        .enumerate()
        .filter(|(f, _)| f / (2 * 16) != 0)
        .map(|(_, t)| *t)
        .collect();
    let tube = fieldtex_mesh::TriMesh::new(torus.positions.clone(), keep);
    let (comps, _) = global_conformal(&tube, &NoProgress).unwrap();
    let c = &comps[0];
    assert_eq!(c.boundaries, 2);
    assert_eq!(c.genus, 0);
    assert!(c.has_uv());
    assert_eq!(distortion(c).flipped, 0);
    // A disk (one boundary).
    let grid = primitives::grid(12, 12, 1.0, 1.0);
    let (comps, _) = global_conformal(&grid, &NoProgress).unwrap();
    assert_eq!((comps[0].boundaries, comps[0].genus), (1, 0));
    assert_eq!(distortion(&comps[0]).flipped, 0);
}

#[test]
fn mass_spring_evens_area_without_flips() {
    let mesh = primitives::icosphere(3);
    let (mut comps, _) = global_conformal(&mesh, &NoProgress).unwrap();
    let st = comps[0].relax_quasi_isometric(&MassSpringOptions::default()).unwrap();
    assert_eq!(st.after.flipped, 0);
    assert!(st.after.log_area_std < 0.95 * st.before.log_area_std, "{st:?}");
    assert!(st.after.angle_mean <= 1.25 + 1e-9, "{st:?}");
    assert_eq!(distortion(&comps[0]).flipped, 0);
}

#[test]
fn same_result_for_one_and_two_threads() {
    let mesh = primitives::torus(1.0, 0.4, 32, 16);
    let run = |t: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap();
        pool.install(|| global_conformal(&mesh, &NoProgress).unwrap().0[0].corner_uv.clone())
    };
    let (a, b) = (run(1), run(2));
    assert!(
        a.iter()
            .flatten()
            .flatten()
            .zip(b.iter().flatten().flatten())
            .all(|(x, y)| x.to_bits() == y.to_bits())
    );
}
