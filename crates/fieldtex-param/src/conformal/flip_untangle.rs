//! Local untangling of the few triangles a discrete conformal map flips.
//!
//! A discrete harmonic map with cotan weights (some negative on obtuse triangles) and
//! an approximate conjugate can fold an isolated triangle where the map compresses the
//! surface by orders of magnitude (the horse's legs under a slit-cylinder map: two
//! faces). This repair moves only the vertices of flipped triangles: each is placed at
//! the mean of its one-ring neighbours as seen from its own chart (a local Tutte step),
//! and the move is kept only when it lowers the number of non-positive triangles
//! around the vertex. A few sweeps, in vertex order, so the result is deterministic.
//! The map stays conformal everywhere else; moved vertices are counted so the caller
//! can report the repair. Vertices of slit fan faces (whose apex corner is built from
//! the others) are not moved, and faces beyond `n_faces` (caps) are ignored.
#![allow(clippy::needless_range_loop)] // index loops over parallel per-face tables

use super::ComponentMap;
use super::periodic_uv::signed_area;

/// Sweeps over the flipped triangles.
const SWEEPS: usize = 12;

/// Repairs `map`'s flipped triangles among the first `n_faces` of `triangles`; returns
/// `(vertices moved, triangles still non-positive)`.
pub fn untangle_flips(
    triangles: &[[u32; 3]],
    n_faces: usize,
    map: &mut ComponentMap,
) -> (usize, usize) {
    let nv = map.base.len();
    let bad = |map: &ComponentMap, f: usize| {
        map.apex[f].is_none()
            && signed_area(&map.corner[f]).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
    };
    let mut flipped: Vec<usize> = (0..n_faces).filter(|&f| bad(map, f)).collect();
    if flipped.is_empty() {
        return (0, 0);
    }
    let mut vertex_faces: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for f in 0..n_faces {
        for &v in &triangles[f] {
            vertex_faces[v as usize].push(f as u32);
        }
    }
    let mut moved = 0;
    for _ in 0..SWEEPS {
        let mut verts: Vec<u32> = flipped.iter().flat_map(|&f| triangles[f]).collect();
        verts.sort_unstable();
        verts.dedup();
        for &v in &verts {
            let v = v as usize;
            let faces = &vertex_faces[v];
            if faces.iter().any(|&f| map.apex[f as usize].is_some()) || map.base[v][0].is_nan() {
                continue;
            }
            // Neighbour corners relative to v's corner in each face, then the mean.
            let (mut sum, mut n) = ([0.0f64; 2], 0.0f64);
            for &f in faces {
                let f = f as usize;
                let k = (0..3).find(|&k| triangles[f][k] as usize == v).unwrap_or(0);
                let own = map.corner[f][k];
                for j in [(k + 1) % 3, (k + 2) % 3] {
                    let c = map.corner[f][j];
                    sum[0] += c[0] - own[0];
                    sum[1] += c[1] - own[1];
                    n += 1.0;
                }
            }
            if n == 0.0 {
                continue;
            }
            let shift = [sum[0] / n, sum[1] / n];
            let count_bad =
                |map: &ComponentMap| faces.iter().filter(|&&f| bad(map, f as usize)).count();
            let before = count_bad(map);
            let saved: Vec<[[f64; 2]; 3]> = faces.iter().map(|&f| map.corner[f as usize]).collect();
            for &f in faces {
                let f = f as usize;
                let k = (0..3).find(|&k| triangles[f][k] as usize == v).unwrap_or(0);
                map.corner[f][k][0] += shift[0];
                map.corner[f][k][1] += shift[1];
            }
            if count_bad(map) < before {
                map.base[v] = [map.base[v][0] + shift[0], map.base[v][1] + shift[1]];
                moved += 1;
            } else {
                for (&f, c) in faces.iter().zip(saved) {
                    map.corner[f as usize] = c;
                }
            }
        }
        flipped.retain(|&f| bad(map, f));
        if flipped.is_empty() {
            break;
        }
    }
    (moved, flipped.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conformal::ConformalMethod;

    #[test]
    fn a_folded_fan_vertex_is_moved_back_inside_its_ring() {
        // A hexagonal fan around vertex 0 whose centre was pushed outside the ring.
        let mut base: Vec<[f64; 2]> = vec![[1.6, 0.0]];
        for k in 0..6 {
            let a = k as f64 * std::f64::consts::PI / 3.0;
            base.push([a.cos(), a.sin()]);
        }
        let triangles: Vec<[u32; 3]> = (0..6).map(|k| [0, 1 + k, 1 + (k + 1) % 6]).collect();
        let corner: Vec<[[f64; 2]; 3]> =
            triangles.iter().map(|t| t.map(|v| base[v as usize])).collect();
        let before = corner.iter().filter(|c| signed_area(c) <= 0.0).count();
        assert!(before > 0);
        let mut map = ComponentMap {
            corner,
            base,
            apex: vec![None; 6],
            ..ComponentMap::empty(ConformalMethod::SlitCylinder)
        };
        let (moved, left) = untangle_flips(&triangles, 6, &mut map);
        assert_eq!((moved, left), (1, 0));
        assert!(map.corner.iter().all(|c| signed_area(c) > 0.0));
        assert!(map.base[0][0].abs() < 1e-12 && map.base[0][1].abs() < 1e-12);
    }
}
