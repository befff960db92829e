//! Curve preprocessing before curve orientation (paper A, §4.1): group nearby pieces
//! of one feature, break curves at sharp turns, drop tiny pieces.
//!
//! Xu et al. ("Feature-aligned shape texturing", §4.1) orient whole curves at a time,
//! so a curve should be one smooth feature: fragments of a ridge interrupted by noise
//! are joined, and a polyline turning a corner (two creases meeting) is split there.
//! The paper leaves the thresholds to the user; the defaults here are in mean edge
//! lengths (the `unit` argument), so they suit any scale:
//!
//! 1. **Join** (greedy, best first). Two open lines of the same [`LineKind`] are joined
//!    at a pair of endpoints when the endpoints are at most
//!    [`CurvePreprocessOptions::join_distance`] apart and the directions agree within
//!    [`CurvePreprocessOptions::join_angle_deg`]: the outward direction of one end
//!    against the inward direction of the other and, for a gap longer than half a unit,
//!    each against the gap itself. Directions are measured over
//!    [`CurvePreprocessOptions::direction_window`] of arc length, so a jagged last
//!    segment does not decide. Pairs are taken by increasing
//!    `distance / join_distance + angle / join_angle`; each endpoint joins once; the
//!    two free ends of one chain may close it into a loop (when the chain is longer
//!    than four join distances).
//! 2. **Break.** The turning angle at a point is the angle between the chords to the
//!    points one `direction_window` before and after it (along the curve); points
//!    turning more than [`CurvePreprocessOptions::break_angle_deg`] that are the
//!    largest turn within a window are break points. A closed curve broken once
//!    becomes an open curve starting there.
//! 3. **Drop** curves shorter than [`CurvePreprocessOptions::min_length`].
//!
//! Joined lines concatenate their points (the gap becomes a segment); per-point
//! triangles follow their points. Works on user curves through
//! [`preprocess_polylines`] (and [`crate::given_curves`] for curves on a mesh).

use crate::FeaturesError;
use crate::crest_lines::{CrestLine, LineKind, LineSource, polyline_length};
use crate::error::check_option;
use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::SpatialGrid;
use fieldtex_mesh::UnionFind;
use serde::Serialize;

/// Options of curve preprocessing; lengths in units of the `unit` argument (the mesh's
/// mean edge length for curves on a mesh).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurvePreprocessOptions {
    /// Largest endpoint gap joined. Default 2. `0` joins only coincident endpoints.
    pub join_distance: f64,
    /// Largest direction mismatch at a join, degrees. Default 30.
    pub join_angle_deg: f64,
    /// Turning angle above which a curve is broken, degrees. Default 60; 180 never
    /// breaks.
    pub break_angle_deg: f64,
    /// Arc length over which directions and turning angles are measured. Default 3.
    pub direction_window: f64,
    /// Curves shorter than this are dropped. Default 5.
    pub min_length: f64,
}

impl Default for CurvePreprocessOptions {
    fn default() -> Self {
        Self {
            join_distance: 2.0,
            join_angle_deg: 30.0,
            break_angle_deg: 60.0,
            direction_window: 3.0,
            min_length: 5.0,
        }
    }
}

impl CurvePreprocessOptions {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), FeaturesError> {
        check_option("join_distance", self.join_distance, self.join_distance >= 0.0, "≥ 0")?;
        check_option(
            "join_angle_deg",
            self.join_angle_deg,
            (0.0..=180.0).contains(&self.join_angle_deg),
            "in [0, 180]",
        )?;
        check_option(
            "break_angle_deg",
            self.break_angle_deg,
            (0.0..=180.0).contains(&self.break_angle_deg),
            "in [0, 180]",
        )?;
        check_option(
            "direction_window",
            self.direction_window,
            self.direction_window > 0.0,
            "> 0",
        )?;
        check_option("min_length", self.min_length, self.min_length >= 0.0, "≥ 0")
    }
}

