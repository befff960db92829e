//! Direction strokes → weighted per-edge constraints `Z ω ≈ U_Z` (Fisher et al. 2007;
//! paper D, §2.1).
//!
//! A stroke (polyline) is sampled every quarter mean edge length. Each sample is located
//! on the domain; the tangent of its segment, expressed in the triangle's tangent frame
//! and raised to the `N`-th power (doubled angle for orientation fields, so that the
//! stroke's sign does not matter), is averaged per triangle. Each triangle touched gets
//! the unit target vector of the mean angle, and each of its three edges the constraint
//! `ω_e = t_f · (p_high − p_low)` with weight `w / |e|²` — the squared error of the
//! tangential component, so that a weight of 1 is comparable with the smoothness energy
//! of one edge. Edges shared by two stroke triangles get the weighted mean target.
//!
//! The constraint is diagonal in the edge basis (`ZᵀWZ` adds `w_e` to `A[e][e]`): adding
//! a stroke is a sum of rank-1 updates with unit vectors. Samples outside the domain are
//! skipped. Not implemented: a stroke's influence width (it constrains only the
//! triangles it crosses) and target magnitudes other than 1.

use fieldtex_core::vec3::{add, dot, norm, scale, sub};

use crate::FieldsError;
use crate::dec::Dec;
use crate::design_elements::{Stroke, Symmetry};
use crate::domain::Frame;

/// One edge constraint: `(edge, weight, weight · target)`.
pub type EdgeConstraint = (usize, f64, f64);

/// Builds the edge constraints of `stroke` (sorted by edge). `locate` maps a point to a
/// triangle and barycentric coordinates, or `None` outside the domain; `frames` holds
/// the per-triangle tangent frames; `weight` is the global stroke weight (multiplied by
/// the stroke's own). `index` names the stroke in errors.
pub fn stroke_edge_constraints(
    dec: &Dec,
    locate: &dyn Fn([f64; 3]) -> Option<(usize, [f64; 3])>,
    frames: &[Frame],
    symmetry: Symmetry,
    stroke: &Stroke,
    weight: f64,
    index: usize,
) -> Result<Vec<EdgeConstraint>, FieldsError> {
    for (k, p) in stroke.points.iter().enumerate() {
        for (c, v) in p.iter().enumerate() {
            if !v.is_finite() {
                return Err(FieldsError::NonFinite {
                    what: "stroke point",
                    index: k,
                    field: ["x", "y", "z"][c],
                    value: *v,
                });
            }
        }
    }
    let w = weight * stroke.weight;
    if !(w.is_finite() && w >= 0.0) {
        return Err(FieldsError::InvalidOption {
            name: "stroke weight",
            value: w,
            expected: "a finite number ≥ 0",
        });
    }
    if stroke.points.len() < 2 {
        return Err(FieldsError::StrokeTooShort { stroke: index, points: stroke.points.len() });
    }
    let n = symmetry.n() as f64;
    let step = 0.25 * dec.mean_edge_length;
    // Only the part of each segment inside the domain's (padded) bounding box is sampled,
    // so a huge stroke cannot make a huge number of samples.
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &dec.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] - dec.mean_edge_length);
            hi[k] = hi[k].max(p[k] + dec.mean_edge_length);
        }
    }
    // Per face: accumulated N-th power direction.
    let mut acc: Vec<(usize, [f64; 2])> = Vec::new();
    for seg in stroke.points.windows(2) {
        let d = sub(seg[1], seg[0]);
        let Some((t0, t1)) = clip_to_box(seg[0], d, lo, hi) else { continue };
        let len = norm(d) * (t1 - t0);
        if len <= 0.0 || !len.is_finite() {
            continue;
        }
        let samples = ((len / step).ceil() as usize).max(1);
        for s in 0..samples {
            let t = t0 + (t1 - t0) * (s as f64 + 0.5) / samples as f64;
            let p = add(seg[0], scale(d, t));
            let Some((f, _)) = locate(p) else { continue };
            let (e1, e2) = frames[f];
            let phi = dot(d, e2).atan2(dot(d, e1)) * n;
            acc.push((f, [phi.cos(), phi.sin()]));
        }
    }
    acc.sort_by_key(|a| a.0);
    let mut per_edge: Vec<(usize, f64, f64)> = Vec::new();
    let mut i = 0;
    while i < acc.len() {
        let f = acc[i].0;
        let mut sum = [0.0, 0.0];
        while i < acc.len() && acc[i].0 == f {
            sum = [sum[0] + acc[i].1[0], sum[1] + acc[i].1[1]];
            i += 1;
        }
        let m = (sum[0] * sum[0] + sum[1] * sum[1]).sqrt();
        if m < 1e-9 {
            continue; // opposite directions cancelled in this triangle
        }
        let (e1, e2) = frames[f];
        let target = add(scale(e1, sum[0] / m), scale(e2, sum[1] / m));
        for k in 0..3 {
            let e = dec.topology.face_edges[f][k] as usize;
            let ev = dec.edge_vector(e);
            let l2 = dot(ev, ev).max(f64::MIN_POSITIVE);
            let we = w / l2;
            per_edge.push((e, we, we * dot(target, ev)));
        }
    }
    if per_edge.is_empty() {
        return Err(FieldsError::StrokeMissesDomain { stroke: index });
    }
    per_edge.sort_by_key(|c| c.0);
    let mut merged: Vec<EdgeConstraint> = Vec::with_capacity(per_edge.len());
    for (e, we, wt) in per_edge {
        match merged.last_mut() {
            Some(last) if last.0 == e => {
                last.1 += we;
                last.2 += wt;
            }
            _ => merged.push((e, we, wt)),
        }
    }
    Ok(merged)
}

/// Parameter range `[t0, t1] ⊂ [0, 1]` of the segment `a + t·d` inside the box
/// (slab clipping), `None` if it misses the box.
fn clip_to_box(a: [f64; 3], d: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        if d[k] == 0.0 {
            if a[k] < lo[k] || a[k] > hi[k] {
                return None;
            }
            continue;
        }
        let (u, v) = ((lo[k] - a[k]) / d[k], (hi[k] - a[k]) / d[k]);
        t0 = t0.max(u.min(v));
        t1 = t1.min(u.max(v));
    }
    (t0 <= t1).then_some((t0, t1))
}
