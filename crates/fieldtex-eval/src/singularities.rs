//! ±1/2 singularities of an orientation field by the index of its doubled angle.
//!
//! For every loop through the centres of a 2×2 block of pixels, the doubled angles
//! `2θ` (well defined for a sign-free orientation) are compared around the loop; the
//! wrapped differences sum to `2π·k` and the loop encloses a singularity of index
//! `k/2` (+1/2: "wedge"/loop core, −1/2: trisector/delta). The index does not depend on
//! whether y points up or down. A field `θ = ½·atan2(y − y0, x − x0)` has index +1/2
//! at `(x0, y0)`, `θ = −½·atan2(…)` index −1/2.
//!
//! Positions are continuous pixel coordinates with pixel `(i, j)` centred at
//! `(i + 0.5, j + 0.5)`, so the loop through pixels `(x, y)…(x+1, y+1)` is centred at
//! `(x + 1, y + 1)`.
//!
//! Gating: a structure-tensor orientation is unreliable where the texture is flat or
//! isotropic, and such regions produce spurious index pairs; yet the coherence always
//! drops *at* a true singularity. So a loop is kept when the mean coherence on a
//! square ring of radius `gate_radius` around it (default 2σ, at least 2 px) reaches
//! `min_coherence`. Raw loops closer than `merge_radius` are then merged into
//! clusters (single linkage); a cluster's index is the sum of its members, so
//! dipoles cancel.

use crate::orientation::OrientationMap;
use fieldtex_fields::singularity_index::loop_turns;
use serde::Serialize;

/// Options of [`singularities`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SingularityOptions {
    /// Minimum mean coherence on the gate ring. Default 0.3.
    pub min_coherence: f32,
    /// Ring radius in pixels; `None` = `max(2, 2σ)` with σ of the map.
    pub gate_radius: Option<usize>,
    /// Single-linkage merge distance in pixels; `None` = `max(3, 1.5σ)`.
    pub merge_radius: Option<f64>,
    /// Loops within this many pixels of the border are ignored; `None` = `⌈2σ⌉ + 2` for
    /// maps from images, 0 for maps from fields.
    pub border: Option<usize>,
}

impl Default for SingularityOptions {
    fn default() -> Self {
        Self { min_coherence: 0.3, gate_radius: None, merge_radius: None, border: None }
    }
}

/// One loop with a non-zero index.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Singularity {
    pub x: f64,
    pub y: f64,
    /// Index: ±0.5 (±1 for a doubled winding inside one loop, rare).
    pub index: f64,
}

/// Merged nearby loops.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SingularityCluster {
    /// Mean position of the members.
    pub x: f64,
    pub y: f64,
    /// Sum of the members' indices.
    pub index: f64,
    /// Number of raw loops merged.
    pub count: usize,
}

/// Result of [`singularities`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SingularityReport {
    /// Every gated loop with a non-zero index, in scan order.
    pub raw: Vec<Singularity>,
    /// Clusters with a non-zero net index, in order of their first member.
    pub merged: Vec<SingularityCluster>,
    /// Merged clusters of positive / negative index.
    pub n_positive: usize,
    pub n_negative: usize,
    /// Sum of all merged indices.
    pub index_sum: f64,
    /// Clusters whose members cancelled (net index 0).
    pub cancelled_clusters: usize,
}

/// Turns of the doubled angle around the loop through the centres of pixels
/// `(x, y)`, `(x+1, y)`, `(x+1, y+1)`, `(x, y+1)` (index = turns / 2), counted by the
/// workspace's one index routine, `fieldtex_fields::singularity_index::loop_turns`.
pub(crate) fn loop_winding(map: &OrientationMap, x: usize, y: usize) -> f64 {
    let w = map.width;
    let idx = [y * w + x, y * w + x + 1, (y + 1) * w + x + 1, (y + 1) * w + x];
    let doubled = idx.map(|i| 2.0 * map.angle[i] as f64);
    f64::from(loop_turns(&doubled))
}

