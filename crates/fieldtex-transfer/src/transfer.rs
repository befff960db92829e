//! The whole transfer of paper B on surface samples: samples and pyramids on source and
//! target, source colours, descriptors, guidance (CCA), feature matching, synthesis.
//! Baking into an atlas and writing files belong to the caller (the facade).

use crate::TransferError;
use crate::descriptors::{DescriptorOptions, compute_descriptors};
use crate::feature_matching::{MatchMode, MatchStep, match_features};
use crate::guidance::{Reduction, build_guidance};
use crate::nonparametric_synthesis::{
    NonparametricOptions, NonparametricStats, nonparametric_synthesis,
};
use crate::parametric_synthesis::{
    ParametricOptions, ParametricStats, SynthesisInput, parametric_synthesis,
};
use crate::scattered_interpolation::Interpolator;
use crate::source_colors::{check_mask_size, source_sample_colors};
use crate::surface_samples::{SamplePyramid, SampleSet};
use fieldtex_core::vec3::{self, V3};
use fieldtex_core::{Image, Progress, Warning};
use fieldtex_mesh::TriMesh;
use serde::Serialize;
use std::time::Instant;

/// Synthesis engine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Engine {
    /// Constrained Heeger–Bergen (default).
    Parametric,
    /// Image analogies on surface samples with Ashikhmin coherence.
    Nonparametric,
}

/// Options of [`transfer`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransferOptions {
    /// Level-0 samples on each mesh. Default 512 000 (paper B §3.1).
    pub samples: usize,
    /// Pyramid levels. Default 3.
    pub levels: usize,
    pub descriptors: DescriptorOptions,
    /// Default CCA.
    pub reduction: Reduction,
    /// Default multiscale.
    pub matching: MatchMode,
    /// Default parametric.
    pub engine: Engine,
    pub parametric: ParametricOptions,
    pub nonparametric: NonparametricOptions,
    pub seed: u64,
}

impl Default for TransferOptions {
    fn default() -> Self {
        Self {
            samples: 512_000,
            levels: 3,
            descriptors: DescriptorOptions::default(),
            reduction: Reduction::CcaWeighted,
            matching: MatchMode::Multiscale,
            engine: Engine::Parametric,
            parametric: ParametricOptions::default(),
            nonparametric: NonparametricOptions::default(),
            seed: 1,
        }
    }
}

/// Everything a transfer computed.
#[derive(Debug, Clone)]
pub struct TransferResult {
    pub source_samples: SampleSet,
    /// `#source × 3` RGB read from the texture.
    pub source_colors: Vec<f64>,
    pub source_valid: Vec<bool>,
    pub target_samples: SampleSet,
    /// `#target × 3` synthesised RGB (sRGB-encoded, `[0, 1]`).
    pub target_colors: Vec<f64>,
    /// `#source × 12`, `#target × 12`.
    pub source_descriptors: Vec<f64>,
    pub target_descriptors: Vec<f64>,
    /// `#source × 3` guidance; `#target × 3` guidance after feature matching.
    pub source_guidance: Vec<f64>,
    pub target_guidance: Vec<f64>,
    /// Canonical correlations (CCA) or explained variance fractions (PCA).
    pub strengths: Vec<f64>,
    /// Projection directions on the standardised descriptors.
    pub directions: Vec<Vec<f64>>,
    pub descriptor_weights: Vec<f64>,
    pub matching: Vec<MatchStep>,
    /// Statistics of the engine that ran.
    pub parametric: Option<ParametricStats>,
    pub nonparametric: Option<NonparametricStats>,
    /// Wall time per stage, milliseconds (not deterministic).
    pub timings_ms: Vec<(String, f64)>,
    pub warnings: Vec<Warning>,
}

fn timed<T>(timings: &mut Vec<(String, f64)>, stage: &str, f: impl FnOnce() -> T) -> T {
    let t0 = Instant::now();
    let out = f();
    timings.push((stage.to_string(), t0.elapsed().as_secs_f64() * 1e3));
    out
}

/// The per-mesh stages, identical for source and target up to the mesh, its name
/// (`"source"` / `"target"`, which also names the random stream and the timing) and its
/// samples.
struct Side<'a> {
    options: &'a TransferOptions,
    progress: &'a dyn Progress,
    timings: &'a mut Vec<(String, f64)>,
    warnings: &'a mut Vec<Warning>,
}

impl Side<'_> {
    fn stream(&self, which: &'static str, index: u64) -> u64 {
        fieldtex_core::rng::stream_seed(self.options.seed, &format!("transfer-{which}"), index)
    }

    fn samples(
        &mut self,
        mesh: &TriMesh,
        which: &'static str,
    ) -> Result<SamplePyramid, TransferError> {
        let seed = self.stream(which, 0);
        let (o, progress, warnings) = (self.options, self.progress, &mut *self.warnings);
        timed(self.timings, &format!("{which}_samples"), || {
            SamplePyramid::build(mesh, o.samples, o.levels, seed, which, progress, warnings)
        })
    }

    fn descriptors(
        &mut self,
        mesh: &TriMesh,
        samples: &SamplePyramid,
        which: &'static str,
    ) -> Result<Vec<f64>, TransferError> {
        let seed = self.stream(which, 1);
        let (o, progress, warnings) = (self.options, self.progress, &mut *self.warnings);
        timed(self.timings, &format!("{which}_descriptors"), || {
            compute_descriptors(
                mesh,
                &samples.levels[0],
                &o.descriptors,
                seed,
                which,
                progress,
                warnings,
            )
        })
    }
}

