//! Where a conformal layout's seams come from (issue 13): `seam_anatomy MESH...`.
//! Per component, the 3-D seam length split into edges between two patches, edges where
//! one patch meets itself, and edges on protrusion slits, and how much of each lies on
//! a snapped critical trajectory. Also a lower bound for any cut layout of the kept
//! surface: the slit lengths plus the spanning tree of shortest edge paths joining the
//! slit openings and the negative-index zero points, each of which a cut must reach
//! ([`spanning_cut`], which the layout now cuts too).

#[path = "common/mod.rs"]
mod common;
use fieldtex_param::conformal::cut_graph::spanning_cut;
use std::collections::HashMap;

fn main() -> Result<(), String> {
    for path in std::env::args().skip(1) {
        let (mesh, comps) = common::mapped(&path)?;
        for c in &comps {
            if !c.has_uv() {
                continue;
            }
            let m = &c.map;
            let lm = &c.local_mesh;
            let n = c.faces.len();
            // Edge → faces (local faces < n only), with global vertex ids so the two sides of a slit meet.
            let g = |v: u32| c.local_to_global[v as usize];
            let mut edges: HashMap<(u32, u32), Vec<(usize, usize)>> = HashMap::new();
            for f in 0..n {
                let t = lm.triangles[f];
                for k in 0..3 {
                    let (a, b) = (g(t[k]), g(t[(k + 1) % 3]));
                    edges.entry((a.min(b), a.max(b))).or_default().push((f, k));
                }
            }
            let lt = |f: usize, k: usize| -> ([f64; 2], [f64; 2], u32) {
                let t = lm.triangles[f];
                (m.corner[f][k], m.corner[f][(k + 1) % 3], g(t[k]))
            };
            let pos = &mesh.positions;
            let (mut between, mut within, mut slit, mut on_traj, mut total) =
                (0.0, 0.0, 0.0, 0.0, 0.0);
            let mut per_pair: HashMap<(u32, u32), f64> = HashMap::new();
            let topo = fieldtex_mesh::Topology::build(lm.n_vertices(), &lm.triangles);
            for (&(a, b), fs) in &edges {
                let len = fieldtex_core::vec3::norm(fieldtex_core::vec3::sub(
                    pos[a as usize],
                    pos[b as usize],
                ));
                if fs.len() != 2 {
                    continue;
                }
                let (f0, k0) = fs[0];
                let (f1, k1) = fs[1];
                let (p0, q0, s0) = lt(f0, k0);
                let (p1, q1, _s1) = lt(f1, k1);
                let (p1, q1) = if s0 == g(lm.triangles[f1][k1]) { (p1, q1) } else { (q1, p1) };
                let close =
                    |x: [f64; 2], y: [f64; 2]| (x[0] - y[0]).abs() + (x[1] - y[1]).abs() < 1e-9;
                if close(p0, p1) && close(q0, q1) {
                    continue;
                }
                total += len;
                let la = lm.triangles[f0][k0];
                let lb = lm.triangles[f0][(k0 + 1) % 3];
                let shared_local = {
                    let t1 = lm.triangles[f1];
                    t1.contains(&la) && t1.contains(&lb)
                };
                if !shared_local {
                    slit += len;
                    continue;
                }
                let e = topo.face_edges[f0][k0] as usize;
                if m.trajectory_cut.get(e).copied().unwrap_or(false) {
                    on_traj += len;
                }
                let (pa, pb) =
                    (m.patch.get(f0).copied().unwrap_or(0), m.patch.get(f1).copied().unwrap_or(0));
                if pa == pb {
                    within += len;
                } else {
                    between += len;
                    *per_pair.entry((pa.min(pb), pa.max(pb))).or_default() += len;
                }
            }
            let (slit_len, mst) = cut_bound(&mesh.positions, c);
            println!(
                "{path} comp {}: slits {slit_len:.4} + spanning tree of openings and zeros {mst:.4} = {:.4}",
                c.component,
                slit_len + mst
            );
            let mut pairs: Vec<_> = per_pair.into_iter().collect();
            pairs.sort_by(|x, y| y.1.total_cmp(&x.1));
            println!(
                "{path} comp {} genus {} method {:?} patches {}: seam {total:.4} = between {between:.4} + within {within:.4} + slit {slit:.4}; on trajectories {on_traj:.4}; top pairs {:?}",
                c.component,
                c.genus,
                c.method,
                m.n_patches(),
                pairs
                    .iter()
                    .take(6)
                    .map(|(k, v)| (k.0, k.1, (v * 1e4).round() / 1e4))
                    .collect::<Vec<_>>()
            );
        }
    }
    Ok(())
}

/// `(slit length, spanning tree length)` of the lower bound in the module docs: the
/// slits' 3-D length and the edges [`spanning_cut`] cuts on the kept copy (the first
/// `faces.len()` faces of the component mesh).
fn cut_bound(pos: &[[f64; 3]], c: &fieldtex_param::conformal::ConformalComponent) -> (f64, f64) {
    let lm = &c.local_mesh;
    let topo = fieldtex_mesh::Topology::build(lm.n_vertices(), &lm.triangles);
    let kept: Vec<bool> = (0..lm.n_triangles()).map(|f| f < c.faces.len()).collect();
    let zeros: Vec<u32> = c.map.zero_points.iter().filter(|z| z.1 < 0).map(|z| z.0).collect();
    let cut = spanning_cut(&lm.positions, &topo, &kept, &zeros);
    let len = |a: [f64; 3], b: [f64; 3]| fieldtex_core::vec3::norm(fieldtex_core::vec3::sub(a, b));
    let tree: f64 = (0..topo.n_edges())
        .filter(|&e| cut[e])
        .map(|e| {
            len(lm.positions[topo.edges[e][0] as usize], lm.positions[topo.edges[e][1] as usize])
        })
        .sum();
    let slits: f64 = c
        .protrusion_slits
        .iter()
        .flat_map(|p| &p.slit_paths)
        .flat_map(|path| path.windows(2))
        .map(|w| len(pos[w[0] as usize], pos[w[1] as usize]))
        .sum();
    (slits, tree)
}
