//! The 12 geometric descriptors of paper B §3.2, per level-0 surface sample:
//!
//! | columns | descriptor | computed |
//! |---|---|---|
//! | 0 | normalised height along the up axis (0 at the bounding box's bottom, 1 at its top) | exactly, per sample |
//! | 1–3 | unit normal (x, y, z; object space) | exactly, per sample (interpolated vertex normal) |
//! | 4–7 | solid-angle curvature at 4 radii relative to the bounding-box diagonal (`fieldtex_mesh::solid_angle_curvature`: analytic, signed solid angles of the triangles clipped to each sphere) | on a coarser Poisson set, interpolated |
//! | 8–11 | directional occlusion, SH bands 0–1 `[c₀₀, c₁₋₁(y), c₁₀(z), c₁₁(x)]` (`fieldtex_mesh::directional_occlusion_sh`) | on a coarser Poisson set, interpolated |
//!
//! The solid-angle and occlusion descriptors vary at the scale of their radii (the
//! smallest is 2 % of the diagonal) and of the occluders, far above the level-0 spacing, so they are computed on
//! `samples` (default 32 768) Poisson samples and interpolated to level 0 with the
//! Gaussian Shepard interpolator (σ = 0.6 × that set's spacing, about 0.3 % of the
//! diagonal on a compact 512K-sample mesh). When level 0 has no more samples than that,
//! they are computed on level 0 directly. The solid angle at radius `r` varies only at
//! the scale of `r`, while its cost per point grows with the area inside the sphere
//! (`∝ r²`); so each radius is evaluated on its own Poisson set of
//! `min(samples, 64 · area / r²)` points (at least 512; about 9.6 sample spacings per
//! radius) and interpolated the same way: every radius then costs about the same,
//! `~200 ×` the triangle count in closed-form solid angles. The interpolation error
//! against evaluating every level-0 sample exactly is measured by
//! `examples/bench_descriptors` (`docs/transfer.md`).

use crate::TransferError;
use crate::scattered_interpolation::Interpolator;
use crate::surface_samples::{SampleSet, sample_surface};
use fieldtex_core::{Progress, Warning};
use fieldtex_mesh::{
    Bvh, DirectionalOcclusionOptions, OrientedPoint, TriMesh, directional_occlusion_sh,
    solid_angle_curvature,
};
use serde::Serialize;

/// Solid-angle evaluation points per `r²` of surface area: about 8 sample spacings per
/// radius (the Poisson spacing is `√(0.7 A / n)`, so `r / spacing = √(64 / 0.7) ≈ 9.6`).
const SOLID_ANGLE_DENSITY: f64 = 64.0;
/// Fewest solid-angle evaluation points at any radius.
const MIN_SOLID_ANGLE_POINTS: usize = 512;

/// Number of descriptors.
pub const N_DESCRIPTORS: usize = 12;

/// Names of the descriptor columns, in order.
pub const DESCRIPTOR_NAMES: [&str; N_DESCRIPTORS] = [
    "height",
    "normal_x",
    "normal_y",
    "normal_z",
    "solid_angle_r0",
    "solid_angle_r1",
    "solid_angle_r2",
    "solid_angle_r3",
    "occlusion_sh00",
    "occlusion_sh1_y",
    "occlusion_sh1_z",
    "occlusion_sh1_x",
];

/// Object-space axis that points up (height is measured along it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum UpAxis {
    X,
    Y,
    Z,
}

impl UpAxis {
    pub fn index(self) -> usize {
        match self {
            UpAxis::X => 0,
            UpAxis::Y => 1,
            UpAxis::Z => 2,
        }
    }
}

/// Options of [`compute_descriptors`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DescriptorOptions {
    /// Up axis. Default `y` (glTF's up).
    pub up: UpAxis,
    /// Solid-angle radii relative to the bounding-box diagonal. Default
    /// `[0.02, 0.05, 0.1, 0.25]`.
    pub radii: [f64; 4],
    /// Ray directions per sample for the directional occlusion. Default 64.
    pub directions: usize,
    /// Samples on which the solid-angle and occlusion descriptors are computed. Default
    /// 32 768.
    pub samples: usize,
}

impl Default for DescriptorOptions {
    fn default() -> Self {
        Self { up: UpAxis::Y, radii: [0.02, 0.05, 0.1, 0.25], directions: 64, samples: 32_768 }
    }
}

