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
    let inside = stroke.points.iter().filter(|p| locate(**p).is_some()).count();
    if stroke.points.len() < 2 || inside < 2 {
        return Err(FieldsError::StrokeTooShort { stroke: index, points: inside });
    }
    let n = symmetry.n() as f64;
    let step = 0.25 * dec.mean_edge_length;
    // Per face: accumulated N-th power direction.
    let mut acc: Vec<(usize, [f64; 2])> = Vec::new();
    for seg in stroke.points.windows(2) {
        let d = sub(seg[1], seg[0]);
        let len = norm(d);
        if len <= 0.0 {
            continue;
        }
        let samples = ((len / step).ceil() as usize).max(1);
        for s in 0..samples {
            let t = (s as f64 + 0.5) / samples as f64;
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
