//! Merging of small or nearly enclosed charts (step 5 of
//! [`crate::chart_segmentation`]), after Sander, Snyder, Gortler & Hoppe 2001,
//! "Texture mapping progressive meshes" (greedy chart merging).
//!
//! Charts are visited from the smallest; a chart with less than `small_fraction` of
//! the mean chart area, or sharing at least half of its perimeter with one neighbour,
//! merges into the neighbour with the longest shared boundary when
//! - the union's normal cone stays within the limit (80° for tiny charts, under 5 % of
//!   the mean area): first bounded from the two charts' cones, and, when that bound
//!   fails for a chart below the mean area, measured over the union's faces around
//!   its mean normal;
//! - unless the chart is tiny, at most 80 % of the shared boundary is a crease (a
//!   dihedral turn above 60°): charts folded over sharp edges flatten into awkward
//!   shapes that pack badly (xatlas weighs such "normal seams" in its chart cost for
//!   the same reason); and
//! - the union is still a disk: with corners joined across interior edges in a global
//!   union-find, `χ(c ∪ d) = χ(c) + χ(d) + I_cd − k`, where `I_cd` counts the shared
//!   edges and `k` the vertex classes the shared edges join (found with a small
//!   union-find over the classes at those edges), so the test costs only the shared
//!   boundary.
//!
//! Each chart merges at most once per pass; passes repeat until nothing merges (at
//! most 12).

use crate::face_graph::{FaceGraph, NONE};
use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::UnionFind;

/// Cosine of the dihedral turn above which a shared edge counts as a crease (60°).
const SHARP_COS: f64 = 0.5;

/// Per-chart bookkeeping of the merge step.
#[derive(Debug, Clone)]
struct ChartStat {
    faces: Vec<u32>,
    area: f64,
    nsum: V3,
    axis: V3,
    half_angle: f64,
    interior: i64,
    chi: i64,
    perimeter: f64,
}

fn cone_of(graph: &FaceGraph, faces: &[u32], nsum: V3) -> (V3, f64) {
    let axis = vec3::normalize(nsum).unwrap_or([0.0, 0.0, 1.0]);
    let mut min_dot: f64 = 1.0;
    for &f in faces {
        if !graph.degenerate[f as usize] {
            min_dot = min_dot.min(vec3::dot(graph.normals[f as usize], axis));
        }
    }
    (axis, min_dot.clamp(-1.0, 1.0).acos())
}

