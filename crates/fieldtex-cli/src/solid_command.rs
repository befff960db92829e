//! `fieldtex solid`: flags → [`fieldtex::SolidOptions`].

use clap::Args;
use fieldtex::Error;
use std::path::PathBuf;

/// Sketch-guided solid texturing (paper E): a 3-D frame field from sketched curves,
/// solid texture synthesised from 2-D exemplars on demand.
#[derive(Args, Debug)]
pub struct SolidArgs {
    /// Input mesh (.obj, .ply, .stl, .glb/.gltf).
    #[arg(long)]
    mesh: PathBuf,
    /// Sketch curves as JSON (schema in docs/solid.md); without it the field is constant.
    #[arg(long)]
    sketch: Option<PathBuf>,
    /// Exemplar for the three planes (xy, yz, zx of the local frame).
    #[arg(long)]
    exemplar: Option<PathBuf>,
    /// Exemplar of the local xy plane (overrides --exemplar there).
    #[arg(long)]
    exemplar_xy: Option<PathBuf>,
    /// Exemplar of the local yz plane.
    #[arg(long)]
    exemplar_yz: Option<PathBuf>,
    /// Exemplar of the local zx plane.
    #[arg(long)]
    exemplar_zx: Option<PathBuf>,
    /// Feature mask for regular exemplars such as bricks (paper E §4): a grey image
    /// the size of the exemplar, white on the feature curves (mortar lines), black
    /// elsewhere. It is matched as a fourth channel beside RGB (neighbourhoods, triple
    /// search, correction) so the features stay connected; it is never shown. Used for
    /// every plane (transposed for yz with a single --exemplar).
    #[arg(long)]
    feature_mask: Option<PathBuf>,
    /// Weight of the feature mask against the colour channels.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    feature_weight: f32,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
    /// Voxels along the bounding box's longest side (cubic voxels).
    #[arg(long, default_value_t = 256)]
    resolution: usize,
    /// Cut plane X,Y,Z,NX,NY,NZ (repeatable): writes cut-N.glb and cut-N.png.
    #[arg(
        long = "cut",
        value_name = "X,Y,Z,NX,NY,NZ",
        value_parser = parse_cut,
        allow_hyphen_values = true
    )]
    cuts: Vec<[f64; 6]>,
    /// Also write the whole grid as volume.nrrd.
    #[arg(long)]
    volume: bool,
    /// Also write frames.ply (the coarse frame field).
    #[arg(long)]
    keep: bool,
    /// Atlas size of the textured meshes, texels.
    #[arg(long, default_value_t = 1024)]
    atlas_size: usize,
    /// Frame-field cells along the bounding box's shortest side.
    #[arg(long, default_value_t = 20)]
    field_cells: usize,
    /// Correction passes per level (half primary grid, half dual grid).
    #[arg(long, default_value_t = 2)]
    passes: usize,
    /// Correction passes per level, finest first (e.g. 2,4,4,4,4), overriding
    /// --passes (and the coarsest level's 4) on the levels listed.
    #[arg(long, value_delimiter = ',')]
    level_passes: Vec<usize>,
    /// Block side M of the dual-grid correction.
    #[arg(long, default_value_t = 12)]
    block: usize,
    /// Neighbourhood side N of the matching (odd; the paper uses 7 and 9).
    #[arg(long, default_value_t = 5)]
    neighbourhood: usize,
    /// Coarsest levels whose correction samples neighbourhoods trilinearly (the finer
    /// ones take the nearest voxel).
    #[arg(long, default_value_t = 3)]
    trilinear_levels: usize,
    /// Coarsest levels whose correction integrates the neighbourhood sample positions
    /// along the field (paper E §4.3); the finer ones span it with the voxel's frame.
    #[arg(long, default_value_t = 2)]
    integrate_levels: usize,
    /// Carry the exemplar along the sketched field (least-squares integral of its
    /// frames) and leave it uncorrected, reading colours between pixels where the warp
    /// falls: layers such as stripes or wood rings then follow the sketch smoothly and
    /// without breaks (a substitute for the synthesis, not paper E's method;
    /// --level-passes adds corrections, read at whole pixels). The default synthesis
    /// suits irregular exemplars (stone, marble) better: this start repeats the
    /// exemplar along the warp and shows a cropped exemplar's borders.
    #[arg(long)]
    integrated_init: bool,
    /// Synthesis levels.
    #[arg(long, default_value_t = 5)]
    levels: usize,
    /// Exemplar of the interior region (e.g. wood inside bark): voxels deeper than
    /// --interior-depth below the surface use it, blended across a thin band.
    #[arg(long)]
    interior: Option<PathBuf>,
    /// Depth of the interior region below the surface, mesh units (default: 15 % of the
    /// bounding box's shortest side).
    #[arg(long, allow_negative_numbers = true)]
    interior_depth: Option<f64>,
}

