//! Directional occlusion projected on spherical harmonics bands 0 and 1 (paper B,
//! Mertens et al. 2006 §3.2; real SH basis of Sloan, Kautz & Snyder 2002).
//!
//! The binary visibility `V(d)` of a surface point (1 when a ray leaving along `d`
//! escapes the object within `max_distance`, 0 when it hits the surface or points below
//! the tangent plane) is projected on the four real SH functions of bands 0–1:
//! `Y₀₀ = ½√(1/π)`, `Y₁₋₁ = √(3/4π)·y`, `Y₁₀ = √(3/4π)·z`, `Y₁₁ = √(3/4π)·x`. The
//! coefficients `c = ∫ V(d) Y(d) dω` are estimated with `n` well-spread directions
//! ([`crate::sphere_directions`], rotated per point): `c ≈ 4π/n Σ V(dᵢ) Y(dᵢ)`.
//! Directions are in object space, so band 1 measures how visibility leans towards
//! each axis (e.g. the sky). `c₀₀ / (2√π)` is the unoccluded fraction of the sphere
//! (ambient accessibility). An open plane gives `c₀₀ = √π ≈ 1.7725` and band 1 equal to
//! `√(3π)/2 ≈ 1.5350` times its normal.
//!
//! Output: `#points` rows `[c₀₀, c₁₋₁ (y), c₁₀ (z), c₁₁ (x)]`.

use crate::bvh::{Bvh, Ray};
use crate::solid_angle_curvature::OrientedPoint;
use crate::sphere_directions::{fibonacci_directions, random_rotation3, rotate};
use fieldtex_core::vec3::{self};
use rayon::prelude::*;

/// Options of [`directional_occlusion_sh`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalOcclusionOptions {
    /// Directions per point over the whole sphere (about half are above the tangent
    /// plane). Default 64.
    pub directions: usize,
    /// Rays farther than this do not occlude. Default `∞`.
    pub max_distance: f64,
    /// Ray origin offset along the normal, absolute. Default `1e-4`; use about `1e-4 ×`
    /// the bounding-box diagonal (the BVH traverses in `f32`, so much smaller offsets let
    /// a ray hit its own triangle).
    pub epsilon: f64,
    pub seed: u64,
}

impl Default for DirectionalOcclusionOptions {
    fn default() -> Self {
        Self { directions: 64, max_distance: f64::INFINITY, epsilon: 1e-4, seed: 0 }
    }
}

const Y00: f64 = 0.282_094_791_773_878_14;
const Y1: f64 = 0.488_602_511_902_919_9;

/// SH bands 0–1 of the visibility of every point (module docs).
pub fn directional_occlusion_sh(
    bvh: &Bvh,
    points: &[OrientedPoint],
    options: &DirectionalOcclusionOptions,
) -> Vec<[f64; 4]> {
    let dirs = fibonacci_directions(options.directions.max(1));
    let w = 4.0 * std::f64::consts::PI / dirs.len() as f64;
    points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let rot = random_rotation3(options.seed ^ 0x5eed_0cc1, i as u64);
            let origin = vec3::add(p.position, vec3::scale(p.normal, options.epsilon));
            let mut c = [0.0; 4];
            for &d0 in &dirs {
                let d = rotate(&rot, d0);
                if vec3::dot(d, p.normal) <= 0.0 {
                    continue;
                }
                let ray = Ray::new(origin, d).with_range(0.0, options.max_distance);
                if bvh.occluded(&ray) {
                    continue;
                }
                c[0] += w * Y00;
                c[1] += w * Y1 * d[1];
                c[2] += w * Y1 * d[2];
                c[3] += w * Y1 * d[0];
            }
            c
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives;

    /// An open plane with normal +z sees the whole upper hemisphere: c₀₀ = √π,
    /// c₁₀ = √(3π)/2, the other two 0.
    #[test]
    fn open_plane_known_answer() {
        let mesh = primitives::grid(10, 10, 1.0, 1.0);
        let n = crate::face_normals(&mesh)[0];
        assert!((n[2] - 1.0).abs() < 1e-12, "grid normal {n:?}");
        let bvh = Bvh::build(&mesh).unwrap();
        let pts: Vec<OrientedPoint> = (0..20)
            .map(|i| OrientedPoint { position: [0.3 + 0.02 * i as f64, 0.5, 0.0], normal: n })
            .collect();
        let opts = DirectionalOcclusionOptions { directions: 512, ..Default::default() };
        let c = directional_occlusion_sh(&bvh, &pts, &opts);
        let pi = std::f64::consts::PI;
        let mean = |k: usize| c.iter().map(|r| r[k]).sum::<f64>() / c.len() as f64;
        assert!((mean(0) - pi.sqrt()).abs() < 0.01 * pi.sqrt(), "{}", mean(0));
        assert!((mean(2) - (3.0 * pi).sqrt() / 2.0).abs() < 0.01, "{}", mean(2));
        assert!(mean(1).abs() < 0.02 && mean(3).abs() < 0.02);
        for r in &c {
            assert!((r[0] - pi.sqrt()).abs() < 0.06 * pi.sqrt(), "{r:?}");
        }
    }

    /// Inside a closed sphere looking inward, everything is occluded; outside, a point
    /// on the sphere sees exactly its upper hemisphere (convex object).
    #[test]
    fn convex_object_sees_its_hemisphere() {
        let mesh = primitives::icosphere(3);
        let bvh = Bvh::build(&mesh).unwrap();
        let normals = crate::face_normals(&mesh);
        let [a, b, c] = mesh.triangle_positions(7);
        let p = vec3::scale(vec3::add(vec3::add(a, b), c), 1.0 / 3.0);
        let pts = [
            OrientedPoint { position: p, normal: normals[7] },
            OrientedPoint { position: p, normal: vec3::scale(normals[7], -1.0) },
        ];
        let r = directional_occlusion_sh(
            &bvh,
            &pts,
            &DirectionalOcclusionOptions { directions: 1024, epsilon: 1e-4, ..Default::default() },
        );
        assert!((r[0][0] - std::f64::consts::PI.sqrt()).abs() < 0.03, "{:?}", r[0]);
        assert!(r[1][0] == 0.0, "{:?}", r[1]);
    }
}
