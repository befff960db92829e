//! Seam coherence of orientation-field (2-RoSy) guided synthesis: how often the
//! exemplar coordinates of a synthesised image stay coherent across the places where
//! the field's representative vectors jump to the opposite direction, compared with
//! the share of coherent neighbour pairs over the whole image.
//!
//! Background (Liu et al. 2013, paper D §4, "Handling orientation"): an orientation
//! field is stored as one representative vector per pixel, and any such choice must
//! flip to the opposite vector along curves leaving each ±1/2 singularity (`u(p)·u(q)
//! < 0` for neighbours `p`, `q`). A synthesis that follows the representative Jacobian
//! `J(p)` blindly predicts the neighbour's exemplar coordinate turned by 180° there, so
//! its patches break along those curves (paper D Fig. 5); the 2-RoSy fix carries a
//! flip indicator so that the coordinates continue across the jump. This module is the
//! measure of that claim (issue 16 point 4): a texture made *with* the fix should be
//! about as coherent across the jumps as everywhere else, one made without it clearly
//! less.
//!
//! Definitions, for every horizontal and vertical neighbour pair `(p, q = p + δ)`,
//! `|δ| = 1` output pixel:
//! - **Jacobian** from the unit field vector `u = (ux, uy)` (pixel units, x right, y
//!   down) and the step `s` (exemplar pixels per output pixel), the convention of
//!   `fieldtex_synth::ImageDomain::from_direction_field`: `J = s·[[ux, uy], [−uy, ux]]`
//!   (the exemplar's x axis along `u`).
//! - **Expected step** `Ĵδ` with `Ĵ = (J(p) + σ J(q)) / 2`, `σ = sign(u(p)·u(q))`: the
//!   mean of the two frames once `q`'s representative is turned to `p`'s (the
//!   trapezoid rule; one frame per pair).
//! - **Coherent**: `min_{ε = ±1} ‖wrap(S[q] − S[p] − ε Ĵδ)‖_∞ ≤ t`, `S` the exemplar
//!   coordinates, `wrap` the toroidal difference over the exemplar size, `t` the
//!   tolerance ([`RosySeamOptions::tolerance`] exemplar pixels, times `max(1, s)`).
//!   Either sign counts: the output shows the exemplar either way round (a sample with
//!   the flip indicator shows it turned by 180°, and its neighbours then step by
//!   `−Ĵδ`); what breaks a texture is a step that matches neither.
//! - **Representation jump**: `u(p)·u(q) < 0`.
//!
//! The report gives the coherent share over all pairs (image-wide), over the pairs
//! across a representation jump (seam share), and their ratio. Pairs where either
//! field vector is zero or not finite are skipped. The result does not depend on the
//! thread count (integer counts; the loop is sequential, `O(W·H)`).
//!
//! **With the synthesis's flip indicators** `I` ([`rosy_seam_coherence_with_flips`]),
//! the jump pairs split in two. A jump pair whose *effective* frames `(−1)^I J` agree
//! (`I(p) ⊕ I(q)` = jump) is a **repaired jump**: the fix made the frames continue, so
//! its coordinates can continue too; this is what the fix is judged on
//! ([`RosySeamReport::repaired`]). Every pair whose effective frames point in opposite
//! directions (`σ · (−1)^(I(p) ⊕ I(q)) < 0`), at a representation jump or not, is an
//! **effective seam**: the seam a ±½ singularity forces on any choice of flips (a loop
//! around it must cross one). Across it the exemplar shows turned by 180°, which no
//! coordinate step continues (the coordinates on the far side are a point reflection
//! of the near side's), so its coherent share is low by construction; it is reported
//! ([`RosySeamReport::effective_seam`]) so that one sees where the synthesis put it.
//! Without flips both are `None`. Why this matters: where the designed singularities
//! are close (the tented arch), the field's representation jump *is* the forced seam
//! (all its pairs are effective seams) and the plain seam ratio is low for any
//! synthesis; where they are far apart (loops, whorl), combing moves the forced seam
//! off the representation jump and the plain ratio is high.
//!
//! **Distance-matched control** ([`SeamSubset::local_share`], repaired jumps only): the
//! image-wide share is a fair yardstick only when the jump pairs sit in ordinary parts
//! of the texture. Near a forced seam no synthesis is coherent (its neighbourhoods
//! straddle a point reflection), and on the tented arch the repaired pairs lie on the
//! same short segment as the forced seam. So the repaired pairs are also compared with
//! the *control* pairs (no representation jump, effective frames agree) at the same
//! distance from the forced seam: with `d(p)` the Chebyshev distance (output pixels,
//! capped at [`LOCAL_DISTANCE_CAP`]; farther counts as one bucket) from the nearest
//! pixel of an effective-seam pair, and a pair's distance `min(d(p), d(q))`, the
//! control share is `Σ_b n_rep(b) · share_ctrl(b) / Σ_b n_rep(b)` over the distance
//! buckets `b` that have control pairs. `local_ratio` = repaired share / that: ≈ 1
//! when the repaired jumps are as coherent as their surroundings, i.e. when what is
//! lost there is the forced seam's disturbance, not the jump's. This is a diagnosis
//! beside the criterion (≥ 0.8× the image-wide share), not a replacement.
//!
//! This is the "coherent pairs" count of `fieldtex-synth`'s `orient_probe` example
//! made into a metric; unlike the probe, it needs no flip indicators (the sign-free
//! test above), so `fieldtex eval` can compute it from a texture's coordinate map
//! (`coords.npy` written by `fieldtex orient`) and its field alone.

