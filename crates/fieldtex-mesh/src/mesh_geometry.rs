//! A per-mesh geometry object: topology, normals, areas and cotangent weights computed
//! at most once and handed out by reference (the `require_*` idea of geometry-central,
//! Sharp, Soliman & Crane).
//!
//! A pipeline builds one [`MeshGeometry`] over its repaired mesh and passes it to each
//! stage instead of each stage calling `Topology::build`, `vertex_normals` or
//! `cotan_edge_weights` again. Each quantity is computed on first request through a
//! `OnceLock`, so a shared `&MeshGeometry` can be used from parallel stages; the values
//! are exactly those of the free functions (`Topology::build`, [`crate::face_normals`],
//! [`crate::vertex_normals`], [`crate::face_areas`], [`crate::cotan_edge_weights`] with
//! default options), so switching a caller to the object never changes its output.
//! The mesh is borrowed: it cannot change while the object lives. Its triangle indices
//! must be in range (a validated or repaired mesh); the fallible request checks them.

use std::sync::OnceLock;

use crate::cotan_laplacian::{CotanOptions, cotan_edge_weights};
use crate::normals::{NormalWeighting, face_normals, vertex_normals};
use crate::{MeshError, Topology, TriMesh};
use fieldtex_core::Warning;
use fieldtex_core::vec3::V3;

/// Cotangent edge weights with their warnings, or why they could not be computed.
type WeightsOrError = Result<(Vec<f64>, Vec<Warning>), MeshError>;

/// Lazily computed geometry of one mesh (module docs).
#[derive(Debug)]
pub struct MeshGeometry<'m> {
    mesh: &'m TriMesh,
    topology: OnceLock<Topology>,
    face_normals: OnceLock<Vec<V3>>,
    face_areas: OnceLock<Vec<f64>>,
    /// Vertex normals per weighting (`Angle`, `Area`, `Uniform`) with their warnings.
    vertex_normals: [OnceLock<(Vec<V3>, Vec<Warning>)>; 3],
    cotan_edge_weights: OnceLock<WeightsOrError>,
}

impl<'m> MeshGeometry<'m> {
    /// An object over `mesh`; nothing is computed yet.
    pub fn new(mesh: &'m TriMesh) -> Self {
        Self {
            mesh,
            topology: OnceLock::new(),
            face_normals: OnceLock::new(),
            face_areas: OnceLock::new(),
            vertex_normals: [OnceLock::new(), OnceLock::new(), OnceLock::new()],
            cotan_edge_weights: OnceLock::new(),
        }
    }

    /// The mesh.
    pub fn mesh(&self) -> &'m TriMesh {
        self.mesh
    }

    /// Edges, face ↔ edge incidence and adjacency (`Topology::build`).
    pub fn require_topology(&self) -> &Topology {
        self.topology.get_or_init(|| Topology::build(self.mesh.n_vertices(), &self.mesh.triangles))
    }

    /// `#F` unit face normals ([`crate::face_normals`]).
    pub fn require_face_normals(&self) -> &[V3] {
        self.face_normals.get_or_init(|| face_normals(self.mesh))
    }

    /// `#F` triangle areas ([`crate::face_areas`]).
    pub fn require_face_areas(&self) -> &[f64] {
        self.face_areas.get_or_init(|| crate::areas::face_areas(self.mesh))
    }

    /// `#V` unit vertex normals with the given weighting and the warnings of their
    /// computation ([`crate::vertex_normals`]).
    pub fn require_vertex_normals(&self, weighting: NormalWeighting) -> (&[V3], &[Warning]) {
        let slot = match weighting {
            NormalWeighting::Angle => 0,
            NormalWeighting::Area => 1,
            NormalWeighting::Uniform => 2,
        };
        let (n, w) = self.vertex_normals[slot].get_or_init(|| vertex_normals(self.mesh, weighting));
        (n, w)
    }

    /// `#E` cotangent edge weights indexed like [`Self::require_topology`]'s edges, with
    /// the default relative area floor ([`crate::cotan_edge_weights`]), and the warnings.
    pub fn require_cotan_edge_weights(&self) -> Result<(&[f64], &[Warning]), MeshError> {
        let r = self.cotan_edge_weights.get_or_init(|| {
            crate::checks::check_indices(self.mesh)?;
            cotan_edge_weights(self.mesh, self.require_topology(), &CotanOptions::default())
        });
        match r {
            Ok((w, warn)) => Ok((w, warn)),
            Err(e) => Err(e.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives::icosphere;

    #[test]
    fn quantities_equal_the_free_functions_and_are_computed_once() {
        let m = icosphere(2);
        let g = MeshGeometry::new(&m);
        let t = Topology::build(m.n_vertices(), &m.triangles);
        assert_eq!(g.require_topology().edges, t.edges);
        assert!(std::ptr::eq(g.require_topology(), g.require_topology()));
        assert_eq!(g.require_face_normals(), &face_normals(&m)[..]);
        assert_eq!(g.require_face_areas(), &crate::areas::face_areas(&m)[..]);
        for w in [NormalWeighting::Angle, NormalWeighting::Area, NormalWeighting::Uniform] {
            assert_eq!(g.require_vertex_normals(w).0, &vertex_normals(&m, w).0[..]);
        }
        let (cw, _) = cotan_edge_weights(&m, &t, &CotanOptions::default()).unwrap();
        assert_eq!(g.require_cotan_edge_weights().unwrap().0, &cw[..]);
        let p = g.require_cotan_edge_weights().unwrap().0.as_ptr();
        assert_eq!(p, g.require_cotan_edge_weights().unwrap().0.as_ptr());
    }

    #[test]
    fn bad_indices_are_an_error_not_a_panic() {
        let mut m = icosphere(0);
        m.triangles[0][0] = 999;
        let g = MeshGeometry::new(&m);
        assert!(g.require_cotan_edge_weights().is_err());
    }
}
