//! Conformal polish of a chart layout (our addition; the paper's map is its anchor).
//!
//! The integrated holomorphic form is exactly conformal in the smooth setting, but on a
//! piecewise-linear mesh its per-triangle angle distortion stays at 1.05–1.08 on coarse
//! or sharply curved meshes, and with its periods fixed it cannot do better (the
//! harmonic parts already minimise the conformal energy, docs/conformal.md). Once the
//! layout is cut into charts, though, the charts need not differ by translations across
//! their seams: the margins are drawn by similarity ghosts either way. Each chart is
//! therefore re-solved as a least squares conformal map (Lévy, Petitjean, Ray & Maillot
//! 2002, eq. 5) with a free boundary, held near the holomorphic map by a weak
//! area-weighted data term ([`crate::lscm::lscm_anchored`], weight [`POLISH_WEIGHT`]):
//! the LSCM rows remove the angle error at the scale of a few triangles, while the
//! anchor keeps what varies slowly — the conformal factor chosen by the uniform form,
//! each chart's place and orientation — from the paper's map.
//!
//! Applied to the slit cylinder (which then loses its periodic seam: one chart, drawn
//! with similarity ghosts across the former seam) and to critical-trajectory patch
//! layouts; the torus image keeps its lattice. A chart whose polished map folds a
//! triangle keeps its holomorphic corners; the whole polish is dropped when it does not
//! lower the mean angle distortion. The charts are repacked and every seam's margin is
//! drawn by similarity ghosts (as after [`super::patch_relaxation`]).
//!
//! The gain comes only from the free chart boundaries (with the boundary held, the
//! polish changes nothing), so the two sides of every seam move apart a little and a
//! first-order similarity ghost no longer continues a chart exactly, where the
//! translation ghosts of the integrated map were exact: the seam colour jump rises
//! (docs/conformal.md, session 16). So the polish runs only where the integrated map's
//! angle distortion away from singularities is above [`POLISH_ABOVE`]; below it the
//! exact seams are worth more than the last percent of conformality.

use super::ComponentMap;
use super::mass_spring::{MapDistortion, map_distortion};
use super::patch_relaxation::{repack_with_similarity_ghosts, split_by_chart};
use super::periodic_uv::signed_area;
use crate::chart_topology::ChartMesh;
use crate::face_graph::FaceGraph;
use crate::lscm::lscm_anchored;
use fieldtex_mesh::{Topology, TriMesh};
use rayon::prelude::*;
use serde::Serialize;

/// Weight of the data term that holds each chart near the holomorphic map, relative to
/// the LSCM energy (both in squared UV units; see [`crate::lscm::lscm_anchored`]): much
/// heavier keeps the holomorphic map's angle error, much lighter lets the conformal
/// factor drift (the sweep is in docs/conformal.md, session 16).
pub const POLISH_WEIGHT: f64 = 3e-4;

/// Mean angle distortion `σ1/σ2` away from singularities above which a map is polished
/// (module docs).
pub const POLISH_ABOVE: f64 = 1.04;

/// Parameters of [`polish_layout`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PolishOptions {
    /// Data weight ([`POLISH_WEIGHT`]).
    pub weight: f64,
    /// Polish only maps whose mean `σ1/σ2` away from singularities exceeds this
    /// ([`POLISH_ABOVE`]).
    pub above: f64,
}

impl Default for PolishOptions {
    fn default() -> Self {
        Self { weight: POLISH_WEIGHT, above: POLISH_ABOVE }
    }
}

/// A face of the split mesh and its polished corners.
type FaceCorners = (u32, [[f64; 2]; 3]);

/// What [`polish_layout`] did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PolishStats {
    /// Charts (connected pieces of the layout); 0 when the map was not polished
    /// because its angle distortion away from singularities is at most [`POLISH_ABOVE`].
    pub charts: usize,
    /// Charts that kept their holomorphic corners because the polished map folded.
    pub charts_kept: usize,
    /// Whether the polished map replaced the integrated one.
    pub applied: bool,
    /// Mean `σ1/σ2` away from singularities before and after (equal when not applied).
    pub away_before: f64,
    pub away_after: f64,
    /// Distortion over the non-slit faces before and after.
    pub before: MapDistortion,
    pub after: MapDistortion,
}