/// Finds the singularities of `map`; see the module docs.
pub fn singularities(map: &OrientationMap, options: &SingularityOptions) -> SingularityReport {
    let (w, h) = (map.width, map.height);
    let sigma = map.sigma;
    let gate = options.gate_radius.unwrap_or(((2.0 * sigma).round() as usize).max(2));
    let merge = options
        .merge_radius
        .filter(|r| r.is_finite() && *r >= 0.0)
        .unwrap_or((1.5 * sigma).max(3.0));
    let border =
        options.border.unwrap_or(if sigma > 0.0 { (2.0 * sigma).ceil() as usize + 2 } else { 0 });
    let mut raw = Vec::new();
    if w < 2 || h < 2 || map.angle.len() != w * h || map.coherence.len() != w * h {
        return summarize(raw, merge);
    }
    let ring_mean = |cx: usize, cy: usize| -> f32 {
        // Square ring of Chebyshev radius `gate` around the loop centre (cx, cy) =
        // corner between pixels cx-1, cx and cy-1, cy.
        let r = gate as isize;
        let (mut s, mut n) = (0f32, 0u32);
        for d in -r..r {
            let pts = [(d, -r), (r - 1, d), (-d - 1, r - 1), (-r, -d - 1)];
            for (dx, dy) in pts {
                let (x, y) = (cx as isize + dx, cy as isize + dy);
                if x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h {
                    s += map.coherence[y as usize * w + x as usize];
                    n += 1;
                }
            }
        }
        if n == 0 { 0.0 } else { s / n as f32 }
    };
    for y in border..(h - 1).saturating_sub(border) {
        for x in border..(w - 1).saturating_sub(border) {
            if sigma == 0.0
                && [y * w + x, y * w + x + 1, (y + 1) * w + x + 1, (y + 1) * w + x]
                    .iter()
                    .any(|&i| map.coherence[i] <= 0.0)
            {
                continue;
            }
            let winding = loop_winding(map, x, y);
            if winding == 0.0 {
                continue;
            }
            if sigma > 0.0 && ring_mean(x + 1, y + 1) < options.min_coherence {
                continue;
            }
            raw.push(Singularity { x: x as f64 + 1.0, y: y as f64 + 1.0, index: 0.5 * winding });
        }
    }
    summarize(raw, merge)
}

/// Single-linkage clustering within `merge` pixels, then the report.
fn summarize(raw: Vec<Singularity>, merge: f64) -> SingularityReport {
    let points: Vec<[f64; 2]> = raw.iter().map(|s| [s.x, s.y]).collect();
    let (labels, count) = crate::single_linkage::single_linkage_labels(&points, merge);
    let mut acc: Vec<(f64, f64, f64, usize)> = vec![(0.0, 0.0, 0.0, 0); count];
    for (s, &l) in raw.iter().zip(&labels) {
        acc[l].0 += s.x;
        acc[l].1 += s.y;
        acc[l].2 += s.index;
        acc[l].3 += 1;
    }
    let mut merged = Vec::new();
    let mut cancelled = 0;
    for (sx, sy, idx, c) in acc {
        if idx.abs() < 0.25 {
            cancelled += 1;
            continue;
        }
        merged.push(SingularityCluster {
            x: sx / c as f64,
            y: sy / c as f64,
            index: idx,
            count: c,
        });
    }
    SingularityReport {
        n_positive: merged.iter().filter(|c| c.index > 0.0).count(),
        n_negative: merged.iter().filter(|c| c.index < 0.0).count(),
        index_sum: merged.iter().map(|c| c.index).sum(),
        cancelled_clusters: cancelled,
        raw,
        merged,
    }
}

/// A designed (expected) singularity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ExpectedSingularity {
    pub x: f64,
    pub y: f64,
    pub index: f64,
}

/// How found singularities compare with designed ones.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SingularityMatch {
    /// Designed singularities with a found cluster of the same sign within the radius.
    pub matched: usize,
    /// Designed singularities without one.
    pub missed: usize,
    /// Found clusters not used by any match.
    pub spurious: usize,
    /// Mean distance of the matched pairs, pixels (NaN if none).
    pub mean_distance_px: f64,
}

/// Greedy matching (closest pairs first) of found clusters to designed singularities
/// of the same sign within `radius` pixels.
pub fn match_singularities(
    found: &[SingularityCluster],
    designed: &[ExpectedSingularity],
    radius: f64,
) -> SingularityMatch {
    let mut pairs = Vec::new();
    for (i, d) in designed.iter().enumerate() {
        for (j, f) in found.iter().enumerate() {
            let dist = ((d.x - f.x).powi(2) + (d.y - f.y).powi(2)).sqrt();
            if dist <= radius && d.index.signum() == f.index.signum() {
                pairs.push((dist, i, j));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let (mut used_d, mut used_f) = (vec![false; designed.len()], vec![false; found.len()]);
    let (mut matched, mut dsum) = (0, 0.0);
    for (dist, i, j) in pairs {
        if !used_d[i] && !used_f[j] {
            used_d[i] = true;
            used_f[j] = true;
            matched += 1;
            dsum += dist;
        }
    }
    SingularityMatch {
        matched,
        missed: designed.len() - matched,
        spurious: found.len() - matched,
        mean_distance_px: if matched > 0 { dsum / matched as f64 } else { f64::NAN },
    }
}
