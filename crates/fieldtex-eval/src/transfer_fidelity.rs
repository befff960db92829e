//! Transfer fidelity (DESIGN.md §6): how well a textured mesh's colour follows a
//! reference colour on the same surface, as Pearson correlation coefficients over
//! paired colour samples taken at the same surface points.
//!
//! `r` per RGB channel, and on the Rec. 709 luma of the sRGB-encoded values (the single
//! number benchmarks quote). 1 means the colours are an increasing affine function of
//! the reference, 0 no linear relation. A constant channel has no correlation: its `r`
//! is reported as 0.

use serde::Serialize;

/// Correlations of a colour set with a reference set.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TransferFidelity {
    /// Paired samples used.
    pub samples: usize,
    /// Pearson r of R, G, B.
    pub pearson_rgb: [f64; 3],
    /// Pearson r of the luma.
    pub pearson_luma: f64,
}

pub use fieldtex_linalg::stats::pearson;

/// Fidelity of `colors` against `reference` (paired RGB samples, module docs).
pub fn transfer_fidelity(colors: &[[f64; 3]], reference: &[[f64; 3]]) -> TransferFidelity {
    let n = colors.len().min(reference.len());
    let ch = |v: &[[f64; 3]], k: usize| -> Vec<f64> { v[..n].iter().map(|c| c[k]).collect() };
    let luma = |v: &[[f64; 3]]| -> Vec<f64> {
        v[..n].iter().map(|c| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]).collect()
    };
    TransferFidelity {
        samples: n,
        pearson_rgb: std::array::from_fn(|k| pearson(&ch(colors, k), &ch(reference, k))),
        pearson_luma: pearson(&luma(colors), &luma(reference)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn affine_colours_correlate_perfectly_and_noise_does_not() {
        let reference: Vec<[f64; 3]> =
            (0..100).map(|i| [i as f64 / 100.0, 0.5, (i * i) as f64 / 1e4]).collect();
        let affine: Vec<[f64; 3]> =
            reference.iter().map(|c| [0.2 + 0.5 * c[0], 0.3, c[2]]).collect();
        let f = transfer_fidelity(&affine, &reference);
        assert!((f.pearson_rgb[0] - 1.0).abs() < 1e-12);
        assert_eq!(f.pearson_rgb[1], 0.0); // constant channel
        assert!((f.pearson_luma - 1.0).abs() < 1e-3);
        let shuffled: Vec<[f64; 3]> = (0..100).map(|i| reference[(i * 37) % 100]).collect();
        assert!(transfer_fidelity(&shuffled, &reference).pearson_rgb[0].abs() < 0.3);
    }
}
