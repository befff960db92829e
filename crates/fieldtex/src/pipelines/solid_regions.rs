//! Two regions of one solid (`fieldtex solid --interior E2`; paper E §6, Fig. 15: bark
//! near the surface, wood inside): a second synthesizer, with its own exemplar analysis
//! but the same lattice and frame field, fills the voxels deeper than `depth` below
//! the surface; across a band of width `band` around that depth the two colours are
//! blended with a smoothstep weight.
//!
//! A voxel's interior weight depends only on its centre and the mesh (the distance to
//! the closest surface point through the BVH, and the ray-parity inside test for
//! voxels deeper than the band's start), and each synthesizer is evaluated on demand
//! for just the voxels with a non-zero weight in its region, so a voxel's colour is
//! still the same whether it is requested alone, in a cut, in the shell or in the
//! volume.

use super::*;

/// The interior region: its synthesizer and where it starts.
pub(crate) struct Interior<'a> {
    pub synth: SolidSynthesizer<'a>,
    pub bvh: &'a Bvh,
    /// Depth below the surface (mesh units) of the middle of the blend band.
    pub depth: f64,
    /// Width of the blend band (mesh units, > 0).
    pub band: f64,
    /// Mesh size for the inside test's step past a hit.
    pub scale: f64,
}

/// The outer synthesizer and, with `--interior`, the interior region.
pub(crate) struct SolidRegions<'a> {
    pub outer: SolidSynthesizer<'a>,
    pub inner: Option<Interior<'a>>,
    pub grid: SolidGrid,
}

/// Adds `b`'s work to `a`, level by level.
fn add_stats(a: &mut Vec<LevelStats>, b: &[LevelStats]) {
    if a.len() < b.len() {
        a.resize(b.len(), LevelStats::default());
    }
    for (x, y) in a.iter_mut().zip(b) {
        x.primary_blocks += y.primary_blocks;
        x.dual_blocks += y.dual_blocks;
        x.corrections += y.corrections;
        x.candidate_evaluations += y.candidate_evaluations;
        x.voxels += y.voxels;
        x.seconds += y.seconds;
    }
}

impl SolidRegions<'_> {
    /// Interior weight of each voxel in `[0, 1]` (module docs).
    fn interior_weights(&self, inner: &Interior<'_>, voxels: &[[i32; 3]]) -> Vec<f32> {
        let g = &self.grid;
        let centres: Vec<[f64; 3]> = voxels
            .iter()
            .map(|v| std::array::from_fn(|a| g.origin[a] + v[a] as f64 * g.spacing))
            .collect();
        let start = inner.depth - 0.5 * inner.band;
        let closest = inner.bvh.closest_points(&centres);
        let dist: Vec<f64> =
            closest.iter().map(|c| c.as_ref().map_or(0.0, |c| c.distance)).collect();
        let deep: Vec<usize> = (0..voxels.len()).filter(|&i| dist[i] > start).collect();
        let deep_centres: Vec<[f64; 3]> = deep.iter().map(|&i| centres[i]).collect();
        let inside = fieldtex_mesh::points_inside(inner.bvh, &deep_centres, inner.scale);
        let mut w = vec![0.0f32; voxels.len()];
        for (&i, ins) in deep.iter().zip(inside) {
            if ins {
                let t = ((dist[i] - start) / inner.band).clamp(0.0, 1.0);
                w[i] = (t * t * (3.0 - 2.0 * t)) as f32;
            }
        }
        w
    }

    /// Colours of `voxels` (RGB, sRGB-encoded), each region evaluated on demand.
    pub fn colors(
        &mut self,
        voxels: &[[i32; 3]],
        progress: &dyn Progress,
    ) -> (Vec<[f32; 3]>, Vec<LevelStats>) {
        let Some(inner) = self.inner.as_ref() else {
            return self.outer.colors(voxels, progress);
        };
        let w = self.interior_weights(inner, voxels);
        let outer_idx: Vec<usize> = (0..voxels.len()).filter(|&i| w[i] < 1.0).collect();
        let inner_idx: Vec<usize> = (0..voxels.len()).filter(|&i| w[i] > 0.0).collect();
        let pick = |idx: &[usize]| idx.iter().map(|&i| voxels[i]).collect::<Vec<_>>();
        let (oc, mut stats) = self.outer.colors(&pick(&outer_idx), progress);
        let inner = self.inner.as_mut().expect("checked above");
        let (ic, istats) = inner.synth.colors(&pick(&inner_idx), progress);
        add_stats(&mut stats, &istats);
        let mut out = vec![[0.0f32; 3]; voxels.len()];
        for (&i, c) in outer_idx.iter().zip(&oc) {
            out[i] = *c;
        }
        for (&i, c) in inner_idx.iter().zip(&ic) {
            let a = w[i];
            out[i] = std::array::from_fn(|ch| (1.0 - a) * out[i][ch] + a * c[ch]);
        }
        (out, stats)
    }

    /// Voxels whose final value is cached, per level, both regions together.
    pub fn cached_voxels(&self) -> Vec<u64> {
        let mut v = self.outer.cached_voxels();
        if let Some(inner) = &self.inner {
            for (a, b) in v.iter_mut().zip(inner.synth.cached_voxels()) {
                *a += b;
            }
        }
        v
    }
}
