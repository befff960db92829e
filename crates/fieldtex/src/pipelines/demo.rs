//! `fieldtex demo`: the main job on built-in inputs (no files needed).
//!
//! Mesh: a bumpy sphere (an icosphere displaced by a smooth angular pattern), made
//! procedurally. Exemplar: procedural brick-like stripes. The mesh is atlased, the
//! exemplar is mapped through the atlas at a uniform texel density and baked; the
//! model, a preview and a report are written.
//!
//! What this demo does NOT do yet: field-guided synthesis on the surface (issues for
//! `orient`/`align`). The texture is the exemplar tiled in chart space, so it shows
//! seams at chart borders; the report says so in `notes`.

use crate::outputs::{prepare_out_dir, write_report};
use crate::pipelines::atlas::{atlas_options, repaired_atlas};
use crate::{Progress, Report, Result};
use fieldtex_core::Image;
use fieldtex_mesh::TriMesh;
use serde::Serialize;
use std::path::Path;

/// Options of [`demo`].
#[derive(Debug, Clone, Serialize)]
pub struct DemoOptions {
    pub seed: u64,
    /// Atlas resolution in texels. Default 1024.
    pub size: usize,
    /// Subdivision level of the sphere (20·4^level triangles). Default 5.
    pub level: usize,
    /// Exemplar repeats per unit of surface length. Default 3.
    pub tiles_per_unit: f64,
}

impl Default for DemoOptions {
    fn default() -> Self {
        Self { seed: 1, size: 1024, level: 5, tiles_per_unit: 3.0 }
    }
}

/// The demo mesh: a unit icosphere with radius `1 + 0.12·bump(direction)`.
pub fn demo_mesh(level: usize) -> TriMesh {
    let mut m = fieldtex_mesh::primitives::icosphere(level);
    for p in &mut m.positions {
        let (x, y, z) = (p[0], p[1], p[2]);
        let bump = (3.0 * x).sin() * (2.0 * y).cos() + 0.5 * (4.0 * z + x).sin();
        let r = 1.0 + 0.12 * bump;
        *p = [x * r, y * r, z * r];
    }
    m
}

/// The demo exemplar: `size²` staggered bricks with mortar and a little seeded noise.
pub fn demo_exemplar(size: usize, seed: u64) -> Image {
    let mut im = Image::new(size, size, [0.0; 4]);
    let rows = 4usize;
    let cols = 2usize;
    let bh = size as f64 / rows as f64;
    let bw = size as f64 / cols as f64;
    for y in 0..size {
        for x in 0..size {
            let row = (y as f64 / bh).floor();
            let shift = if !(row as usize).is_multiple_of(2) { 0.5 * bw } else { 0.0 };
            let fx = ((x as f64 + shift) % bw) / bw;
            let fy = (y as f64 % bh) / bh;
            let mortar = fx < 0.06 || fy < 0.12;
            let brick = ((x as f64 + shift) / bw).floor() as u64 * 31 + row as u64 * 17;
            let tone =
                0.85 + 0.15 * fieldtex_core::rng::hash_unit(seed, "demo-brick", brick) as f32;
            let n = 0.06
                * fieldtex_core::rng::hash_unit(seed, "demo-noise", (y * size + x) as u64) as f32;
            let c = if mortar {
                [0.78 + n, 0.76 + n, 0.72 + n, 1.0]
            } else {
                [0.62 * tone + n, 0.27 * tone + n, 0.18 * tone + n, 1.0]
            };
            im.set(x, y, c);
        }
    }
    im
}

/// Runs the demo into `out_dir`.
pub fn demo(out_dir: &Path, options: &DemoOptions, progress: &dyn Progress) -> Result<Report> {
    let aopts = atlas_options(options.size, 4)?;
    let mut report =
        Report::new("demo", options.seed, serde_json::to_value(options).unwrap_or_default());
    prepare_out_dir(out_dir)?;
    let mesh = report.time("mesh", || demo_mesh(options.level.min(7)));
    let exemplar = report.time("exemplar", || demo_exemplar(128, options.seed));
    report.input = serde_json::json!({
        "mesh": "procedural bumpy icosphere",
        "vertices": mesh.n_vertices(),
        "triangles": mesh.n_triangles(),
        "exemplar": "procedural bricks 128x128",
    });
    let atlas = repaired_atlas(&mesh, None, &aopts, &mut report, progress)?;
    // UV → exemplar: one atlas unit holds `resolution / texels_per_unit` surface units.
    let texture = report.time("bake", || -> Result<Image> {
        let res = atlas.resolution as usize;
        let map = fieldtex_param::build_texel_map(&atlas.mesh, res, res, atlas.gutter)
            .map_err(|e| crate::Error::Internal(format!("texel map: {e}")))?;
        let s = atlas.resolution as f64 / atlas.stats.texels_per_unit.max(1e-12)
            * options.tiles_per_unit;
        let uvs = atlas.mesh.uvs.as_ref();
        let bg = [0.5, 0.5, 0.5, 1.0];
        fieldtex_param::bake_surface(&atlas.mesh, &map, bg, |f, bary, _p| {
            let Some(uv) = uvs else { return [0.5, 0.5, 0.5, 1.0] };
            let t = uv.indices[f as usize];
            let mut u = 0.0;
            let mut v = 0.0;
            for k in 0..3 {
                u += bary[k] as f64 * uv.values[t[k] as usize][0];
                v += bary[k] as f64 * uv.values[t[k] as usize][1];
            }
            let ex = exemplar.width as f64;
            exemplar.get_wrapped((u * s * ex).floor() as i64, ((1.0 - v) * s * ex).floor() as i64)
        })
        .map_err(|e| crate::Error::Internal(format!("bake: {e}")))
    })?;
    report.time("write", || super::write_model(out_dir, &atlas.mesh, Some(&texture)))?;
    let preview =
        report.time("preview", || super::render::preview(&atlas.mesh, Some(&texture), 800, None));
    fieldtex_io::write_png(&out_dir.join("preview.png"), &preview)?;
    report.metric("atlas", atlas.stats);
    report.notes.push(
        "substitute: the texture is the exemplar tiled in chart space at uniform texel density; \
         field-guided synthesis is not wired into the demo yet, so chart borders show seams"
            .to_string(),
    );
    write_report(out_dir, &report)?;
    Ok(report)
}
