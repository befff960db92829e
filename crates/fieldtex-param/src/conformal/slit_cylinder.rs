//! Genus-0 closed surfaces: two point slits and a conformal map onto one cylinder.
//!
//! A closed genus-0 surface has no holomorphic 1-form (Wang et al. 2005 are silent about
//! this case). We open it at two extremal vertices `a` (farthest from the centroid) and
//! `b` (farthest from `a` in edge hops; for a mesh with holes, the centres of the caps of
//! the longest hole and, when at least half as long and at least half the largest hop
//! distance away, of the second one): removing their triangle fans leaves an annulus.
//! On it `u` is harmonic with `u = 0` on the ring of `a` and `u = 1` on the ring of `b`;
//! its conjugate `v` comes from the harmonic 1-form of the annulus (Neumann boundary,
//! period 1 around the hole, [`super::harmonic_one_forms`]) scaled to best match
//! `n × ∇u` (the fit residual is reported). `(v, u)` maps the annulus conformally onto
//! the cylinder `[0, P) × [0, 1]`, periodic in x with `P` the flux of `∇u`: the map the
//! double cover would give for an annulus. The fan triangles become thin "slit"
//! triangles with their apex one ring-edge beyond the ends; they are excluded from the
//! angle-distortion statistics.

use super::ComponentMap;
use super::cotan_system::{FixedLaplacian, conformal_error, edge_weights};
use super::harmonic_one_forms::{face_areas_normals, face_vectors, harmonic_projection};
use super::periodic_uv::{Lattice, along2, integrate, reduce_faces, signed_area};
use super::tree_cotree::edge_sign_in_face;
use crate::ParamError;
use fieldtex_core::vec3;
use fieldtex_mesh::{CotanOptions, Topology, TriMesh, cotan_face_weights};
use std::collections::VecDeque;

