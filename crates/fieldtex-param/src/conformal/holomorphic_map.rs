//! Closed surfaces of genus `g ≥ 1`: the holomorphic 1-form basis (Gu & Yau 2003) and,
//! for `g = 1`, the global conformal map onto one periodic rectangle.
//!
//! Steps: tree–cotree generators → closed forms `η_k` of their dual loops → harmonic
//! forms `ω_k` ([`super::harmonic_one_forms`]) → conjugates `⋆ω_k`
//! ([`super::holomorphic_basis`]) → a holomorphic form `φ = ω + i ⋆ω`. For `g = 1` the
//! space is one complex dimension, so `φ` is unique up to a complex factor; we rotate it
//! so that the first period is real. Then the horizontal trajectories (iso-v curves) are
//! closed, the torus cut along one of them is a cylinder, and `∫φ` maps it onto the
//! rectangle `[0, |z1|) × [0, Im z2)` whose sides are identified by `(|z1|, 0)` and
//! `z2` — one conformal geometry image without zero points.
//!
//! For `g ≥ 2` the paper picks the most uniform combination (Jin, Wang, Yau & Gu 2004)
//! and cuts along critical trajectories. Implemented here: the basis, its conjugates,
//! the combination with the most uniform conformal factor ([`super::uniform_form`], a
//! compass search — a substitute for Jin et al.'s solver) and its zero points; then the critical
//! horizontal trajectories through the zero points ([`super::critical_trajectories`])
//! cut the surface into patches, each mapped by `∫φ` ([`super::translation_patches`]).
//! Optionally ([`HOMOLOGY_LOOPS`], off: it did not shorten fertility's seams) a short
//! homology basis ([`super::homology_loops`]) is cut first and the trajectories stop at it.

use super::cotan_system::{FixedLaplacian, conformal_error, edge_weights};
use super::critical_trajectories::critical_trajectories;
use super::cut_graph;
use super::harmonic_one_forms::{face_areas_normals, face_vectors, harmonic_projection};
use super::holomorphic_basis::conjugates;
use super::homology_loops::shortest_homology_basis;
use super::periodic_uv::{Lattice, along2, integrate, reduce_basis, reduce_faces, signed_area};
use super::seam_placement::shortest_level;
use super::translation_patches::{PatchOptions, translation_patches};
use super::tree_cotree::tree_cotree;
use super::uniform_form::most_uniform_form;
use super::zero_points::vertex_indices;
use super::{ComponentMap, ConformalMethod};
use crate::ParamError;
use fieldtex_core::vec3;
use fieldtex_mesh::{CotanOptions, Topology, TriMesh, cotan_face_weights};

/// Length budget of a critical trajectory, in units of `√(surface area)`.
pub const TRAJECTORY_LENGTH: f64 = 0.15;
/// Largest patch piece side, in units of `√(UV area)`.
pub const PIECE_SIDE: f64 = 3.0;
/// Candidate levels tried for each period seam of a torus image.
pub const SEAM_LEVELS: usize = 64;
/// Objective evaluations of the most-uniform-form search.
pub const UNIFORM_FORM_EVALS: usize = 400;
/// Cut genus ≥ 2 surfaces along the shortest homology loops as well as the critical
/// trajectories ([`super::homology_loops`]).
pub const HOMOLOGY_LOOPS: bool = false;
/// Candidate base points (besides the zero points) whose loop systems feed the
/// homology basis, spread by vertex index.
pub const LOOP_BASES: usize = 32;
/// Face rings drawn as ghosts beyond each cut (image margins, §4.2).
pub const GHOST_RINGS: usize = 1;
/// Also cut along the spanning tree of shortest paths joining the kept region's
/// openings and the zero points ([`super::cut_graph`]).
pub const SPANNING_CUT: bool = true;

/// How a genus ≥ 2 surface is cut into patches ([`holomorphic_map_with`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayoutOptions {
    /// Length budget of a critical trajectory, × `√area` ([`TRAJECTORY_LENGTH`]).
    pub trajectory_length: f64,
    /// Largest patch piece side, × `√(UV area)` ([`PIECE_SIDE`]).
    pub piece_side: f64,
    /// Merge patches into maximal injective charts ([`super::patch_merging`]).
    pub merge: bool,
    /// Cut along a short homology basis first ([`HOMOLOGY_LOOPS`]).
    pub homology_loops: bool,
    /// Cut along the spanning tree of the openings and zero points as well
    /// ([`SPANNING_CUT`]).
    pub spanning_cut: bool,
}

impl Default for LayoutOptions {
    fn default() -> Self {
        Self {
            trajectory_length: TRAJECTORY_LENGTH,
            piece_side: PIECE_SIDE,
            merge: true,
            homology_loops: HOMOLOGY_LOOPS,
            spanning_cut: SPANNING_CUT,
        }
    }
}

