//! Orientation designs: every fingerprint preset produces exactly its designed
//! singularities (type and position within one grid cell), on the grid field and on the
//! 512² pixel field; presets on disk agree with the built-in versions.

use fieldtex_fields::orientation_field::{
    detect_design_singularities, detect_pixel_singularities, sample_plane,
};
use fieldtex_fields::presets::{PRESET_NAMES, preset};
use fieldtex_fields::*;

const SIZE: usize = 512;

/// Matches found singularities to designed ones one-to-one: same index and within
/// one grid cell in x and in y.
fn assert_matches(found: &[DetectedSingularity], designed: &[Singularity], cell: f64, what: &str) {
    assert_eq!(found.len(), designed.len(), "{what}: found {found:?}, designed {designed:?}");
    let mut used = vec![false; found.len()];
    for s in designed {
        let k = found.iter().enumerate().position(|(k, f)| {
            !used[k]
                && f.index == s.kind.index()
                && (f.position[0] - s.position[0]).abs() <= cell
                && (f.position[1] - s.position[1]).abs() <= cell
        });
        match k {
            Some(k) => used[k] = true,
            None => panic!(
                "{what}: designed {} at {:?} not found within one cell in {found:?}",
                s.kind.name(),
                s.position
            ),
        }
    }
}

#[test]
fn every_preset_has_exactly_its_designed_singularities() {
    // One factored domain, elements swapped per preset (the interactive edit path).
    let first = preset(PRESET_NAMES[0], SIZE as f64, SIZE as f64, 128).unwrap();
    let grid = first.plane_grid().unwrap();
    let (hx, hy) = grid.cell_size();
    let cell = hx.max(hy);
    let mut design =
        FieldDesign::new(Domain::Plane(grid), Symmetry::Orientation, first.options()).unwrap();
    for name in PRESET_NAMES {
        let file = preset(name, SIZE as f64, SIZE as f64, 128).unwrap();
        assert_eq!(file.plane_grid(), Some(grid));
        for (id, _) in design.singularities() {
            design.remove_singularity(id).unwrap();
        }
        let strokes: Vec<StrokeId> = design.strokes().iter().map(|s| s.0).collect();
        for id in strokes {
            design.remove_stroke(id).unwrap();
        }
        let designed = file.singularity_list().unwrap();
        for s in &designed {
            design.add_singularity(*s).unwrap();
        }
        for s in file.stroke_list() {
            design.add_stroke(s).unwrap();
        }
        let field = design.solve().unwrap();
        assert!(field.residual < 1e-8, "{name}: residual {}", field.residual);
        let on_grid = detect_design_singularities(&design, &field, 1.5 * cell);
        assert_matches(&on_grid, &designed, cell, &format!("{name} (grid field)"));
        let pixels = sample_plane(&design, &field, SIZE, SIZE).unwrap();
        assert!(
            pixels.iter().all(|v| ((v[0] * v[0] + v[1] * v[1]) - 1.0).abs() < 1e-5),
            "{name}: unit vectors"
        );
        let on_pixels =
            detect_pixel_singularities(&pixels, SIZE, SIZE, Symmetry::Orientation, 1.5 * cell)
                .unwrap();
        assert_matches(&on_pixels, &designed, cell, &format!("{name} (pixel field)"));
        // The index sum of the pixel field is the designed one (no hidden ±pairs merged away
        // beyond one cell).
        let raw = fieldtex_fields::singularity_index::pixel_singularities(&pixels, SIZE, SIZE, 2);
        let sum: f64 = raw.iter().map(|s| s.index).sum();
        let designed_sum: f64 = designed.iter().map(|s| s.kind.index()).sum();
        assert_eq!(sum, designed_sum, "{name}: index sum");
    }
}

#[test]
fn preset_files_agree_with_builtin_presets() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("presets");
    for name in PRESET_NAMES {
        let path = dir.join(format!("{name}.toml"));
        let text = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e}; regenerate with `cargo run --release -p fieldtex-fields --example write_presets`", path.display()));
        let from_file = DesignFile::from_toml_str(&text).unwrap();
        let builtin = preset(name, 512.0, 512.0, 128).unwrap();
        assert_eq!(
            from_file, builtin,
            "{name}: presets/{name}.toml differs from the built-in preset; regenerate it with the write_presets example"
        );
        // And the text form round-trips.
        assert_eq!(DesignFile::from_toml_str(&builtin.to_toml_string()).unwrap(), builtin);
    }
    assert!(matches!(preset("loop", 512.0, 512.0, 128), Err(FieldsError::UnknownPreset { .. })));
}

