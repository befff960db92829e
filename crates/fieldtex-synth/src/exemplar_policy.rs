//! The one exemplar policy of every synthesis pipeline (`align`, `orient`): a size
//! limit, and what happens above it.
//!
//! Exemplars up to [`MAX_EXEMPLAR_SIDE`] pixels per side are used as they are. A larger
//! exemplar is reduced by the smallest integer box factor `f` that brings both sides to
//! the limit or below (each output pixel the mean of an `f × f` block, the last partial
//! row/column dropped), with a warning, *before* any analysis allocates memory that
//! scales with the exemplar. Pipelines multiply their pattern scale by `f` so that the
//! pattern keeps the size the user asked for: `--scale` always counts output pixels
//! (texels) per pixel of the exemplar *file*.

use fieldtex_core::{Image, Warning};

/// Largest exemplar side (pixels) a synthesis pipeline works on.
pub const MAX_EXEMPLAR_SIDE: usize = 2048;

/// An exemplar made to fit [`MAX_EXEMPLAR_SIDE`].
#[derive(Debug, Clone, PartialEq)]
pub struct FittedExemplar {
    pub image: Image,
    /// Box factor applied (1 = unchanged): one pixel of `image` is `factor` pixels of
    /// the input.
    pub factor: usize,
    /// Set when the exemplar was reduced.
    pub warning: Option<Warning>,
}

/// Applies the policy (module docs) to `exemplar`, with limit `max_side` (pipelines
/// pass [`MAX_EXEMPLAR_SIDE`]; `max_side ≥ 1`).
pub fn fit_exemplar(exemplar: Image, max_side: usize) -> FittedExemplar {
    let max_side = max_side.max(1);
    let (w, h) = (exemplar.width, exemplar.height);
    let factor = w.max(h).div_ceil(max_side).max(1);
    if factor == 1 {
        return FittedExemplar { image: exemplar, factor, warning: None };
    }
    let (nw, nh) = ((w / factor).max(1), (h / factor).max(1));
    let mut out = Image::new(nw, nh, [0.0; 4]);
    let inv = 1.0 / (factor * factor) as f32;
    for y in 0..nh {
        for x in 0..nw {
            let mut acc = [0.0f32; 4];
            for dy in 0..factor {
                let row = &exemplar.pixels[((y * factor + dy).min(h - 1)) * w..];
                for dx in 0..factor {
                    let p = row[(x * factor + dx).min(w - 1)];
                    for k in 0..4 {
                        acc[k] += p[k];
                    }
                }
            }
            out.pixels[y * nw + x] = acc.map(|v| v * inv);
        }
    }
    let warning = Warning::new(
        "exemplar-downscaled",
        format!(
            "the exemplar is {w}×{h} pixels, above the {max_side}-pixel limit: it was reduced \
             {factor}× to {nw}×{nh} (the pattern keeps its size on the output; crop the \
             exemplar to keep its finest detail)"
        ),
    );
    FittedExemplar { image: out, factor, warning: Some(warning) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_exemplars_pass_and_large_ones_are_box_reduced() {
        let img = Image::new(100, 40, [0.25, 0.5, 0.75, 1.0]);
        let f = fit_exemplar(img.clone(), 128);
        assert_eq!((f.factor, f.warning.is_none()), (1, true));
        assert_eq!(f.image, img);
        let mut big = Image::new(300, 90, [0.0, 0.0, 0.0, 1.0]);
        for y in 0..90 {
            for x in 0..300 {
                let v = ((x + y) % 2) as f32;
                big.set(x, y, [v, v, v, 1.0]);
            }
        }
        let f = fit_exemplar(big, 128);
        assert_eq!((f.factor, f.image.width, f.image.height), (3, 100, 30));
        assert!(f.warning.is_some());
        // A 3×3 block of a checkerboard averages to 4/9 or 5/9.
        assert!(
            f.image
                .pixels
                .iter()
                .all(|p| (p[0] - 4.0 / 9.0).abs() < 1e-6 || (p[0] - 5.0 / 9.0).abs() < 1e-6)
        );
    }
}