/// Holomorphic data and the UV map of a closed genus-`g ≥ 1` mesh.
/// For `g ≥ 2` only the first `n_keep` faces get UVs (the input's faces of a capped or
/// doubled mesh).
pub fn holomorphic_map(
    mesh: &TriMesh,
    genus: usize,
    n_keep: usize,
) -> Result<ComponentMap, ParamError> {
    holomorphic_map_with(mesh, genus, n_keep, &LayoutOptions::default())
}

/// [`holomorphic_map`] with the genus ≥ 2 layout options given.
pub fn holomorphic_map_with(
    mesh: &TriMesh,
    genus: usize,
    n_keep: usize,
    options: &LayoutOptions,
) -> Result<ComponentMap, ParamError> {
    let LayoutOptions { trajectory_length, piece_side, merge, homology_loops: loops, spanning_cut } =
        *options;
    let nv = mesh.n_vertices();
    let nf = mesh.n_triangles();
    let tris = &mesh.triangles;
    let topo = Topology::build(nv, tris);
    let tc = tree_cotree(&topo);
    if tc.generators.len() != 2 * genus {
        return Err(conformal_error(&format!(
            "tree–cotree found {} generators, expected 2g = {}",
            tc.generators.len(),
            2 * genus
        )));
    }
    let keep = vec![true; nf];
    let (half_cot, _) = cotan_face_weights(mesh, &CotanOptions::default())?;
    let w = edge_weights(&topo, &half_cot, &keep);
    let fixed: Vec<Option<f64>> = (0..nv)
        .map(|v| if v == 0 || topo.vertex_faces(v).is_empty() { Some(0.0) } else { None })
        .collect();
    let lap = FixedLaplacian::new(&topo, &w, &fixed)?;
    let mut forms = Vec::with_capacity(tc.generators.len());
    let mut cocycles = Vec::with_capacity(tc.generators.len());
    for &g in &tc.generators {
        let eta = tc.dual_loop_form(&topo, g);
        forms.push(harmonic_projection(&topo, &w, &lap, &eta)?);
        cocycles.push(eta);
    }
    let xs: Vec<Vec<[f64; 3]>> =
        forms.iter().map(|om| face_vectors(&topo, &mesh.positions, tris, om, &keep)).collect();
    let (areas, normals) = face_areas_normals(mesh);
    let conj = conjugates(&forms, &w, &xs, &areas, &normals)?;
    // Genus 1: the form is unique up to a complex factor (the best basis form, no
    // search). Genus ≥ 2: the combination with the most uniform conformal factor.
    let evals = if genus >= 2 { UNIFORM_FORM_EVALS } else { 0 };
    let uniform = most_uniform_form(&xs, &areas, evals);
    let a = uniform.coefficients.clone();
    let x_re: Vec<[f64; 3]> = (0..nf)
        .map(|f| (0..xs.len()).fold([0.0; 3], |v, k| vec3::add(v, vec3::scale(xs[k][f], a[k]))))
        .collect();
    let zero_points =
        vertex_indices(&mesh.positions, tris, |v| topo.vertex_faces(v).to_vec(), &x_re, &keep);
    // ⋆(Σ a_k ω_k) = Σ_k a_k Σ_j c_kj ω_j.
    let b: Vec<f64> = (0..forms.len())
        .map(|j| (0..forms.len()).map(|k| a[k] * conj.coefficients[k][j]).sum())
        .collect();
    let mut d: Vec<[f64; 2]> = (0..topo.n_edges())
        .map(|e| {
            let re: f64 = (0..forms.len()).map(|k| a[k] * forms[k][e]).sum();
            let im: f64 = (0..forms.len()).map(|j| b[j] * forms[j][e]).sum();
            [re, im]
        })
        .collect();
    if genus >= 2 {
        // Orientation: ∇v = n × ∇u keeps it, but guard against a reversed discrete star.
        let positive: f64 = (0..nf)
            .map(|f| {
                let c = [[0.0, 0.0], along2(&topo, &d, f, 0, 1), along2(&topo, &d, f, 0, 2)];
                signed_area(&c).signum()
            })
            .sum();
        if positive < 0.0 {
            for v in d.iter_mut() {
                v[0] = -v[0];
            }
        }
        let zeros: Vec<u32> = zero_points.iter().map(|z| z.0).collect();
        let area: f64 = areas.iter().sum();
        // A short homology basis opens every handle; the trajectories then split the
        // cone angle at the zeros and stop at the loops.
        let loop_cut = if loops {
            let mut roots = zeros.clone();
            roots.extend((0..nv as u32).step_by((nv / LOOP_BASES).max(1)));
            shortest_homology_basis(&mesh.positions, &topo, &cocycles, &roots)
                .map_or_else(|| vec![false; topo.n_edges()], |s| s.cut)
        } else {
            Vec::new()
        };
        let mut on_loop = vec![false; nv];
        for (e, _) in loop_cut.iter().enumerate().filter(|(_, c)| **c) {
            for v in topo.edges[e] {
                on_loop[v as usize] = true;
            }
        }
        let (trajectories, cut) = critical_trajectories(
            &mesh.positions,
            tris,
            &topo,
            &d,
            &zeros,
            trajectory_length * area.sqrt(),
            &on_loop,
        );
        let kept: Vec<bool> = (0..nf).map(|f| f < n_keep).collect();
        // The trajectories and the spanning tree of the openings and the zero points.
        let cut = if spanning_cut {
            let cones: Vec<u32> = zero_points.iter().filter(|z| z.1 < 0).map(|z| z.0).collect();
            let span = cut_graph::spanning_cut(&mesh.positions, &topo, &kept, &cones);
            cut.iter().zip(&span).map(|(&a, &b)| a || b).collect()
        } else {
            cut
        };
        let all_cut: Vec<bool> =
            (0..cut.len()).map(|e| cut[e] || loop_cut.get(e).is_some_and(|&c| c)).collect();
        let layout = translation_patches(
            &mesh.positions,
            tris,
            &topo,
            &d,
            &all_cut,
            &kept,
            PatchOptions { rings: GHOST_RINGS, piece_side, merge },
        );
        return Ok(ComponentMap {
            method: ConformalMethod::CriticalTrajectoryPatches,
            corner: layout.corner,
            base: vec![[f64::NAN; 2]; nv],
            apex: vec![None; nf],
            zero_points,
            conjugate_residual: conj.residual,
            conjugate_residual_wedge_system: conj.residual_wedge_system,
            harmonic_forms: forms.len(),
            patch: layout.patch,
            ghosts: layout.ghosts,
            cut_curves: trajectories.into_iter().map(|t| t.points).collect(),
            small_patches: layout.small_patches,
            folded_faces: layout.folded,
            patch_merges: layout.merges,
            stretch_cv: Some([uniform.cv_basis, uniform.cv]),
            trajectory_cut: cut,
            loop_cut,
            ..ComponentMap::empty(ConformalMethod::CriticalTrajectoryPatches)
        });
    }
    let puv = integrate(&topo, tris, &keep, &d);
    let period = |e: u32| {
        let ed = topo.edges[e as usize];
        let (b0, b1) = (puv.base[ed[0] as usize], puv.base[ed[1] as usize]);
        let de = d[e as usize];
        [b0[0] + de[0] - b1[0], b0[1] + de[1] - b1[1]]
    };
    let (z1, z2) = reduce_basis(period(tc.generators[0]), period(tc.generators[1]));
    let len1 = (z1[0] * z1[0] + z1[1] * z1[1]).sqrt();
    if len1 <= 0.0 || !len1.is_finite() {
        return Err(conformal_error("the first period of the holomorphic 1-form vanishes"));
    }
    let (cs, sn) = (z1[0] / len1, z1[1] / len1);
    let rot = |p: [f64; 2]| [cs * p[0] + sn * p[1], -sn * p[0] + cs * p[1]];
    let mut base: Vec<[f64; 2]> = puv.base.iter().map(|&p| rot(p)).collect();
    let mut corner: Vec<[[f64; 2]; 3]> =
        puv.corner.iter().map(|c| [rot(c[0]), rot(c[1]), rot(c[2])]).collect();
    let mut b = rot(z2);
    let positive: f64 = corner.iter().map(|c| signed_area(c).signum()).sum();
    if positive < 0.0 {
        for p in base.iter_mut() {
            p[0] = -p[0];
        }
        for c in corner.iter_mut() {
            for p in c.iter_mut() {
                p[0] = -p[0];
            }
        }
        b[0] = -b[0];
    }
    if b[1] < 0.0 {
        b = [-b[0], -b[1]];
    }
    if b[1].abs() <= 1e-12 * len1 {
        return Err(conformal_error(
            "the two periods are parallel; the homology basis is degenerate",
        ));
    }
    b[0] = b[0].rem_euclid(len1);
    let lattice = Lattice { a: Some(len1), b: Some(b) };
    // Seams along the shortest level curves: first v (then reduce in y), then u.
    let shift = |corner: &mut Vec<[[f64; 2]; 3]>, base: &mut Vec<[f64; 2]>, s: [f64; 2]| {
        for p in corner.iter_mut().flat_map(|c| c.iter_mut()).chain(base.iter_mut()) {
            p[0] -= s[0];
            p[1] -= s[1];
        }
    };
    let cy = shortest_level(&corner, tris, &mesh.positions, 1, b[1], SEAM_LEVELS);
    shift(&mut corner, &mut base, [0.0, cy]);
    reduce_faces(&mut corner, &Lattice { a: None, b: Some(b) });
    let cx = shortest_level(&corner, tris, &mesh.positions, 0, len1, SEAM_LEVELS);
    shift(&mut corner, &mut base, [cx, 0.0]);
    reduce_faces(&mut corner, &lattice);
    Ok(ComponentMap {
        method: ConformalMethod::HolomorphicTorus,
        corner,
        base,
        apex: vec![None; nf],
        lattice,
        zero_points,
        conjugate_residual: conj.residual,
        conjugate_residual_wedge_system: conj.residual_wedge_system,
        harmonic_forms: forms.len(),
        ..ComponentMap::empty(ConformalMethod::HolomorphicTorus)
    })
}