/// Transfers the texture of `source` (per-corner UVs + `texture`, optional `mask` of the
/// texture's size, white = ignore) to `target` (module docs).
pub fn transfer(
    source: &TriMesh,
    texture: &Image,
    mask: Option<&Image>,
    target: &TriMesh,
    options: &TransferOptions,
    progress: &dyn Progress,
) -> Result<TransferResult, TransferError> {
    if options.engine == Engine::Nonparametric {
        options.nonparametric.validate()?;
    }
    if !(256..=8_000_000).contains(&options.samples) {
        return Err(TransferError::InvalidOption {
            what: "samples",
            message: format!("must be in 256..=8000000, got {}", options.samples),
        });
    }
    if !(1..=6).contains(&options.levels) {
        return Err(TransferError::InvalidOption {
            what: "levels",
            message: format!("must be in 1..=6, got {}", options.levels),
        });
    }
    if source.uvs.is_none() {
        return Err(TransferError::SourceNotTextured { what: "has no texture coordinates".into() });
    }
    check_mask_size(mask, texture)?;
    if source.n_triangles() == 0 {
        return Err(TransferError::EmptyMesh { which: "source" });
    }
    if target.n_triangles() == 0 {
        return Err(TransferError::EmptyMesh { which: "target" });
    }
    let seed = options.seed;
    let mut warnings = Vec::new();
    let mut t = Vec::new();
    let mut side = Side { options, progress, timings: &mut t, warnings: &mut warnings };
    let sp = side.samples(source, "source")?;
    let tp = side.samples(target, "target")?;
    let (source_colors, source_valid) = timed(&mut t, "source_colors", || {
        source_sample_colors(source, texture, mask, &sp.levels[0])
    })?;
    let usable = source_valid.iter().filter(|&&v| v).count();
    if usable < 16 {
        return Err(TransferError::TooFewSamples { found: usable, needed: 16 });
    }
    let mut side = Side { options, progress, timings: &mut t, warnings: &mut warnings };
    let xs = side.descriptors(source, &sp, "source")?;
    let xt = side.descriptors(target, &tp, "target")?;
    let g = timed(&mut t, "guidance", || {
        build_guidance(&xs, &source_colors, &source_valid, &xt, options.reduction)
    })?;
    let mut gt = g.target.clone();
    let matching = timed(&mut t, "feature_matching", || {
        match_features(&mut gt, &g.source, &sp, &tp, options.matching, seed)
    })?;
    progress.stage("synthesis", 1);
    let input = SynthesisInput {
        source: &sp,
        source_guidance: &g.source,
        source_colors: &source_colors,
        source_valid: &source_valid,
        target: &tp,
        target_guidance: &gt,
    };
    let (target_colors, parametric, nonparametric) = timed(&mut t, "synthesis", || match options
        .engine
    {
        Engine::Parametric => {
            parametric_synthesis(&input, &options.parametric, seed).map(|(c, s)| (c, Some(s), None))
        }
        Engine::Nonparametric => {
            nonparametric_synthesis(&input, options.descriptors.up.index(), &options.nonparametric)
                .map(|(c, s)| (c, None, Some(s)))
        }
    })?;
    progress.advance(1);
    progress.finish_stage();
    let SamplePyramid { levels, .. } = sp;
    let source_samples = levels.into_iter().next().expect("level 0");
    let target_samples = tp.levels.into_iter().next().expect("level 0");
    Ok(TransferResult {
        source_samples,
        source_colors,
        source_valid,
        target_samples,
        target_colors,
        source_descriptors: xs,
        target_descriptors: xt,
        source_guidance: g.source,
        target_guidance: gt,
        strengths: g.strengths,
        directions: g.directions,
        descriptor_weights: g.descriptor_weights,
        matching,
        parametric,
        nonparametric,
        timings_ms: t,
        warnings,
    })
}

/// Interpolates per-sample values (`#samples × dim`) at surface points
/// `(triangle, barycentric)` of `mesh` (the mesh the samples were taken on, possibly with
/// other UVs), Gaussian σ = 0.6 × the sample spacing (see [`Interpolator`]).
pub fn values_at_surface_points(
    mesh: &TriMesh,
    samples: &SampleSet,
    values: &[f64],
    dim: usize,
    points: &[(u32, [f64; 3])],
) -> Vec<f64> {
    let (vn, _) = fieldtex_mesh::vertex_normals(mesh, fieldtex_mesh::NormalWeighting::default());
    let mut pos: Vec<V3> = Vec::with_capacity(points.len());
    let mut nrm: Vec<V3> = Vec::with_capacity(points.len());
    for &(f, b) in points {
        let tri = mesh.triangles[f as usize];
        let mut p = [0.0; 3];
        let mut n = [0.0; 3];
        for k in 0..3 {
            p = vec3::add(p, vec3::scale(mesh.positions[tri[k] as usize], b[k]));
            n = vec3::add(n, vec3::scale(vn[tri[k] as usize], b[k]));
        }
        pos.push(p);
        nrm.push(vec3::normalize(n).unwrap_or([0.0, 0.0, 1.0]));
    }
    Interpolator::gaussian(&samples.positions, &samples.normals, &pos, &nrm, 0.6 * samples.spacing)
        .apply(values, dim)
}