use crate::EvalError;
use crate::image_view::FieldView;
use serde::Serialize;

/// Options of [`rosy_seam_coherence`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RosySeamOptions {
    /// Largest coordinate error, in exemplar pixels, of a coherent pair; scaled by
    /// `max(1, step)` for steps above one exemplar pixel per output pixel. Default 1
    /// (synthesised coordinates are snapped to exemplar pixels, so a coherent pair
    /// off the axes is off by up to one pixel; an incoherent pair is typically off by
    /// tens of pixels).
    pub tolerance: f64,
}

impl Default for RosySeamOptions {
    fn default() -> Self {
        Self { tolerance: 1.0 }
    }
}

/// Coherent neighbour pairs across the field's representation jumps and image-wide.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RosySeamReport {
    /// Neighbour pairs evaluated (both field vectors non-zero).
    pub pairs: usize,
    /// Coherent share of those pairs (image-wide), in [0, 1].
    pub coherent_share: f64,
    /// Pairs across a representation jump (`u(p)·u(q) < 0`).
    pub jump_pairs: usize,
    /// Coherent share of the jump pairs (the seam share); `None` without jumps.
    pub jump_coherent_share: Option<f64>,
    /// `jump_coherent_share / coherent_share`: about 1 when the seams are as coherent
    /// as the rest of the texture, near 0 when every seam pair breaks. `None` without
    /// jumps or without any coherent pair.
    pub seam_ratio: Option<f64>,
    /// Jump pairs whose effective frames agree (repaired by the flips), judged like the
    /// seam share; `None` without flips. See the module docs.
    pub repaired: Option<SeamSubset>,
    /// Pairs whose effective frames point in opposite directions (the forced seams),
    /// anywhere in the image; `None` without flips.
    pub effective_seam: Option<SeamSubset>,
    /// Exemplar pixels per output pixel used for the expected steps.
    pub step: f64,
    /// Tolerance used, exemplar pixels.
    pub tolerance_px: f64,
}

