//! Where a conformal layout's seams come from (issue 13): `seam_anatomy MESH...`.
//! Per component, the 3-D seam length split into edges between two patches, edges where
//! one patch meets itself, and edges on protrusion slits, and how much of each lies on
//! a snapped critical trajectory. Also a lower bound for any cut layout of the kept
//! surface: the slit lengths plus a minimum spanning tree (edge-path distances) joining
//! the slit openings and the negative-index zero points, each of which a cut must reach.
use fieldtex_param::conformal::global_conformal;
use std::collections::HashMap;

fn main() -> Result<(), String> {
    for path in std::env::args().skip(1) {
        let mesh =
            fieldtex_io::read_mesh(std::path::Path::new(&path)).map_err(|e| e.to_string())?.mesh;
        let mesh = fieldtex_mesh::repair(&mesh, &Default::default()).mesh;
        let (comps, _) =
            global_conformal(&mesh, &fieldtex_core::NoProgress).map_err(|e| e.to_string())?;
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

/// `(slit length, MST length)` of the lower bound in the module docs, on the component's
/// first `faces.len()` faces (the kept copy), in global positions.
fn cut_bound(pos: &[[f64; 3]], c: &fieldtex_param::conformal::ConformalComponent) -> (f64, f64) {
    use std::cmp::Ordering;
    use std::collections::BinaryHeap;
    let g = |v: u32| c.local_to_global.get(v as usize).copied().unwrap_or(u32::MAX) as usize;
    let lp = &c.local_mesh.positions;
    let n = c.faces.len();
    let nv = c.local_mesh.n_vertices();
    let mut adj: Vec<Vec<(usize, f64)>> = vec![Vec::new(); nv];
    for t in &c.local_mesh.triangles[..n] {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let l = fieldtex_core::vec3::norm(fieldtex_core::vec3::sub(lp[a], lp[b]));
            adj[a].push((b, l));
            adj[b].push((a, l));
        }
    }
    // Terminals: each slit (its vertex set) and each negative-index zero point.
    let mut terminals: Vec<Vec<usize>> = Vec::new();
    let mut slit_len = 0.0;
    if let Some(p) = &c.protrusion_slits {
        for path in &p.slit_paths {
            let local: Vec<usize> =
                (0..nv).filter(|&v| path.contains(&(g(v as u32) as u32))).collect();
            for w in path.windows(2) {
                slit_len += fieldtex_core::vec3::norm(fieldtex_core::vec3::sub(
                    pos[w[0] as usize],
                    pos[w[1] as usize],
                ));
            }
            if !local.is_empty() {
                terminals.push(local);
            }
        }
    }
    for &(v, i) in &c.map.zero_points {
        if i < 0 && (v as usize) < nv {
            terminals.push(vec![v as usize]);
        }
    }
    #[derive(PartialEq)]
    struct Item(f64, usize);
    impl Eq for Item {}
    impl PartialOrd for Item {
        fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
            Some(self.cmp(o))
        }
    }
    impl Ord for Item {
        fn cmp(&self, o: &Self) -> Ordering {
            o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
        }
    }
    let dijkstra = |src: &[usize]| {
        let mut d = vec![f64::INFINITY; nv];
        let mut heap = BinaryHeap::new();
        for &s in src {
            d[s] = 0.0;
            heap.push(Item(0.0, s));
        }
        while let Some(Item(dv, v)) = heap.pop() {
            if dv > d[v] {
                continue;
            }
            for &(w, l) in &adj[v] {
                if dv + l < d[w] {
                    d[w] = dv + l;
                    heap.push(Item(d[w], w));
                }
            }
        }
        d
    };
    let m = terminals.len();
    let dist: Vec<Vec<f64>> = terminals
        .iter()
        .map(|t| {
            let d = dijkstra(t);
            terminals
                .iter()
                .map(|u| u.iter().map(|&v| d[v]).fold(f64::INFINITY, f64::min))
                .collect()
        })
        .collect();
    // Prim.
    let mut in_tree = vec![false; m];
    let mut best = vec![f64::INFINITY; m];
    let mut total = 0.0;
    if m > 0 {
        best[0] = 0.0;
    }
    for _ in 0..m {
        let Some(u) = (0..m).filter(|&i| !in_tree[i]).min_by(|&a, &b| best[a].total_cmp(&best[b]))
        else {
            break;
        };
        in_tree[u] = true;
        if best[u].is_finite() {
            total += best[u];
        }
        for v in 0..m {
            if !in_tree[v] && dist[u][v] < best[v] {
                best[v] = dist[u][v];
            }
        }
    }
    (slit_len, total)
}
