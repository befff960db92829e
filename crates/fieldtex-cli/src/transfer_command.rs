//! `fieldtex transfer`: flags → `fieldtex::TransferCommandOptions`.

use crate::GlobalArgs;
use clap::Args;
use fieldtex::Error;
use fieldtex::pipelines_transfer as t;
use std::path::PathBuf;

/// Texture transfer by geometry correlation (paper B): learn how the source's colour
/// follows its shape and synthesise the same on the target.
#[derive(Args, Debug)]
pub struct TransferArgs {
    /// Textured source mesh (OBJ+MTL+image, glTF/GLB with a base-colour texture).
    #[arg(long)]
    source: PathBuf,
    /// Base-colour image for the source's UVs, replacing its material's texture (use it
    /// for an OBJ with UVs but no MTL file).
    #[arg(long)]
    source_texture: Option<PathBuf>,
    /// Target mesh (any format the readers take).
    #[arg(long)]
    target: PathBuf,
    /// Output directory: model.glb, preview.png, report.json (+ guidance.ply with --keep).
    #[arg(long)]
    out: PathBuf,
    /// Mask image of the source texture's size; white texels are ignored.
    #[arg(long)]
    mask: Option<PathBuf>,
    /// Up axis for the height descriptor: x, y or z.
    #[arg(long, default_value = "y")]
    up: String,
    /// Dimensionality reduction: cca-weighted (default; canonical variates weighted by
    /// their correlations, the paper's √Λ Wₓᵀx), cca (unit-variance variates) or pca
    /// (ablation).
    #[arg(long, default_value = "cca-weighted")]
    reduce: String,
    /// Feature matching: none, marginals or multiscale.
    #[arg(long = "match", default_value = "multiscale")]
    matching: String,
    /// Synthesis engine: parametric (constrained Heeger–Bergen) or nonparametric (image
    /// analogies with Ashikhmin coherence).
    #[arg(long, default_value = "parametric")]
    engine: String,
    /// Non-parametric engine: Ashikhmin coherence parameter κ (0 = best match only).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    coherence: f64,
    /// Non-parametric engine: side of the tangent-plane neighbourhood (odd).
    #[arg(long, default_value_t = 5)]
    neighbourhood: usize,
    /// Surface samples at the finest level on each mesh.
    #[arg(long, default_value_t = 512_000)]
    samples: usize,
    /// Samples on which the ray-cast descriptors are computed (then interpolated), 256 to
    /// 8000000.
    #[arg(long, default_value_t = 32_768)]
    descriptor_samples: usize,
    /// k-means clusters of the parametric engine.
    #[arg(long, default_value_t = 50)]
    clusters: usize,
    /// Atlas texture size in texels.
    #[arg(long, default_value_t = 1024)]
    size: usize,
    /// Also write guidance.ply (per-vertex descriptors, guidance and colour of the target).
    #[arg(long)]
    keep: bool,
}

fn bad(flag: &str, value: &str, allowed: &str) -> Error {
    Error::bad_input(None, format!("--{flag} {value:?}: expected one of {allowed}"))
}

/// Runs the command.
/// Refuses out-of-range numbers naming the flag, whatever the engine (the library checks
/// the same ranges but names its option fields, and the non-parametric engine's only when
/// that engine runs, so `--coherence NaN` passed silently with the default engine).
fn check_ranges(a: &TransferArgs) -> Result<(), Error> {
    let bad = |m: String| Err(Error::bad_input(None, m));
    if !(256..=8_000_000).contains(&a.samples) {
        return bad(format!("--samples must be in 256..=8000000, got {}", a.samples));
    }
    // Fewer descriptor samples ran (0 and 1 exited 0) with every ray-cast descriptor
    // interpolated from a handful of points.
    if !(256..=8_000_000).contains(&a.descriptor_samples) {
        return bad(format!(
            "--descriptor-samples must be in 256..=8000000, got {}",
            a.descriptor_samples
        ));
    }
    if a.clusters == 0 {
        return bad("--clusters must be at least 1".into());
    }
    if !(a.coherence.is_finite() && a.coherence >= 0.0) {
        return bad(format!("--coherence must be finite and ≥ 0, got {:?}", a.coherence));
    }
    if a.neighbourhood.is_multiple_of(2) || !(1..=9).contains(&a.neighbourhood) {
        return bad(format!("--neighbourhood must be odd, 1 to 9, got {}", a.neighbourhood));
    }
    Ok(())
}

pub fn run(
    args: TransferArgs,
    g: &GlobalArgs,
    progress: &dyn fieldtex::Progress,
) -> Result<(), Error> {
    check_ranges(&args)?;
    let mut opts = fieldtex::TransferCommandOptions {
        source: args.source,
        source_texture: args.source_texture,
        target: args.target,
        mask: args.mask,
        size: args.size,
        keep: args.keep,
        ..Default::default()
    };
    let tr = &mut opts.transfer;
    tr.descriptors.up = t::parse_up_axis(&args.up).ok_or_else(|| bad("up", &args.up, "x, y, z"))?;
    tr.reduction = t::parse_reduction(&args.reduce)
        .ok_or_else(|| bad("reduce", &args.reduce, "cca, cca-weighted, pca"))?;
    tr.matching = t::parse_match_mode(&args.matching)
        .ok_or_else(|| bad("match", &args.matching, "none, marginals, multiscale"))?;
    tr.engine = t::parse_engine(&args.engine)
        .ok_or_else(|| bad("engine", &args.engine, "parametric, nonparametric"))?;
    tr.samples = args.samples;
    tr.descriptors.samples = args.descriptor_samples;
    tr.parametric.clusters = args.clusters;
    tr.nonparametric.coherence = args.coherence;
    tr.nonparametric.neighbourhood = args.neighbourhood;
    tr.seed = g.seed;
    let report = fieldtex::transfer_files(&args.out, &opts, progress)?;
    if !g.quiet {
        for w in &report.warnings {
            eprintln!("warning: {w}");
        }
        println!("wrote {}/{{model.glb,preview.png,report.json}}", args.out.display());
    }
    Ok(())
}
