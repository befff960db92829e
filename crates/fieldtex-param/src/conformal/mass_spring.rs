//! Quasi-isometric relaxation of a conformal geometry image (Wang et al. 2005, §5.1,
//! eq. 2): a mass-spring system on the mesh edges in the parameter plane.
//!
//! Eq. 2 pushes a vertex away from its neighbours with a strength proportional to the
//! product of the local conformal factors `η`, so regions the map shrank grow. As
//! printed it only expands; we use it in the balanced form of a spring with rest length
//! `r_uv = |r_u − r_v| / η̄` (`η̄` the global ratio of surface to parameter length), whose
//! force `F(v) = Σ_u (η_uv / η̄ − 1)(φ(v) − φ(u))` is the paper's expansion where the
//! edge's conformal factor is above the mean and a matching contraction where it is
//! below, so the system has a rest state (a documented substitute for the unbalanced
//! form).
//!
//! **Integration (substitute for the paper's explicit steps, which take an hour on the
//! bunny):** each step is *implicit* — an energy `Σ w_uv |φ_v − φ_u − t_uv|²` is
//! minimised by one sparse solve (a weighted graph Laplacian,
//! [`super::cotan_system::FixedLaplacian`]). Two choices of targets `t_uv`:
//! - **rigid triangles** ([`Targets::RigidTriangles`]): each
//!   triangle's own 3-D shape at the image's global scale, rotated onto the current
//!   triangle (the ARAP local step of Liu et al. 2008), with the cotangent weights of
//!   the rest shape scaled per face by the symmetric Dirichlet weight of its current
//!   stretch (an isotropic simplification of SLIM's reweighting, Rabinovich et al.
//!   2017), so faces the conformal map squeezed pull hardest; the system is
//!   refactorised each step ([`super::rigid_triangles`]);
//! - **edge springs** ([`Targets::Springs`], eq. 2's rest lengths): every edge's target along its current
//!   direction with length `|e| (r_uv / |e|)^κ`, stiffness `1/|e|²` of the conformal
//!   edge, factorised once.
//!
//! Both replace eq. 2's explicit forces. The rigid targets also restore angles; at the
//! same angle bound they lower the area distortion further on some meshes (bunny −44 %
//! against −37 %) and less on others (armadillo), so the default ([`Targets::Best`])
//! runs both and keeps the better map (numbers in `docs/conformal.md`). The move towards the minimiser is then scaled by a
//! backtracking line search, starting at the full move and halved until no triangle
//! flips or collapses (signed area above 5 % of its conformal and its previous value) —
//! the paper's "ε chosen so that no triangle flips", without the force-limited step
//! length that makes explicit integration slow in regions the map compressed by orders
//! of magnitude. The relaxation stops where the mean angle distortion `σ1/σ2` would
//! pass the bound (the last step is bisected onto it), when a step no longer lowers the
//! area distortion, or after `iterations` steps. Lattice translations (the periods) are
//! kept, so periodic images stay periodic. Sequential and deterministic.
#![allow(clippy::needless_range_loop)] // index loops over parallel per-face tables

use super::ComponentMap;
use super::cotan_system::FixedLaplacian;
use super::periodic_uv::{reduce_faces, signed_area};
use super::rigid_triangles::RigidTriangles;
use crate::distortion::triangle_jacobian;
use fieldtex_core::vec3;
use fieldtex_mesh::{Topology, TriMesh, UnionFind};
use serde::Serialize;

/// Options of [`relax`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MassSpringOptions {
    /// Largest number of implicit steps. Default 40.
    pub iterations: usize,
    /// Fraction `κ ∈ (0, 1]` of the way (in log length) from each edge's current
    /// length to its rest length that a step's targets ask for (edge springs only).
    /// Default 0.25.
    pub step: f64,
    /// Stop (keeping the last state within the bound) when the mean angle distortion
    /// `σ1/σ2` passes this value: the trade-off between angle and area. Default 1.3.
    pub max_angle_distortion: f64,
    /// Which step targets (module docs). Default [`Targets::Best`].
    pub targets: Targets,
}

