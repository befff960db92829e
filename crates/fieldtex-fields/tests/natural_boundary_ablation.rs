//! Paper D, Fig. 2: one source (or vortex) on a disk. With the natural boundary term the
//! design has exactly one singularity; with Fisher et al.'s free boundary only (the
//! ablation), spurious saddles appear near the boundary.

use fieldtex_fields::orientation_field::detect_design_singularities;
use fieldtex_fields::*;

fn design(
    kind: SingularityKind,
    pos: [f64; 3],
    natural: bool,
    model: SingularityModel,
) -> Vec<DetectedSingularity> {
    let options = FieldDesignOptions {
        natural_boundary: natural,
        singularity_model: model,
        ..Default::default()
    };
    let mut d =
        FieldDesign::new(Domain::Mesh(disk_mesh(1.0, 24)), Symmetry::Vector, options).unwrap();
    d.add_singularity(Singularity::new(kind, pos)).unwrap();
    let f = d.solve().unwrap();
    assert!(f.residual < 1e-8);
    let h = d.dec().mean_edge_length;
    detect_design_singularities(&d, &f, 1.5 * h)
}

fn assert_single(found: &[DetectedSingularity], pos: [f64; 3], what: &str) {
    assert_eq!(found.len(), 1, "{what}: expected exactly one singularity, found {found:?}");
    assert_eq!(found[0].index, 1.0, "{what}: index");
    let d =
        ((found[0].position[0] - pos[0]).powi(2) + (found[0].position[1] - pos[1]).powi(2)).sqrt();
    assert!(d < 0.1, "{what}: found at {:?}, designed at {pos:?}", found[0].position);
}

#[test]
fn source_at_disk_centre_gives_exactly_one_singularity() {
    for model in [SingularityModel::PointDelta, SingularityModel::ModelField] {
        let found = design(SingularityKind::Source, [0.0, 0.0, 0.0], true, model);
        assert_single(&found, [0.0, 0.0, 0.0], &format!("{model:?} centred source"));
    }
}

#[test]
fn natural_boundary_removes_spurious_singularities_of_an_off_centre_source_and_vortex() {
    // The paper's literal point divergence / point curl (Fig. 2 setting).
    let pos = [0.6, 0.3, 0.0];
    let model = SingularityModel::PointDelta;
    for kind in [SingularityKind::Source, SingularityKind::Vortex] {
        let what = format!("{kind:?} {model:?}");
        assert_single(&design(kind, pos, true, model), pos, &format!("{what} natural"));
        // Ablation: Fisher et al.'s energy (div² + curl² with the boundary flux).
        let found = design(kind, pos, false, model);
        let spurious: Vec<_> = found.iter().filter(|s| s.index < 0.0).collect();
        assert!(
            !spurious.is_empty(),
            "{what} ablation: expected spurious saddles, found {found:?}"
        );
        // The source's spurious saddles sit near the boundary (the vortex's may not).
        for s in spurious.iter().filter(|_| kind == SingularityKind::Source) {
            let r = (s.position[0].powi(2) + s.position[1].powi(2)).sqrt();
            assert!(
                r > 0.6,
                "{what} ablation: spurious saddle at {:?} is not near the boundary",
                s.position
            );
        }
    }
    // The default model imposes the singularity's exact model field: one singularity
    // with or without the boundary term (the deviation from it is zero).
    for natural in [true, false] {
        let found = design(SingularityKind::Source, pos, natural, SingularityModel::ModelField);
        assert_single(&found, pos, &format!("ModelField natural={natural}"));
    }
}

#[test]
fn natural_boundary_keeps_a_two_stroke_design_free_of_singularities() {
    // Two strokes, no singularity: the Dirichlet-smoothest field has none; Fisher's
    // energy leaves the harmonic directions free and a spurious saddle appears.
    let strokes = [[[-0.6, -0.5, 0.0], [-0.6, 0.5, 0.0]], [[0.3, 0.6, 0.0], [0.7, 0.2, 0.0]]];
    for natural in [true, false] {
        let options = FieldDesignOptions { natural_boundary: natural, ..Default::default() };
        let mut d =
            FieldDesign::new(Domain::Mesh(disk_mesh(1.0, 24)), Symmetry::Vector, options).unwrap();
        for s in strokes {
            d.add_stroke(Stroke::new(s.to_vec())).unwrap();
        }
        let f = d.solve().unwrap();
        let found = detect_design_singularities(&d, &f, 1.5 * d.dec().mean_edge_length);
        let (mut lo, mut hi) = (f64::MAX, 0.0f64);
        for u in &f.face_vectors {
            let m = (u[0] * u[0] + u[1] * u[1]).sqrt();
            lo = lo.min(m);
            hi = hi.max(m);
        }
        if natural {
            assert!(found.is_empty(), "natural: {found:?}");
            assert!(lo > 0.2 && hi < 1.2, "natural: |u| in [{lo}, {hi}]");
        } else {
            assert!(
                found.iter().any(|s| s.index == -1.0),
                "ablation: expected a spurious saddle, found {found:?}"
            );
        }
    }
}
