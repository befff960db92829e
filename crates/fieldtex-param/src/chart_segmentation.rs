//! Chart segmentation: cuts a mesh into charts that are topological disks and
//! flatten with little distortion.
//!
//! Method (a variational, proxy-based clustering in the spirit of Cohen-Steiner,
//! Alliez & Desbrun 2004, "Variational Shape Approximation", with the normal-cone
//! chart growing of Lévy, Petitjean, Ray & Maillot 2002 §4 and the merging of small
//! charts of Sander, Snyder, Gortler & Hoppe 2001, "Texture mapping progressive
//! meshes"):
//! 1. **Growing.** Every chart has a proxy: a seed triangle, a unit normal `N` and a
//!    centre `c`. Charts grow from their seeds, best triangle first, with the cost
//!    `(1 − n·N) + w‖x − c‖² / R² + w_b·β` (`n`, `x`: the triangle's normal and
//!    centroid; `R²` = total area / (π · #charts); `w` =
//!    [`SegmentationOptions::compactness_weight`]; `β` ∈ `[0, 2]` grows with the part
//!    of the triangle's perimeter not yet shared with the chart, so notches fill first
//!    and boundaries stay short, `w_b` = [`SegmentationOptions::boundary_weight`]). A
//!    triangle may join a chart only if its normal lies within
//!    [`SegmentationOptions::max_normal_angle_deg`] of `N`.
//! 2. **Seeding.** Regions left uncovered get a new chart (seeded at their most
//!    representative triangle) when they are large enough or form a whole component;
//!    new charts grow into uncovered triangles only, round after round. Small
//!    leftovers are finally absorbed by their neighbours without the cone limit.
//! 3. **Lloyd relaxation.** Proxies move to the area-weighted mean normal and centroid
//!    of their chart and the seed to the chart's cheapest triangle; all charts grow
//!    again at once (then step 2 covers what is left).
//! 4. **Boundary smoothing.** A triangle with two neighbours in another chart (and at
//!    most one in its own) moves there when that chart's cone allows it (this never
//!    disconnects a chart).
//! 5. **Merging.** Charts smaller than [`SegmentationOptions::small_chart_fraction`] of
//!    the mean chart area (by default every chart), or nearly enclosed by a neighbour,
//!    merge into the neighbour with the longest shared boundary when the union stays a
//!    disk, its normal cone stays within the limit and the shared boundary is not
//!    mostly a sharp crease ([`crate::chart_merging`]).
//! 6. **Disk guarantee.** Every chart whose Euler characteristic is not 1 (see
//!    [`crate::chart_topology`]) is split in two by a farthest-pair flood, repeatedly.
//!
//! Steps 1–3 work on planar units ([`crate::planar_units`]: connected groups of
//! at most 8 triangles within 0.01° of one plane, one unit per triangle elsewhere), with a unit's
//! area-weighted normal and centroid in the cost and its perimeter in `β`; steps 4–6
//! work on triangles.
//!
//! Charts follow chart adjacency ([`crate::face_graph`]): they never cross a
//! non-manifold or inconsistently oriented edge, nor a gap between components.
//! Not implemented: feature-curve detection (Lévy et al. §3) and texture-seam costs.

