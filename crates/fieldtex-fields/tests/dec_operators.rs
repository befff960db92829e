//! DEC operator invariants and the sign of the natural boundary term.

use fieldtex_fields::dec::Dec;
use fieldtex_fields::natural_boundary::boundary_term_value;
use fieldtex_fields::{PlaneGrid, disk_mesh};
use fieldtex_linalg::SparseMatrix;

fn one_form(dec: &Dec, f: impl Fn([f64; 3], [f64; 3]) -> f64) -> Vec<f64> {
    dec.topology
        .edges
        .iter()
        .map(|e| f(dec.positions[e[0] as usize], dec.positions[e[1] as usize]))
        .collect()
}

/// (div² + curl², boundary term) of a 1-form.
fn energies(dec: &Dec, omega: &[f64]) -> (f64, f64, f64) {
    let div =
        SparseMatrix::from_triplets(dec.n_vertices(), dec.n_edges(), &dec.divergence_triplets())
            .unwrap();
    let s = div.mul_vec(omega);
    let e_div: f64 = s.iter().zip(&dec.star0).map(|(s, a)| s * s / a).sum();
    let e_curl: f64 =
        (0..dec.n_faces()).map(|f| dec.face_curl(f, omega).powi(2) * dec.star2[f]).sum();
    (e_div, e_curl, boundary_term_value(dec, omega))
}

#[test]
fn d1_d0_vanishes_and_euler() {
    for mesh in [disk_mesh(1.0, 6), PlaneGrid::with_cells(40.0, 30.0, 8).mesh()] {
        let (dec, _) = Dec::new(&mesh).unwrap();
        assert_eq!(dec.topology.euler_characteristic(), 1);
        let d0 = dec.d0();
        let d1 = dec.d1();
        let f: Vec<f64> = (0..dec.n_vertices()).map(|v| (v as f64 * 0.37).sin()).collect();
        let w = d1.mul_vec(&d0.mul_vec(&f));
        assert!(w.iter().all(|x| x.abs() < 1e-12), "d1 d0 f != 0");
        assert!(dec.star0.iter().all(|a| *a > 0.0));
        assert!(dec.star1.iter().all(|a| *a >= 0.0));
    }
}

#[test]
fn whitney_reproduces_gradients_and_inverse_map() {
    let (dec, _) = Dec::new(&disk_mesh(2.0, 5)).unwrap();
    // f = 3x - 2y + 1: ω = d0 f, face vectors = (3, -2, 0) everywhere.
    let f = |p: [f64; 3]| 3.0 * p[0] - 2.0 * p[1] + 1.0;
    let omega = one_form(&dec, |a, b| f(b) - f(a));
    for u in dec.face_vectors(&omega) {
        assert!(
            (u[0] - 3.0).abs() < 1e-12 && (u[1] + 2.0).abs() < 1e-12 && u[2].abs() < 1e-12,
            "{u:?}"
        );
    }
    let u = dec.whitney_at(3, [0.2, 0.5, 0.3], &omega);
    assert!((u[0] - 3.0).abs() < 1e-12 && (u[1] + 2.0).abs() < 1e-12);
    let back = dec.one_form_from_face_vectors(&dec.face_vectors(&omega));
    for (a, b) in back.iter().zip(&omega) {
        assert!((a - b).abs() < 1e-12);
    }
}

#[test]
fn boundary_term_turns_div_curl_into_dirichlet_energy() {
    let (dec, _) = Dec::new(&disk_mesh(1.0, 16)).unwrap();
    let area: f64 = dec.face_areas.iter().sum();
    // Constant field: zero everywhere (Fisher's boundary-flux divergence included).
    let c = one_form(&dec, |a, b| 0.7 * (b[0] - a[0]) - 0.2 * (b[1] - a[1]));
    let (d, k, b) = energies(&dec, &c);
    assert!(d.abs() < 1e-20 && k.abs() < 1e-20 && b.abs() < 1e-12, "{d} {k} {b}");
    type EdgeIntegral = Box<dyn Fn([f64; 3], [f64; 3]) -> f64>;
    let fields: [(&str, EdgeIntegral); 3] = [
        ("(x, y)", Box::new(|a, b| 0.5 * (b[0] * b[0] + b[1] * b[1] - a[0] * a[0] - a[1] * a[1]))),
        ("(x, -y)", Box::new(|a, b| 0.5 * (b[0] * b[0] - b[1] * b[1] - a[0] * a[0] + a[1] * a[1]))),
        ("(-y, x)", Box::new(|a, b| a[0] * (b[1] - a[1]) - a[1] * (b[0] - a[0]))),
    ];
    for (name, f) in fields {
        let omega = one_form(&dec, f);
        let (d, k, b) = energies(&dec, &omega);
        let dirichlet = d + k - b;
        eprintln!(
            "{name}: div {d:.4} curl {k:.4} boundary {b:.4} -> {dirichlet:.4} (2A = {:.4})",
            2.0 * area
        );
        assert!(
            (dirichlet - 2.0 * area).abs() < 0.1 * area,
            "{name}: {dirichlet} vs {}",
            2.0 * area
        );
    }
}

#[test]
fn model_field_one_forms_are_exact_edge_integrals() {
    use fieldtex_fields::singular_model_field::{ModelField, ModelKind};
    let (dec, _) = Dec::new(&PlaneGrid::with_cells(10.0, 8.0, 10).mesh()).unwrap();
    for kind in [ModelKind::Pole, ModelKind::Saddle] {
        let m = ModelField {
            kind,
            origin: [4.37, 3.71, 0.0],
            e1: [1.0, 0.0, 0.0],
            e2: [0.0, 1.0, 0.0],
            c: [0.8, -0.6],
        };
        let mut omega = vec![0.0; dec.n_edges()];
        m.add_one_form(&dec, 1e-6, &mut omega);
        for (e, ed) in dec.topology.edges.iter().enumerate() {
            let (a, b) = (dec.positions[ed[0] as usize], dec.positions[ed[1] as usize]);
            let za = [a[0] - 4.37, a[1] - 3.71];
            let zb = [b[0] - 4.37, b[1] - 3.71];
            // Per-edge closed form and a 2000-point midpoint quadrature of u·dx.
            assert!((m.segment_integral(za, zb, 1e-6) - omega[e]).abs() < 1e-12);
            let n = 2000;
            let mut q = 0.0;
            for k in 0..n {
                let t = (k as f64 + 0.5) / n as f64;
                let z = [za[0] + t * (zb[0] - za[0]), za[1] + t * (zb[1] - za[1])];
                let u = m.value(z);
                q += (u[0] * (zb[0] - za[0]) + u[1] * (zb[1] - za[1])) / n as f64;
            }
            assert!(
                (q - omega[e]).abs() < 1e-4 * (1.0 + q.abs()),
                "{kind:?} edge {e}: {q} vs {}",
                omega[e]
            );
        }
        // A pole's circulation is 2π Im c around the triangle that holds it, 0 elsewhere.
        let curls: Vec<f64> = (0..dec.n_faces()).map(|f| dec.face_curl(f, &omega)).collect();
        let nonzero: Vec<_> = curls.iter().filter(|c| c.abs() > 1e-9).collect();
        if kind == ModelKind::Pole {
            assert_eq!(nonzero.len(), 1);
            assert!((nonzero[0] - 2.0 * std::f64::consts::PI * -0.6).abs() < 1e-9);
        }
    }
}
