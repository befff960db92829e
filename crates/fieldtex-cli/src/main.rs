//! `fieldtex`: the command-line front end. Glue only: parse flags into options, call
//! the library, print a summary, map errors to exit codes (0 ok, 1 internal, 2 bad
//! input or usage).

mod conformal_command;
mod progress_bar;
mod solid_command;
mod studio_command;
mod transfer_command;

use clap::{Args, Parser, Subcommand};
use fieldtex::Error;
use progress_bar::TerminalProgress;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(name = "fieldtex", version, about = "Texture 3D shapes so the texture follows the shape")]
struct Cli {
    #[command(flatten)]
    global: GlobalArgs,
    #[command(subcommand)]
    command: Command,
}

#[derive(Args, Debug, Clone)]
struct GlobalArgs {
    /// Random seed; the same inputs, options and seed give byte-identical outputs.
    #[arg(long, global = true, default_value_t = 1)]
    seed: u64,
    /// Worker threads, 1 to 256 (default: all cores). Output does not depend on it.
    #[arg(long, global = true)]
    threads: Option<usize>,
    /// No progress bars or summaries (errors are still printed).
    #[arg(long, global = true)]
    quiet: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Local web studio: design orientation fields interactively (http://127.0.0.1:7878).
    Studio(studio_command::StudioArgs),
    /// Run the main job on built-in inputs (no files needed): procedural stripes aligned
    /// to the creases of a cube (`align`), and the whorl preset of `orient` beside it.
    Demo {
        /// Output directory (created if missing): model.glb, preview.png, orient.png,
        /// report.json.
        #[arg(long)]
        out: PathBuf,
        /// Texture resolution of the cube's atlas, 64 to 2048.
        #[arg(long, default_value_t = 256)]
        size: usize,
    },
    /// Print counts, topology and defects of a mesh.
    Inspect {
        /// Mesh file: OBJ, PLY, STL, glTF or GLB (format read from the content).
        mesh: PathBuf,
        /// Print the full report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Weld, drop degenerate and unreferenced elements, fix orientation, split
    /// non-manifold vertices; lists every change.
    Repair {
        /// Mesh file: OBJ, PLY, STL, glTF or GLB.
        mesh: PathBuf,
        /// Output mesh (.obj, .ply or .glb); never the input file.
        #[arg(long)]
        out: PathBuf,
        /// Weld vertices closer than this fraction of the bounding-box diagonal
        /// (0 = only identical positions).
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        weld_epsilon: f64,
        /// Print the repair report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Segment into charts, flatten, pack; writes model.glb, preview.png, report.json.
    Atlas {
        /// Mesh file: OBJ, PLY, STL, glTF or GLB.
        mesh: PathBuf,
        /// Output directory (created if missing); never a folder's input files.
        #[arg(long)]
        out: PathBuf,
        /// Atlas resolution in texels (square).
        #[arg(long, default_value_t = 1024)]
        size: usize,
        /// Gutter between charts in texels.
        #[arg(long, default_value_t = 4)]
        gutter: usize,
    },
    /// Orientation-field guided synthesis (paper D): a design file, a fingerprint preset
    /// or an external field steers the exemplar's x axis.
    Orient {
        /// TOML design file (singularities, strokes, weights).
        #[arg(long, group = "source")]
        design: Option<PathBuf>,
        /// Fingerprint preset: arch, tented-arch, left-loop, right-loop, whorl.
        #[arg(long, group = "source")]
        preset: Option<String>,
        /// External field .npy (H×W×2 float32 (dx, dy), x right, y down).
        #[arg(long, group = "source")]
        field: Option<PathBuf>,
        /// Exemplar image: PNG, JPEG, TGA, BMP, TIFF or PNM (8/16-bit, grey/RGB/RGBA);
        /// above 2048 pixels per side it is reduced (with a warning) and the pattern keeps
        /// its size.
        #[arg(long)]
        exemplar: PathBuf,
        /// Output size in pixels (square).
        #[arg(long, default_value_t = 512)]
        size: usize,
        /// Field grid cells per side (presets).
        #[arg(long, default_value_t = 128)]
        grid: usize,
        /// Pattern size: output pixels per pixel of the exemplar file (2 = the pattern
        /// twice as large; the same meaning in align and orient), 1/64 to 16.
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        scale: f64,
        /// Disable the 2-RoSy fix of paper D §4 (ablation).
        #[arg(long)]
        no_rosy_fix: bool,
        /// Start from the exemplar carried along the field (least-squares integral of the
        /// field's frames) instead of random patches: stripes and weaves then flow
        /// without stripe endings on designs without singularities (e.g. the arch
        /// preset); near singularities, and with irregular exemplars (wood, stone), the
        /// default start is better.
        #[arg(long)]
        integrated_init: bool,
        /// Skip the image metrics of report.json (coherence, orientation error, defects);
        /// timings and the designed singularities are kept.
        #[arg(long)]
        no_metrics: bool,
        /// Exhaustive nearest-patch searches in the metrics (coherence, completeness,
        /// guided coherence) instead of the default approximate ones (PCA + kd-tree,
        /// within a few per cent; see docs/first-hour.md); tens of seconds at 512².
        #[arg(long)]
        exact_metrics: bool,
        /// Also the search-based completeness (nearest output patch of every exemplar
        /// patch) beside the default source coverage read from the synthesis's own
        /// exemplar coordinates (no search; see docs/first-hour.md). Implied by
        /// --exact-metrics and by --mesh.
        #[arg(long)]
        search_completeness: bool,
        /// Mesh file (OBJ, PLY, STL, glTF/GLB) of a disk-topology patch; default: the
        /// plane. Parameterise it (LSCM), design the field on it and
        /// synthesise in parameter space; also writes model.glb. Plane designs and
        /// presets are laid on the patch's UV bounding box.
        #[arg(long)]
        mesh: Option<PathBuf>,
        /// With --mesh: texture only the connected region within radius R of the point
        /// (X, Y, Z), e.g. to cut a disk out of a closed mesh.
        #[arg(long, value_name = "X,Y,Z,R", value_delimiter = ',', allow_hyphen_values = true)]
        patch: Option<Vec<f64>>,
        /// Output directory (created if missing): texture.png, field.npy, preview.png,
        /// report.json, and coords.npy (each pixel's exemplar coordinate, for
        /// `eval --coords`) on the plane or model.glb with --mesh.
        #[arg(long)]
        out: PathBuf,
    },
    /// Crest lines (ridges, valleys) and salient creases as OBJ polylines (paper A).
    Crest {
        /// Mesh file: OBJ, PLY, STL, glTF or GLB.
        mesh: PathBuf,
        /// Output OBJ with `l` polylines.
        #[arg(long)]
        out: PathBuf,
        /// Ascending strength thresholds (comma-separated), one level of detail each; a
        /// line's strength is ∫|k| ds along it (unitless, scale-invariant). Lines below
        /// the first are dropped. Default: the detector's own thresholds, 3,9,27.
        #[arg(long, value_delimiter = ',', value_name = "T1,T2,...")]
        levels: Option<Vec<f64>>,
        /// Keep only lines of this level and above.
        #[arg(long, default_value_t = 0)]
        level: usize,
        /// Also render the mesh with the lines drawn (red ridges, blue valleys) to this
        /// PNG; never one of the inputs.
        #[arg(long)]
        preview: Option<PathBuf>,
    },
    /// A tangent field following oriented feature curves (paper A §4); writes a PLY with
    /// per-vertex `x y z nx ny nz fx fy fz`.
    Field {
        /// Mesh file: OBJ, PLY, STL, glTF or GLB.
        mesh: PathBuf,
        /// OBJ polylines (`l` elements); default: detected crest lines.
        #[arg(long)]
        curves: Option<PathBuf>,
        /// Curve orientation: greedy (paper A §4.1) or arbitrary (random, from --seed).
        #[arg(long, default_value = "greedy", value_parser = ["greedy", "arbitrary"])]
        orient: String,
        /// Output PLY (per-vertex x y z nx ny nz fx fy fz).
        #[arg(long)]
        out: PathBuf,
    },
    /// Uniform texture synthesis on a global conformal parameterisation (paper C):
    /// conformal geometry images, multi-scale quilting; writes model.glb, preview.png,
    /// report.json (and patches.ply, trajectories.obj, images with --keep).
    Conformal(conformal_command::ConformalArgs),
    /// Feature-aligned texturing (paper A): crest lines or given curves, an oriented
    /// field, texture optimisation on the surface with feature-to-feature alignment;
    /// writes model.glb, preview.png, report.json (and curves.obj, field.ply with --keep).
    Align {
        /// Mesh file: OBJ, PLY, STL, glTF or GLB.
        #[arg(long)]
        mesh: PathBuf,
        /// Exemplar image: PNG, JPEG, TGA, BMP, TIFF or PNM (8/16-bit, grey/RGB/RGBA);
        /// above 2048 pixels per side it is reduced (with a warning) and the pattern keeps
        /// its size.
        #[arg(long)]
        exemplar: PathBuf,
        /// OBJ polylines (`l` elements) to align to; default: detected crest lines.
        #[arg(long)]
        curves: Option<PathBuf>,
        /// Exemplar feature lines as OBJ polylines in pixel coordinates (x right, y down);
        /// default: detected from the exemplar.
        #[arg(long)]
        exemplar_lines: Option<PathBuf>,
        /// Atlas texture size in texels (square).
        #[arg(long, default_value_t = 1024)]
        size: usize,
        /// Pattern size: output texels per pixel of the exemplar file (2 = the pattern
        /// twice as large; the same meaning in align and orient).
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        scale: f64,
        /// Where no feature curve constrains the field: follow this global direction
        /// projected onto the surface (default: the smoothest field, along curvature
        /// where it is clearly anisotropic).
        #[arg(long, value_name = "X,Y,Z", value_delimiter = ',', allow_negative_numbers = true)]
        direction: Option<Vec<f64>>,
        /// Ablation: no feature-to-feature alignment (paper A §5.2).
        #[arg(long)]
        no_feature_align: bool,
        /// Curve orientation: greedy (paper A §4.1) or arbitrary (random, from --seed).
        #[arg(long, default_value = "greedy", value_parser = ["greedy", "arbitrary"])]
        orient: String,
        /// Also write curves.obj and field.ply.
        #[arg(long)]
        keep: bool,
        /// Draw the curves on preview.png.
        #[arg(long)]
        draw_curves: bool,
        /// Output directory (created if missing): model.glb, preview.png, report.json.
        #[arg(long)]
        out: PathBuf,
    },
    /// Render a shaded preview of a mesh (textured when it has a texture).
    Render {
        /// Mesh file (OBJ, PLY, STL, glTF or GLB), textured when it has a texture.
        model: PathBuf,
        /// Output image: .png, .jpg or .jpeg (format from the extension).
        #[arg(long)]
        out: PathBuf,
        /// Image size in pixels (square).
        #[arg(long, default_value_t = 800)]
        size: usize,
        /// View direction as "azimuth,elevation" in degrees.
        #[arg(long, value_parser = parse_view)]
        view: Option<(f64, f64)>,
    },
    /// Texture transfer by geometry correlation (paper B).
    Transfer(transfer_command::TransferArgs),
    /// Sketch-guided solid texturing (paper E): model.glb, preview.png, report.json,
    /// cut-N.glb/png, volume.nrrd.
    Solid(solid_command::SolidArgs),
    /// Quality metrics of a synthesised image against its exemplar (DESIGN.md §6).
    Eval {
        /// The synthesised image (image metrics, with --exemplar).
        #[arg(required_unless_present = "mesh")]
        image: Option<PathBuf>,
        /// The exemplar it was made from.
        #[arg(long, required_unless_present = "mesh")]
        exemplar: Option<PathBuf>,
        /// A textured mesh (GLB, glTF or OBJ+MTL) to compare with --reference: transfer
        /// fidelity, the correlation of the two colourings at the same surface points.
        #[arg(long, requires = "reference", conflicts_with_all = ["image", "exemplar"])]
        mesh: Option<PathBuf>,
        /// The reference texturing of the same surface (with --mesh).
        #[arg(long, requires = "mesh")]
        reference: Option<PathBuf>,
        /// Surface samples for --mesh/--reference, 256 to 8000000.
        #[arg(long, default_value_t = 100_000)]
        samples: usize,
        /// Guidance field as .npy (H×W×2 float32 unit (dx, dy), x right, y down).
        #[arg(long, conflicts_with = "angle")]
        field: Option<PathBuf>,
        /// Constant guidance direction in degrees (counter-clockwise from +x on screen).
        #[arg(long)]
        angle: Option<f64>,
        /// The image's exemplar-coordinate map (orient's coords.npy, with --field): adds
        /// `rosy_seam`, the coherent share of neighbour pairs across the field's 2-RoSy
        /// representation jumps against the image-wide share.
        #[arg(long, requires = "field")]
        coords: Option<PathBuf>,
        /// With --coords: the pattern size the image was made with (orient's --scale).
        #[arg(long, default_value_t = 1.0, requires = "coords", allow_negative_numbers = true)]
        scale: f64,
        /// Exhaustive nearest-patch searches instead of the default approximate ones
        /// (PCA + kd-tree, within a few per cent; see docs/first-hour.md); minutes at
        /// 1024².
        #[arg(long)]
        exact_metrics: bool,
        /// Write the metrics JSON here as well as printing it.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// Largest accepted `--threads`.
const MAX_THREADS: usize = 256;

/// Prints a line to stdout; a closed pipe (`fieldtex inspect M --json | head -1`) ends
/// the output quietly instead of panicking.
/// With `--json` the pretty JSON that `pretty` makes, else the summary lines.
fn print_json_or_lines(
    json: bool,
    pretty: impl FnOnce() -> serde_json::Result<String>,
    lines: Vec<String>,
) {
    if json {
        print_stdout(&pretty().unwrap_or_default());
    } else {
        for line in lines {
            print_stdout(&line);
        }
    }
}

fn print_stdout(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{text}").and_then(|()| out.flush());
}

fn parse_view(s: &str) -> Result<(f64, f64), String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 2 {
        return Err(format!("expected \"azimuth,elevation\" in degrees, got {s:?}"));
    }
    let a = parts[0].trim().parse::<f64>().map_err(|e| format!("azimuth {:?}: {e}", parts[0]))?;
    let e = parts[1].trim().parse::<f64>().map_err(|e| format!("elevation {:?}: {e}", parts[1]))?;
    if !a.is_finite() || !e.is_finite() || e.abs() > 90.0 {
        return Err("azimuth must be finite and elevation within [-90, 90]".into());
    }
    Ok((a, e))
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    if let Some(n) = cli.global.threads {
        // Regression: --threads 100000 hung or aborted while spawning threads.
        if n == 0 || n > MAX_THREADS {
            eprintln!(
                "error: --threads must be in 1..={MAX_THREADS}, got {n} (leave it out to use all \
                 cores)"
            );
            return ExitCode::from(2);
        }
        if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n).build_global() {
            eprintln!("error: could not start {n} worker threads: {e}");
            return ExitCode::from(1);
        }
    }
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

fn run(cli: Cli) -> Result<(), Error> {
    let g = cli.global;
    let progress = TerminalProgress::new(g.quiet);
    let say = |s: &str| {
        if !g.quiet {
            eprintln!("{s}");
        }
    };
    match cli.command {
        Command::Studio(a) => studio_command::run(a, g.seed, g.quiet)?,
        Command::Demo { out, size } => {
            let opts = fieldtex::DemoOptions { seed: g.seed, size, ..Default::default() };
            let report = fieldtex::demo(&out, &opts, &progress)?;
            print_warnings(&report.warnings, g.quiet);
            say(&format!(
                "wrote {}/model.glb, preview.png, orient.png, report.json",
                out.display()
            ));
        }
        Command::Inspect { mesh, json } => {
            let (report, warnings) = fieldtex::inspect_file(&mesh)?;
            print_warnings(&warnings, g.quiet);
            print_json_or_lines(
                json,
                || serde_json::to_string_pretty(&report),
                report.summary_lines(),
            );
        }
        Command::Repair { mesh, out, weld_epsilon, json } => {
            let opts = fieldtex::RepairCommandOptions { weld_epsilon };
            let summary = fieldtex::repair_file(&mesh, &out, &opts)?;
            print_json_or_lines(json, || serde_json::to_string_pretty(&summary), summary.lines());
        }
        Command::Atlas { mesh, out, size, gutter } => {
            let opts = fieldtex::AtlasCommandOptions { size, gutter, seed: g.seed };
            let report = fieldtex::atlas_file(&mesh, &out, &opts, &progress)?;
            print_warnings(&report.warnings, g.quiet);
            say(&format!("wrote {}/model.glb, preview.png, report.json", out.display()));
            if !g.quiet {
                print_stdout(&serde_json::to_string_pretty(&report.metrics).unwrap_or_default());
            }
        }
        Command::Orient {
            design,
            preset,
            field,
            exemplar,
            size,
            grid,
            scale,
            no_rosy_fix,
            integrated_init,
            no_metrics,
            exact_metrics,
            search_completeness,
            mesh,
            patch,
            out,
        } => {
            let source = match (design, preset, field) {
                (Some(d), _, _) => fieldtex::FieldSource::Design(d),
                (None, Some(p), _) => fieldtex::FieldSource::Preset(p),
                (None, None, Some(f)) => fieldtex::FieldSource::Field(f),
                (None, None, None) => {
                    return Err(Error::bad_input(
                        None,
                        "orient needs one of --design FILE, --preset NAME or --field F.npy",
                    ));
                }
            };
            let mut opts = fieldtex::OrientOptions::new(source, exemplar);
            opts.size = size;
            opts.grid = grid;
            opts.scale = scale;
            opts.rosy_fix = !no_rosy_fix;
            opts.integrated_init = integrated_init;
            opts.metrics = !no_metrics;
            opts.exact_metrics = exact_metrics;
            opts.search_completeness = search_completeness;
            opts.seed = g.seed;
            let model = if mesh.is_some() { "model.glb, " } else { "coords.npy, " };
            opts.mesh = mesh;
            opts.patch = match patch.as_deref() {
                None => None,
                Some(&[x, y, z, r]) => Some([x, y, z, r]),
                Some(v) => {
                    return Err(Error::bad_input(
                        None,
                        format!("--patch needs four numbers X,Y,Z,R; got {}", v.len()),
                    ));
                }
            };
            let report = fieldtex::orient(&out, &opts, &progress)?;
            print_warnings(&report.warnings, g.quiet);
            say(&format!(
                "wrote {}/{model}texture.png, field.npy, preview.png, report.json",
                out.display()
            ));
        }
        Command::Crest { mesh, out, levels, level, preview } => {
            let opts = fieldtex::CrestCommandOptions { levels, min_level: level, preview };
            let summary = fieldtex::crest_file(&mesh, &out, &opts)?;
            // The warnings are in the printed summary; printing them again doubled them.
            print_stdout(&serde_json::to_string_pretty(&summary).unwrap_or_default());
        }
        Command::Field { mesh, curves, orient, out } => {
            let opts =
                fieldtex::FieldCommandOptions { curves, greedy: orient == "greedy", seed: g.seed };
            let summary = fieldtex::field_file(&mesh, &out, &opts, &progress)?;
            // The warnings are in the printed summary (not printed twice).
            print_stdout(&serde_json::to_string_pretty(&summary).unwrap_or_default());
        }
        Command::Align {
            mesh,
            exemplar,
            curves,
            exemplar_lines,
            size,
            scale,
            direction,
            no_feature_align,
            orient,
            keep,
            draw_curves,
            out,
        } => {
            let direction = match direction.as_deref() {
                None => None,
                Some(&[x, y, z]) => Some([x, y, z]),
                Some(v) => {
                    return Err(Error::bad_input(
                        None,
                        format!("--direction needs three numbers X,Y,Z; got {}", v.len()),
                    ));
                }
            };
            let opts = fieldtex::AlignOptions {
                mesh,
                exemplar,
                curves,
                exemplar_lines,
                size,
                scale,
                direction,
                feature_align: !no_feature_align,
                greedy: orient == "greedy",
                keep,
                draw_curves,
                seed: g.seed,
            };
            let report = fieldtex::align(&out, &opts, &progress)?;
            print_warnings(&report.warnings, g.quiet);
            say(&format!("wrote {}/{{model.glb,preview.png,report.json}}", out.display()));
        }
        Command::Conformal(args) => conformal_command::run(args, g.seed, g.quiet, &progress)?,
        Command::Transfer(args) => transfer_command::run(args, &g, &progress)?,
        Command::Solid(a) => {
            let out = solid_command::out_dir(&a);
            let report = solid_command::run_solid(a, g.seed, &progress)?;
            print_warnings(&report.warnings, g.quiet);
            say(&format!("wrote {}/{{model.glb,preview.png,report.json}}", out.display()));
        }
        Command::Render { model, out, size, view } => {
            let opts = fieldtex::RenderCommandOptions { size, view };
            fieldtex::render_file(&model, &out, &opts)?;
            say(&format!("wrote {}", out.display()));
        }
        Command::Eval { mesh: Some(mesh), reference: Some(reference), samples, out, .. } => {
            let fidelity = fieldtex::transfer_fidelity_files(&mesh, &reference, samples, g.seed)?;
            let text = serde_json::to_string_pretty(&fidelity).unwrap_or_default();
            if let Some(o) = out {
                fieldtex::write_text(&o, &text)?;
            }
            print_stdout(&text);
        }
        Command::Eval {
            image, exemplar, field, angle, coords, scale, exact_metrics, out, ..
        } => {
            let (Some(image), Some(exemplar)) = (image, exemplar) else {
                return Err(Error::bad_input(
                    None,
                    "eval needs IMAGE and --exemplar, or --mesh and --reference",
                ));
            };
            let guide = match (field, angle) {
                (Some(f), _) => Some(fieldtex::Guidance::FieldFile(f)),
                (None, Some(a)) => Some(fieldtex::Guidance::Angle(a)),
                (None, None) => None,
            };
            let seam = coords.map(|path| fieldtex::SeamCoordinates { path, scale });
            let metrics = fieldtex::eval_files(
                &image,
                &exemplar,
                guide.as_ref(),
                seam.as_ref(),
                g.seed,
                exact_metrics,
                &progress,
            )?;
            let text = serde_json::to_string_pretty(&metrics).unwrap_or_default();
            if let Some(o) = out {
                fieldtex::write_text(&o, &text)?;
            }
            print_stdout(&text);
        }
    }
    Ok(())
}

/// Prints each warning once, in its own words (the message, not the library's code);
/// warnings repeating a code are counted on the first one's line.
fn print_warnings(w: &[fieldtex::Warning], quiet: bool) {
    if quiet {
        return;
    }
    let mut seen: Vec<(&str, &str, usize)> = Vec::new();
    for x in w {
        match seen.iter_mut().find(|s| s.0 == x.code || s.1 == x.message) {
            Some(s) => s.2 += 1,
            None => seen.push((x.code.as_str(), x.message.as_str(), 0)),
        }
    }
    for (_, message, more) in seen {
        if more > 0 {
            eprintln!("warning: {message} (and {more} more like this; see report.json)");
        } else {
            eprintln!("warning: {message}");
        }
    }
}
