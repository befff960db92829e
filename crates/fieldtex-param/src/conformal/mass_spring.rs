//! Quasi-isometric relaxation of a conformal geometry image (Wang et al. 2005, §5.1,
//! eq. 2): a mass-spring system on the mesh edges in the parameter plane.
//!
//! Eq. 2 pushes a vertex away from its neighbours with a strength proportional to the
//! product of the local conformal factors `η`, so regions the map shrank grow. As
//! printed it only expands; we use it in the balanced form of a spring with rest length
//! `|r_u − r_v| / η̄` (`η̄` the global ratio of surface to parameter length):
//! `F(v) = Σ_u (η_uv / η̄ − 1) (φ(v) − φ(u))`, `η_uv = |r_u − r_v| / |φ_u − φ_v|` — the
//! paper's expansion where the edge's conformal factor is above the mean and a matching
//! contraction where it is below, so the system has a rest state (a documented
//! substitute for the unbalanced form). The step is `ε = κ h / max|F|` (`h` the median
//! parameter edge length): inversely proportional to the largest force as in the
//! paper. A vertex whose move would flip (or collapse) a triangle keeps its position for
//! that step, so no triangle ever flips. Each move is also capped at `κ` times the
//! vertex's shortest parameter edge (our addition, so compressed regions move at their
//! own scale); when the refusals do not settle within a few
//! passes the step is dropped and `κ` halved. Lattice translations (the periods) are kept, so
//! periodic images stay periodic. Sequential and deterministic.
#![allow(clippy::needless_range_loop)] // index loops over parallel per-face tables

use super::ComponentMap;
use super::periodic_uv::{reduce_faces, signed_area};
use crate::distortion::triangle_jacobian;
use fieldtex_core::vec3;
use fieldtex_mesh::TriMesh;
use serde::Serialize;

/// Options of [`relax`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MassSpringOptions {
    /// Number of steps. Default 400.
    pub iterations: usize,
    /// Largest move per step in median edge lengths (`κ`). Default 0.1.
    pub step: f64,
    /// Stop (keeping the last state within the bound) when the mean angle distortion
    /// `σ1/σ2` passes this value: the trade-off between angle and area. Default 1.25.
    pub max_angle_distortion: f64,
}

impl Default for MassSpringOptions {
    fn default() -> Self {
        Self { iterations: 1500, step: 0.05, max_angle_distortion: 1.25 }
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
    /// Vertex moves refused to avoid a flip, over all steps.
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
        return MassSpringStats { before, after: before, iterations: 0, frozen_moves: 0 };
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
    let mut vertex_faces: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for f in 0..n_faces {
        for &v in &tris[f] {
            vertex_faces[v as usize].push(f as u32);
        }
    }
    let area0: Vec<f64> = (0..n_faces).map(|f| signed_area(&corners_of(&phi, f))).collect();
    let mut frozen_moves = 0usize;
    let mut kappa = options.step;
    let mut iterations = 0;
    let mut checkpoint = (phi.clone(), 0usize);
    let apex_flags: Vec<bool> = map.apex.iter().map(|x| x.is_some()).collect();
    for it in 0..options.iterations {
        if it % 10 == 0 && it > 0 {
            let corner: Vec<[[f64; 2]; 3]> = (0..n_faces).map(|f| corners_of(&phi, f)).collect();
            let d = map_distortion(mesh, n_faces, &corner, &|f| apex_flags[f]);
            if d.angle_mean > options.max_angle_distortion || d.flipped > 0 {
                phi = checkpoint.0.clone();
                iterations = checkpoint.1;
                break;
            }
            checkpoint = (phi.clone(), it);
        }
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
        let mut force = vec![[0.0f64; 2]; nv];
        for (s, &(i, j, _, l3)) in springs.iter().enumerate() {
            let (e, luv) = lens[s];
            if luv <= 0.0 {
                continue;
            }
            let k = (l3 / luv / eta_mean - 1.0).clamp(-0.9, 4.0);
            force[i as usize][0] -= k * e[0];
            force[i as usize][1] -= k * e[1];
            force[j as usize][0] += k * e[0];
            force[j as usize][1] += k * e[1];
        }
        let max_f = force.iter().map(|f| (f[0] * f[0] + f[1] * f[1]).sqrt()).fold(0.0, f64::max);
        if max_f <= 0.0 || !max_f.is_finite() {
            break;
        }
        let mut sorted: Vec<f64> = lens.iter().map(|l| l.1).collect();
        let mid = sorted.len() / 2;
        sorted.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
        let h = sorted[mid];
        let eps = kappa * h / max_f;
        // Each move is also at most κ times the vertex's shortest parameter edge, so
        // small (compressed) regions move in proportion to their own size.
        let mut hv = vec![f64::INFINITY; nv];
        for (sp, &(i, j, _, _)) in springs.iter().enumerate() {
            let l = lens[sp].1;
            hv[i as usize] = hv[i as usize].min(l);
            hv[j as usize] = hv[j as usize].min(l);
        }
        let old = phi.clone();
        for v in 0..nv {
            if !phi[v][0].is_nan() && !vertex_faces[v].is_empty() {
                let mut d = [eps * force[v][0], eps * force[v][1]];
                let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
                let cap = kappa * hv[v];
                if len > cap && len > 0.0 {
                    d = [d[0] * cap / len, d[1] * cap / len];
                }
                phi[v] = [phi[v][0] + d[0], phi[v][1] + d[1]];
            }
        }
        // Refuse moves that would flip or collapse a triangle (a few passes; then revert).
        let mut bad: Vec<usize> = (0..n_faces)
            .filter(|&f| {
                signed_area(&corners_of(&phi, f))
                    <= 0.05 * area0[f].min(signed_area(&corners_of(&old, f)))
            })
            .collect();
        let mut pass = 0;
        while !bad.is_empty() && pass < 8 {
            let mut touched = Vec::new();
            for &f in &bad {
                for &v in &tris[f] {
                    if phi[v as usize] != old[v as usize] {
                        phi[v as usize] = old[v as usize];
                        frozen_moves += 1;
                        touched.push(v);
                    }
                }
            }
            let mut check: Vec<usize> = touched
                .iter()
                .flat_map(|&v| vertex_faces[v as usize].iter().map(|&f| f as usize))
                .collect();
            check.sort_unstable();
            check.dedup();
            bad = check
                .into_iter()
                .filter(|&f| {
                    signed_area(&corners_of(&phi, f))
                        <= 0.05 * area0[f].min(signed_area(&corners_of(&old, f)))
                })
                .collect();
            pass += 1;
        }
        if !bad.is_empty() {
            // The refusals did not settle: drop this step and halve the step size.
            phi = old;
            kappa *= 0.5;
            if kappa < options.step / 64.0 {
                break;
            }
            continue;
        }
        iterations = it + 1;
    }
    let mut corner: Vec<[[f64; 2]; 3]> = (0..n_faces).map(|f| corners_of(&phi, f)).collect();
    reduce_faces(&mut corner, &map.lattice);
    map.corner[..n_faces].copy_from_slice(&corner);
    map.base = phi;
    let after = map_distortion(mesh, n_faces, &map.corner, &slit_of(&map.apex));
    MassSpringStats { before, after, iterations, frozen_moves }
}