/// Polishes the first `n_faces` faces of `map` on `mesh` (module docs) when their mean
/// `σ1/σ2` away from singularities exceeds `options.above`; `original` names each vertex's
/// surface point for the seams (as for [`super::patch_relaxation::relax_patches`]),
/// `slit(f)` marks the faces left out of the distortion statistics and `near(f)` those
/// near a singularity as well. `None` when the map has no UVs.
pub fn polish_layout(
    mesh: &TriMesh,
    n_faces: usize,
    map: &mut ComponentMap,
    original: &[u32],
    slit: &dyn Fn(usize) -> bool,
    near: &dyn Fn(usize) -> bool,
    options: &PolishOptions,
) -> Option<PolishStats> {
    let PolishOptions { weight, above } = *options;
    let n = n_faces.min(map.corner.len()).min(mesh.n_triangles());
    if n == 0 {
        return None;
    }
    let before = map_distortion(mesh, n, &map.corner[..n], slit);
    let away_before = map_distortion(mesh, n, &map.corner[..n], near).angle_mean;
    // The map left as it was.
    let unchanged = |charts: usize, charts_kept: usize| PolishStats {
        charts,
        charts_kept,
        applied: false,
        away_before,
        away_after: away_before,
        before,
        after: before,
    };
    if away_before.is_nan() || away_before <= above {
        return Some(unchanged(0, 0));
    }
    let (split, anchor) = split_by_chart(mesh, n, map);
    let topo = Topology::build(split.n_vertices(), &split.triangles);
    let (label, n_charts) = topo.face_components(&split.triangles);
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); n_charts];
    for (f, &c) in label.iter().enumerate() {
        members[c as usize].push(f as u32);
    }
    let graph = FaceGraph::build(&split);
    // Each chart on its own (independent solves, so any thread count gives the same
    // corners); `None` keeps the chart's holomorphic corners.
    let solved: Vec<Option<Vec<FaceCorners>>> = members
        .into_par_iter()
        .map(|faces| {
            let chart = ChartMesh::build(faces, &graph, &split.triangles);
            let local_anchor: Vec<[f64; 2]> =
                chart.vertex_global.iter().map(|&v| anchor[v as usize]).collect();
            let mut uv = lscm_anchored(&chart, &split, &graph, &local_anchor, weight).ok()?;
            similarity_fit(&mut uv, &local_anchor);
            let corners: Vec<FaceCorners> = chart
                .faces
                .iter()
                .zip(&chart.corners)
                .map(|(&f, c)| (f, c.map(|v| uv[v as usize])))
                .collect();
            corners
                .iter()
                .all(|(_, c)| {
                    let a = signed_area(c);
                    a.is_finite() && a > 0.0
                })
                .then_some(corners)
        })
        .collect();
    let mut moved = map.corner[..n].to_vec();
    let mut kept = 0;
    for chart in &solved {
        match chart {
            Some(corners) => {
                for &(f, c) in corners {
                    moved[f as usize] = c;
                }
            }
            None => kept += 1,
        }
    }
    let after = map_distortion(mesh, n, &moved, slit);
    let lower = after.angle_mean.partial_cmp(&before.angle_mean) == Some(std::cmp::Ordering::Less);
    if kept == n_charts || after.flipped > 0 || !lower {
        return Some(unchanged(n_charts, kept));
    }
    let away_after = map_distortion(mesh, n, &moved, near).angle_mean;
    repack_with_similarity_ghosts(mesh, n, map, original, moved);
    Some(PolishStats {
        charts: n_charts,
        charts_kept: kept,
        applied: true,
        away_before,
        away_after,
        before,
        after,
    })
}

/// Moves `uv` by the similarity `z ↦ a z + b` (complex `a`, `b`) that brings it closest
/// to `anchor` in least squares over the vertices: the weak data term lets a chart
/// shrink a little (the LSCM energy scales with its size), and this restores its scale,
/// rotation and place without touching its angles.
fn similarity_fit(uv: &mut [[f64; 2]], anchor: &[[f64; 2]]) {
    let n = uv.len().min(anchor.len());
    if n < 2 {
        return;
    }
    let mean = |p: &[[f64; 2]]| {
        let s = p[..n].iter().fold([0.0, 0.0], |s, q| [s[0] + q[0], s[1] + q[1]]);
        [s[0] / n as f64, s[1] / n as f64]
    };
    let (zc, oc) = (mean(uv), mean(anchor));
    let (mut zz, mut re, mut im) = (0.0, 0.0, 0.0);
    for (z, o) in uv.iter().zip(anchor) {
        let z = [z[0] - zc[0], z[1] - zc[1]];
        let o = [o[0] - oc[0], o[1] - oc[1]];
        zz += z[0] * z[0] + z[1] * z[1];
        re += z[0] * o[0] + z[1] * o[1];
        im += z[0] * o[1] - z[1] * o[0];
    }
    if zz.is_nan() || zz <= 0.0 {
        return;
    }
    let a = [re / zz, im / zz];
    for z in uv.iter_mut() {
        let d = [z[0] - zc[0], z[1] - zc[1]];
        *z = [a[0] * d[0] - a[1] * d[1] + oc[0], a[0] * d[1] + a[1] * d[0] + oc[1]];
    }
}
