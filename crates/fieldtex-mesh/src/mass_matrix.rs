//! Lumped (diagonal) mass matrix.
//!
//! `M = diag(m)` with `m_i` the area share of vertex `i` ([`crate::areas`]):
//! barycentric (a third of each incident triangle; default) or mixed Voronoi (Meyer et
//! al. 2003). `Σ m_i` is the total surface area. Unreferenced vertices and vertices that
//! touch only zero-area triangles get `m_i = 0`, which makes `M` singular there: systems
//! such as `M + t L` need those rows handled (the heat method drops unreferenced vertices
//! and regularises zero masses; see [`crate::heat_geodesic`]).
//!
//! Together with [`crate::cotan_laplacian`] (`L` positive semi-definite), `−M⁻¹ L`
//! is the usual discrete Laplace–Beltrami operator. The consistent (non-diagonal) FEM
//! mass matrix is not implemented.

use crate::areas::{VertexAreaKind, vertex_areas};
use crate::{MeshError, TriMesh};
use fieldtex_linalg::SparseMatrix;

/// `#V` lumped masses (the diagonal of `M`).
pub fn lumped_mass(mesh: &TriMesh, kind: VertexAreaKind) -> Result<Vec<f64>, MeshError> {
    crate::checks::check_indices(mesh)?;
    Ok(vertex_areas(mesh, kind))
}

/// The `#V × #V` diagonal mass matrix `M` (every diagonal entry stored, zeros included).
pub fn mass_matrix(mesh: &TriMesh, kind: VertexAreaKind) -> Result<SparseMatrix, MeshError> {
    Ok(SparseMatrix::from_diagonal(&lumped_mass(mesh, kind)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::areas::total_area;
    use crate::primitives::{icosphere, torus};

    #[test]
    fn mass_sums_to_area_and_is_diagonal() {
        for m in [icosphere(3), torus(1.5, 0.4, 30, 12)] {
            let a = total_area(&m);
            for kind in [VertexAreaKind::Barycentric, VertexAreaKind::MixedVoronoi] {
                let mm = mass_matrix(&m, kind).unwrap();
                assert_eq!(mm.nnz(), m.n_vertices());
                let s: f64 = mm.diagonal().iter().sum();
                assert!((s - a).abs() < 1e-12 * a);
                assert!(mm.diagonal().iter().all(|&d| d > 0.0));
            }
        }
    }

    #[test]
    fn mass_sums_to_area_over_categories_and_fixtures() {
        let fixtures = ["fertility.obj", "stanford-bunny.obj", "defects/narrow_triangles.obj"];
        let all = crate::test_meshes::categories_and(&fixtures);
        for (name, m) in &all {
            let a = total_area(m);
            for kind in [VertexAreaKind::Barycentric, VertexAreaKind::MixedVoronoi] {
                let d = lumped_mass(m, kind).unwrap();
                assert!(d.iter().all(|x| x.is_finite() && *x >= 0.0), "{name}");
                let s: f64 = d.iter().sum();
                assert!((s - a).abs() <= 1e-9 * a, "{name} {kind:?}: {s} vs {a}");
            }
        }
    }

    #[test]
    fn unreferenced_vertex_has_zero_mass_and_bad_index_is_an_error() {
        let mut m = icosphere(1);
        m.positions.push([5.0, 5.0, 5.0]);
        let d = lumped_mass(&m, VertexAreaKind::Barycentric).unwrap();
        assert_eq!(*d.last().unwrap(), 0.0);
        m.triangles.push([0, 1, 999]);
        assert!(matches!(
            lumped_mass(&m, VertexAreaKind::MixedVoronoi),
            Err(MeshError::IndexOutOfRange { index: 999, .. })
        ));
    }
}
