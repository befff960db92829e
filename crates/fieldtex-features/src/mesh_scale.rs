//! Length scales of a mesh that make the detector's thresholds scale-invariant.

use crate::FeaturesError;
use fieldtex_core::vec3;
use fieldtex_mesh::{Topology, TriMesh};

/// The mean length of the mesh's unique edges (the unit of every distance option of
/// this crate, "mean edge lengths"). Zero-length edges count. Returns
/// [`FeaturesError::EmptyMesh`] for a mesh without triangles and
/// [`FeaturesError::NoLengthScale`] when the mean is zero or not finite.
pub fn mean_edge_length(mesh: &TriMesh) -> Result<f64, FeaturesError> {
    if mesh.triangles.is_empty() {
        return Err(FeaturesError::EmptyMesh);
    }
    mesh.validate()?;
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    mean_edge_length_of(mesh, &topo)
}

/// [`mean_edge_length`] for a mesh whose topology is already built.
pub(crate) fn mean_edge_length_of(mesh: &TriMesh, topo: &Topology) -> Result<f64, FeaturesError> {
    let n = topo.n_edges();
    let sum: f64 = topo
        .edges
        .iter()
        .map(|e| {
            vec3::norm(vec3::sub(mesh.positions[e[0] as usize], mesh.positions[e[1] as usize]))
        })
        .sum();
    let mean = sum / n.max(1) as f64;
    if mean > 0.0 && mean.is_finite() {
        Ok(mean)
    } else {
        Err(FeaturesError::NoLengthScale { n_edges: n })
    }
}
