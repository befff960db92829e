//! Field-following corner reads of the four-corner neighbourhood where the field
//! curves ([`crate::SynthesisOptions::warped_corners`]; Lefebvre & Hoppe 2006
//! "Appearance-space texture synthesis" §6, anisometric synthesis, with the 2-RoSy
//! frames of paper D §4).
//!
//! The correction compares, for each exemplar-space corner `Δ ∈ {±1}²`, the output's
//! appearance at the warped offset `φ(Δ) = J(p)⁻¹ Δ` from `p` with the exemplar's at
//! `u + (−1)^β h Δ`. The engine predicts that corner from a neighbour `q = p + δ`:
//! its prediction of `p` is `P = S[q] − h F δ`, `F` the frame of the segment `q → p`
//! (with [`crate::SynthesisOptions::trapezoid_frames`] the mean of `F(q)` and
//! `(−1)^α J(p)`), and Lefebvre & Hoppe 2006 (eq. of §6, `Ñ_S(p; Δ) = ⅓ Σ Ẽ[P + Δ]`)
//! then read the corner at `P + (−1)^α h Δ`: the corner offset is laid out in `p`'s own
//! frame, one rotation per pixel. Following the field instead, the corner point
//! `x_c = p + φ(Δ)` seen from `q` lies at
//!
//! `S[q] + h F (φ(Δ) − δ) = P + h F J(p)⁻¹ Δ`,
//!
//! i.e. the corner offset is turned by `R = F ((−1)^α J(p))⁻¹`, the rotation from `p`'s
//! effective frame to the frame of the neighbour's segment: each of the three
//! predictions of a corner uses its own neighbour's interpolated rotation. Where the
//! field is constant `F = (−1)^α J(p)`, `R = I` and the read is the tabulated one
//! (bit for bit: the warp is used only when `F` differs from `(−1)^α J(p)`). The read
//! at a warped corner takes the appearance vector of the pixel under it (the same
//! nearest-pixel rule as the tabulated corners; the exemplar is toroidal).
//!
//! Only for 2-D lattices (a 2 × 2 Jacobian); 3-D lattices keep the tabulated reads.

use crate::exemplar_analysis::APPEARANCE_DIMS;
use crate::exemplar_level::ExemplarLevel;
use crate::lattice_domain::{CORNERS, Jacobian};

/// The inverse of a 2-D sample's Jacobian (`None` for other dimensions or a singular
/// matrix, which the domain checks already reject).
#[inline]
pub(crate) fn inverse_frame<const D: usize>(j: &Jacobian<D>) -> Option<[[f32; 2]; 2]> {
    if D != 2 {
        return None;
    }
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    if !(det.is_finite() && det != 0.0) {
        return None;
    }
    Some([[j[1][1] / det, -j[0][1] / det], [-j[1][0] / det, j[0][0] / det]])
}

/// The corner map `h F J(p)⁻¹` of one neighbour's prediction (`f`: the segment frame
/// `F`; `fpa`: `p`'s frame with the prediction's flip, `(−1)^α J(p)`; `jinv`:
/// `J(p)⁻¹`), or `None` where the two frames are equal and the tabulated corners are
/// exact.
#[inline]
pub(crate) fn corner_map<const D: usize>(
    f: &Jacobian<D>,
    fpa: &Jacobian<D>,
    jinv: &[[f32; 2]; 2],
    h: f32,
) -> Option<[[f32; 2]; 2]> {
    if D != 2 || f == fpa {
        return None;
    }
    let m = |r: usize, c: usize| h * (f[r][0] * jinv[0][c] + f[r][1] * jinv[1][c]);
    Some([[m(0, 0), m(0, 1)], [m(1, 0), m(1, 1)]])
}

/// The appearance vector of copy `app` (`Ẽ_α`) at the warped corner `ci` of
/// [`CORNERS`] of the prediction `u` with corner map `m` ([`corner_map`]).
#[inline]
pub(crate) fn warped_corner<'a>(
    ex: &ExemplarLevel,
    app: &'a [[i8; APPEARANCE_DIMS]],
    u: [f32; 2],
    m: &[[f32; 2]; 2],
    ci: usize,
) -> &'a [i8; APPEARANCE_DIMS] {
    let d = CORNERS[ci].map(|c| c as f32);
    let at =
        ex.wrap([u[0] + m[0][0] * d[0] + m[0][1] * d[1], u[1] + m[1][0] * d[0] + m[1][1] * d[1]]);
    &app[ex.pixel(at)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_frames_use_the_tabulated_corners() {
        let j = [[0.8f32, 0.6], [-0.6, 0.8]];
        let jinv = inverse_frame(&j).unwrap();
        assert!(corner_map(&j, &j, &jinv, 4.0).is_none());
    }

    #[test]
    fn the_corner_turns_with_the_neighbours_frame() {
        // p's frame is the identity; the segment's frame is turned by 90°: the corner
        // offset h Δ turns with it.
        let jp = [[1.0f32, 0.0], [0.0, 1.0]];
        let f = [[0.0f32, -1.0], [1.0, 0.0]];
        let m = corner_map(&f, &jp, &inverse_frame(&jp).unwrap(), 2.0).unwrap();
        let d = [1.0f32, -1.0];
        let out = [m[0][0] * d[0] + m[0][1] * d[1], m[1][0] * d[0] + m[1][1] * d[1]];
        assert_eq!(out, [2.0, 2.0]);
        // A 3-D Jacobian has no corner map.
        let j3 = [[1.0f32, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!(inverse_frame(&j3).is_none());
    }
}
