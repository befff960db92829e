//! Whether an exemplar tiles: the one test every pipeline and metric uses to decide
//! whether the exemplar may be read toroidally (its right edge continuing into its left
//! edge, its bottom into its top).
//!
//! Most exemplars are crops of photos: reading them toroidally puts a seam at the wrap
//! that is not exemplar content. A metric that searches exemplar patches toroidally
//! credits that seam (an output copying it scores as coherent), and a synthesis told
//! that the exemplar tiles copies it into the output.
//!
//! The test (a heuristic of this project, not from a paper): per axis, the **wrap-jump
//! ratio** is the mean colour jump across the wrap against the mean jump between
//! interior neighbours along the same axis,
//!
//! ```text
//! r_x = mean_y ‖E(W−1, y) − E(0, y)‖ / mean_{y, 0 ≤ x < W−1} ‖E(x+1, y) − E(x, y)‖
//! ```
//!
//! (`‖·‖` the Euclidean RGB distance, alpha ignored; `r_y` likewise over rows). For an
//! image that tiles, the wrap pair is one more neighbour pair and `r ≈ 1` (within the
//! sampling noise of a mean over one column, a few percent at 100+ pixels); across the
//! edge of a crop the two sides are unrelated and `r` grows with how much smoother the
//! texture is than a jump between unrelated pixels. The exemplar **tiles** when both
//! ratios are at most [`TILING_JUMP_RATIO`].
//!
//! The threshold 1.4 is set on the shared exemplars (`/work/shared/data/exemplars`,
//! docs/real-exemplars.md "session 13"): those whose 2 × 2 tiling shows no seam have
//! ratios ≤ 1.34 (bricks 1.31 / 1.05, gravel 1.29 / 1.24, terrazzo 1.31 / 1.34,
//! 512² wood 1.06 / 0.96), those with a visible seam ≥ 1.56 (bands 1.57 / 1.25,
//! herringbone 0.28 / 1.56, stripes 2.44 / 6.11, wood 8.51 / 2.24, weave 3.85 / 2.11).
//! On synthetic images (tests below, 20 seeds each): exactly periodic noise tiles at
//! every size from 64² to 512² (worst ratio 1.37) except 2 of 20 of the smoothest (a
//! few waves across the image, ratio ≈ 1.8: one column of a smooth field varies more);
//! crops of it never tile (least ratio 2.5 for the roughest, 17–27 for smooth ones).
//! The test errs on the safe side: a tileable exemplar whose wrap happens to fall on
//! one of its own strong edges (a mortar line) can read as not tiling, which only makes
//! the metrics stricter and keeps the synthesis's border margin; an exemplar whose
//! crop edge is no sharper than its own texture (fine noise) reads as tiling, and there
//! the wrap shows no seam. A constant exemplar tiles.

use fieldtex_core::Image;

/// Largest wrap-jump ratio (both axes) of an exemplar that tiles (module docs).
pub const TILING_JUMP_RATIO: f64 = 1.4;

/// Added to both sides of the ratio so that a constant image reads as 1 (colour units
/// in `[0, 1]`, far below any visible jump).
const JUMP_FLOOR: f64 = 1e-6;

/// The outcome of [`exemplar_tiling`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TilingTest {
    /// Wrap-jump ratio across the left/right wrap (`[0]`, `r_x`) and the top/bottom wrap
    /// (`[1]`, `r_y`).
    pub jump_ratio: [f64; 2],
    /// The threshold applied ([`TILING_JUMP_RATIO`]).
    pub threshold: f64,
    /// Both ratios at most `threshold`.
    pub tiles: bool,
}

/// The wrap-jump ratios of `exemplar` and whether it tiles (module docs). Images
/// narrower or lower than 2 pixels have no interior pair along that axis: the ratio
/// there is 1 (nothing to tell apart).
pub fn exemplar_tiling(exemplar: &Image) -> TilingTest {
    let (w, h) = (exemplar.width, exemplar.height);
    let px = |x: usize, y: usize| exemplar.pixels[y * w + x];
    let rx = wrap_jump_ratio(w, h, px);
    let ry = wrap_jump_ratio(h, w, |i, j| px(j, i));
    let threshold = TILING_JUMP_RATIO;
    TilingTest { jump_ratio: [rx, ry], threshold, tiles: rx <= threshold && ry <= threshold }
}