/// The targets of the implicit steps (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Targets {
    /// Eq. 2's rest lengths along the current edge directions.
    Springs,
    /// The triangles' own rest shapes rotated into place, reweighted
    /// ([`super::rigid_triangles`]).
    RigidTriangles,
    /// Both, keeping the map with the lower area distortion (ties: springs). Neither
    /// wins on every mesh: the rigid targets on the bunny, koala and rocker arm, the
    /// springs on the armadillo, the bust and fandisk (`docs/conformal.md`).
    Best,
}

impl Default for MassSpringOptions {
    fn default() -> Self {
        Self { iterations: 40, step: 0.25, max_angle_distortion: 1.3, targets: Targets::Best }
    }
}

/// Distortion of a map: area-weighted mean `σ1/σ2` over non-slit triangles, the
/// standard deviation of `log` of the normalised area ratio, flipped triangles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MapDistortion {
    pub angle_mean: f64,
    pub log_area_std: f64,
    pub flipped: usize,
}

/// Before/after numbers of a relaxation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MassSpringStats {
    pub before: MapDistortion,
    pub after: MapDistortion,
    pub iterations: usize,
    /// The targets whose map was kept.
    pub targets: Targets,
    /// Halvings of the line search (moves shortened to avoid a flip), over all steps.
    pub frozen_moves: usize,
}

/// Distortion of the first `n_faces` triangles of `mesh` under `corner` UVs.
pub fn map_distortion(
    mesh: &TriMesh,
    n_faces: usize,
    corner: &[[[f64; 2]; 3]],
    slit: &dyn Fn(usize) -> bool,
) -> MapDistortion {
    let mut rows = Vec::with_capacity(n_faces);
    let mut flipped = 0;
    let (mut s3, mut suv) = (0.0, 0.0);
    for f in 0..n_faces {
        let Some((s1, s2, auv, a3)) = triangle_jacobian(mesh.triangle_positions(f), corner[f], 0.0)
        else {
            continue;
        };
        if auv <= 0.0 || auv.is_nan() {
            flipped += 1;
            continue;
        }
        s3 += a3;
        suv += auv;
        rows.push((f, s1 / s2.max(f64::MIN_POSITIVE), auv, a3));
    }
    let (mut am, mut aw) = (0.0, 0.0);
    let (mut l1, mut l2) = (0.0, 0.0);
    for &(f, r, auv, a3) in &rows {
        if !slit(f) && r.is_finite() {
            am += a3 * r;
            aw += a3;
        }
        let l = ((auv / suv) / (a3 / s3)).ln();
        l1 += a3 * l;
        l2 += a3 * l * l;
    }
    let mean = l1 / s3.max(f64::MIN_POSITIVE);
    MapDistortion {
        angle_mean: if aw > 0.0 { am / aw } else { f64::NAN },
        log_area_std: (l2 / s3.max(f64::MIN_POSITIVE) - mean * mean).max(0.0).sqrt(),
        flipped,
    }
}

/// Relaxes `map` on the first `n_faces` triangles of the capped component `mesh`.
pub fn relax(
    mesh: &TriMesh,
    n_faces: usize,
    map: &mut ComponentMap,
    options: &MassSpringOptions,
) -> MassSpringStats {
    match options.targets {
        Targets::Best => {
            let mut rigid_map = map.clone();
            let rigid = relax_with(mesh, n_faces, &mut rigid_map, options, Targets::RigidTriangles);
            let springs = relax_with(mesh, n_faces, map, options, Targets::Springs);
            if rigid.after.flipped == 0 && rigid.after.log_area_std < springs.after.log_area_std {
                *map = rigid_map;
                rigid
            } else {
                springs
            }
        }
        t => relax_with(mesh, n_faces, map, options, t),
    }
}

