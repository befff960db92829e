//! Well-spread unit directions for Monte-Carlo integrals over the sphere.
//!
//! A spherical Fibonacci set of `n` directions (González 2010, "Measurement of areas on
//! a sphere using Fibonacci and latitude–longitude lattices"), turned by a uniformly
//! random rotation per query point (a unit quaternion from
//! `hash_unit(seed, "sphere-directions", 4·index + k)`, Shoemake 1992), so that the
//! estimates of neighbouring points do not share the lattice's aliasing. Each direction
//! stands for the solid angle `4π / n`.

use fieldtex_core::rng::hash_unit;
use fieldtex_core::vec3::V3;

/// The `n` spherical Fibonacci directions (unrotated).
pub fn fibonacci_directions(n: usize) -> Vec<V3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            [r * phi.cos(), r * phi.sin(), z]
        })
        .collect()
}

/// A uniformly random rotation matrix (row-major 3×3) for query point `index`.
pub fn random_rotation3(seed: u64, index: u64) -> [[f64; 3]; 3] {
    let u = |k: u64| hash_unit(seed, "sphere-directions", 4 * index + k);
    let (u1, u2, u3) = (u(0), u(1), u(2));
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (w, x, y, z) =
        (a * (tau * u2).sin(), a * (tau * u2).cos(), b * (tau * u3).sin(), b * (tau * u3).cos());
    [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
    ]
}

/// `m · d`.
#[inline]
pub fn rotate(m: &[[f64; 3]; 3], d: V3) -> V3 {
    [
        m[0][0] * d[0] + m[0][1] * d[1] + m[0][2] * d[2],
        m[1][0] * d[0] + m[1][1] * d[1] + m[1][2] * d[2],
        m[2][0] * d[0] + m[2][1] * d[1] + m[2][2] * d[2],
    ]
}