use crate::chart_merging::merge_small_charts;
use crate::chart_topology::{ChartMesh, split_in_two};
use crate::face_graph::{FaceGraph, NONE};
use crate::planar_units::Units;
use fieldtex_core::vec3::{self, V3};
use serde::{Deserialize, Serialize};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Options of [`segment_charts`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SegmentationOptions {
    /// Largest angle in degrees between a triangle's normal and its chart's normal
    /// while growing, and of the merged charts' normal cones. Default 80.
    pub max_normal_angle_deg: f64,
    /// Weight of the compactness term of the growing cost. Default 0.15.
    pub compactness_weight: f64,
    /// Lloyd relaxation rounds once every triangle is covered. Default 4.
    pub lloyd_iterations: usize,
    /// Charts with less than this fraction of the mean chart area try to merge into a
    /// neighbour. Default 10: in effect every chart; merging is then limited by the
    /// normal cone, the disk condition and creases (see [`crate::chart_merging`]).
    pub small_chart_fraction: f64,
    /// Boundary smoothing passes. Default 2.
    pub smoothing_passes: usize,
    /// Weight of the boundary-length term of the growing cost (0 when every neighbour
    /// of a triangle is in the chart, 2 when none is). Default 0.3.
    pub boundary_weight: f64,
}

impl Default for SegmentationOptions {
    fn default() -> Self {
        Self {
            max_normal_angle_deg: 80.0,
            compactness_weight: 0.15,
            lloyd_iterations: 4,
            small_chart_fraction: 10.0,
            smoothing_passes: 2,
            boundary_weight: 0.3,
        }
    }
}

/// The result of [`segment_charts`].
#[derive(Debug, Clone, PartialEq)]
pub struct Segmentation {
    /// `#F` chart of each triangle.
    pub chart_of_triangle: Vec<u32>,
    /// Triangles of each chart, sorted; charts ordered by their first triangle.
    pub charts: Vec<Vec<u32>>,
}

#[derive(Debug, Clone, Copy)]
struct Proxy {
    seed: u32,
    normal: V3,
    center: V3,
}

/// Segments the mesh behind `graph` into disk-shaped charts (see the module docs).
/// `triangles` are the mesh's triangles. Every triangle gets a chart.
pub fn segment_charts(
    graph: &FaceGraph,
    triangles: &[[u32; 3]],
    options: &SegmentationOptions,
) -> Segmentation {
    let nf = graph.n_faces();
    if nf == 0 {
        return Segmentation { chart_of_triangle: Vec::new(), charts: Vec::new() };
    }
    let theta = options.max_normal_angle_deg.clamp(1.0, 89.0).to_radians();
    let cos_max = theta.cos();
    let w = options.compactness_weight.max(0.0);
    let total_area: f64 = graph.areas.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    let units = Units::build(graph);

    let ctx =
        GrowCtx { units: &units, cos_max, w, wb: options.boundary_weight.max(0.0), total_area };
    let mut proxies: Vec<Proxy> = Vec::new();
    let mut assign = vec![NONE; units.n_units()];
    let mut budget = MAX_SEEDING_ROUNDS;
    seed_uncovered(&ctx, &mut assign, &mut proxies, &mut budget);
    for _ in 0..options.lloyd_iterations {
        proxies = lloyd_update(&ctx, &assign, &proxies);
        assign.fill(NONE);
        grow(&ctx, &proxies, 0..proxies.len(), &mut assign);
        seed_uncovered(&ctx, &mut assign, &mut proxies, &mut budget);
    }
    absorb_uncovered(&ctx, &mut assign, &proxies);
    // Seeds for anything still uncovered (cannot happen unless growth was capped).
    let mut next = proxies.len() as u32;
    for a in assign.iter_mut() {
        if *a == NONE {
            *a = next;
            next += 1;
        }
    }
    let assign: Vec<u32> = units.unit_of_face.iter().map(|&u| assign[u as usize]).collect();
    let mut charts = collect_charts(&assign);
    for _ in 0..options.smoothing_passes {
        smooth_boundaries(graph, &mut charts, cos_max);
    }
    let mut charts = merge_small_charts(graph, charts, options.small_chart_fraction, theta);
    ensure_disks(graph, triangles, &mut charts);
    finish(nf, charts)
}

/// Upper bound on seeding rounds (each adds at least one chart).
const MAX_SEEDING_ROUNDS: usize = 200;

/// What chart growing needs besides the proxies. Growing, seeding and the Lloyd
/// steps work on planar units ([`crate::planar_units`]); `assign` is per unit there.
struct GrowCtx<'a> {
    units: &'a Units,
    cos_max: f64,
    w: f64,
    wb: f64,
    total_area: f64,
}