/// Coherence of a subset of the neighbour pairs (flip-aware split, module docs).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeamSubset {
    pub pairs: usize,
    /// Coherent share of these pairs; `None` when there are none.
    pub coherent_share: Option<f64>,
    /// `coherent_share / ` the image-wide share; `None` when there are no pairs or no
    /// coherent pair in the image.
    pub ratio: Option<f64>,
    /// Repaired jumps only: the coherent share of the control pairs at the same
    /// distances from the forced seam (module docs, "distance-matched control");
    /// `None` for the effective seam, or without pairs or controls.
    pub local_share: Option<f64>,
    /// `coherent_share / local_share`; `None` when either is missing or zero.
    pub local_ratio: Option<f64>,
}

/// Distances from the forced seam beyond this many output pixels share one bucket of
/// the distance-matched control ([`SeamSubset::local_share`]).
pub const LOCAL_DISTANCE_CAP: usize = 16;

/// The seam measure (module docs) of an exemplar-coordinate map `coords`
/// (`height × width × 2`, `(x, y)` in exemplar pixels, row-major like the field) made
/// with the guidance `field` of the same size, on an exemplar of
/// `exemplar_size = [width, height]` pixels (coordinates wrap around it), at `step`
/// exemplar pixels per output pixel.
pub fn rosy_seam_coherence(
    coords: &[f32],
    field: &FieldView,
    exemplar_size: [usize; 2],
    step: f64,
    options: &RosySeamOptions,
) -> Result<RosySeamReport, EvalError> {
    rosy_seam_coherence_with_flips(coords, field, None, exemplar_size, step, options)
}