/// Merges small or enclosed charts into neighbours (module docs). `theta` is the
/// normal-cone half-angle in radians.
pub(crate) fn merge_small_charts(
    graph: &FaceGraph,
    charts: Vec<Vec<u32>>,
    small_fraction: f64,
    theta: f64,
) -> Vec<Vec<u32>> {
    let nf = graph.n_faces();
    let n0 = charts.len();
    if n0 < 2 {
        return charts;
    }
    let mut chart_of = vec![0u32; nf];
    for (c, faces) in charts.iter().enumerate() {
        for &f in faces {
            chart_of[f as usize] = c as u32;
        }
    }
    // Global corner union-find: corners joined across interior edges of one chart.
    let mut uf = UnionFind::new(3 * nf);
    for f in 0..nf {
        for i in 0..3 {
            let g = graph.adj[f][i];
            if g == NONE || (g as usize) < f || chart_of[g as usize] != chart_of[f] {
                continue;
            }
            let j = graph.adj_edge[f][i] as usize;
            uf.union(3 * f + i, 3 * g as usize + (j + 1) % 3);
            uf.union(3 * f + (i + 1) % 3, 3 * g as usize + j);
        }
    }
    let mut stats: Vec<ChartStat> = Vec::with_capacity(n0);
    let mut root_seen = vec![u32::MAX; 3 * nf];
    for (c, faces) in charts.into_iter().enumerate() {
        let mut area = 0.0;
        let mut nsum = [0.0; 3];
        let mut interior = 0i64;
        let mut perimeter = 0.0;
        let mut nv = 0i64;
        for &f in &faces {
            let f = f as usize;
            area += graph.areas[f];
            nsum = vec3::add(nsum, vec3::scale(graph.normals[f], graph.areas[f]));
            for i in 0..3 {
                let g = graph.adj[f][i];
                if g != NONE && chart_of[g as usize] == c as u32 {
                    interior += 1; // counted from both sides
                } else {
                    perimeter += graph.edge_len[f][i];
                }
                let r = uf.find(3 * f + i);
                if root_seen[r] != c as u32 {
                    root_seen[r] = c as u32;
                    nv += 1;
                }
            }
        }
        interior /= 2;
        let (axis, half_angle) = cone_of(graph, &faces, nsum);
        let chi = nv - 2 * faces.len() as i64 + interior;
        stats.push(ChartStat { faces, area, nsum, axis, half_angle, interior, chi, perimeter });
    }
    let total_area: f64 = stats.iter().map(|s| s.area).sum();
    let tiny_theta = theta.max(80f64.to_radians());
    for _pass in 0..12 {
        let alive: Vec<usize> = (0..stats.len()).filter(|&c| !stats[c].faces.is_empty()).collect();
        let mean_area = total_area / alive.len().max(1) as f64;
        // Shared edges between different charts, each edge once: (c_lo, c_hi, f, i).
        let mut shared: Vec<(u32, u32, u32, u8)> = Vec::new();
        for f in 0..nf {
            for i in 0..3 {
                let g = graph.adj[f][i];
                if g == NONE || (g as usize) < f {
                    continue;
                }
                let (a, b) = (chart_of[f], chart_of[g as usize]);
                if a != b {
                    shared.push((a.min(b), a.max(b), f as u32, i as u8));
                }
            }
        }
        shared.sort_unstable();
        // Pair groups: (a, b, start, end, length).
        let mut pairs: Vec<(u32, u32, usize, usize, f64)> = Vec::new();
        // Per pair: the length of shared edges across which the surface bends sharply.
        let mut sharp_len: Vec<f64> = Vec::new();
        let mut s = 0;
        while s < shared.len() {
            let mut e = s;
            let mut len = 0.0;
            let mut sharp = 0.0;
            while e < shared.len() && shared[e].0 == shared[s].0 && shared[e].1 == shared[s].1 {
                let (f, i) = (shared[e].2 as usize, shared[e].3 as usize);
                let l = graph.edge_len[f][i];
                len += l;
                let g = graph.adj[f][i] as usize;
                if vec3::dot(graph.normals[f], graph.normals[g]) < SHARP_COS {
                    sharp += l;
                }
                e += 1;
            }
            pairs.push((shared[s].0, shared[s].1, s, e, len));
            sharp_len.push(sharp);
            s = e;
        }
        let mut nbrs: Vec<Vec<usize>> = vec![Vec::new(); stats.len()];
        for (k, p) in pairs.iter().enumerate() {
            nbrs[p.0 as usize].push(k);
            nbrs[p.1 as usize].push(k);
        }
        let mut order = alive.clone();
        order.sort_by(|&a, &b| stats[a].area.total_cmp(&stats[b].area).then(a.cmp(&b)));
        let mut locked = vec![false; stats.len()];
        let mut merged_any = false;
        for &c in &order {
            if locked[c] {
                continue;
            }
            let mut cand: Vec<usize> = nbrs[c].clone();
            cand.sort_by(|&x, &y| pairs[y].4.total_cmp(&pairs[x].4).then(x.cmp(&y)));
            let best_len = cand.first().map_or(0.0, |&k| pairs[k].4);
            let small = stats[c].area < small_fraction * mean_area;
            let enclosed = best_len >= 0.5 * stats[c].perimeter;
            if !small && !enclosed {
                continue;
            }
            let tiny = stats[c].area < 0.05 * mean_area;
            let limit = if tiny { tiny_theta } else { theta };
            for &k in &cand {
                let (a, b, s0, s1, len) = pairs[k];
                // Charts that are not tiny do not merge across a mostly sharp crease.
                if !tiny && sharp_len[k] > 0.8 * len {
                    continue;
                }
                let d = if a as usize == c { b as usize } else { a as usize };
                if locked[d] {
                    continue;
                }
                // Cone bound of the union.
                let nsum = vec3::add(stats[c].nsum, stats[d].nsum);
                let Some(axis) = vec3::normalize(nsum) else { continue };
                let ang =
                    |s: &ChartStat| vec3::dot(axis, s.axis).clamp(-1.0, 1.0).acos() + s.half_angle;
                if ang(&stats[c]).max(ang(&stats[d])) > limit {
                    // The bound is loose: for charts below the mean area, measure the
                    // union's cone around its axis.
                    if stats[c].area >= mean_area {
                        continue;
                    }
                    let cos_limit = limit.cos();
                    let within = |s: &ChartStat| {
                        s.faces.iter().all(|&f| {
                            graph.degenerate[f as usize]
                                || vec3::dot(graph.normals[f as usize], axis) >= cos_limit
                        })
                    };
                    if !(within(&stats[c]) && within(&stats[d])) {
                        continue;
                    }
                }
                // Euler characteristic of the union.
                let mut roots: Vec<(usize, usize)> = Vec::new();
                for &(_, _, f, i) in &shared[s0..s1] {
                    let (f, i) = (f as usize, i as usize);
                    let g = graph.adj[f][i] as usize;
                    let j = graph.adj_edge[f][i] as usize;
                    roots.push((uf.find(3 * f + i), uf.find(3 * g + (j + 1) % 3)));
                    roots.push((uf.find(3 * f + (i + 1) % 3), uf.find(3 * g + j)));
                }
                let mut ids: Vec<usize> = roots.iter().flat_map(|&(x, y)| [x, y]).collect();
                ids.sort_unstable();
                ids.dedup();
                let mut small_uf = UnionFind::new(ids.len());
                let mut k_merges = 0i64;
                for &(x, y) in &roots {
                    let (lx, ly) =
                        (ids.binary_search(&x).unwrap_or(0), ids.binary_search(&y).unwrap_or(0));
                    if small_uf.union(lx, ly) {
                        k_merges += 1;
                    }
                }
                let i_cd = (s1 - s0) as i64;
                let chi = stats[c].chi + stats[d].chi + i_cd - k_merges;
                if chi != 1 {
                    continue;
                }
                // Accept: merge c into d.
                for &(x, y) in &roots {
                    uf.union(x, y);
                }
                let faces_c = std::mem::take(&mut stats[c].faces);
                for &f in &faces_c {
                    chart_of[f as usize] = d as u32;
                }
                let sc = stats[c].clone();
                let sd = &mut stats[d];
                sd.faces.extend(faces_c);
                sd.area += sc.area;
                sd.nsum = nsum;
                sd.interior += sc.interior + i_cd;
                sd.chi = chi;
                sd.perimeter += sc.perimeter - 2.0 * len;
                let (ax, ha) = cone_of(graph, &sd.faces, sd.nsum);
                sd.axis = ax;
                sd.half_angle = ha;
                stats[c].area = 0.0;
                locked[c] = true;
                locked[d] = true;
                merged_any = true;
                break;
            }
        }
        if !merged_any {
            break;
        }
    }
    stats.into_iter().filter(|s| !s.faces.is_empty()).map(|s| s.faces).collect()
}
