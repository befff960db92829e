//! Multi-resolution uniform surface samples and Gaussian/Laplacian pyramids over them
//! (paper B §3.1 after Turk 2001, "Texture synthesis on surfaces").
//!
//! **Nested levels.** Level 0 holds about `finest` samples, level `l` about
//! `finest / 4^l`, and every level contains all coarser ones: the coarsest is placed
//! first, then held fixed while denser samples are added around it, level by level —
//! the structure of Turk's hierarchy. The spreading rule is Poisson-disk dart throwing
//! (`fieldtex_mesh::poisson_disk_sampling_nested`: a sample is accepted only when no
//! sample of its own or a coarser level lies within that level's radius, so each level
//! is `r_l`-separated and close to maximal) instead of Turk's point repulsion (Turk
//! 1991/1992: random points pushed apart by a short-range force and re-projected onto
//! the surface). Both give an even, blue-noise spread; `docs/transfer.md` ("Samples")
//! gives the measured spacing statistics of these sets. The coarsest radius comes from
//! the sampler's target-count mode, the finer radii from the density it reached
//! (`n r² / A`), so counts are within a few percent of the request. Every
//! sample carries its triangle, barycentric point, position and the interpolated
//! (smooth) vertex normal, plus the triangle's normal.
//!
//! A Gaussian pyramid of any per-sample signal is built by smoothing and down-sampling:
//! level `l + 1` is the Gaussian-weighted mean (σ = level-`l` spacing) of level `l`
//! ([`Interpolator`]). Up-sampling interpolates a coarse level at the finer samples
//! (σ = 0.6 × the coarse spacing). The Laplacian pyramid stores `G_l − up(G_{l+1})` and
//! the coarsest Gaussian level unchanged (Burt & Adelson 1983); reconstruction adds the
//! levels back from coarse to fine, so it is exact.

use crate::TransferError;
use crate::scattered_interpolation::Interpolator;
use fieldtex_core::vec3::{self, V3};
use fieldtex_core::{Progress, Warning};
use fieldtex_mesh::{PoissonDiskOptions, PoissonDiskSamples, TriMesh};

/// One resolution of uniform surface samples.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleSet {
    pub triangles: Vec<u32>,
    pub barycentric: Vec<[f64; 3]>,
    pub positions: Vec<V3>,
    /// Interpolated vertex normals (unit).
    pub normals: Vec<V3>,
    /// Normals of the triangles holding the samples (unit, outward for an oriented mesh).
    pub face_normals: Vec<V3>,
    /// Poisson-disk radius: the minimum distance between samples.
    pub spacing: f64,
}

impl SampleSet {
    pub fn len(&self) -> usize {
        self.positions.len()
    }
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }
}

/// Samples at several resolutions with the operators between consecutive levels.
#[derive(Debug, Clone)]
pub struct SamplePyramid {
    /// Finest first.
    pub levels: Vec<SampleSet>,
    /// `down[l]`: level `l` → level `l + 1` (smoothing and down-sampling).
    down: Vec<Interpolator>,
    /// `up[l]`: level `l + 1` → level `l` (interpolation).
    up: Vec<Interpolator>,
}

/// Poisson-disk samples of `mesh` (about `count`), with normals.
pub fn sample_surface(
    mesh: &TriMesh,
    count: usize,
    seed: u64,
    which: &'static str,
    warnings: &mut Vec<Warning>,
) -> Result<SampleSet, TransferError> {
    let opts = PoissonDiskOptions { target_count: Some(count.max(1)), ..poisson_options(seed) };
    let (s, w) = fieldtex_mesh::poisson_disk_sampling(mesh, &opts)
        .map_err(|e| TransferError::numeric("surface sampling", e))?;
    warnings.extend(w);
    to_sample_set(mesh, &s, which)
}

fn poisson_options(seed: u64) -> PoissonDiskOptions {
    PoissonDiskOptions { seed, candidate_factor: 8.0, ..Default::default() }
}