impl GrowCtx<'_> {
    /// `R²` of the compactness term for `n` charts.
    fn r2(&self, n: usize) -> f64 {
        self.total_area / (std::f64::consts::PI * n.max(1) as f64)
    }
}

/// Adds charts for uncovered regions and grows them into uncovered units only,
/// until no region qualifies (see [`seeds_for_uncovered`]) or the budget is spent.
fn seed_uncovered(ctx: &GrowCtx, assign: &mut [u32], proxies: &mut Vec<Proxy>, budget: &mut usize) {
    while *budget > 0 {
        let r2 = ctx.r2(proxies.len());
        let mean_area = ctx.total_area / proxies.len().max(1) as f64;
        let new = seeds_for_uncovered(ctx.units, assign, ctx.w, r2, 0.1 * mean_area);
        if new.is_empty() {
            break;
        }
        *budget -= 1;
        let start = proxies.len();
        proxies.extend(new);
        grow(ctx, proxies, start..proxies.len(), assign);
    }
}

/// Best-first growth of the proxies in `active` through uncovered units under the
/// normal-cone limit; units already assigned stay where they are.
fn grow(ctx: &GrowCtx, proxies: &[Proxy], active: std::ops::Range<usize>, assign: &mut [u32]) {
    let units = ctx.units;
    let r2 = ctx.r2(proxies.len());
    let mut heap = BinaryHeap::new();
    for c in active {
        if assign[proxies[c].seed as usize] == NONE {
            heap.push(Reverse((0u64, proxies[c].seed, c as u32)));
        }
    }
    while let Some(Reverse((_, f, c))) = heap.pop() {
        if assign[f as usize] != NONE {
            continue;
        }
        assign[f as usize] = c;
        let p = &proxies[c as usize];
        for (g, _) in units.neighbours(f as usize) {
            if assign[g as usize] != NONE {
                continue;
            }
            let d = vec3::dot(units.normals[g as usize], p.normal);
            if !units.degenerate[g as usize] && d < ctx.cos_max {
                continue;
            }
            let cost = unit_cost(units, g as usize, p, ctx.w, r2)
                + ctx.wb * boundary_term(units, assign, g as usize, c);
            heap.push(Reverse((cost.to_bits(), g, c)));
        }
    }
}

/// Change of the chart's boundary length if unit `f` joined chart `c`, relative to
/// `f`'s perimeter, shifted to `[0, 2]`: 0 when all its neighbours are in `c`.
#[inline]
fn boundary_term(units: &Units, assign: &[u32], f: usize, c: u32) -> f64 {
    let total = units.perimeter[f];
    if total.is_nan() || total <= 0.0 {
        return 1.0;
    }
    let mut inside = 0.0;
    for (g, len) in units.neighbours(f) {
        if assign[g as usize] == c {
            inside += len;
        }
    }
    // (outside - inside) / total + 1 = 2 (total - inside) / total.
    2.0 * (total - inside) / total
}

#[inline]
fn unit_cost(units: &Units, f: usize, p: &Proxy, w: f64, r2: f64) -> f64 {
    let normal_term = if units.degenerate[f] {
        0.0
    } else {
        (1.0 - vec3::dot(units.normals[f], p.normal)).max(0.0)
    };
    let d2 = vec3::norm2(vec3::sub(units.centroids[f], p.center));
    let c = normal_term + w * d2 / r2;
    if c.is_finite() { c.max(0.0) } else { f64::MAX }
}