/// Preprocesses plain polylines (module docs); `unit` scales the options' lengths.
/// Curves with fewer than two points are dropped; a non-finite point is an error.
pub fn preprocess_polylines(
    curves: &[Vec<V3>],
    unit: f64,
    options: &CurvePreprocessOptions,
) -> Result<Vec<Vec<V3>>, FeaturesError> {
    options.validate()?;
    check_option("unit", unit, unit > 0.0, "> 0 (e.g. the mean edge length)")?;
    check_finite(curves)?;
    let lines = curves.iter().map(|c| given_line(c.clone(), Vec::new())).collect();
    Ok(preprocess_lines(lines, unit, options).into_iter().map(|l| l.points).collect())
}

/// The first non-finite point of `curves` as an error.
pub(crate) fn check_finite(curves: &[Vec<V3>]) -> Result<(), FeaturesError> {
    for (c, pts) in curves.iter().enumerate() {
        if let Some(p) = pts.iter().position(|p| !vec3::is_finite(*p)) {
            return Err(FeaturesError::NonFiniteCurvePoint { curve: c, point: p });
        }
    }
    Ok(())
}

/// A user curve as a line (closed when its last point repeats its first).
pub(crate) fn given_line(points: Vec<V3>, faces: Vec<u32>) -> CrestLine {
    let closed = points.len() > 3 && points.first() == points.last();
    CrestLine {
        length: polyline_length(&points),
        points,
        faces,
        kind: LineKind::Given,
        source: LineSource::User,
        closed,
        strength: 0.0,
        level: 0,
    }
}

/// Join, break and drop (module docs). `options` must be valid and `unit > 0`.
pub fn preprocess_lines(
    lines: Vec<CrestLine>,
    unit: f64,
    options: &CurvePreprocessOptions,
) -> Vec<CrestLine> {
    let window = options.direction_window * unit;
    let lines: Vec<CrestLine> = lines.into_iter().filter(|l| l.points.len() >= 2).collect();
    let joined = join_lines(lines, unit, options);
    let mut out = Vec::with_capacity(joined.len());
    for l in joined {
        out.extend(break_line(l, window, options.break_angle_deg.to_radians()));
    }
    out.retain(|l| l.length >= options.min_length * unit && l.points.len() >= 2);
    out
}

/// Unit direction from `a` to `b`, or `None` for coincident points.
fn direction(a: V3, b: V3) -> Option<V3> {
    vec3::normalize(vec3::sub(b, a))
}

/// Angle between unit vectors.
fn angle(a: V3, b: V3) -> f64 {
    vec3::dot(a, b).clamp(-1.0, 1.0).acos()
}

/// The point reached walking from `points[i]` in direction `step` (±1) until the arc
/// length reaches `window` (or the curve ends), with the arc length walked.
fn walk(points: &[V3], i: usize, step: isize, window: f64, cyclic: bool) -> (V3, f64) {
    let n = points.len() as isize;
    let (mut j, mut s) = (i as isize, 0.0);
    for _ in 0..points.len() {
        let mut k = j + step;
        if cyclic {
            k = k.rem_euclid(n);
        } else if k < 0 || k >= n {
            break;
        }
        s += vec3::norm(vec3::sub(points[k as usize], points[j as usize]));
        j = k;
        if s >= window {
            break;
        }
    }
    (points[j as usize], s)
}

/// Outward unit direction at end `end` (0 = first point, 1 = last) of an open line.
fn end_direction(points: &[V3], end: usize, window: f64) -> Option<V3> {
    let (i, step) = if end == 0 { (0, 1) } else { (points.len() - 1, -1) };
    let (q, _) = walk(points, i, step, window, false);
    direction(q, points[i])
}