/// [`relax`] with one kind of targets.
fn relax_with(
    mesh: &TriMesh,
    n_faces: usize,
    map: &mut ComponentMap,
    options: &MassSpringOptions,
    targets: Targets,
) -> MassSpringStats {
    let tris = &mesh.triangles;
    let slit_of = |apex: &[Option<(u8, bool)>]| {
        let a: Vec<bool> = apex.iter().map(|x| x.is_some()).collect();
        move |f: usize| a[f]
    };
    let before = map_distortion(mesh, n_faces, &map.corner, &slit_of(&map.apex));
    // Lattice offset of every non-apex corner relative to its vertex's base position.
    let offset: Vec<[[f64; 2]; 3]> = (0..n_faces)
        .map(|f| {
            let mut o = [[0.0; 2]; 3];
            for k in 0..3 {
                if map.apex[f].map(|a| a.0 as usize) != Some(k) {
                    let b = map.base[tris[f][k] as usize];
                    o[k] = [map.corner[f][k][0] - b[0], map.corner[f][k][1] - b[1]];
                }
            }
            o
        })
        .collect();
    // Springs: (i, j, offset of j minus offset of i, 3-D length), deduplicated.
    let mut springs: Vec<(u32, u32, [f64; 2], f64)> = Vec::with_capacity(3 * n_faces / 2);
    for f in 0..n_faces {
        let apex = map.apex[f].map(|a| a.0 as usize);
        for k in 0..3 {
            let l = (k + 1) % 3;
            if Some(k) == apex || Some(l) == apex {
                continue;
            }
            let (i, j) = (tris[f][k], tris[f][l]);
            let o = [offset[f][l][0] - offset[f][k][0], offset[f][l][1] - offset[f][k][1]];
            let len = vec3::norm(vec3::sub(mesh.positions[j as usize], mesh.positions[i as usize]));
            if i < j {
                springs.push((i, j, o, len));
            } else {
                springs.push((j, i, [-o[0], -o[1]], len));
            }
        }
    }
    springs.sort_by_key(|a| (a.0, a.1));
    springs.dedup_by(|a, b| a.0 == b.0 && a.1 == b.1);
    if springs.is_empty() {
        return MassSpringStats { before, after: before, iterations: 0, targets, frozen_moves: 0 };
    }
    let nv = mesh.n_vertices();
    let mut phi = map.base.clone();
    let corners_of = |phi: &[[f64; 2]], f: usize| -> [[f64; 2]; 3] {
        let mut c = [[0.0; 2]; 3];
        let apex = map.apex[f];
        for k in 0..3 {
            if apex.map(|a| a.0 as usize) != Some(k) {
                let b = phi[tris[f][k] as usize];
                c[k] = [b[0] + offset[f][k][0], b[1] + offset[f][k][1]];
            }
        }
        if let Some((k, at_start)) = apex {
            let k = k as usize;
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let (ci, cj) = (c[i], c[j]);
            let h = 0.866 * ((cj[0] - ci[0]).powi(2) + (cj[1] - ci[1]).powi(2)).sqrt();
            let mx = 0.5 * (ci[0] + cj[0]);
            c[k] = if at_start { [mx, ci[1].min(cj[1]) - h] } else { [mx, ci[1].max(cj[1]) + h] };
        }
        c
    };
    let area0: Vec<f64> = (0..n_faces).map(|f| signed_area(&corners_of(&phi, f))).collect();
    // The spring graph's Laplacian (weights below), vertices without springs and one
    // gauge vertex held (the unknowns are displacements, so held means unmoved).
    let sub = Topology::build(nv, &tris[..n_faces]);
    let mut has_spring = vec![false; nv];
    for &(i, j, _, _) in &springs {
        has_spring[i as usize] = true;
        has_spring[j as usize] = true;
    }
    // Stiffness 1 / |e|² of the conformal map's edge: the energy measures each edge's
    // misfit relative to its own length, so a region the map compressed moves at its
    // own scale instead of being crushed by its large neighbours.
    let spring_weight: Vec<f64> = springs
        .iter()
        .map(|&(i, j, o, _)| {
            let (pi, pj) = (phi[i as usize], phi[j as usize]);
            let l2 = (pj[0] + o[0] - pi[0]).powi(2) + (pj[1] + o[1] - pi[1]).powi(2);
            if l2 > 0.0 && l2.is_finite() { 1.0 / l2 } else { 0.0 }
        })
        .collect();
    let mut weights: Vec<f64> = sub
        .edges
        .iter()
        .map(|ed| {
            let key = (ed[0].min(ed[1]), ed[0].max(ed[1]));
            springs.binary_search_by_key(&key, |s| (s.0, s.1)).map_or(0.0, |s| spring_weight[s])
        })
        .collect();
    // Rigid-triangle targets: rest shapes at the image's global length ratio, weights
    // the rest triangles' cotangents.
    let mut rigid = if targets == Targets::RigidTriangles {
        let (mut a3, mut auv) = (0.0, 0.0);
        for f in (0..n_faces).filter(|&f| map.apex[f].is_none()) {
            let a = signed_area(&corners_of(&phi, f));
            if a.is_finite() && a > 0.0 {
                auv += a;
                let p = mesh.triangle_positions(f);
                a3 += 0.5 * vec3::norm(vec3::cross(vec3::sub(p[1], p[0]), vec3::sub(p[2], p[0])));
            }
        }
        let use_face: Vec<bool> = (0..n_faces).map(|f| map.apex[f].is_none()).collect();
        let eta = (a3 / auv).sqrt();
        match RigidTriangles::new(mesh, n_faces, &use_face, eta) {
            Ok(rt) if eta.is_finite() && eta > 0.0 => {
                weights.iter_mut().for_each(|w| *w = 0.0);
                for (f, fe) in sub.face_edges.iter().enumerate() {
                    for k in 0..3 {
                        weights[fe[k] as usize] += rt.weight(f, k);
                    }
                }
                has_spring.iter_mut().for_each(|h| *h = false);
                for (e, ed) in sub.edges.iter().enumerate() {
                    if weights[e] != 0.0 {
                        has_spring[ed[0] as usize] = true;
                        has_spring[ed[1] as usize] = true;
                    }
                }
                Some(rt)
            }
            _ => None,
        }
    } else {
        None
    };
    // One gauge vertex per connected piece of the spring graph (a patch layout has one
    // piece per chart): its first vertex with a spring.
    let mut pieces = UnionFind::new(nv);
    for (e, ed) in sub.edges.iter().enumerate() {
        if weights[e] != 0.0 {
            pieces.union(ed[0] as usize, ed[1] as usize);
        }
    }
    let mut gauged = vec![false; nv];
    let fixed: Vec<Option<f64>> = (0..nv)
        .map(|v| {
            let gauge = has_spring[v]
                && !phi[v][0].is_nan()
                && !std::mem::replace(&mut gauged[pieces.find(v)], true);
            if !has_spring[v] || gauge || phi[v][0].is_nan() { Some(0.0) } else { None }
        })
        .collect();
    let Ok(mut lap) = FixedLaplacian::new(&sub, &weights, &fixed) else {
        return MassSpringStats { before, after: before, iterations: 0, targets, frozen_moves: 0 };
    };
    let kappa = options.step.clamp(1e-3, 1.0);
    let apex_flags: Vec<bool> = map.apex.iter().map(|x| x.is_some()).collect();
    let distortion_at = |phi: &[[f64; 2]]| {
        let corner: Vec<[[f64; 2]; 3]> = (0..n_faces).map(|f| corners_of(phi, f)).collect();
        map_distortion(mesh, n_faces, &corner, &|f| apex_flags[f])
    };
    let valid = |phi: &[[f64; 2]], old_area: &[f64]| {
        // NaN areas (faces at a slit's unused corner) are not judged, as before.
        !(0..n_faces).any(|f| signed_area(&corners_of(phi, f)) <= 0.05 * area0[f].min(old_area[f]))
    };
    let moved = |phi: &[[f64; 2]], delta: &[[f64; 2]], t: f64| -> Vec<[f64; 2]> {
        phi.iter().zip(delta).map(|(p, d)| [p[0] + t * d[0], p[1] + t * d[1]]).collect()
    };
    let max_angle = options.max_angle_distortion;
    let mut frozen_moves = 0usize;
    let mut iterations = 0;
    let mut current = before;
    for it in 0..options.iterations {
        let (mut s3, mut suv) = (0.0, 0.0);
        let mut lens = Vec::with_capacity(springs.len());
        for &(i, j, o, l3) in &springs {
            let (pi, pj) = (phi[i as usize], phi[j as usize]);
            let e = [pj[0] + o[0] - pi[0], pj[1] + o[1] - pi[1]];
            let luv = (e[0] * e[0] + e[1] * e[1]).sqrt();
            s3 += l3;
            suv += luv;
            lens.push((e, luv));
        }
        let eta_mean = s3 / suv.max(f64::MIN_POSITIVE);
        // Eq. 2's per-vertex conformal factor η(v): the mean ratio of surface to
        // parameter length over the vertex's springs.
        let (mut eta, mut count) = (vec![0.0; nv], vec![0usize; nv]);
        for (s, &(i, j, _, l3)) in springs.iter().enumerate() {
            let luv = lens[s].1;
            if luv > 0.0 && luv.is_finite() {
                for v in [i as usize, j as usize] {
                    eta[v] += l3 / luv;
                    count[v] += 1;
                }
            }
        }
        for v in 0..nv {
            eta[v] = if count[v] > 0 { eta[v] / count[v] as f64 } else { eta_mean };
        }
        // Right-hand side of L δ = Σ (target − current edge vector), per coordinate.
        let (mut rx, mut ry) = (vec![0.0; nv], vec![0.0; nv]);
        if let Some(rt) = &mut rigid {
            // Reweighted (the energy's local weights at the current map), refactorised.
            for f in 0..n_faces {
                rt.reweight(f, &corners_of(&phi, f));
            }
            weights.iter_mut().for_each(|w| *w = 0.0);
            for (f, fe) in sub.face_edges.iter().enumerate() {
                for k in 0..3 {
                    weights[fe[k] as usize] += rt.weight(f, k);
                }
            }
            let Ok(l) = FixedLaplacian::new(&sub, &weights, &fixed) else { break };
            lap = l;
            for f in 0..n_faces {
                let c = corners_of(&phi, f);
                let Some(t) = rt.targets(f, &c) else { continue };
                for k in 0..3 {
                    let l = (k + 1) % 3;
                    let w = rt.weight(f, k);
                    let r =
                        [w * (t[k][0] - (c[l][0] - c[k][0])), w * (t[k][1] - (c[l][1] - c[k][1]))];
                    let (i, j) = (tris[f][k] as usize, tris[f][l] as usize);
                    rx[i] -= r[0];
                    ry[i] -= r[1];
                    rx[j] += r[0];
                    ry[j] += r[1];
                }
            }
        }
        for (s, &(i, j, _, _)) in springs.iter().enumerate().filter(|_| rigid.is_none()) {
            let (e, luv) = lens[s];
            if luv <= 0.0 || !luv.is_finite() {
                continue;
            }
            // Rest length |e| √(η_u η_v) / η̄ (the product of eq. 2), κ of the way in log.
            let grow = (eta[i as usize] * eta[j as usize]).sqrt() / eta_mean;
            let scale = spring_weight[s] * (grow.powf(kappa) - 1.0);
            let r = [scale * e[0], scale * e[1]];
            rx[i as usize] -= r[0];
            ry[i as usize] -= r[1];
            rx[j as usize] += r[0];
            ry[j as usize] += r[1];
        }
        let (Ok(dx), Ok(dy)) = (lap.solve(&rx), lap.solve(&ry)) else { break };
        let delta: Vec<[f64; 2]> = dx.iter().zip(&dy).map(|(&x, &y)| [x, y]).collect();
        let old_area: Vec<f64> = (0..n_faces).map(|f| signed_area(&corners_of(&phi, f))).collect();
        let mut t = 1.0;
        let mut next = moved(&phi, &delta, t);
        while !valid(&next, &old_area) && t > 1e-4 {
            t *= 0.5;
            frozen_moves += 1;
            next = moved(&phi, &delta, t);
        }
        if t <= 1e-4 {
            break;
        }
        let d = distortion_at(&next);
        if d.angle_mean > max_angle {
            // Bisect the step onto the angle bound, then stop.
            let (mut lo, mut hi) = (0.0, t);
            for _ in 0..8 {
                let mid = 0.5 * (lo + hi);
                let cand = moved(&phi, &delta, mid);
                if distortion_at(&cand).angle_mean <= max_angle {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            if lo > 0.0 {
                phi = moved(&phi, &delta, lo);
                iterations = it + 1;
            }
            break;
        }
        if d.log_area_std > current.log_area_std * (1.0 - 1e-3) {
            break;
        }
        phi = next;
        current = d;
        iterations = it + 1;
    }
    let mut corner: Vec<[[f64; 2]; 3]> = (0..n_faces).map(|f| corners_of(&phi, f)).collect();
    reduce_faces(&mut corner, &map.lattice);
    map.corner[..n_faces].copy_from_slice(&corner);
    map.base = phi;
    let after = map_distortion(mesh, n_faces, &map.corner, &slit_of(&map.apex));
    MassSpringStats { before, after, iterations, targets, frozen_moves }
}
