//! User-given curves as salient curves on a mesh: located on (and optionally snapped
//! to) the surface, preprocessed like detected crest lines, and given a strength.
//!
//! This is the "users can pass their own curves" path of paper A's pipeline (the
//! orientation step does not care where curves come from). Every point gets its
//! nearest triangle (the mesh's BVH, `fieldtex_mesh::Bvh::closest_points`); with
//! [`GivenCurvesOptions::snap_to_surface`] the point also moves to the closest surface
//! point. Strength is `∫ max(|k_max|, |k_min|) ds` (for ordering only: nothing is
//! dropped by strength, every curve gets level 0).

use crate::FeaturesError;
use crate::crest_lines::{CrestLines, CrestStats, assign_strength_and_levels};
use crate::curve_preprocessing::{
    CurvePreprocessOptions, check_finite, given_line, preprocess_lines,
};
use crate::mesh_scale::mean_edge_length_of;
use fieldtex_core::Warning;
use fieldtex_core::vec3::V3;
use fieldtex_mesh::{Bvh, CurvatureOptions, Topology, TriMesh};
use serde::Serialize;

/// Options of [`given_curves`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GivenCurvesOptions {
    /// Move every point to the closest surface point. Default `true`.
    pub snap_to_surface: bool,
    /// Joining, breaking and minimum length in mean edge lengths; `None` keeps the
    /// curves as given. Default `Some(CurvePreprocessOptions::default())`.
    pub preprocess: Option<CurvePreprocessOptions>,
}

impl Default for GivenCurvesOptions {
    fn default() -> Self {
        Self { snap_to_surface: true, preprocess: Some(CurvePreprocessOptions::default()) }
    }
}

/// `curves` (polylines in mesh coordinates) as [`CrestLines`] of kind
/// [`crate::LineKind::Given`] on `mesh` (module docs). Curves with fewer than two
/// points are dropped; a non-finite point is an error. Points far from the surface
/// are kept (and snapped when asked); a warning reports the largest distance when it
/// exceeds two mean edge lengths.
pub fn given_curves(
    mesh: &TriMesh,
    curves: &[Vec<V3>],
    options: &GivenCurvesOptions,
) -> Result<CrestLines, FeaturesError> {
    if let Some(p) = &options.preprocess {
        p.validate()?;
    }
    if mesh.triangles.is_empty() {
        return Err(FeaturesError::EmptyMesh);
    }
    mesh.validate()?;
    check_finite(curves)?;
    let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
    let h = mean_edge_length_of(mesh, &topo)?;
    let diagonal = mesh.bounding_box().map_or(0.0, |b| b.diagonal());
    let bvh = Bvh::build(mesh)?;
    let mut farthest: f64 = 0.0;
    let mut lines = Vec::with_capacity(curves.len());
    for c in curves.iter().filter(|c| c.len() >= 2) {
        let located: Vec<(V3, u32)> = bvh
            .closest_points(c)
            .into_iter()
            .zip(c)
            .map(|(q, &p)| q.map_or((p, 0), |q| (q.point, q.triangle)))
            .collect();
        for (p, (q, _)) in c.iter().zip(&located) {
            farthest = farthest.max(fieldtex_core::vec3::norm(fieldtex_core::vec3::sub(*p, *q)));
        }
        let points =
            if options.snap_to_surface { located.iter().map(|x| x.0).collect() } else { c.clone() };
        lines.push(given_line(points, located.iter().map(|x| x.1).collect()));
    }
    let raw = lines.len();
    if let Some(p) = &options.preprocess {
        lines = preprocess_lines(lines, h, p);
    }
    let preprocessed = lines.len();
    let (curv, mut warnings) =
        fieldtex_mesh::principal_curvatures(mesh, &CurvatureOptions::default())?;
    let lines = assign_strength_and_levels(mesh, &curv, &[], lines, &[]);
    if farthest > 2.0 * h {
        warnings.push(Warning::new(
            "curves-off-surface",
            format!(
                "a given curve point lies {:.3} mean edge lengths from the surface; check that \
                 the curves belong to this mesh and its coordinates",
                farthest / h
            ),
        ));
    }
    let stats = CrestStats {
        mean_edge_length: h,
        diagonal,
        raw_lines: raw,
        preprocessed_lines: preprocessed,
        lines: lines.len(),
        ..Default::default()
    };
    Ok(CrestLines { lines, stats, warnings })
}