#[test]
fn wedge_and_trisector_have_their_rotation() {
    // A lone wedge with α: its single radial ridge points in direction 2α; a lone
    // trisector's three radial ridges point at −2α/3 + k·120°.
    for (kind, alpha, rays) in [
        (SingularityKind::Wedge, 30f64, vec![60f64]),
        (SingularityKind::Trisector, 30f64, vec![-20f64, 100.0, 220.0]),
    ] {
        let mut d = FieldDesign::new(
            Domain::Plane(PlaneGrid::with_cells(256.0, 256.0, 64)),
            Symmetry::Orientation,
            FieldDesignOptions::default(),
        )
        .unwrap();
        let (cx, cy) = (129.3, 126.1);
        d.add_singularity(Singularity::at_pixel(kind, cx, cy).with_angle(alpha.to_radians()))
            .unwrap();
        let f = d.solve().unwrap();
        let px = sample_plane(&d, &f, 256, 256).unwrap();
        // Radial directions: where the orientation is parallel to the ray from the centre,
        // sampled on a circle of radius 40 px.
        let mut radial = Vec::new();
        for k in 0..720 {
            let t = (k as f64 * 0.5).to_radians();
            let (x, y) = (cx + 40.0 * t.cos(), cy + 40.0 * t.sin());
            let v = px[y as usize * 256 + x as usize];
            let cross = (v[0] as f64 * t.sin() - v[1] as f64 * t.cos()).abs();
            radial.push((cross, t.to_degrees()));
        }
        for ray in rays {
            let best = radial
                .iter()
                .filter(|(_, a)| {
                    let d = (a - ray).rem_euclid(360.0);
                    d.min(360.0 - d) < 30.0
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .unwrap();
            let d = (best.1 - ray).rem_euclid(360.0);
            assert!(
                best.0 < 0.05 && d.min(360.0 - d) < 6.0,
                "{kind:?}: radial ridge near {ray}° found at {:?}",
                best
            );
        }
    }
}

#[test]
fn vector_singularities_on_the_plane() {
    // Two designs whose model fields force no extra zeros: a source–sink dipole and a
    // vortex–saddle pair. (Two poles side by side always have a saddle between them.)
    let designs = [
        vec![
            Singularity::at_pixel(SingularityKind::Source, 80.3, 120.6),
            Singularity::at_pixel(SingularityKind::Sink, 170.4, 140.8),
        ],
        vec![
            Singularity::at_pixel(SingularityKind::Vortex, 90.2, 90.9),
            Singularity::at_pixel(SingularityKind::Saddle, 160.7, 170.1).with_angle(0.3),
        ],
    ];
    for designed in designs {
        let mut d = FieldDesign::new(
            Domain::Plane(PlaneGrid::with_cells(256.0, 256.0, 64)),
            Symmetry::Vector,
            FieldDesignOptions::default(),
        )
        .unwrap();
        for s in &designed {
            d.add_singularity(*s).unwrap();
        }
        let f = d.solve().unwrap();
        let px = sample_plane(&d, &f, 256, 256).unwrap();
        let found = detect_pixel_singularities(&px, 256, 256, Symmetry::Vector, 6.0).unwrap();
        assert_matches(&found, &designed, 4.0, "vector design");
        // Directions next to each singularity: a source points away, a sink towards it, a
        // positive vortex turns from +x towards +y (clockwise on screen, y down).
        let at = |x: f64, y: f64| px[y as usize * 256 + x as usize];
        for s in &designed {
            let v = at(s.position[0] + 10.0, s.position[1]);
            match s.kind {
                SingularityKind::Source => assert!(v[0] > 0.9, "source: {v:?}"),
                SingularityKind::Sink => assert!(v[0] < -0.9, "sink: {v:?}"),
                SingularityKind::Vortex => assert!(v[1] > 0.9, "vortex: {v:?}"),
                // Saddle e^{−i(θ+α)}: at θ = 0 the direction is −α.
                _ => assert!(((v[1] as f64).atan2(v[0] as f64) + 0.3).abs() < 0.1, "saddle: {v:?}"),
            }
        }
    }
}

/// The one-shot build (no checkpoint copy) solves to the very same bits as the editable
/// one.
#[test]
fn one_shot_build_gives_the_same_field_bits() {
    let file = preset("whorl", 128.0, 128.0, 64).unwrap();
    let mut editable = file.build(None).unwrap();
    let mut once = file.build_once(None).unwrap();
    let (a, b) = (editable.solve().unwrap(), once.solve().unwrap());
    let (pa, pb) = (
        sample_plane(&editable, &a, 128, 128).unwrap(),
        sample_plane(&once, &b, 128, 128).unwrap(),
    );
    let bits = |p: &[[f32; 2]]| p.iter().flat_map(|v| v.map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&pa), bits(&pb));
    assert_eq!(a.residual.to_bits(), b.residual.to_bits());
}