/// [`rosy_seam_coherence`] plus, with the synthesis's flip indicators `flips` (`W·H`,
/// row-major like the field), the split into repaired jumps and effective seams
/// (module docs).
pub fn rosy_seam_coherence_with_flips(
    coords: &[f32],
    field: &FieldView,
    flips: Option<&[bool]>,
    exemplar_size: [usize; 2],
    step: f64,
    options: &RosySeamOptions,
) -> Result<RosySeamReport, EvalError> {
    let (w, h) = (field.width, field.height);
    if let Some(f) = flips
        && f.len() != w * h
    {
        return Err(EvalError::BufferSize {
            what: "flip indicators",
            width: w,
            height: h,
            channels: 1,
            expected: w * h,
            found: f.len(),
        });
    }
    if coords.len() != field.data.len() {
        return Err(EvalError::BufferSize {
            what: "coordinate map",
            width: w,
            height: h,
            channels: 2,
            expected: field.data.len(),
            found: coords.len(),
        });
    }
    if let Some((index, &value)) = coords.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(EvalError::NonFinite { what: "coordinate map", index, value });
    }
    if exemplar_size[0] == 0 || exemplar_size[1] == 0 {
        return Err(EvalError::InvalidOption {
            name: "exemplar_size",
            value: format!("{exemplar_size:?}"),
            reason: "must be at least 1×1 pixels",
        });
    }
    if !(step.is_finite() && step > 0.0) {
        return Err(EvalError::InvalidOption {
            name: "step",
            value: step.to_string(),
            reason: "must be a positive number of exemplar pixels per output pixel",
        });
    }
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(EvalError::InvalidOption {
            name: "tolerance",
            value: options.tolerance.to_string(),
            reason: "must be a positive number of exemplar pixels",
        });
    }
    let tol = options.tolerance * step.max(1.0);
    let (ew, eh) = (exemplar_size[0] as f64, exemplar_size[1] as f64);
    let unit = |x: usize, y: usize| -> Option<[f64; 2]> {
        let v = field.at(x, y);
        let (a, b) = (v[0] as f64, v[1] as f64);
        let len = (a * a + b * b).sqrt();
        (len.is_finite() && len > 1e-12).then_some([a / len, b / len])
    };
    let coord = |x: usize, y: usize| {
        let i = 2 * (y * w + x);
        [coords[i] as f64, coords[i + 1] as f64]
    };
    let wrap = |d: f64, period: f64| d - (d / period).round() * period;
    // Distance of every pixel from the forced seam (only with flips).
    let seam_distance = flips.map(|f| forced_seam_distance(w, h, &unit, f));
    // (pairs, coherent) per distance bucket of the repaired jumps and of the controls.
    let mut rep_by_d = [[0usize; 2]; LOCAL_DISTANCE_CAP + 2];
    let mut ctrl_by_d = [[0usize; 2]; LOCAL_DISTANCE_CAP + 2];
    let (mut pairs, mut coherent, mut jumps, mut jump_coherent) = (0usize, 0usize, 0usize, 0usize);
    // (pairs, coherent) of the repaired jumps and of the effective seams.
    let (mut repaired, mut seam) = ([0usize; 2], [0usize; 2]);
    for y in 0..h {
        for x in 0..w {
            let Some(up) = unit(x, y) else { continue };
            let sp = coord(x, y);
            for (qx, qy, d) in [(x + 1, y, [1.0, 0.0]), (x, y + 1, [0.0, 1.0])] {
                if qx >= w || qy >= h {
                    continue;
                }
                let Some(uq) = unit(qx, qy) else { continue };
                let dot = up[0] * uq[0] + up[1] * uq[1];
                let jump = dot < 0.0;
                let sigma = if jump { -1.0 } else { 1.0 };
                // Mean unit direction of the two frames, then J δ with the step.
                let m = [0.5 * (up[0] + sigma * uq[0]), 0.5 * (up[1] + sigma * uq[1])];
                let expected =
                    [step * (m[0] * d[0] + m[1] * d[1]), step * (-m[1] * d[0] + m[0] * d[1])];
                let sq = coord(qx, qy);
                let diff = [sq[0] - sp[0], sq[1] - sp[1]];
                let ok = [1.0, -1.0].iter().any(|&e| {
                    let ex = wrap(diff[0] - e * expected[0], ew);
                    let ey = wrap(diff[1] - e * expected[1], eh);
                    ex.abs().max(ey.abs()) <= tol
                });
                pairs += 1;
                coherent += ok as usize;
                if jump {
                    jumps += 1;
                    jump_coherent += ok as usize;
                }
                if let Some(f) = flips {
                    // Effective frames (−1)^I J disagree: a forced seam; agree across a
                    // representation jump: a repaired jump.
                    let toggled = f[y * w + x] != f[qy * w + qx];
                    if jump == toggled
                        && let Some(dist) = &seam_distance
                    {
                        let b = dist[y * w + x].min(dist[qy * w + qx]) as usize;
                        let by_d = if jump { &mut rep_by_d } else { &mut ctrl_by_d };
                        by_d[b][0] += 1;
                        by_d[b][1] += ok as usize;
                    }
                    let slot = if jump != toggled {
                        Some(&mut seam)
                    } else if jump {
                        Some(&mut repaired)
                    } else {
                        None
                    };
                    if let Some(slot) = slot {
                        slot[0] += 1;
                        slot[1] += ok as usize;
                    }
                }
            }
        }
    }
    let coherent_share = if pairs > 0 { coherent as f64 / pairs as f64 } else { 0.0 };
    let jump_coherent_share = (jumps > 0).then(|| jump_coherent as f64 / jumps as f64);
    let seam_ratio = jump_coherent_share.filter(|_| coherent > 0).map(|s| s / coherent_share);
    let subset = |[n, ok]: [usize; 2], local_share: Option<f64>| {
        let share = (n > 0).then(|| ok as f64 / n as f64);
        SeamSubset {
            pairs: n,
            coherent_share: share,
            ratio: share.filter(|_| coherent > 0).map(|s| s / coherent_share),
            local_share,
            local_ratio: share.zip(local_share.filter(|&l| l > 0.0)).map(|(s, l)| s / l),
        }
    };
    // Distance-matched control share of the repaired jumps.
    let (mut weight, mut sum) = (0usize, 0.0f64);
    for (r, c) in rep_by_d.iter().zip(&ctrl_by_d) {
        if r[0] > 0 && c[0] > 0 {
            weight += r[0];
            sum += r[0] as f64 * c[1] as f64 / c[0] as f64;
        }
    }
    let local_share = (weight > 0).then(|| sum / weight as f64);
    Ok(RosySeamReport {
        repaired: flips.map(|_| subset(repaired, local_share)),
        effective_seam: flips.map(|_| subset(seam, None)),
        pairs,
        coherent_share,
        jump_pairs: jumps,
        jump_coherent_share,
        seam_ratio,
        step,
        tolerance_px: tol,
    })
}

