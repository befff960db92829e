//! Toroidal Gaussian stack of an exemplar (Lefebvre & Hoppe 2005, §3.1).
//!
//! A Gaussian *stack* keeps every level at the full exemplar resolution (unlike a
//! pyramid), so exemplar coordinates are the same at all levels. Level `0` is the
//! exemplar itself; level `c` is level `c − 1` filtered with the binomial kernel
//! `[1, 4, 6, 4, 1] / 16` whose taps are spaced `2^(c−1)` pixels apart (an "à trous"
//! filter), separably in x and y. The cumulative filter width therefore doubles per
//! level, matching the spacing `2^c` at which level `c` is sampled by the synthesis.
//! Borders wrap (the exemplar is treated as toroidal), which is exact for tileable
//! exemplars and a mild approximation for the others.

use rayon::prelude::*;

const TAPS: [f32; 5] = [1.0 / 16.0, 4.0 / 16.0, 6.0 / 16.0, 4.0 / 16.0, 1.0 / 16.0];

/// The `levels` stack levels of the `width × height` RGB image `colors` (row-major):
/// `levels` images of `width × height` pixels, finest first. `levels ≥ 1`.
pub fn gaussian_stack(
    colors: &[[f32; 3]],
    width: usize,
    height: usize,
    levels: usize,
) -> Vec<Vec<[f32; 3]>> {
    assert_eq!(colors.len(), width * height, "gaussian_stack: colors must hold width × height");
    let mut stack = vec![colors.to_vec()];
    for c in 1..levels.max(1) {
        let next = next_stack_level(&stack[c - 1], width, height, c);
        stack.push(next);
    }
    stack
}

/// Stack level `c ≥ 1` from level `c − 1` (`width × height` RGB each), for callers that
/// keep one level at a time.
pub fn next_stack_level(prev: &[[f32; 3]], width: usize, height: usize, c: usize) -> Vec<[f32; 3]> {
    assert!(c >= 1 && prev.len() == width * height, "next_stack_level: c ≥ 1, W × H pixels");
    let spacing = 1usize << (c - 1).min(40);
    let horizontal = blur_rows(prev, width, height, spacing);
    blur_columns(&horizontal, width, height, spacing)
}

fn blur_rows(src: &[[f32; 3]], width: usize, height: usize, spacing: usize) -> Vec<[f32; 3]> {
    let mut out = vec![[0.0f32; 3]; width * height];
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        let line = &src[y * width..(y + 1) * width];
        for (x, o) in row.iter_mut().enumerate() {
            let mut acc = [0.0f32; 3];
            for (t, w) in TAPS.iter().enumerate() {
                let off = (t as i64 - 2) * spacing as i64;
                let xi = (x as i64 + off).rem_euclid(width as i64) as usize;
                for ch in 0..3 {
                    acc[ch] += w * line[xi][ch];
                }
            }
            *o = acc;
        }
    });
    out
}

fn blur_columns(src: &[[f32; 3]], width: usize, height: usize, spacing: usize) -> Vec<[f32; 3]> {
    let mut out = vec![[0.0f32; 3]; width * height];
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (t, w) in TAPS.iter().enumerate() {
            let off = (t as i64 - 2) * spacing as i64;
            let yi = (y as i64 + off).rem_euclid(height as i64) as usize;
            let line = &src[yi * width..(yi + 1) * width];
            for (o, s) in row.iter_mut().zip(line) {
                for ch in 0..3 {
                    o[ch] += w * s[ch];
                }
            }
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stack_preserves_mean_and_smooths() {
        let (w, h) = (12, 10);
        let img: Vec<[f32; 3]> = (0..w * h)
            .map(|i| if (i % w + i / w) % 2 == 0 { [1.0; 3] } else { [0.0; 3] })
            .collect();
        let stack = gaussian_stack(&img, w, h, 4);
        assert_eq!(stack.len(), 4);
        let mean = |l: &[[f32; 3]]| l.iter().map(|c| c[0]).sum::<f32>() / l.len() as f32;
        for l in &stack {
            assert!((mean(l) - 0.5).abs() < 1e-5);
        }
        let range = |l: &[[f32; 3]]| {
            let (lo, hi) =
                l.iter().fold((f32::MAX, f32::MIN), |(a, b), c| (a.min(c[0]), b.max(c[0])));
            hi - lo
        };
        assert!(range(&stack[1]) < 0.5 * range(&stack[0]));
        assert!(range(&stack[3]) <= range(&stack[1]) + 1e-6);
    }
}
