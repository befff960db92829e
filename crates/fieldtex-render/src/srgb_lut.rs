//! Table-driven sRGB transfer functions for the per-sample hot loops.
//!
//! 4096 intervals with linear interpolation; the largest error against the exact
//! functions of `fieldtex_core::image` is about 2e-5, far below one 8-bit step.

use fieldtex_core::image::{linear_to_srgb, srgb_to_linear};
use std::sync::OnceLock;

const N: usize = 4096;

struct Tables {
    to_linear: Vec<f32>,
    to_srgb: Vec<f32>,
}

fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| Tables {
        to_linear: (0..=N).map(|i| srgb_to_linear(i as f32 / N as f32)).collect(),
        to_srgb: (0..=N).map(|i| linear_to_srgb(i as f32 / N as f32)).collect(),
    })
}

#[inline]
fn lookup(table: &[f32], v: f32) -> f32 {
    let x = if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 } * N as f32;
    let i = (x as usize).min(N - 1);
    let t = x - i as f32;
    table[i] + (table[i + 1] - table[i]) * t
}

/// sRGB-encoded → linear, input clamped to `[0, 1]` (NaN → 0).
#[inline]
pub(crate) fn to_linear(v: f32) -> f32 {
    lookup(&tables().to_linear, v)
}

/// Linear → sRGB-encoded, input clamped to `[0, 1]` (NaN → 0).
#[inline]
pub(crate) fn to_srgb(v: f32) -> f32 {
    lookup(&tables().to_srgb, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_match_exact_functions() {
        for i in 0..=10_000 {
            let v = i as f32 / 10_000.0;
            assert!((to_linear(v) - srgb_to_linear(v)).abs() < 1e-4);
            assert!((to_srgb(v) - linear_to_srgb(v)).abs() < 1e-4);
        }
        assert_eq!(to_linear(f32::NAN), 0.0);
        assert!((to_srgb(2.0) - 1.0).abs() < 1e-6);
    }
}