/// New proxies for the connected uncovered regions that are at least `min_area` large
/// (or that touch no chart at all, i.e. whole components). The largest region always
/// qualifies when it is at least a tenth of `min_area`.
fn seeds_for_uncovered(
    units: &Units,
    assign: &[u32],
    w: f64,
    r2: f64,
    min_area: f64,
) -> Vec<Proxy> {
    let nu = units.n_units();
    let mut seen = vec![false; nu];
    let mut regions: Vec<(Vec<u32>, f64, bool)> = Vec::new();
    let mut stack = Vec::new();
    for s in 0..nu {
        if seen[s] || assign[s] != NONE {
            continue;
        }
        seen[s] = true;
        stack.push(s as u32);
        let mut members = Vec::new();
        let mut area = 0.0;
        let mut touches = false;
        while let Some(f) = stack.pop() {
            members.push(f);
            area += units.areas[f as usize];
            for (g, _) in units.neighbours(f as usize) {
                if assign[g as usize] != NONE {
                    touches = true;
                } else if !seen[g as usize] {
                    seen[g as usize] = true;
                    stack.push(g);
                }
            }
        }
        regions.push((members, area, touches));
    }
    let largest = regions
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.1.total_cmp(&b.1.1).then(b.0.cmp(&a.0)))
        .map(|(i, _)| i);
    let mut out = Vec::new();
    for (k, (members, area, touches)) in regions.iter().enumerate() {
        let qualifies =
            !*touches || *area >= min_area || (Some(k) == largest && *area >= 0.1 * min_area);
        if qualifies {
            out.push(proxy_for(units, members, w, r2, None));
        }
    }
    out
}

/// The proxy of a set of units: mean normal and centroid, seed at the cheapest unit.
/// When the mean normal vanishes (a closed part) the `fallback` normal or the largest
/// unit's normal is used.
fn proxy_for(units: &Units, members: &[u32], w: f64, r2: f64, fallback: Option<V3>) -> Proxy {
    let mut nsum = [0.0; 3];
    let mut csum = [0.0; 3];
    let mut area = 0.0;
    for &f in members {
        let a = units.areas[f as usize];
        nsum = vec3::add(nsum, vec3::scale(units.normals[f as usize], a));
        csum = vec3::add(csum, vec3::scale(units.centroids[f as usize], a));
        area += a;
    }
    let center = if area > 0.0 {
        vec3::scale(csum, 1.0 / area)
    } else {
        units.centroids[members[0] as usize]
    };
    let normal = match vec3::normalize(nsum) {
        Some(n) if vec3::norm(nsum) > 0.2 * area => n,
        _ => fallback.unwrap_or_else(|| {
            let big = members
                .iter()
                .copied()
                .max_by(|&a, &b| {
                    units.areas[a as usize].total_cmp(&units.areas[b as usize]).then(b.cmp(&a))
                })
                .unwrap_or(members[0]);
            units.normals[big as usize]
        }),
    };
    let mut p = Proxy { seed: members[0], normal, center };
    let mut best = f64::INFINITY;
    for &f in members {
        let c = unit_cost(units, f as usize, &p, w, r2);
        if c < best {
            best = c;
            p.seed = f;
        }
    }
    p
}

fn lloyd_update(ctx: &GrowCtx, assign: &[u32], proxies: &[Proxy]) -> Vec<Proxy> {
    let (units, w, r2) = (ctx.units, ctx.w, ctx.r2(proxies.len()));
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); proxies.len()];
    for (f, &c) in assign.iter().enumerate() {
        if c != NONE {
            members[c as usize].push(f as u32);
        }
    }
    members
        .iter()
        .zip(proxies)
        .filter(|(m, _)| !m.is_empty())
        .map(|(m, p)| proxy_for(units, m, w, r2, Some(p.normal)))
        .collect()
}

/// Assigns uncovered units to neighbouring charts, best first, without the cone limit.
fn absorb_uncovered(ctx: &GrowCtx, assign: &mut [u32], proxies: &[Proxy]) {
    let (units, w, r2) = (ctx.units, ctx.w, ctx.r2(proxies.len()));
    let mut heap = BinaryHeap::new();
    for f in 0..units.n_units() {
        if assign[f] == NONE {
            continue;
        }
        for (g, _) in units.neighbours(f) {
            if assign[g as usize] == NONE {
                let c = assign[f];
                let cost = unit_cost(units, g as usize, &proxies[c as usize], w, r2);
                heap.push(Reverse((cost.to_bits(), g, c)));
            }
        }
    }
    while let Some(Reverse((_, f, c))) = heap.pop() {
        if assign[f as usize] != NONE {
            continue;
        }
        assign[f as usize] = c;
        for (g, _) in units.neighbours(f as usize) {
            if assign[g as usize] == NONE {
                let cost = unit_cost(units, g as usize, &proxies[c as usize], w, r2);
                heap.push(Reverse((cost.to_bits(), g, c)));
            }
        }
    }
}

