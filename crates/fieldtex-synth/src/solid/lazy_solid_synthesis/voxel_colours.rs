//! The colours of voxels in lazy solid synthesis (module docs of [`super`]): the
//! plane-weighted mean of the three exemplar colours at a voxel's triple — what the
//! output shows — and the matched values (RGB, plus the feature channel with masks)
//! that the correction compares; with the uncorrected integrated start, the exemplars
//! read by cubic convolution at the warp's sub-pixel position. Split from the
//! synthesizer's block and cache logic.

use super::*;
use crate::color_lookup::keys_cubic;

impl SolidSynthesizer<'_> {
    /// Colours (RGB, sRGB-encoded as the exemplars) of `voxels`: the mean of the three
    /// finest exemplar colours at each final triple. With the uncorrected integrated
    /// start ([`SolidSynthesisOptions::integrated_init`]) each plane is read by cubic
    /// convolution at the triple moved by the warp's sub-pixel part
    /// ([`Self::warp_residual`]), so the output samples the continuous warp instead of
    /// its whole-pixel steps.
    pub fn colors(
        &mut self,
        voxels: &[[i32; 3]],
        progress: &dyn Progress,
    ) -> (Vec<[f32; 3]>, Vec<LevelStats>) {
        let (t, stats) = self.triples(voxels, progress);
        let colours = t
            .iter()
            .zip(voxels)
            .map(|(t, &v)| {
                let m = self.voxel_matched(v, t);
                [m[0], m[1], m[2]]
            })
            .collect();
        (colours, stats)
    }

    /// The sub-pixel part of the integrated warp at finest voxel `v` (exemplar pixels per
    /// axis, each in `[−½, ½]`): every triple of the uncorrected warp is `round(2^g U − φ)
    /// +` a constant, so adding it gives the continuous warp. `None` unless the
    /// integrated start is left uncorrected ([`Self::subpixel`]), and off its grid.
    fn warp_residual(&self, v: [i32; 3]) -> Option<[f32; 3]> {
        if !self.subpixel {
            return None;
        }
        Some(self.init.as_ref()?.residual(v)?.map(|x| x as f32))
    }

    /// The finest matched values ([`Self::triple_matched`]) of voxel `v` holding triple
    /// `t`: with the uncorrected integrated start, every plane read at its pixel moved by
    /// the warp's sub-pixel part ([`Self::warp_residual`], mapped to the planes as
    /// [`moved`] does), so that the output shows the continuous warp. (Corrections, when
    /// asked for, compare whole-pixel values: the sub-pixel read is only consistent for
    /// voxels left on the warp.) A function of `v` and `t` alone (the on-demand
    /// equality).
    fn voxel_matched(&self, v: [i32; 3], t: &Triple) -> [f32; 4] {
        let Some(r) = self.warp_residual(v) else {
            return self.triple_matched(0, t);
        };
        let w = self.exemplar.options.plane_weights;
        let ch = self.exemplar.channels();
        let shift = [[r[0], r[1]], [r[1], r[2]], [r[2], r[0]]];
        let mut acc = [0.0f32; 4];
        for p in 0..3 {
            if w[p] == 0.0 {
                continue;
            }
            let m = self.cubic_matched(p, t[p], shift[p]);
            for k in 0..ch {
                acc[k] += w[p] * m[k];
            }
        }
        let total = w[0] + w[1] + w[2];
        acc.map(|v| v / total)
    }

    /// Finest matched values of plane `p` at pixel `xy` moved by `d` (`|d| ≤ 1` per
    /// axis), by Keys cubic convolution over the 4 × 4 pixels around it (wrapped), each
    /// channel clamped to the range of its taps (as `orient`'s colour lookup,
    /// [`crate::color_lookup`]): exact at `d = 0`, sharper than bilinear between pixels.
    fn cubic_matched(&self, p: usize, xy: [i32; 2], d: [f32; 2]) -> [f32; 4] {
        let (x, y) = (xy[0] as f64 + d[0] as f64, xy[1] as f64 + d[1] as f64);
        keys_cubic(x, y, |x, y| self.exemplar.matched(p, 0, x as i32, y as i32))
    }

    /// Plane-weighted mean of the three level-`c` exemplar colours at `t`
    /// ([`super::SolidAnalysisOptions::plane_weights`]).
    #[inline]
    pub fn triple_color(&self, c: usize, t: &Triple) -> [f32; 3] {
        let w = self.exemplar.options.plane_weights;
        let mut acc = [0.0f32; 3];
        for p in 0..3 {
            if w[p] == 0.0 {
                continue;
            }
            let col = self.exemplar.color(p, c, t[p][0], t[p][1]);
            for ch in 0..3 {
                acc[ch] += w[p] * col[ch];
            }
        }
        let total = w[0] + w[1] + w[2];
        acc.map(|v| v / total)
    }

    /// Plane-weighted mean of the three level-`c` matched values at `t` (RGB, and the
    /// feature channel when the exemplars carry masks): what the correction's voxel
    /// neighbourhoods compare. Its RGB part equals [`Self::triple_color`].
    #[inline]
    pub fn triple_matched(&self, c: usize, t: &Triple) -> [f32; 4] {
        let w = self.exemplar.options.plane_weights;
        let ch = self.exemplar.channels();
        let mut acc = [0.0f32; 4];
        for p in 0..3 {
            if w[p] == 0.0 {
                continue;
            }
            let m = self.exemplar.matched(p, c, t[p][0], t[p][1]);
            for k in 0..ch {
                acc[k] += w[p] * m[k];
            }
        }
        let total = w[0] + w[1] + w[2];
        acc.map(|v| v / total)
    }
}