/// Row-major `#samples × 12` descriptors of the level-0 `samples` of `mesh` (module docs).
pub fn compute_descriptors(
    mesh: &TriMesh,
    samples: &SampleSet,
    options: &DescriptorOptions,
    seed: u64,
    which: &'static str,
    progress: &dyn Progress,
    warnings: &mut Vec<Warning>,
) -> Result<Vec<f64>, TransferError> {
    if options.directions == 0 || options.directions > 4096 {
        return Err(TransferError::InvalidOption {
            what: "descriptor directions",
            message: format!("must be in 1..=4096, got {}", options.directions),
        });
    }
    let bbox = mesh.bounding_box().ok_or(TransferError::EmptyMesh { which })?;
    let diag = bbox.diagonal().max(1e-300);
    let up = options.up.index();
    let (lo, hi) = (bbox.min[up], bbox.max[up]);
    let span = if hi > lo { hi - lo } else { 1.0 };
    let n = samples.len();
    let mut out = vec![0.0; n * N_DESCRIPTORS];
    for i in 0..n {
        let row = &mut out[i * N_DESCRIPTORS..(i + 1) * N_DESCRIPTORS];
        row[0] = (samples.positions[i][up] - lo) / span;
        row[1..4].copy_from_slice(&samples.normals[i]);
    }
    // Solid-angle and occlusion descriptors on a coarser set (or on level 0).
    let coarse_owned;
    let coarse: &SampleSet = if n > options.samples {
        coarse_owned = sample_surface(
            mesh,
            options.samples,
            fieldtex_core::rng::stream_seed(seed, "transfer-descriptor-samples", 0),
            which,
            warnings,
        )?;
        &coarse_owned
    } else {
        samples
    };
    let bvh = Bvh::build(mesh).map_err(|e| TransferError::numeric("BVH", e))?;
    let pts: Vec<OrientedPoint> = coarse
        .positions
        .iter()
        .zip(&coarse.face_normals)
        .map(|(&position, &normal)| OrientedPoint { position, normal })
        .collect();
    let radii: Vec<f64> = options.radii.iter().map(|r| r * diag).collect();
    progress.stage(&format!("{which} descriptors"), 2);
    // Solid angle at radius r varies at the scale of r: it is evaluated on about
    // `SOLID_ANGLE_DENSITY · area / r²` points (at most the descriptor set), so every
    // radius costs about the same (module docs).
    let area = fieldtex_mesh::total_area(mesh);
    let mut sa_coarse = vec![0.0; coarse.len() * 4];
    let mut sa_own: Vec<(usize, SampleSet, Vec<f64>)> = Vec::new();
    for (k, &r) in radii.iter().enumerate() {
        let want = (SOLID_ANGLE_DENSITY * area / (r * r)).ceil();
        let solid_angle = |set: &SampleSet| {
            solid_angle_curvature(mesh, &set.positions, &[r])
                .map_err(|e| TransferError::numeric("solid-angle curvature", e))
        };
        if want >= coarse.len() as f64 {
            for (i, x) in solid_angle(coarse)?.into_iter().enumerate() {
                sa_coarse[i * 4 + k] = x;
            }
        } else {
            let count = (want as usize).max(MIN_SOLID_ANGLE_POINTS);
            let stream = fieldtex_core::rng::stream_seed(seed, "transfer-solid-angle", k as u64);
            let set = sample_surface(mesh, count, stream, which, warnings)?;
            let v = solid_angle(&set)?;
            sa_own.push((k, set, v));
        }
    }
    progress.advance(1);
    let sh = directional_occlusion_sh(
        &bvh,
        &pts,
        &DirectionalOcclusionOptions {
            directions: options.directions,
            epsilon: 1e-4 * diag,
            seed: fieldtex_core::rng::stream_seed(seed, "transfer-occlusion", 0),
            ..Default::default()
        },
    );
    progress.advance(1);
    progress.finish_stage();
    let mut ray = vec![0.0; coarse.len() * 8];
    for i in 0..coarse.len() {
        ray[i * 8..i * 8 + 4].copy_from_slice(&sa_coarse[i * 4..i * 4 + 4]);
        ray[i * 8 + 4..i * 8 + 8].copy_from_slice(&sh[i]);
    }
    let to_level0 = |set: &SampleSet, values: &[f64], dim: usize| {
        Interpolator::gaussian(
            &set.positions,
            &set.normals,
            &samples.positions,
            &samples.normals,
            0.6 * set.spacing,
        )
        .apply(values, dim)
    };
    let fine = if std::ptr::eq(coarse, samples) { ray } else { to_level0(coarse, &ray, 8) };
    for i in 0..n {
        out[i * N_DESCRIPTORS + 4..(i + 1) * N_DESCRIPTORS]
            .copy_from_slice(&fine[i * 8..i * 8 + 8]);
    }
    for (k, set, v) in &sa_own {
        let v = to_level0(set, v, 1);
        for i in 0..n {
            out[i * N_DESCRIPTORS + 4 + k] = v[i];
        }
    }
    Ok(out)
}
