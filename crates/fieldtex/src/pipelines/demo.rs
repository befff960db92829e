//! `fieldtex demo`: the main job on built-in inputs (no files needed).
//!
//! Shape: a cube (`fieldtex_mesh::primitives::cube`), the simplest shape with crisp
//! features: twelve sharp creases. Exemplar: procedural stripes (two colours with soft
//! edges, a little seeded noise), generated in code. Both go through the real `align`
//! pipeline ([`crate::align_in_memory`], paper A): crease/crest curves → greedy curve
//! orientation and harmonic field (§4) → atlas → texture optimisation on the surface
//! with feature-to-feature alignment (§5) → `model.glb`, `preview.png`, `report.json`
//! with align's metrics (feature coverage, surface orientation error). The stripes run
//! along the cube's edges and bend smoothly across each face, which a chart-space tiling
//! cannot do.
//!
//! Beside it, with [`DemoOptions::orient`] (default on), the `orient` pipeline (paper D)
//! synthesises the same stripes in the plane along the built-in "whorl" fingerprint
//! preset: `orient.png` (with the designed singularities marked) and its metrics under
//! `orient` in the report.

use crate::pipelines::orient::{FieldSource, OrientOptions};
use crate::{AlignOptions, Progress, Report, Result};
use fieldtex_core::Image;
use fieldtex_mesh::TriMesh;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Options of [`demo`].
#[derive(Debug, Clone, Serialize)]
pub struct DemoOptions {
    pub seed: u64,
    /// Atlas resolution in texels of the aligned cube. Default 256.
    pub size: usize,
    /// Grid cells per cube face side (`12·cells²` triangles). Default 12.
    pub cells: usize,
    /// Exemplar side in pixels. Default 64.
    pub exemplar_size: usize,
    /// Also run the `orient` whorl preset on the same stripes (`orient.png`). Default
    /// true.
    pub orient: bool,
    /// Output side of the orient image in pixels. Default 256.
    pub orient_size: usize,
}

impl Default for DemoOptions {
    fn default() -> Self {
        Self { seed: 1, size: 256, cells: 12, exemplar_size: 64, orient: true, orient_size: 256 }
    }
}

/// The demo mesh: the cube `[-1, 1]³` with `cells × cells` cells per face.
pub fn demo_mesh(cells: usize) -> TriMesh {
    fieldtex_mesh::primitives::cube(cells.clamp(2, 64))
}

/// The demo exemplar: `size²` horizontal stripes (period `size / 4`, so the image
/// tiles), alternating a warm and a cool colour with soft edges, plus seeded noise.
/// The stripes run along the exemplar's x axis, the axis the pipelines steer.
pub fn demo_exemplar(size: usize, seed: u64) -> Image {
    let size = size.max(16);
    let mut im = Image::new(size, size, [0.0; 4]);
    let period = size as f64 / 4.0;
    let warm = [0.80, 0.42, 0.16];
    let cool = [0.93, 0.88, 0.78];
    for y in 0..size {
        // Smooth square wave in y: flat bands with short soft transitions.
        let phase = (2.0 * std::f64::consts::PI * (y as f64 + 0.5) / period).sin();
        let t = (0.5 + 0.5 * (3.0 * phase).tanh()) as f32;
        for x in 0..size {
            let n = 0.08
                * (fieldtex_core::rng::hash_unit(seed, "demo-stripes", (y * size + x) as u64)
                    as f32
                    - 0.5);
            let c: [f32; 3] = std::array::from_fn(|k| {
                (warm[k] as f32 * t + cool[k] as f32 * (1.0 - t) + n).clamp(0.0, 1.0)
            });
            im.set(x, y, [c[0], c[1], c[2], 1.0]);
        }
    }
    im
}

/// Runs the demo into `out_dir` (module docs).
pub fn demo(out_dir: &Path, options: &DemoOptions, progress: &dyn Progress) -> Result<Report> {
    if !(64..=2048).contains(&options.size) {
        return Err(crate::Error::bad_input(
            None,
            format!("--size must be in 64..=2048 texels for the demo, got {}", options.size),
        ));
    }
    let total = fieldtex_core::StageGuard::begin(progress, "demo", 0);
    let mesh = demo_mesh(options.cells);
    let exemplar = demo_exemplar(options.exemplar_size, options.seed);
    let (w, h) = (exemplar.width, exemplar.height);
    let aopts = AlignOptions {
        mesh: PathBuf::from(format!(
            "<built-in: cube, {} cells per face side, {} triangles>",
            options.cells.clamp(2, 64),
            mesh.n_triangles()
        )),
        exemplar: PathBuf::from(format!("<built-in: stripes {w}×{h}>")),
        size: options.size,
        seed: options.seed,
        ..Default::default()
    };
    // The orient image first (in memory), so that every output is written together.
    let orient =
        if options.orient { Some(orient_beside(options, &exemplar, progress)?) } else { None };
    let n_tris = mesh.n_triangles();
    let mut add = |stage: &Path, report: &mut Report| -> Result<()> {
        report.command = "demo".to_string();
        report.options = serde_json::json!({ "demo": options, "align": &aopts });
        report.notes.push(format!(
            "demo: the built-in cube ({n_tris} triangles, 12 sharp creases) and procedural \
             stripes ({w}×{h}) went through `align` (paper A): crease curves, greedy curve \
             orientation, harmonic field, atlas, texture optimisation on the surface with \
             feature alignment; the metrics are align's"
        ));
        if let Some((image, metrics, timings)) = &orient {
            fieldtex_io::write_png(&stage.join("orient.png"), image)?;
            report.metric("orient", metrics);
            // Timings stay in the (nondeterministic) timings section.
            for (stage_name, ms) in timings {
                report.timings_ms.push((format!("orient_{stage_name}"), *ms));
            }
            report.notes.push(
                "demo: orient.png is the `orient` pipeline (paper D) on the same stripes along \
                 the built-in whorl fingerprint preset, in the plane (designed singularities \
                 marked); its metrics are under metrics.orient"
                    .to_string(),
            );
        }
        report.timings_ms.push(("demo_total".to_string(), total.elapsed_ms()));
        Ok(())
    };
    // The aligned cube: the real align pipeline; model.glb, preview.png, orient.png and
    // report.json appear together.
    super::align::align_impl(out_dir, &aopts, Some((&mesh, &exemplar)), Some(&mut add), progress)
}

/// The orient image, its metrics and its stage timings.
type OrientBeside = (Image, serde_json::Value, Vec<(String, f64)>);

/// The orient whorl preset on `exemplar`: the image with the designed singularities
/// marked, and its metrics for the report.
fn orient_beside(
    options: &DemoOptions,
    exemplar: &Image,
    progress: &dyn Progress,
) -> Result<OrientBeside> {
    let n = options.orient_size.clamp(64, 1024);
    let mut oopts = OrientOptions::new(FieldSource::Preset("whorl".into()), PathBuf::new());
    oopts.size = n;
    oopts.grid = 64;
    oopts.seed = options.seed;
    // A scratch report: only its metrics and timings are kept.
    let mut sub = Report::new("orient", options.seed, serde_json::Value::Null);
    let image = super::orient::orient_in_memory(&oopts, exemplar, &mut sub, progress)?;
    Ok((
        image,
        serde_json::json!({
            "preset": "whorl",
            "size": n,
            "metrics": sub.metrics,
        }),
        sub.timings_ms,
    ))
}