/// Maps a closed, connected genus-0 mesh onto a cylinder (see the module docs). `ends`
/// overrides the slit points (e.g. the centres of capped holes, so a disk's boundary or
/// an annulus's two boundaries become the ends of the cylinder).
pub fn slit_cylinder(mesh: &TriMesh, ends: [Option<usize>; 2]) -> Result<ComponentMap, ParamError> {
    let nv = mesh.n_vertices();
    let nf = mesh.n_triangles();
    let tris = &mesh.triangles;
    let topo = Topology::build(nv, tris);
    let mut c = [0.0; 3];
    for p in &mesh.positions {
        c = vec3::add(c, *p);
    }
    let c = vec3::scale(c, 1.0 / nv as f64);
    let far = |from: [f64; 3]| {
        (0..nv)
            .filter(|&v| !topo.vertex_faces(v).is_empty())
            .max_by(|&i, &j| {
                vec3::norm2(vec3::sub(mesh.positions[i], from))
                    .total_cmp(&vec3::norm2(vec3::sub(mesh.positions[j], from)))
            })
            .unwrap_or(0)
    };
    let a = ends[0].unwrap_or_else(|| far(c));
    // b: the hinted second hole when it is far from a (at least half the largest hop
    // distance), else the vertex farthest from a in edge hops.
    let (far_b, hops) = farthest_in_hops(&topo, a);
    let b = match ends[1] {
        Some(b) if 2 * hops[b] as u64 >= hops[far_b] as u64 => b,
        _ => far_b,
    };
    let mut role = vec![0u8; nv]; // 1: ring of a, 2: ring of b
    for (end, r) in [(a, 1u8), (b, 2u8)] {
        for &f in topo.vertex_faces(end) {
            for &v in &tris[f as usize] {
                if v as usize != end {
                    if role[v as usize] != 0 && role[v as usize] != r {
                        return Err(conformal_error(
                            "the two slit points are neighbours; the component is too small",
                        ));
                    }
                    role[v as usize] = r;
                }
            }
        }
    }
    if role[a] != 0 || role[b] != 0 {
        return Err(conformal_error(
            "the two slit points are neighbours; the component is too small",
        ));
    }
    let keep: Vec<bool> =
        tris.iter().map(|t| !t.iter().any(|&v| v as usize == a || v as usize == b)).collect();
    let (half_cot, _) = cotan_face_weights(mesh, &CotanOptions::default())?;
    let w = edge_weights(&topo, &half_cot, &keep);
    let fixed_u: Vec<Option<f64>> = (0..nv)
        .map(|v| {
            if v == a || role[v] == 1 {
                Some(0.0)
            } else if v == b || role[v] == 2 {
                Some(1.0)
            } else if topo.vertex_faces(v).is_empty() {
                Some(0.5)
            } else {
                None
            }
        })
        .collect();
    let u = FixedLaplacian::new(&topo, &w, &fixed_u)?.solve(&vec![0.0; nv])?;

    // Dual path from the ring of a to the ring of b through kept faces.
    let ring_edge = |e: usize, r: u8| {
        let ed = topo.edges[e];
        role[ed[0] as usize] == r && role[ed[1] as usize] == r && topo.edge_faces(e).len() == 2
    };
    let mut parent = vec![(u32::MAX, u32::MAX); nf];
    let mut seen = vec![false; nf];
    let mut queue = VecDeque::new();
    let mut entry = vec![u32::MAX; nf];
    for f in 0..nf {
        if !keep[f] {
            continue;
        }
        if let Some(&e) = topo.face_edges[f].iter().find(|&&e| ring_edge(e as usize, 1)) {
            seen[f] = true;
            entry[f] = e;
            queue.push_back(f);
        }
    }
    let mut last = None;
    while let Some(f) = queue.pop_front() {
        if let Some(&e) = topo.face_edges[f].iter().find(|&&e| ring_edge(e as usize, 2)) {
            last = Some((f, e));
            break;
        }
        for &e in &topo.face_edges[f] {
            for &g in topo.edge_faces(e as usize) {
                let g = g as usize;
                if keep[g] && !seen[g] {
                    seen[g] = true;
                    parent[g] = (f as u32, e);
                    queue.push_back(g);
                }
            }
        }
    }
    let (tf, te) = last
        .ok_or_else(|| conformal_error("no path between the two slits (disconnected annulus)"))?;
    let mut eta = vec![0.0; topo.n_edges()];
    eta[te as usize] += edge_sign_in_face(&topo, tf, te);
    let mut f = tf;
    while parent[f].0 != u32::MAX {
        let (p, e) = parent[f];
        eta[e as usize] += edge_sign_in_face(&topo, p as usize, e);
        f = p as usize;
    }
    let e0 = entry[f];
    let fan_face =
        topo.edge_faces(e0 as usize).iter().map(|&g| g as usize).find(|&g| !keep[g]).unwrap_or(f);
    eta[e0 as usize] += edge_sign_in_face(&topo, fan_face, e0);

    let pin = (0..nv).find(|&v| role[v] == 1).unwrap_or(0);
    let fixed_w: Vec<Option<f64>> = (0..nv)
        .map(|v| {
            if v == a
                || v == b
                || v == pin
                || topo.vertex_faces(v).iter().all(|&f| !keep[f as usize])
            {
                Some(0.0)
            } else {
                None
            }
        })
        .collect();
    let lap_w = FixedLaplacian::new(&topo, &w, &fixed_w)?;
    let omega = harmonic_projection(&topo, &w, &lap_w, &eta)?;
    let du: Vec<f64> = topo.edges.iter().map(|ed| u[ed[1] as usize] - u[ed[0] as usize]).collect();
    let x = face_vectors(&topo, &mesh.positions, tris, &omega, &keep);
    let gu = face_vectors(&topo, &mesh.positions, tris, &du, &keep);
    let (mut num, mut den, mut gg) = (0.0, 0.0, 0.0);
    let (areas, normals) = face_areas_normals(mesh);
    for f in 0..nf {
        if !keep[f] {
            continue;
        }
        let g = vec3::cross(normals[f], gu[f]);
        num += areas[f] * vec3::dot(g, x[f]);
        den += areas[f] * vec3::dot(x[f], x[f]);
        gg += areas[f] * vec3::dot(g, g);
    }
    if den <= 0.0 || gg <= 0.0 {
        return Err(conformal_error("the harmonic 1-form of the annulus vanishes"));
    }
    let scale = num / den;
    let mut res = 0.0;
    for f in 0..nf {
        if keep[f] {
            let g = vec3::cross(normals[f], gu[f]);
            res += areas[f] * vec3::norm2(vec3::sub(g, vec3::scale(x[f], scale)));
        }
    }
    let residual = (res / gg).sqrt();
    let d: Vec<[f64; 2]> = (0..topo.n_edges()).map(|e| [scale * omega[e], du[e]]).collect();
    let mut puv = integrate(&topo, tris, &keep, &d);
    let positive: f64 = puv
        .corner
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(c, _)| signed_area(c).signum())
        .sum();
    let flip = positive < 0.0;
    if flip {
        for p in puv.base.iter_mut() {
            p[0] = -p[0];
        }
        for c in puv.corner.iter_mut() {
            for p in c.iter_mut() {
                p[0] = -p[0];
            }
        }
    }
    let dx = |v: [f64; 2]| if flip { [-v[0], v[1]] } else { v };
    let period = scale.abs();
    let mut apex = vec![None; nf];
    for f in 0..nf {
        if keep[f] {
            continue;
        }
        let t = tris[f];
        let k = (0..3).find(|&k| t[k] as usize == a || t[k] as usize == b).unwrap_or(0);
        let at_start = t[k] as usize == a;
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let ci = puv.base[t[i] as usize];
        let dij = dx(along2(&topo, &d, f, i, j));
        let cj = [ci[0] + dij[0], ci[1] + dij[1]];
        let h = 0.866 * (dij[0] * dij[0] + dij[1] * dij[1]).sqrt();
        let mid_x = 0.5 * (ci[0] + cj[0]);
        let ap =
            if at_start { [mid_x, ci[1].min(cj[1]) - h] } else { [mid_x, ci[1].max(cj[1]) + h] };
        let mut corner = [[0.0; 2]; 3];
        corner[k] = ap;
        corner[i] = ci;
        corner[j] = cj;
        puv.corner[f] = corner;
        apex[f] = Some((k as u8, at_start));
    }
    let lattice = Lattice { a: Some(period), b: None };
    reduce_faces(&mut puv.corner, &lattice);
    Ok(ComponentMap {
        method: super::ConformalMethod::SlitCylinder,
        corner: puv.corner,
        base: puv.base,
        apex,
        lattice,
        zero_points: Vec::new(),
        conjugate_residual: residual,
        slit_vertices: vec![a as u32, b as u32],
        harmonic_forms: 1,
        ..ComponentMap::empty(super::ConformalMethod::SlitCylinder)
    })
}

/// The vertex with the most edge hops from `a` (lowest index among ties) and the hop
/// distance of every vertex (`u32::MAX` when unreachable).
fn farthest_in_hops(topo: &Topology, a: usize) -> (usize, Vec<u32>) {
    let nbr = topo.vertex_neighbors();
    let mut dist = vec![u32::MAX; topo.n_vertices];
    dist[a] = 0;
    let mut queue = VecDeque::from([a]);
    let mut last = a;
    while let Some(v) = queue.pop_front() {
        last = v;
        for &w in nbr.row(v) {
            if dist[w as usize] == u32::MAX {
                dist[w as usize] = dist[v] + 1;
                queue.push_back(w as usize);
            }
        }
    }
    let dmax = dist[last];
    ((0..topo.n_vertices).find(|&v| dist[v] == dmax).unwrap_or(last), dist)
}