/// Chebyshev distance (output pixels, capped at [`LOCAL_DISTANCE_CAP`] + 1) of every
/// pixel from the nearest pixel of a forced-seam pair (horizontal or vertical
/// neighbours whose effective frames `(−1)^I u` point in opposite directions), by a
/// breadth-first sweep over the 8-neighbours. `unit` gives the unit field vector
/// (`None`: skipped pixel). Not `fieldtex_features::distance_transform` (exact
/// Euclidean, Felzenszwalb & Huttenlocher 2012): eval does not depend on that crate, and
/// the control needs only capped integer buckets.
fn forced_seam_distance(
    w: usize,
    h: usize,
    unit: &dyn Fn(usize, usize) -> Option<[f64; 2]>,
    flips: &[bool],
) -> Vec<u8> {
    let far = (LOCAL_DISTANCE_CAP + 1) as u8;
    let mut dist = vec![far; w * h];
    let mut front = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let Some(up) = unit(x, y) else { continue };
            for (qx, qy) in [(x + 1, y), (x, y + 1)] {
                if qx >= w || qy >= h {
                    continue;
                }
                let Some(uq) = unit(qx, qy) else { continue };
                let jump = up[0] * uq[0] + up[1] * uq[1] < 0.0;
                if jump != (flips[y * w + x] != flips[qy * w + qx]) {
                    for i in [y * w + x, qy * w + qx] {
                        if dist[i] != 0 {
                            dist[i] = 0;
                            front.push(i);
                        }
                    }
                }
            }
        }
    }
    for d in 1..far {
        let mut next = Vec::new();
        for &i in &front {
            let (x, y) = (i % w, i / w);
            for qy in y.saturating_sub(1)..(y + 2).min(h) {
                for qx in x.saturating_sub(1)..(x + 2).min(w) {
                    let q = qy * w + qx;
                    if dist[q] > d {
                        dist[q] = d;
                        next.push(q);
                    }
                }
            }
        }
        front = next;
    }
    dist
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: usize = 64;
    const EX: usize = 128;

    /// A field along +x on the left half and −x on the right half (the same line
    /// field, with a representation jump along the column `N/2 − 1 | N/2`).
    fn split_field() -> Vec<f32> {
        (0..N * N).flat_map(|i| if i % N < N / 2 { [1.0, 0.0] } else { [-1.0, 0.0] }).collect()
    }

    /// Coordinates `S(p) = origin + ε F p` with the effective frame `F = ±I` per half.
    fn coords(right_sign: f32, right_origin: [f32; 2]) -> Vec<f32> {
        let mut c = Vec::with_capacity(2 * N * N);
        for y in 0..N {
            for x in 0..N {
                let (sx, sy) = if x < N / 2 {
                    (10.0 + x as f32, 20.0 + y as f32)
                } else {
                    (
                        right_origin[0] + right_sign * x as f32,
                        right_origin[1] + right_sign * y as f32,
                    )
                };
                c.push(sx.rem_euclid(EX as f32));
                c.push(sy.rem_euclid(EX as f32));
            }
        }
        c
    }

    fn measure(c: &[f32], f: &[f32]) -> RosySeamReport {
        let fv = FieldView::new(f, N, N).unwrap();
        rosy_seam_coherence(c, &fv, [EX, EX], 1.0, &RosySeamOptions::default()).unwrap()
    }

    #[test]
    fn coherent_seam_scores_like_the_image() {
        // The right half continues the left half's coordinates (the 2-RoSy fix):
        // coherent everywhere, seam share = image-wide share = 1.
        let f = split_field();
        let r = measure(&coords(1.0, [10.0, 20.0]), &f);
        assert_eq!(r.jump_pairs, N);
        assert_eq!(r.pairs, 2 * N * (N - 1));
        assert_eq!(r.coherent_share, 1.0);
        assert_eq!(r.seam_ratio, Some(1.0));
    }

    #[test]
    fn planted_incoherent_seam_drops() {
        // Right half follows its own representative (S steps by −δ) from an unrelated
        // origin: coherent inside each half, broken at every seam pair.
        let f = split_field();
        let r = measure(&coords(-1.0, [90.0, 5.0]), &f);
        assert_eq!(r.jump_coherent_share, Some(0.0));
        assert!(r.coherent_share > 0.98, "{r:?}");
        assert_eq!(r.seam_ratio, Some(0.0));
    }

    #[test]
    fn seam_share_tracks_image_share_under_noise() {
        // A coherent seam in a texture where every 5th sample was moved elsewhere: the
        // seam share stays close to the image-wide share (ratio ≈ 1, not 0 or ≫ 1).
        let f = split_field();
        let mut c = coords(1.0, [10.0, 20.0]);
        for i in (0..N * N).step_by(5) {
            c[2 * i] = (c[2 * i] + 57.0).rem_euclid(EX as f32);
        }
        let r = measure(&c, &f);
        assert!(r.coherent_share < 0.7 && r.coherent_share > 0.5, "{r:?}");
        let ratio = r.seam_ratio.unwrap();
        assert!((0.8..1.25).contains(&ratio), "{r:?}");
    }

    #[test]
    fn rotated_field_and_wrap() {
        // A constant 30° field at step 2: S = J p, wrapped into the exemplar.
        let (s, cs) = 30f32.to_radians().sin_cos();
        let f: Vec<f32> = (0..N * N).flat_map(|_| [cs, s]).collect();
        let mut c = Vec::new();
        for y in 0..N {
            for x in 0..N {
                let (px, py) = (x as f32, y as f32);
                c.push((2.0 * (cs * px + s * py)).rem_euclid(EX as f32));
                c.push((2.0 * (-s * px + cs * py)).rem_euclid(EX as f32));
            }
        }
        let fv = FieldView::new(&f, N, N).unwrap();
        let r = rosy_seam_coherence(&c, &fv, [EX, EX], 2.0, &RosySeamOptions::default()).unwrap();
        assert_eq!(r.coherent_share, 1.0);
        assert_eq!(r.jump_pairs, 0);
        assert_eq!(r.seam_ratio, None);
        // The same coordinates judged against the perpendicular field: no pair fits.
        let (s2, c2) = 120f32.to_radians().sin_cos();
        let g: Vec<f32> = (0..N * N).flat_map(|_| [c2, s2]).collect();
        let gv = FieldView::new(&g, N, N).unwrap();
        let r = rosy_seam_coherence(&c, &gv, [EX, EX], 2.0, &RosySeamOptions::default()).unwrap();
        assert_eq!(r.coherent_share, 0.0);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let f = split_field();
        let fv = FieldView::new(&f, N, N).unwrap();
        let o = RosySeamOptions::default();
        assert!(rosy_seam_coherence(&f[..10], &fv, [EX, EX], 1.0, &o).is_err());
        let mut c = coords(1.0, [10.0, 20.0]);
        c[7] = f32::NAN;
        assert!(rosy_seam_coherence(&c, &fv, [EX, EX], 1.0, &o).is_err());
        let c = coords(1.0, [10.0, 20.0]);
        assert!(rosy_seam_coherence(&c, &fv, [0, EX], 1.0, &o).is_err());
        assert!(rosy_seam_coherence(&c, &fv, [EX, EX], 0.0, &o).is_err());
        let bad = RosySeamOptions { tolerance: -1.0 };
        assert!(rosy_seam_coherence(&c, &fv, [EX, EX], 1.0, &bad).is_err());
    }

    #[test]
    fn flips_split_repaired_jumps_from_forced_seams() {
        let f = split_field();
        let fv = FieldView::new(&f, N, N).unwrap();
        let o = RosySeamOptions::default();
        // Coherent seam, the right half flipped: every jump pair is repaired, none is an
        // effective seam.
        let c = coords(1.0, [10.0, 20.0]);
        let flips: Vec<bool> = (0..N * N).map(|i| i % N >= N / 2).collect();
        let r = rosy_seam_coherence_with_flips(&c, &fv, Some(&flips), [EX, EX], 1.0, &o).unwrap();
        let rep = r.repaired.clone().unwrap();
        assert_eq!((rep.pairs, rep.ratio), (N, Some(1.0)));
        assert_eq!(r.effective_seam.as_ref().unwrap().pairs, 0);
        // No flips at all: the jump column is an effective seam (and broken there).
        let c = coords(-1.0, [90.0, 5.0]);
        let none = vec![false; N * N];
        let r = rosy_seam_coherence_with_flips(&c, &fv, Some(&none), [EX, EX], 1.0, &o).unwrap();
        assert_eq!(r.repaired.as_ref().unwrap().pairs, 0);
        let seam = r.effective_seam.unwrap();
        assert_eq!((seam.pairs, seam.coherent_share), (N, Some(0.0)));
        // A flip toggle away from the jump (column 10) is an effective seam too.
        let c = coords(1.0, [10.0, 20.0]);
        let moved: Vec<bool> = (0..N * N).map(|i| i % N >= 10).collect();
        let r = rosy_seam_coherence_with_flips(&c, &fv, Some(&moved), [EX, EX], 1.0, &o).unwrap();
        assert_eq!(r.effective_seam.unwrap().pairs, 2 * N);
        assert!(
            rosy_seam_coherence_with_flips(&c, &fv, Some(&moved[1..]), [EX, EX], 1.0, &o).is_err()
        );
        // Without flips the split is absent.
        assert!(measure(&c, &f).repaired.is_none());
    }

    #[test]
    fn local_control_matches_the_repaired_jumps_surroundings() {
        // Repaired jump at column 31 | 32, a forced seam planted at column 9 | 10, and
        // every 5th sample scrambled from column 27 on (all farther than the distance
        // cap from the seam): the repaired pairs are as coherent as the controls around
        // them (local ratio ≈ 1) but clearly less than the image-wide share.
        let f = split_field();
        let fv = FieldView::new(&f, N, N).unwrap();
        let mut c = coords(1.0, [10.0, 20.0]);
        for i in (0..N * N).filter(|i| i % N >= 27 && i.is_multiple_of(5)) {
            c[2 * i] = (c[2 * i] + 57.0).rem_euclid(EX as f32);
        }
        let flips: Vec<bool> = (0..N * N).map(|i| (i % N >= N / 2) != (i % N < 10)).collect();
        let o = RosySeamOptions::default();
        let r = rosy_seam_coherence_with_flips(&c, &fv, Some(&flips), [EX, EX], 1.0, &o).unwrap();
        let rep = r.repaired.unwrap();
        assert_eq!(rep.pairs, N);
        assert_eq!(r.effective_seam.as_ref().unwrap().pairs, N);
        let (ratio, local) = (rep.ratio.unwrap(), rep.local_ratio.unwrap());
        assert!(ratio < 0.9, "{ratio}");
        assert!((0.85..1.15).contains(&local), "local ratio {local}, share {:?}", rep.local_share);
        assert!(r.effective_seam.unwrap().local_share.is_none());
        // The coherent version: everything 1.
        let c = coords(1.0, [10.0, 20.0]);
        let r = rosy_seam_coherence_with_flips(&c, &fv, Some(&flips), [EX, EX], 1.0, &o).unwrap();
        assert_eq!(r.repaired.unwrap().local_ratio, Some(1.0));
    }
}
