//! Helpers shared by the fields tests: curves for the curve-field tests (paper A §4)
//! a scalar reference for plane sampling, and vector comparisons.
#![allow(dead_code)]

use fieldtex_core::vec3::{self, V3};
use fieldtex_fields::orientation_field::{self, nrosy_root};
use fieldtex_fields::{FieldDesign, SolvedField};

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

/// Scalar reference: locate every pixel centre, interpolate the vertex values.
pub fn reference_pixels(d: &FieldDesign, f: &SolvedField, w: usize, h: usize) -> Vec<[f64; 2]> {
    let zv = orientation_field::vertex_complex(d, f);
    let g = *d.plane().unwrap();
    (0..w * h)
        .map(|k| {
            let (c, r) = (k % w, k / w);
            let x = (c as f64 + 0.5) * g.width / w as f64;
            let y = (r as f64 + 0.5) * g.height / h as f64;
            let (face, b) = g.locate(x, y);
            let t = d.dec().triangles[face];
            let mut z = [0.0; 2];
            for i in 0..3 {
                z[0] += b[i] * zv[t[i] as usize][0];
                z[1] += b[i] * zv[t[i] as usize][1];
            }
            nrosy_root(z, f.symmetry)
        })
        .collect()
}

/// Largest absolute entry.
pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Largest absolute entrywise difference.
pub fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}