/// The wrap-jump ratio along an axis of length `n` (pixels `at(i, j)`, `i` along the
/// axis, `j` across it, `m` lines): serial sums in a fixed order (deterministic).
fn wrap_jump_ratio(n: usize, m: usize, at: impl Fn(usize, usize) -> [f32; 4]) -> f64 {
    if n < 2 || m == 0 {
        return 1.0;
    }
    let jump = |a: [f32; 4], b: [f32; 4]| {
        (0..3).map(|k| (a[k] as f64 - b[k] as f64).powi(2)).sum::<f64>().sqrt()
    };
    let (mut interior, mut wrap) = (0.0, 0.0);
    for j in 0..m {
        for i in 0..n - 1 {
            interior += jump(at(i, j), at(i + 1, j));
        }
        wrap += jump(at(n - 1, j), at(0, j));
    }
    let interior = interior / (m * (n - 1)) as f64;
    let wrap = wrap / m as f64;
    (wrap + JUMP_FLOOR) / (interior + JUMP_FLOOR)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::stream;
    use rand::RngExt;

    /// A `w × h` image of `f(x, y)` (grey).
    fn grey(w: usize, h: usize, f: impl Fn(f64, f64) -> f64) -> Image {
        Image::from_fn(w, h, |x, y| {
            let v = f(x as f64, y as f64) as f32;
            [v, v, v, 1.0]
        })
    }

    /// Random periodic noise: a sum of sinusoids with integer frequencies over the image
    /// (so it tiles exactly), `max_freq` the highest frequency (small: smooth).
    fn periodic_noise(w: usize, h: usize, max_freq: i32, seed: u64) -> Image {
        let mut rng = stream(seed, "periodic-noise", 0);
        let waves: Vec<(f64, f64, f64, f64)> = (0..24)
            .map(|_| {
                let fx = rng.random_range(-max_freq..=max_freq) as f64;
                let fy = rng.random_range(-max_freq..=max_freq) as f64;
                (fx, fy, rng.random_range(0.0..std::f64::consts::TAU), rng.random_range(0.2..1.0))
            })
            .collect();
        let norm: f64 = waves.iter().map(|w| w.3).sum();
        grey(w, h, |x, y| {
            let s: f64 = waves
                .iter()
                .map(|&(fx, fy, ph, a)| {
                    a * (std::f64::consts::TAU * (fx * x / w as f64 + fy * y / h as f64) + ph).sin()
                })
                .sum();
            0.5 + 0.5 * s / norm
        })
    }

    /// The `cw × ch` crop at `(x0, y0)` of `im`.
    fn crop(im: &Image, x0: usize, y0: usize, cw: usize, ch: usize) -> Image {
        let mut out = Image::new(cw, ch, [0.0; 4]);
        for y in 0..ch {
            for x in 0..cw {
                out.pixels[y * cw + x] = im.pixels[(y0 + y) * im.width + x0 + x];
            }
        }
        out
    }

    #[test]
    fn periodic_images_tile_at_every_smoothness_and_size() {
        for &(w, h) in &[(64, 64), (124, 124), (116, 200), (512, 512)] {
            for &f in &[2, 6, 20] {
                let mut tiles = 0;
                let mut worst = 0.0f64;
                for seed in 0..20u64 {
                    let t = exemplar_tiling(&periodic_noise(w, h, f, seed + 1000 * f as u64));
                    tiles += usize::from(t.tiles);
                    worst = worst.max(t.jump_ratio[0].max(t.jump_ratio[1]));
                }
                // The smoothest (a few waves across the image) may err on the safe side:
                // one column of a smooth field varies more (measured: 18 of 20 tile,
                // the other two ≈ 1.8); from a few more waves on, all tile.
                let need = if f == 2 { 16 } else { 20 };
                assert!(tiles >= need, "{w}×{h}, max frequency {f}: {tiles}/20 tile");
                if f > 2 {
                    assert!(worst <= TILING_JUMP_RATIO, "{w}×{h}, {f}: worst {worst}");
                }
            }
        }
    }

    #[test]
    fn crops_of_smooth_textures_do_not_tile() {
        // Crops of a larger periodic texture, cut where no period ends.
        for &f in &[2, 6, 20, 60] {
            let mut tiles = 0;
            let mut least = f64::MAX;
            for seed in 0..20u64 {
                let big = periodic_noise(400, 400, f, 500 + seed);
                let x0 = 17 + (seed as usize * 37) % 200;
                let t = exemplar_tiling(&crop(&big, x0, 91, 124, 124));
                tiles += usize::from(t.tiles);
                least = least.min(t.jump_ratio[0].max(t.jump_ratio[1]));
            }
            // Never on the unsafe side; the margin shrinks as the texture gets rougher
            // (a jump between unrelated pixels is then closer to a neighbour's).
            assert_eq!(tiles, 0, "max frequency {f}");
            assert!(least > 1.5 * TILING_JUMP_RATIO, "max frequency {f}: least {least}");
        }
    }

    #[test]
    fn stripes_tile_only_with_a_whole_number_of_periods() {
        // Horizontal stripes (vary along y), period 10: over 120 rows they tile; over 125
        // rows the wrap cuts a stripe and the y ratio reports it, the x ratio stays 1.
        let stripes = |h, phase: f64| {
            grey(64, h, |_, y| 0.5 + 0.4 * (std::f64::consts::TAU * (y + phase) / 10.0).sin())
        };
        let t = exemplar_tiling(&stripes(120, 2.5));
        assert!(t.tiles, "{t:?}");
        let t = exemplar_tiling(&stripes(125, 2.5));
        assert!(!t.tiles, "{t:?}");
        assert!((t.jump_ratio[0] - 1.0).abs() < 1e-9 && t.jump_ratio[1] > 3.0, "{t:?}");
        // The safe-side error of the module docs: the same tiling stripes with the wrap on
        // their steepest edge read as the largest interior jump over the mean, ≈ π/2.
        let t = exemplar_tiling(&stripes(120, 0.0));
        assert!((t.jump_ratio[1] - std::f64::consts::FRAC_PI_2).abs() < 0.05 && !t.tiles, "{t:?}");
    }

    #[test]
    fn white_noise_crops_tile_and_gradients_do_not() {
        // No structure wider than a pixel: the crop edge is no sharper than the texture.
        let mut rng = stream(7, "white-noise", 0);
        let noise: Vec<f64> = (0..100 * 80).map(|_| rng.random::<f64>()).collect();
        let t = exemplar_tiling(&grey(100, 80, |x, y| noise[y as usize * 100 + x as usize]));
        assert!(t.tiles, "{t:?}");
        // A ramp: every interior step small, the wrap jumps back over the whole range.
        let t = exemplar_tiling(&grey(100, 80, |x, _| x / 100.0));
        assert!(!t.tiles && t.jump_ratio[0] > 50.0 && t.jump_ratio[1] == 1.0, "{t:?}");
    }

    #[test]
    fn degenerate_images() {
        let t = exemplar_tiling(&Image::new(7, 5, [0.3, 0.2, 0.1, 1.0]));
        assert!(t.tiles && t.jump_ratio == [1.0, 1.0], "constant: {t:?}");
        let t = exemplar_tiling(&grey(1, 9, |_, y| y / 9.0));
        assert_eq!(t.jump_ratio[0], 1.0, "{t:?}");
        assert!(!t.tiles, "a ramp along y: {t:?}");
        let t = exemplar_tiling(&Image::new(0, 0, [0.0; 4]));
        assert!(t.tiles, "{t:?}");
    }

    #[test]
    fn alpha_is_ignored_and_the_test_is_symmetric_under_transposition() {
        let im = periodic_noise(90, 70, 8, 3);
        let big = periodic_noise(300, 300, 5, 4);
        let cropped = crop(&big, 11, 13, 90, 70);
        for im in [im, cropped] {
            let mut tr = Image::new(im.height, im.width, [0.0; 4]);
            let mut alpha = im.clone();
            for y in 0..im.height {
                for x in 0..im.width {
                    tr.pixels[x * im.height + y] = im.pixels[y * im.width + x];
                    alpha.pixels[y * im.width + x][3] = ((x * 7 + y) % 5) as f32 / 4.0;
                }
            }
            let (a, b) = (exemplar_tiling(&im), exemplar_tiling(&tr));
            assert_eq!(a.jump_ratio, [b.jump_ratio[1], b.jump_ratio[0]]);
            assert_eq!(exemplar_tiling(&alpha), a);
        }
    }
}
