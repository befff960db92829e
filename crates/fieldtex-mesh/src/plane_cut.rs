//! Cutting a triangle mesh with a plane and capping the cut (for cut views of solid
//! textures, paper E §6).
//!
//! The part on the negative side of the plane `(p − point) · normal ≤ 0` is kept:
//! triangles are clipped against the plane (new vertices on crossing edges, shared
//! between the two triangles of an edge), and the boundary half-edges that lie on the
//! plane are chained into loops and triangulated in the plane
//! ([`crate::polygon_triangulation`]) as the cap, facing `+normal`. Where the input is
//! closed and consistently oriented the result is closed (every edge has two
//! triangles). Loops that do not close (an open input crossing the plane) are left
//! open and counted.

use crate::TriMesh;
use crate::polygon_triangulation::triangulate_polygons;
use std::collections::HashMap;

/// A capped cut: the kept surface triangles first, then the cap.
#[derive(Clone, Debug)]
pub struct PlaneCut {
    pub mesh: TriMesh,
    /// Triangles `cap_start..` are the cap.
    pub cap_start: usize,
    /// Closed loops capped.
    pub loops: usize,
    /// Chains of on-plane boundary edges that did not close (not capped).
    pub open_chains: usize,
    /// Ear-clipping steps that found no valid ear (degenerate loops).
    pub forced_clips: usize,
}

/// Cuts `mesh` with the plane through `point` with normal `normal` (module docs).
/// Vertex attributes other than positions are dropped. `None` for a zero normal.
pub fn cut_with_plane(mesh: &TriMesh, point: [f64; 3], normal: [f64; 3]) -> Option<PlaneCut> {
    let len = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
    if !(len.is_finite() && len > 1e-300) {
        return None;
    }
    let n = [normal[0] / len, normal[1] / len, normal[2] / len];
    let dist: Vec<f64> = mesh
        .positions
        .iter()
        .map(|p| (p[0] - point[0]) * n[0] + (p[1] - point[1]) * n[1] + (p[2] - point[2]) * n[2])
        .collect();
    let kept = |v: u32| dist[v as usize] <= 0.0;
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut on_plane: Vec<bool> = Vec::new();
    let mut remap: Vec<u32> = vec![u32::MAX; mesh.positions.len()];
    let mut edge_points: HashMap<(u32, u32), u32> = HashMap::new();
    let mut old_vertex = |v: u32, positions: &mut Vec<[f64; 3]>, on_plane: &mut Vec<bool>| -> u32 {
        if remap[v as usize] == u32::MAX {
            remap[v as usize] = positions.len() as u32;
            positions.push(mesh.positions[v as usize]);
            on_plane.push(dist[v as usize] == 0.0);
        }
        remap[v as usize]
    };
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for t in &mesh.triangles {
        let k = t.iter().filter(|&&v| kept(v)).count();
        if k == 0 {
            continue;
        }
        if k == 3 {
            let tri = t.map(|v| old_vertex(v, &mut positions, &mut on_plane));
            triangles.push(tri);
            continue;
        }
        let mut poly: Vec<u32> = Vec::with_capacity(4);
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            if kept(a) {
                poly.push(old_vertex(a, &mut positions, &mut on_plane));
            }
            if kept(a) != kept(b) {
                let (inside, outside) = if kept(a) { (a, b) } else { (b, a) };
                if dist[inside as usize] == 0.0 {
                    // The crossing is the on-plane vertex itself.
                    let v = old_vertex(inside, &mut positions, &mut on_plane);
                    if poly.last() != Some(&v) {
                        poly.push(v);
                    }
                    continue;
                }
                let key = (a.min(b), a.max(b));
                let v = *edge_points.entry(key).or_insert_with(|| {
                    let (pi, po) =
                        (mesh.positions[inside as usize], mesh.positions[outside as usize]);
                    let (di, d_o) = (dist[inside as usize], dist[outside as usize]);
                    let s = di / (di - d_o);
                    positions.push([
                        pi[0] + s * (po[0] - pi[0]),
                        pi[1] + s * (po[1] - pi[1]),
                        pi[2] + s * (po[2] - pi[2]),
                    ]);
                    on_plane.push(true);
                    (positions.len() - 1) as u32
                });
                poly.push(v);
            }
        }
        poly.dedup();
        if poly.len() > 1 && poly[0] == poly[poly.len() - 1] {
            poly.pop();
        }
        for i in 1..poly.len().saturating_sub(1) {
            triangles.push([poly[0], poly[i], poly[i + 1]]);
        }
    }
    let cap_start = triangles.len();
    // Boundary half-edges on the plane, reversed, chained into loops.
    let mut half: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &triangles {
        for e in 0..3 {
            *half.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
        }
    }
    let mut next: std::collections::BTreeMap<u32, u32> = std::collections::BTreeMap::new();
    for t in &triangles {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            if on_plane[a as usize] && on_plane[b as usize] && !half.contains_key(&(b, a)) {
                // The cap uses the reversed edge b → a.
                next.entry(b).or_insert(a);
            }
        }
    }
    let mut loops: Vec<Vec<usize>> = Vec::new();
    let mut open_chains = 0;
    let mut used: std::collections::BTreeSet<u32> = std::collections::BTreeSet::new();
    let starts: Vec<u32> = next.keys().copied().collect();
    for s in starts {
        if used.contains(&s) {
            continue;
        }
        let mut l = vec![s as usize];
        used.insert(s);
        let mut cur = s;
        let closed = loop {
            let Some(&nx) = next.get(&cur) else { break false };
            if nx == s {
                break true;
            }
            if !used.insert(nx) {
                break false;
            }
            l.push(nx as usize);
            cur = nx;
        };
        if closed && l.len() >= 3 {
            loops.push(l);
        } else {
            open_chains += 1;
        }
    }
    // Plane basis e1, e2 with e1 × e2 = n.
    let helper = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let e1 = normalize(cross3(helper, n));
    let e2 = cross3(n, e1);
    let pts2: Vec<[f64; 2]> = positions
        .iter()
        .map(|p| {
            let d = [p[0] - point[0], p[1] - point[1], p[2] - point[2]];
            [dot3(d, e1), dot3(d, e2)]
        })
        .collect();
    let (cap, forced_clips) = triangulate_polygons(&pts2, &loops);
    triangles.extend(cap.iter().map(|t| [t[0] as u32, t[1] as u32, t[2] as u32]));
    Some(PlaneCut {
        mesh: TriMesh::new(positions, triangles),
        cap_start,
        loops: loops.len(),
        open_chains,
        forced_clips,
    })
}

fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = dot3(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every undirected edge has exactly two triangles, in opposite directions.
    fn is_closed(m: &TriMesh) -> bool {
        let mut half: HashMap<(u32, u32), usize> = HashMap::new();
        for t in &m.triangles {
            for e in 0..3 {
                *half.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
            }
        }
        half.iter().all(|(&(a, b), &c)| c == 1 && half.get(&(b, a)) == Some(&1))
    }

    #[test]
    fn cuts_of_closed_meshes_are_closed() {
        let torus = crate::primitives::torus(1.0, 0.4, 32, 16);
        let sphere = crate::primitives::icosphere(3);
        assert!(is_closed(&torus) && is_closed(&sphere));
        for (mesh, point, normal) in [
            (&sphere, [0.1, 0.05, 0.02], [0.3, 0.2, 1.0]),
            (&torus, [0.0, 0.0, 0.013], [0.0, 0.0, 1.0]), // an annulus: a cap with a hole
            (&torus, [0.011, 0.0, 0.0], [1.0, 0.0, 0.0]), // two discs
        ] {
            let cut = cut_with_plane(mesh, point, normal).unwrap();
            assert!(cut.loops >= 1 && cut.open_chains == 0 && cut.forced_clips == 0);
            assert!(cut.mesh.triangles.len() > cut.cap_start);
            assert!(is_closed(&cut.mesh), "cut {normal:?} is not closed");
            // Nothing is left on the positive side.
            let n = normalize(normal);
            for p in &cut.mesh.positions {
                let d = dot3([p[0] - point[0], p[1] - point[1], p[2] - point[2]], n);
                assert!(d <= 1e-9);
            }
        }
    }
}
