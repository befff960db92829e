//! `fieldtex conformal`: flags → [`fieldtex::ConformalOptions`].

use clap::Args;
use fieldtex::Error;
use std::path::PathBuf;

/// Uniform texture synthesis on a global conformal parameterisation (paper C).
#[derive(Args, Debug)]
pub struct ConformalArgs {
    /// Input mesh (.obj, .ply, .stl, .glb/.gltf); repaired first, each component mapped
    /// on its own.
    #[arg(long)]
    mesh: PathBuf,
    /// Exemplar image (PNG or JPEG), at least one quilting patch on each side.
    #[arg(long)]
    exemplar: PathBuf,
    /// Output directory (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Long side of each geometry image in texels.
    #[arg(long, default_value_t = 1024)]
    size: usize,
    /// Mass-spring relaxation towards an isometry before synthesis (paper §5).
    #[arg(long)]
    quasi_isometric: bool,
    /// Ablation: one exemplar scale everywhere (paper Fig. 1a/b).
    #[arg(long)]
    no_multiscale: bool,
    /// Genus 0: always the two-point slit cylinder, without slits at protrusion tips
    /// (legs, ears) and the double cover that keeps them from shrinking.
    #[arg(long)]
    no_protrusion_slits: bool,
    /// Keep the integrated holomorphic map as it is: no per-chart least squares
    /// conformal polish (which lowers its angle distortion on coarse meshes).
    #[arg(long)]
    no_polish: bool,
    /// Leave the colour steps the margin copy makes at patch cuts as they are (by
    /// default the texels on the two sides of a cut meet halfway, faded over 4 texels).
    #[arg(long)]
    no_seam_feather: bool,
    /// Split every triangle into four (same surface) where the mesh is too coarse for a
    /// conformal map: `auto` refines while the map's mean angle distortion (σ1/σ2, away
    /// from zero points and slits) is above 1.04, up to 2 levels and 160K triangles;
    /// `0` keeps the input's triangles; `1`–`3` refine that many times. The refined mesh
    /// is what model.glb holds.
    #[arg(long, default_value = "auto")]
    refine: fieldtex::Refine,
    /// Number of exemplar scale levels.
    #[arg(long, default_value_t = 6)]
    levels: usize,
    /// Exemplar pixels per texture texel at the reference conformal factor, 1/64 to 16.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    scale: f64,
    /// Quilting patch side in texels (paper: 30–50).
    #[arg(long, default_value_t = 40)]
    patch_size: usize,
    /// Also write patches.ply, trajectories.obj, geometry images and τ maps.
    #[arg(long)]
    keep: bool,
}

/// Runs the command.
pub fn run(
    args: ConformalArgs,
    seed: u64,
    quiet: bool,
    progress: &dyn fieldtex::Progress,
) -> Result<(), Error> {
    let opts = fieldtex::ConformalOptions {
        mesh: args.mesh,
        exemplar: args.exemplar,
        size: args.size,
        quasi_isometric: args.quasi_isometric,
        multiscale: !args.no_multiscale,
        protrusion_slits: !args.no_protrusion_slits,
        polish: !args.no_polish,
        seam_feather: !args.no_seam_feather,
        refine: args.refine,
        levels: args.levels,
        scale: args.scale,
        patch_size: args.patch_size,
        keep: args.keep,
        seed,
    };
    let report = fieldtex::conformal(&opts, &args.out, progress)?;
    crate::print_warnings(&report.warnings, quiet);
    if !quiet {
        eprintln!("wrote {}/{{model.glb,preview.png,report.json}}", args.out.display());
    }
    Ok(())
}
