//! One domain level tabulated for the parallel synthesis ([`crate::synthesize`]):
//! neighbours, Jacobians (times the option scale), subpass classes, parents and, per
//! sample, which neighbours predict each corner of the four-corner neighbourhood.

use rayon::prelude::*;

use crate::domain::check_jacobian;
use crate::parallel_synthesis::CORNERS;
use crate::{SynthError, SynthesisDomain};

/// No neighbour.
pub(crate) const NONE: u32 = u32::MAX;

/// Neighbour offsets in angular order (angle `k · 45°` from +x, y down).
pub(crate) const OFFS8: [[i32; 2]; 8] =
    [[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1]];

/// One domain level, tabulated.
pub(crate) struct LevelTables {
    pub(crate) nbr: Vec<[u32; 8]>,
    pub(crate) jac: Vec<[f32; 4]>,
    pub(crate) classes: Vec<Vec<u32>>,
    pub(crate) parent: Vec<(u32, [f32; 2])>,
    /// Per sample and corner `Δ`, the neighbour (index into [`OFFS8`]) whose direction is
    /// closest to the warped corner offset `J⁻¹ Δ`; the corner averages that neighbour's
    /// prediction and those of its two angular neighbours.
    pub(crate) corner_dir: Vec<[u8; 4]>,
}

/// Unit vectors of [`OFFS8`] (angle `k · 45°`).
const DIRS8: [[f32; 2]; 8] = {
    const R: f32 = std::f32::consts::FRAC_1_SQRT_2;
    [[1.0, 0.0], [R, R], [0.0, 1.0], [-R, R], [-1.0, 0.0], [-R, -R], [0.0, -1.0], [R, -R]]
};

/// The [`LevelTables::corner_dir`] entry of Jacobian `j`: per corner, the direction of
/// [`OFFS8`] with the largest dot product with `J⁻¹ Δ` (the angularly nearest; the
/// lowest index on exact ties).
fn corner_directions(j: &[f32; 4]) -> [u8; 4] {
    let jinv = inverse(j);
    CORNERS.map(|cd| {
        let phi = mat_vec(&jinv, [cd[0] as f32, cd[1] as f32]);
        let mut best = (f32::NEG_INFINITY, 0u8);
        for (k, d) in DIRS8.iter().enumerate() {
            let dot = d[0] * phi[0] + d[1] * phi[1];
            if dot > best.0 {
                best = (dot, k as u8);
            }
        }
        best.1
    })
}

pub(crate) fn tabulate(
    domain: &dyn SynthesisDomain,
    level: usize,
    scale: f32,
    subpasses: usize,
    with_parent: bool,
) -> Result<LevelTables, SynthError> {
    let n = domain.sample_count(level);
    let coarse_n = if with_parent { domain.sample_count(level + 1) } else { 0 };
    type Row = ([u32; 8], [f32; 4], u8, (u32, [f32; 2]));
    let rows: Vec<Result<Row, SynthError>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut nb = [NONE; 8];
            for (k, o) in OFFS8.iter().enumerate() {
                if let Some(q) = domain.neighbor(level, i, *o) {
                    if q >= n {
                        return Err(SynthError::InvalidDomain {
                            reason: format!(
                                "level {level} sample {i}: neighbour {q} ≥ sample count {n}"
                            ),
                        });
                    }
                    nb[k] = q as u32;
                }
            }
            let j = domain.jacobian(level, i);
            check_jacobian(level, i, &j)?;
            let j = j.map(|v| v * scale);
            let class = if subpasses == 1 { 0 } else { domain.subpass_class(level, i) };
            if class >= 4 {
                return Err(SynthError::InvalidDomain {
                    reason: format!("level {level} sample {i}: subpass class {class} ≥ 4"),
                });
            }
            let parent = if with_parent {
                let (pi, off) = domain.parent(level, i);
                if pi >= coarse_n || !off.iter().all(|v| v.is_finite()) {
                    return Err(SynthError::InvalidDomain {
                        reason: format!(
                            "level {level} sample {i}: parent {pi} / offset {off:?} invalid"
                        ),
                    });
                }
                (pi as u32, off)
            } else {
                (0, [0.0; 2])
            };
            Ok((nb, j, class as u8, parent))
        })
        .collect();
    let mut t = LevelTables {
        nbr: Vec::with_capacity(n),
        jac: Vec::with_capacity(n),
        classes: vec![Vec::new(); subpasses],
        parent: Vec::with_capacity(n),
        corner_dir: Vec::with_capacity(n),
    };
    for (i, r) in rows.into_iter().enumerate() {
        let (nb, j, class, parent) = r?;
        t.nbr.push(nb);
        t.corner_dir.push(corner_directions(&j));
        t.jac.push(j);
        t.classes[class as usize].push(i as u32);
        t.parent.push(parent);
    }
    t.classes.retain(|c| !c.is_empty());
    Ok(t)
}

#[inline]
pub(crate) fn mat_vec(j: &[f32; 4], v: [f32; 2]) -> [f32; 2] {
    [j[0] * v[0] + j[1] * v[1], j[2] * v[0] + j[3] * v[1]]
}

#[inline]
pub(crate) fn frobenius(a: &[f32; 4], b: &[f32; 4]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

#[inline]
pub(crate) fn inverse(j: &[f32; 4]) -> [f32; 4] {
    let det = j[0] * j[3] - j[1] * j[2];
    [j[3] / det, -j[1] / det, -j[2] / det, j[0] / det]
}