fn parse_cut(s: &str) -> Result<[f64; 6], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().map_err(|e| format!("{t:?}: {e}")))
        .collect::<Result<_, _>>()?;
    if v.len() != 6 || v.iter().any(|x| !x.is_finite()) {
        return Err(format!("expected X,Y,Z,NX,NY,NZ (six finite numbers), got {s:?}"));
    }
    if v[3] == 0.0 && v[4] == 0.0 && v[5] == 0.0 {
        return Err("the cut normal NX,NY,NZ must not be zero".into());
    }
    Ok([v[0], v[1], v[2], v[3], v[4], v[5]])
}

/// Refuses out-of-range flags before any input is read, naming the flag (the library's
/// own checks name its option fields and some run only after the frame field is
/// solved). The ranges are the synthesiser's (`SolidAnalysisOptions`,
/// `SolidSynthesisOptions`) and the atlas's; `--feature-weight` is also bounded above
/// (1000: the mask alone decides far below it; larger squared distances lose the
/// colour channels' precision in `f32`).
fn check_ranges(a: &SolidArgs) -> Result<(), Error> {
    let bad = |m: String| Err(Error::bad_input(None, m));
    if let Some(d) = a.interior_depth
        && !(d.is_finite() && d > 0.0)
    {
        return bad(format!(
            "--interior-depth must be a positive distance in mesh units, got {d:?}"
        ));
    }
    if !(8..=16384).contains(&a.atlas_size) {
        return bad(format!("--atlas-size must be in 8..=16384 texels, got {}", a.atlas_size));
    }
    if !(1..=8).contains(&a.levels) {
        return bad(format!("--levels must be in 1..=8, got {}", a.levels));
    }
    if !(3..=15).contains(&a.neighbourhood) || a.neighbourhood.is_multiple_of(2) {
        return bad(format!("--neighbourhood must be odd, 3 to 15, got {}", a.neighbourhood));
    }
    let fw = a.feature_weight;
    if !(fw.is_finite() && (0.0..=1000.0).contains(&fw)) {
        return bad(format!("--feature-weight must be in [0, 1000], got {fw:?}"));
    }
    if !(4..=64).contains(&a.block) {
        return bad(format!("--block must be in 4..=64, got {}", a.block));
    }
    if a.passes > 16 {
        return bad(format!("--passes must be at most 16, got {}", a.passes));
    }
    if let Some(p) = a.level_passes.iter().find(|&&p| p > 32) {
        return bad(format!("--level-passes must be at most 32 per level, got {p}"));
    }
    Ok(())
}

/// Runs the command; returns the output directory for the summary line.
pub fn run_solid(
    a: SolidArgs,
    seed: u64,
    progress: &dyn fieldtex::Progress,
) -> Result<fieldtex::Report, Error> {
    check_ranges(&a)?;
    let mut opts = fieldtex::SolidOptions {
        mesh: a.mesh,
        sketch: a.sketch,
        exemplar: a.exemplar,
        exemplar_xy: a.exemplar_xy,
        exemplar_yz: a.exemplar_yz,
        exemplar_zx: a.exemplar_zx,
        feature_mask: a.feature_mask,
        resolution: a.resolution,
        cuts: a.cuts,
        volume: a.volume,
        keep: a.keep,
        interior: a.interior,
        interior_depth: a.interior_depth.unwrap_or(0.0),
        atlas_size: a.atlas_size,
        field_cells: a.field_cells,
        seed,
        ..Default::default()
    };
    opts.synthesis.passes = a.passes;
    opts.synthesis.level_passes = a.level_passes;
    opts.synthesis.block = a.block;
    opts.synthesis.seed = seed;
    opts.synthesis.trilinear_levels = a.trilinear_levels;
    opts.synthesis.integrate_levels = a.integrate_levels;
    opts.synthesis.integrated_init = a.integrated_init;
    opts.analysis.levels = a.levels;
    opts.analysis.neighbourhood = a.neighbourhood;
    opts.analysis.feature_weight = a.feature_weight;
    fieldtex::solid(&a.out, &opts, progress)
}

/// The output directory of `a` (read before `run_solid` consumes the arguments).
pub fn out_dir(a: &SolidArgs) -> PathBuf {
    a.out.clone()
}
