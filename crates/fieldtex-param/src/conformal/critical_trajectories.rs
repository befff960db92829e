//! Critical horizontal trajectories of a holomorphic 1-form (Wang, Gu, Mueller & Yau
//! 2005 §3, Fig. 2d and Fig. 3): the curves of constant `v = Im ∫φ` that leave a zero
//! point. A zero of index `−m` has `2(m + 1)` of them; cutting the surface along them
//! splits the cone of total angle `2π(m + 1)` around the zero into half-planes, and
//! the surface into patches that `∫φ` maps to rectangles and strips.
//!
//! Discretisation: `φ` is one 2-vector `(du, dv)` per edge (low → high vertex), linear
//! in each triangle. A trajectory starts in each triangle of the zero's fan whose two far
//! corners have `v` of opposite signs (`v ≥ 0` counts as positive, so a level through a
//! vertex is crossed once), and walks from triangle to triangle across the edge where
//! `v` changes sign, carrying `v` along by the form (so the multi-valued `v` is never
//! needed globally). It stops on reaching another zero point, a vertex already on a
//! cut, a boundary edge, or the length budget — on a generic discrete form the
//! trajectories through zeros spiral instead of closing (the paper picks a form with
//! finite trajectories; we cut them at `max_length` and let the patch construction
//! absorb the rest, see [`super::translation_patches`]).
//!
//! Each trajectory is also *snapped* to a mesh edge path: on every crossed edge the end
//! with the smaller `|v|` is taken; consecutive picks lie in one triangle, so the picks
//! form an edge path starting at the zero point. Cuts run along these paths (the mesh is
//! never split), so a cut lies within one triangle of the exact trajectory.

use super::periodic_uv::along2;
use fieldtex_core::vec3;
use fieldtex_mesh::Topology;

/// Why a trajectory stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrajectoryEnd {
    ZeroPoint,
    Cut,
    Boundary,
    Length,
}

/// One traced critical horizontal trajectory.
#[derive(Debug, Clone)]
pub struct Trajectory {
    /// The zero point it leaves.
    pub start: u32,
    /// 3-D polyline: the zero point, then every edge crossing.
    pub points: Vec<[f64; 3]>,
    /// Snapped edge path (vertex ids, starting at `start`, no repeats in a row).
    pub path: Vec<u32>,
    /// Surface length of `points`.
    pub length: f64,
    pub end: TrajectoryEnd,
}