/// Samples with their normals; an empty set is an error naming the mesh.
fn to_sample_set(
    mesh: &TriMesh,
    s: &PoissonDiskSamples,
    which: &'static str,
) -> Result<SampleSet, TransferError> {
    if s.samples.is_empty() {
        return Err(TransferError::EmptyMesh { which });
    }
    let (vn, _) = fieldtex_mesh::vertex_normals(mesh, fieldtex_mesh::NormalWeighting::default());
    let fnrm = fieldtex_mesh::face_normals(mesh);
    let mut out = SampleSet {
        triangles: Vec::with_capacity(s.samples.len()),
        barycentric: Vec::with_capacity(s.samples.len()),
        positions: Vec::with_capacity(s.samples.len()),
        normals: Vec::with_capacity(s.samples.len()),
        face_normals: Vec::with_capacity(s.samples.len()),
        spacing: s.radius,
    };
    for smp in &s.samples {
        let t = mesh.triangles[smp.triangle as usize];
        let fnv = fnrm[smp.triangle as usize];
        let mut n = [0.0; 3];
        for k in 0..3 {
            n = vec3::add(n, vec3::scale(vn[t[k] as usize], smp.barycentric[k]));
        }
        let n = vec3::normalize(n).unwrap_or(fnv);
        out.triangles.push(smp.triangle);
        out.barycentric.push(smp.barycentric);
        out.positions.push(smp.position);
        out.normals.push(n);
        out.face_normals.push(fnv);
    }
    Ok(out)
}

impl SamplePyramid {
    /// Samples `mesh` at `levels` resolutions, the finest with about `finest` samples
    /// (module docs). Coarse levels keep at least 64 samples.
    pub fn build(
        mesh: &TriMesh,
        finest: usize,
        levels: usize,
        seed: u64,
        which: &'static str,
        progress: &dyn Progress,
        warnings: &mut Vec<Warning>,
    ) -> Result<Self, TransferError> {
        let levels = levels.max(1);
        progress.stage(&format!("{which} samples"), levels as u64);
        // The coarsest level's radius comes from a target count (the sampler iterates on
        // its radius); its density `n r² / A` gives the radius of every finer level.
        let area = fieldtex_mesh::total_area(mesh);
        let counts: Vec<usize> = (0..levels).map(|l| (finest >> (2 * l)).max(64)).collect();
        let s = fieldtex_core::rng::stream_seed(seed, "transfer-samples", 0);
        let coarsest = sample_surface(mesh, counts[levels - 1], s, which, warnings)?;
        progress.advance(1);
        let density =
            coarsest.len() as f64 * coarsest.spacing * coarsest.spacing / area.max(1e-300);
        // Radii coarsest first, strictly decreasing (equal counts at the 64 floor are
        // separated by a hair so the nested sampler accepts them).
        let mut radii: Vec<f64> = Vec::with_capacity(levels);
        for l in (0..levels).rev() {
            let r = if l == levels - 1 {
                coarsest.spacing
            } else {
                (density * area / counts[l] as f64).sqrt()
            };
            let r = match radii.last() {
                Some(&prev) if r >= prev => prev * (1.0 - 1e-6),
                _ => r,
            };
            radii.push(r);
        }
        let (nested, w) =
            fieldtex_mesh::poisson_disk_sampling_nested(mesh, &radii, &poisson_options(s))
                .map_err(|e| TransferError::numeric("surface sampling", e))?;
        warnings.extend(w);
        let mut sets: Vec<SampleSet> = Vec::with_capacity(levels);
        for level in nested.iter().rev() {
            sets.push(to_sample_set(mesh, level, which)?);
        }
        progress.advance(levels.saturating_sub(1) as u64);
        progress.finish_stage();
        let mut down = Vec::new();
        let mut up = Vec::new();
        for l in 0..levels - 1 {
            let (f, c) = (&sets[l], &sets[l + 1]);
            down.push(Interpolator::gaussian(
                &f.positions,
                &f.normals,
                &c.positions,
                &c.normals,
                f.spacing.max(0.5 * c.spacing),
            ));
            up.push(Interpolator::gaussian(
                &c.positions,
                &c.normals,
                &f.positions,
                &f.normals,
                0.6 * c.spacing,
            ));
        }
        Ok(Self { levels: sets, down, up })
    }

    pub fn n_levels(&self) -> usize {
        self.levels.len()
    }

