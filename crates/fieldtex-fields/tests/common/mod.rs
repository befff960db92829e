//! Curves shared by the curve-field tests (paper A §4).
#![allow(dead_code)]

use fieldtex_core::vec3::{self, V3};

/// `n + 1` evenly spaced points from `a` to `b`.
pub fn line(a: V3, b: V3, n: usize) -> Vec<V3> {
    (0..=n).map(|i| vec3::lerp(a, b, i as f64 / n as f64)).collect()
}

/// Arc on the unit sphere at longitude `lon` from latitude `lat0` to `lat1` (radians).
pub fn meridian(lon: f64, lat0: f64, lat1: f64, n: usize) -> Vec<V3> {
    (0..=n)
        .map(|i| {
            let lat = lat0 + (lat1 - lat0) * i as f64 / n as f64;
            [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()]
        })
        .collect()
}