fn collect_charts(assign: &[u32]) -> Vec<Vec<u32>> {
    let n = assign.iter().copied().max().map_or(0, |m| m as usize + 1);
    let mut charts = vec![Vec::new(); n];
    for (f, &c) in assign.iter().enumerate() {
        charts[c as usize].push(f as u32);
    }
    charts.retain(|c| !c.is_empty());
    charts
}

fn chart_normal(graph: &FaceGraph, faces: &[u32]) -> V3 {
    let mut s = [0.0; 3];
    for &f in faces {
        s = vec3::add(s, vec3::scale(graph.normals[f as usize], graph.areas[f as usize]));
    }
    vec3::normalize(s).unwrap_or([0.0; 3])
}

/// One pass of boundary smoothing (module docs, step 4).
fn smooth_boundaries(graph: &FaceGraph, charts: &mut Vec<Vec<u32>>, cos_max: f64) {
    let nf = graph.n_faces();
    let mut chart_of = vec![NONE; nf];
    for (c, faces) in charts.iter().enumerate() {
        for &f in faces {
            chart_of[f as usize] = c as u32;
        }
    }
    let normals: Vec<V3> = charts.iter().map(|c| chart_normal(graph, c)).collect();
    let mut changed = false;
    for f in 0..nf {
        let own = chart_of[f];
        let nb = graph.adj[f];
        let same = nb.iter().filter(|&&g| g != NONE && chart_of[g as usize] == own).count();
        if same > 1 {
            continue;
        }
        for k in 0..3 {
            if nb[k] == NONE {
                continue;
            }
            let other = chart_of[nb[k] as usize];
            if other == own {
                continue;
            }
            let cnt = nb.iter().filter(|&&g| g != NONE && chart_of[g as usize] == other).count();
            let ok = graph.degenerate[f]
                || vec3::dot(graph.normals[f], normals[other as usize]) >= cos_max;
            if cnt >= 2 && ok {
                chart_of[f] = other;
                changed = true;
                break;
            }
        }
    }
    if changed {
        let mut out = vec![Vec::new(); charts.len()];
        for (f, &c) in chart_of.iter().enumerate() {
            out[c as usize].push(f as u32);
        }
        out.retain(|c| !c.is_empty());
        *charts = out;
    }
}

/// Splits every chart that is not a disk until all are (module docs, step 6).
fn ensure_disks(graph: &FaceGraph, triangles: &[[u32; 3]], charts: &mut Vec<Vec<u32>>) {
    let mut out = Vec::with_capacity(charts.len());
    let mut work: Vec<Vec<u32>> = std::mem::take(charts);
    work.reverse();
    while let Some(faces) = work.pop() {
        let cm = ChartMesh::build(faces, graph, triangles);
        if cm.is_disk() {
            out.push(cm.faces);
            continue;
        }
        match split_in_two(&cm.faces, graph) {
            Some(parts) => {
                for p in parts.into_iter().rev() {
                    work.push(p);
                }
            }
            None => out.push(cm.faces),
        }
    }
    *charts = out;
}

/// Sorts charts by first triangle and builds the per-triangle table.
fn finish(nf: usize, mut charts: Vec<Vec<u32>>) -> Segmentation {
    for c in charts.iter_mut() {
        c.sort_unstable();
    }
    charts.sort_by_key(|c| c[0]);
    let mut chart_of_triangle = vec![0u32; nf];
    for (k, c) in charts.iter().enumerate() {
        for &f in c {
            chart_of_triangle[f as usize] = k as u32;
        }
    }
    Segmentation { chart_of_triangle, charts }
}