    /// Gaussian pyramid of row-major `#level0 × dim` values: finest first.
    pub fn gaussian(&self, values: &[f64], dim: usize) -> Vec<Vec<f64>> {
        let mut out = vec![values.to_vec()];
        for d in &self.down {
            let next = d.apply(out.last().expect("non-empty"), dim);
            out.push(next);
        }
        out
    }

    /// Laplacian pyramid (module docs): `n_levels` bands, finest first, the last one the
    /// coarsest Gaussian level.
    pub fn laplacian(&self, values: &[f64], dim: usize) -> Vec<Vec<f64>> {
        let g = self.gaussian(values, dim);
        let mut bands = Vec::with_capacity(g.len());
        for l in 0..g.len() - 1 {
            let upv = self.up[l].apply(&g[l + 1], dim);
            bands.push(g[l].iter().zip(&upv).map(|(a, b)| a - b).collect());
        }
        bands.push(g[g.len() - 1].clone());
        bands
    }

    /// Inverse of [`laplacian`](Self::laplacian).
    pub fn reconstruct(&self, bands: &[Vec<f64>], dim: usize) -> Vec<f64> {
        let mut acc = bands[bands.len() - 1].clone();
        for l in (0..bands.len() - 1).rev() {
            let upv = self.up[l].apply(&acc, dim);
            acc = bands[l].iter().zip(&upv).map(|(a, b)| a + b).collect();
        }
        acc
    }

    /// Values at level 0 carried to level `l` through the smoothing operators.
    pub fn down_to(&self, values: &[f64], dim: usize, l: usize) -> Vec<f64> {
        let mut v = values.to_vec();
        for d in &self.down[..l] {
            v = d.apply(&v, dim);
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::NoProgress;

    #[test]
    fn laplacian_reconstruction_is_exact_and_levels_shrink() {
        let mesh = fieldtex_mesh::primitives::icosphere(3);
        let mut w = Vec::new();
        let p = SamplePyramid::build(&mesh, 4000, 3, 1, "test", &NoProgress, &mut w).unwrap();
        assert_eq!(p.n_levels(), 3);
        assert!(p.levels[1].len() * 3 < p.levels[0].len());
        let vals: Vec<f64> = p.levels[0].positions.iter().map(|q| q[0] * q[1] + q[2]).collect();
        let bands = p.laplacian(&vals, 1);
        let back = p.reconstruct(&bands, 1);
        for (a, b) in vals.iter().zip(&back) {
            assert!((a - b).abs() < 1e-9);
        }
        // The coarse band is a smoothed copy: its values stay inside the input range.
        let (lo, hi) = vals.iter().fold((f64::MAX, f64::MIN), |a, &v| (a.0.min(v), a.1.max(v)));
        assert!(bands[2].iter().all(|&v| v >= lo - 1e-9 && v <= hi + 1e-9));
    }

    /// Turk's hierarchy is nested: every level holds all coarser samples (as its
    /// prefix), each level keeps its minimum spacing, and counts grow about 4× per level.
    #[test]
    fn levels_are_nested_and_keep_their_spacing() {
        let mesh = fieldtex_mesh::primitives::torus(1.0, 0.4, 48, 24);
        let mut w = Vec::new();
        let p = SamplePyramid::build(&mesh, 8000, 3, 5, "test", &NoProgress, &mut w).unwrap();
        for l in 0..2 {
            let (fine, coarse) = (&p.levels[l], &p.levels[l + 1]);
            assert_eq!(&fine.positions[..coarse.len()], &coarse.positions[..]);
            let ratio = fine.len() as f64 / coarse.len() as f64;
            assert!((3.0..5.0).contains(&ratio), "level {l}: ratio {ratio}");
            assert!(fine.spacing < coarse.spacing);
        }
        for set in &p.levels {
            let grid = fieldtex_mesh::SpatialGrid::new(&set.positions, set.spacing);
            for (i, q) in set.positions.iter().enumerate() {
                grid.for_each_within(&set.positions, *q, set.spacing * (1.0 - 1e-9), |j, _| {
                    assert_eq!(j as usize, i, "samples {i} and {j} closer than the spacing");
                });
            }
        }
        assert!((7600..8400).contains(&p.levels[0].len()), "{}", p.levels[0].len());
    }
}