/// Traces every critical horizontal trajectory of the form `d` (`#E` values of
/// `(du, dv)`) from the `zeros`, in zero order and counter-clockwise fan order per zero,
/// each at most `max_length` long. A trajectory also stops on reaching a vertex with
/// `stop[v]` (cuts made before, e.g. homology loops; empty: none). Returns the
/// trajectories and a per-edge flag of the snapped cut edges.
pub fn critical_trajectories(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    topology: &Topology,
    d: &[[f64; 2]],
    zeros: &[u32],
    max_length: f64,
    stop: &[bool],
) -> (Vec<Trajectory>, Vec<bool>) {
    let nv = positions.len();
    let mut is_zero = vec![false; nv];
    for &z in zeros {
        is_zero[z as usize] = true;
    }
    let mut on_cut: Vec<bool> = (0..nv).map(|v| stop.get(v).is_some_and(|&s| s)).collect();
    let mut cut_edge = vec![false; topology.n_edges()];
    let mut out = Vec::new();
    let pos = |v: u32| positions[v as usize];
    let corner_of = |f: usize, v: u32| (0..3).find(|&k| triangles[f][k] == v).unwrap_or(0);
    let edge_between = |f: usize, a: u32, b: u32| -> usize {
        let (ka, kb) = (corner_of(f, a), corner_of(f, b));
        let k = if (ka + 1) % 3 == kb { ka } else { kb };
        topology.face_edges[f][k] as usize
    };
    for &z in zeros {
        on_cut[z as usize] = true;
        let mut starts: Vec<u32> = topology.vertex_faces(z as usize).to_vec();
        starts.sort_unstable();
        for f0 in starts {
            let f0 = f0 as usize;
            let k = corner_of(f0, z);
            let (x, y) = (triangles[f0][(k + 1) % 3], triangles[f0][(k + 2) % 3]);
            let vx = along2(topology, d, f0, k, (k + 1) % 3)[1];
            let vy = along2(topology, d, f0, k, (k + 2) % 3)[1];
            if (vx >= 0.0) == (vy >= 0.0) {
                continue;
            }
            // State: current face, crossed edge (a, b) of it with v values (va, vb).
            let (mut f, mut a, mut b, mut va, mut vb) = (f0, x, y, vx, vy);
            let mut points = vec![pos(z)];
            let mut path = vec![z];
            let mut length = 0.0;
            let mut end = TrajectoryEnd::Length;
            let mut steps = 0usize;
            loop {
                let t = if va != vb { va / (va - vb) } else { 0.5 };
                let p = vec3::add(pos(a), vec3::scale(vec3::sub(pos(b), pos(a)), t));
                length += vec3::norm(vec3::sub(p, *points.last().unwrap_or(&p)));
                points.push(p);
                let snap = if va.abs() <= vb.abs() { a } else { b };
                if snap != *path.last().unwrap_or(&snap) {
                    let last = *path.last().unwrap_or(&snap);
                    let e = edge_between(f, last, snap);
                    cut_edge[e] = true;
                    path.push(snap);
                    if is_zero[snap as usize] {
                        end = TrajectoryEnd::ZeroPoint;
                        break;
                    }
                    if on_cut[snap as usize] {
                        end = TrajectoryEnd::Cut;
                        break;
                    }
                    on_cut[snap as usize] = true;
                }
                if length >= max_length || steps > 4 * triangles.len() {
                    break;
                }
                steps += 1;
                // Cross edge (a, b) into the neighbouring face.
                let e = edge_between(f, a, b);
                let fs = topology.edge_faces(e);
                let Some(&g) = fs.iter().find(|&&g| g as usize != f) else {
                    end = TrajectoryEnd::Boundary;
                    break;
                };
                let g = g as usize;
                let (ka, kb) = (corner_of(g, a), corner_of(g, b));
                let kc = 3 - ka - kb;
                let c = triangles[g][kc];
                let vc = va + along2(topology, d, g, ka, kc)[1];
                f = g;
                if (va >= 0.0) != (vc >= 0.0) {
                    b = c;
                    vb = vc;
                } else {
                    a = c;
                    va = vc;
                }
            }
            // The first pick may equal the zero's own neighbour already cut: keep it.
            out.push(Trajectory { start: z, points, path, length, end });
        }
    }
    (out, cut_edge)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_mesh::primitives;

    /// On a flat grid with `φ = e^{-iθ} dz` the horizontal trajectories through a
    /// regular vertex are the two rays of the line at angle `θ` through it.
    #[test]
    fn straight_lines_on_a_flat_grid() {
        let mesh = primitives::grid(20, 20, 1.0, 1.0);
        let topo = Topology::build(mesh.n_vertices(), &mesh.triangles);
        let (cs, sn) = (0.1f64.cos(), 0.1f64.sin());
        let d: Vec<[f64; 2]> = topo
            .edges
            .iter()
            .map(|e| {
                let (p, q) = (mesh.positions[e[0] as usize], mesh.positions[e[1] as usize]);
                let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
                [cs * dx + sn * dy, -sn * dx + cs * dy]
            })
            .collect();
        let z = (0..mesh.n_vertices())
            .find(|&v| {
                let p = mesh.positions[v];
                (p[0] - 0.5).abs() < 1e-9 && (p[1] - 0.5).abs() < 1e-9
            })
            .unwrap() as u32;
        let (tr, cut) =
            critical_trajectories(&mesh.positions, &mesh.triangles, &topo, &d, &[z], 10.0, &[]);
        // A regular point has two horizontal directions (index 0 → 2 trajectories).
        assert_eq!(tr.len(), 2, "{tr:?}");
        for t in &tr {
            assert_eq!(t.end, TrajectoryEnd::Boundary);
            let off = |p: [f64; 3]| -sn * (p[0] - 0.5) + cs * (p[1] - 0.5);
            for p in &t.points {
                assert!(off(*p).abs() < 1e-9, "left the line: {p:?}");
            }
            for &v in &t.path {
                assert!(off(mesh.positions[v as usize]).abs() < 0.05 + 1e-9);
            }
        }
        assert!(cut.iter().filter(|c| **c).count() >= 18);
    }
}
