//! Reference frames on a curved patch (paper D, §3): the x-axis of the local frames is
//! the smoothest field (natural-boundary design) with one fixed vector, so that the
//! doubled-angle representation of an orientation field is measured against a smooth
//! frame. On a flat patch this gives a constant frame; on a curved one it is the
//! Dirichlet-smoothest frame, whose holonomy is ignored (the orientation square root
//! is taken per triangle in its own frame — a documented approximation).

use fieldtex_core::vec3::{add, dot, scale, sub};
use fieldtex_linalg::Cholesky;

use crate::FieldsError;
use crate::dec::Dec;
use crate::domain::{Frame, locate_in_mesh, projected_frames};

/// Frames from the field of least design energy whose three edge values on the triangle
/// nearest the vertex centroid are fixed to those of its first edge direction (hard
/// constraints, by three solves with the factor of the design matrix `A`:
/// `ω = Σ_k λ_k A⁻¹ e_k` with `ω[e_j] = t_j`).
pub fn reference_frames(dec: &Dec, factor: &Cholesky) -> Result<Vec<Frame>, FieldsError> {
    let centroid = scale(
        dec.positions.iter().fold([0.0; 3], |a, p| add(a, *p)),
        1.0 / dec.n_vertices() as f64,
    );
    let (f0, _, _) = locate_in_mesh(dec, centroid).expect("validated mesh has triangles");
    let tri = dec.triangles[f0];
    let dir = sub(dec.positions[tri[1] as usize], dec.positions[tri[0] as usize]);
    let edges: Vec<usize> = (0..3).map(|k| dec.topology.face_edges[f0][k] as usize).collect();
    let targets: Vec<f64> = edges.iter().map(|&e| dot(dir, dec.edge_vector(e))).collect();
    let basis: Vec<Vec<f64>> = edges
        .iter()
        .map(|&e| {
            let mut b = vec![0.0; dec.n_edges()];
            b[e] = 1.0;
            b
        })
        .collect();
    let cols = factor.solve_many(&basis)?;
    let g: Vec<[f64; 3]> = (0..3).map(|j| std::array::from_fn(|k| cols[k][edges[j]])).collect();
    let lambda = solve3([g[0], g[1], g[2]], [targets[0], targets[1], targets[2]]);
    let mut omega = vec![0.0; dec.n_edges()];
    for k in 0..3 {
        for (o, c) in omega.iter_mut().zip(&cols[k]) {
            *o += lambda[k] * c;
        }
    }
    Ok(projected_frames(dec, &dec.face_vectors(&omega)))
}

/// Solves a 3×3 system by Cramer's rule (zero where singular).
fn solve3(m: [[f64; 3]; 3], r: [f64; 3]) -> [f64; 3] {
    let det = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(m);
    if d.abs() < 1e-300 || !d.is_finite() {
        return [0.0; 3];
    }
    std::array::from_fn(|k| {
        let mut a = m;
        for (row, rv) in a.iter_mut().zip(r) {
            row[k] = rv;
        }
        det(a) / d
    })
}