fn join_lines(
    lines: Vec<CrestLine>,
    unit: f64,
    options: &CurvePreprocessOptions,
) -> Vec<CrestLine> {
    let radius = options.join_distance * unit;
    let max_angle = options.join_angle_deg.to_radians();
    let window = options.direction_window * unit;
    let n = lines.len();
    // Endpoint `2l + end`.
    let open = |l: usize| !lines[l].closed;
    let ends: Vec<(V3, Option<V3>)> = (0..2 * n)
        .map(|id| {
            let pts = &lines[id / 2].points;
            let p = if id % 2 == 0 { pts[0] } else { pts[pts.len() - 1] };
            (p, end_direction(pts, id % 2, window))
        })
        .collect();
    let boxes: Vec<(V3, V3)> = ends
        .iter()
        .enumerate()
        .map(|(id, &(p, _))| if open(id / 2) { (p, p) } else { ([f64::NAN; 3], [f64::NAN; 3]) })
        .collect();
    let grid = SpatialGrid::from_boxes(&boxes, radius.max(unit));
    let mut candidates: Vec<(f64, u32, u32)> = Vec::new();
    for i in 0..2 * n {
        let (p, Some(di)) = ends[i] else { continue };
        if !open(i / 2) {
            continue;
        }
        let r = [radius; 3];
        grid.for_each_in_box(vec3::sub(p, r), vec3::add(p, r), |j| {
            let j = j as usize;
            if j <= i || lines[j / 2].kind != lines[i / 2].kind {
                return;
            }
            let (q, Some(dj)) = ends[j] else { return };
            let gap = vec3::sub(q, p);
            let dist = vec3::norm(gap);
            if dist > radius {
                return;
            }
            let mut worst = angle(di, vec3::scale(dj, -1.0));
            if dist > 0.5 * unit {
                let g = vec3::scale(gap, 1.0 / dist);
                worst = worst.max(angle(di, g)).max(angle(vec3::scale(dj, -1.0), g));
            }
            if worst <= max_angle {
                let cost = dist / radius.max(1e-300) + worst / max_angle.max(1e-300);
                candidates.push((cost, i as u32, j as u32));
            }
        });
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    candidates.dedup_by(|a, b| a.1 == b.1 && a.2 == b.2);
    let mut partner = vec![u32::MAX; 2 * n];
    // Chains as sets of lines with their total length: a join inside one chain closes
    // it, which only long chains may do.
    let mut uf = UnionFind::new(n);
    let mut chain_length: Vec<f64> = lines.iter().map(|l| l.length).collect();
    for &(_, i, j) in &candidates {
        let (i, j) = (i as usize, j as usize);
        if partner[i] != u32::MAX || partner[j] != u32::MAX {
            continue;
        }
        let (ri, rj) = (uf.find(i / 2), uf.find(j / 2));
        if ri == rj {
            if chain_length[ri] <= 4.0 * radius.max(unit) {
                continue;
            }
        } else {
            uf.union(ri, rj);
            let r = uf.find(ri);
            chain_length[r] = chain_length[ri] + chain_length[rj];
        }
        partner[i] = j as u32;
        partner[j] = i as u32;
    }
    assemble(lines, &partner)
}

/// Concatenates lines along the endpoint pairing `partner` (chains first, then loops).
fn assemble(lines: Vec<CrestLine>, partner: &[u32]) -> Vec<CrestLine> {
    let n = lines.len();
    let mut visited = vec![false; n];
    let mut out = Vec::new();
    let follow = |start_line: usize, enter: usize, visited: &mut Vec<bool>| {
        let mut pieces: Vec<(usize, bool)> = Vec::new();
        let (mut l, mut enter) = (start_line, enter);
        loop {
            visited[l] = true;
            pieces.push((l, enter == 2 * l));
            let exit = if enter == 2 * l { 2 * l + 1 } else { 2 * l };
            let next = partner[exit];
            if next == u32::MAX || visited[next as usize / 2] {
                return (pieces, next != u32::MAX);
            }
            enter = next as usize;
            l = enter / 2;
        }
    };
    let mut chains = Vec::new();
    for l in 0..n {
        if visited[l] || lines[l].closed {
            continue;
        }
        for enter in [2 * l, 2 * l + 1] {
            if partner[enter] == u32::MAX && !visited[l] {
                chains.push(follow(l, enter, &mut visited));
            }
        }
    }
    for l in 0..n {
        if !visited[l] && !lines[l].closed {
            chains.push(follow(l, 2 * l, &mut visited));
        }
    }
    let mut slots: Vec<Option<CrestLine>> = lines.into_iter().map(Some).collect();
    for slot in &mut slots {
        if slot.as_ref().is_some_and(|x| x.closed) {
            out.extend(slot.take());
        }
    }
    for (pieces, closed) in chains {
        let mut it = pieces.into_iter();
        let (l0, fwd0) = it.next().expect("a chain has a piece");
        let mut acc = slots[l0].take().expect("each line is in one chain");
        if !fwd0 {
            acc.points.reverse();
            acc.faces.reverse();
        }
        for (l, fwd) in it {
            let mut next = slots[l].take().expect("each line is in one chain");
            if !fwd {
                next.points.reverse();
                next.faces.reverse();
            }
            let skip = usize::from(acc.points.last() == next.points.first());
            let with_faces =
                acc.faces.len() == acc.points.len() && next.faces.len() == next.points.len();
            acc.points.extend_from_slice(&next.points[skip..]);
            if with_faces {
                acc.faces.extend_from_slice(&next.faces[skip..]);
            } else {
                acc.faces.clear();
            }
            if acc.source != next.source {
                acc.source = LineSource::Mixed;
            }
        }
        if closed {
            if acc.points.first() != acc.points.last() {
                let (p, f) = (acc.points[0], acc.faces.first().copied());
                acc.points.push(p);
                if let Some(f) = f {
                    acc.faces.push(f);
                }
            }
            acc.closed = acc.points.len() > 3;
        }
        acc.length = polyline_length(&acc.points);
        out.push(acc);
    }
    out
}

/// Splits a line at its sharp turns (module docs, step 2).
fn break_line(line: CrestLine, window: f64, break_angle: f64) -> Vec<CrestLine> {
    if break_angle >= std::f64::consts::PI || line.points.len() < 3 {
        return vec![line];
    }
    let cyclic = line.closed;
    // For a closed line work on the points without the repeated last one.
    let m = if cyclic { line.points.len() - 1 } else { line.points.len() };
    let pts = &line.points[..m];
    let mut arc = vec![0.0; m];
    for i in 1..m {
        arc[i] = arc[i - 1] + vec3::norm(vec3::sub(pts[i], pts[i - 1]));
    }
    let total = line.length;
    let mut turns: Vec<(f64, usize)> = Vec::new();
    for i in 0..m {
        if !cyclic && (i == 0 || i == m - 1) {
            continue;
        }
        let (b, sb) = walk(pts, i, -1, window, cyclic);
        let (f, sf) = walk(pts, i, 1, window, cyclic);
        if sb < 0.5 * window || sf < 0.5 * window {
            continue;
        }
        let (Some(d0), Some(d1)) = (direction(b, pts[i]), direction(pts[i], f)) else { continue };
        let a = angle(d0, d1);
        if a > break_angle {
            turns.push((a, i));
        }
    }
    turns.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    let separation = |i: usize, j: usize| {
        let d = (arc[i] - arc[j]).abs();
        if cyclic { d.min(total - d) } else { d }
    };
    let mut breaks: Vec<usize> = Vec::new();
    for &(_, i) in &turns {
        if breaks.iter().all(|&j| separation(i, j) >= window) {
            breaks.push(i);
        }
    }
    if breaks.is_empty() {
        return vec![line];
    }
    breaks.sort_unstable();
    let has_faces = line.faces.len() == line.points.len();
    let piece = |idx: &[usize]| {
        let mut l = line.clone();
        l.points = idx.iter().map(|&i| pts[i]).collect();
        l.faces = if has_faces { idx.iter().map(|&i| line.faces[i]).collect() } else { Vec::new() };
        l.closed = false;
        l.length = polyline_length(&l.points);
        l
    };
    let mut out = Vec::new();
    if cyclic {
        for (k, &b) in breaks.iter().enumerate() {
            let e = breaks[(k + 1) % breaks.len()];
            let mut idx = vec![b];
            let mut i = b;
            loop {
                i = (i + 1) % m;
                idx.push(i);
                if i == e {
                    break;
                }
            }
            out.push(piece(&idx));
        }
    } else {
        let mut start = 0;
        for &b in breaks.iter().chain(std::iter::once(&(m - 1))) {
            let idx: Vec<usize> = (start..=b).collect();
            if idx.len() >= 2 {
                out.push(piece(&idx));
            }
            start = b;
        }
    }
    out
}

#[cfg(test)]
#[path = "curve_preprocessing_tests.rs"]
mod tests;
