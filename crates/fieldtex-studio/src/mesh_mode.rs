//! The mesh modes' server side (align and solid, paper A and E): a mesh opened from
//! the workspace (or the read-only meshes folder) is read, repaired exactly as the
//! pipelines repair it (the default [`fieldtex_mesh::repair`]), and kept with its BVH;
//! the page gets its triangles and crest lines (`fieldtex-features`, default options),
//! draws curves on it by ray picking in three.js, and asks for the curve-aligned field
//! (`fieldtex_fields::orient_curves`, greedy orientation, as `align` computes it),
//! which comes back as surface streamlines
//! ([`fieldtex_fields::surface_streamlines::surface_streamlines`]).

use fieldtex_features::{CrestOptions, LineKind, crest_lines};
use fieldtex_fields::surface_streamlines::{StreamlineOptions, surface_streamlines};
use fieldtex_fields::{CurveOrientationOptions, orient_curves};
use fieldtex_mesh::{Bvh, TriMesh};
use std::path::Path;
use std::time::Instant;

/// Largest mesh the studio opens interactively (triangles after repair).
pub const MAX_TRIANGLES: usize = 400_000;
/// Most curves and points per curve a field request may carry.
pub const MAX_CURVES: usize = 512;
pub const MAX_CURVE_POINTS: usize = 4096;

/// An opened mesh.
pub struct MeshSession {
    /// Root name and path it was read from (jobs read the same file).
    pub root: String,
    pub path: String,
    pub mesh: TriMesh,
    pub bvh: Bvh,
    /// Crest lines: points and `"ridge"`/`"valley"`/`"crease"`.
    pub crest: Vec<(Vec<[f64; 3]>, &'static str)>,
    pub warnings: Vec<String>,
}

impl MeshSession {
    /// Reads and repairs the mesh at `file` and finds its crest lines.
    pub fn open(file: &Path, root: &str, rel: &str) -> Result<Self, (u16, String)> {
        let loaded = fieldtex_io::read_mesh(file).map_err(|e| (400, format!("{rel}: {e}")))?;
        let mut warnings: Vec<String> = loaded.warnings.iter().map(|w| w.to_string()).collect();
        let repaired =
            fieldtex_mesh::repair(&loaded.mesh, &fieldtex_mesh::RepairOptions::default());
        warnings.extend(repaired.changes.iter().map(|c| format!("repair: {}", c.message)));
        let mesh = repaired.mesh;
        if mesh.triangles.is_empty() {
            return Err((400, format!("{rel}: no usable triangle is left after repair")));
        }
        if mesh.n_triangles() > MAX_TRIANGLES {
            return Err((
                413,
                format!(
                    "{rel} has {} triangles; the studio opens at most {MAX_TRIANGLES} (run the CLI on it instead)",
                    mesh.n_triangles()
                ),
            ));
        }
        let bvh = Bvh::build(&mesh).map_err(|e| (400, format!("{rel}: {e}")))?;
        let crest = match crest_lines(&mesh, &CrestOptions::default()) {
            Ok(c) => {
                warnings.extend(c.warnings.iter().map(|w| w.to_string()));
                c.lines
                    .into_iter()
                    .map(|l| {
                        let kind = match (l.source, l.kind) {
                            (fieldtex_features::LineSource::Crease, _) => "crease",
                            (_, LineKind::Ridge) => "ridge",
                            (_, LineKind::Valley) => "valley",
                            _ => "given",
                        };
                        (l.points, kind)
                    })
                    .collect()
            }
            Err(e) => {
                warnings.push(format!("no crest lines: {e}"));
                Vec::new()
            }
        };
        Ok(Self { root: root.to_string(), path: rel.to_string(), mesh, bvh, crest, warnings })
    }

    /// `[u32 LE json length][json][#V×3 f32 positions][#T×3 u32 indices]`.
    pub fn encode(&self, id: &str) -> Vec<u8> {
        let (lo, hi) = bbox(&self.mesh);
        let crest: Vec<serde_json::Value> =
            self.crest.iter().map(|(p, k)| serde_json::json!({ "kind": k, "points": p })).collect();
        let json = serde_json::json!({
            "id": id,
            "root": self.root,
            "path": self.path,
            "vertices": self.mesh.n_vertices(),
            "triangles": self.mesh.n_triangles(),
            "bbox": [lo, hi],
            "crest": crest,
            "warnings": self.warnings,
        })
        .to_string();
        let mut out = Vec::with_capacity(4 + json.len() + self.mesh.n_vertices() * 12);
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(json.as_bytes());
        while out.len() % 4 != 0 {
            out.push(b' ');
        }
        // The JSON is padded with spaces so the arrays start 4-byte aligned; its
        // length field counts the padding too.
        let len = (out.len() - 4) as u32;
        out[..4].copy_from_slice(&len.to_le_bytes());
        for p in &self.mesh.positions {
            for c in p {
                out.extend_from_slice(&(*c as f32).to_le_bytes());
            }
        }
        for t in &self.mesh.triangles {
            for i in t {
                out.extend_from_slice(&i.to_le_bytes());
            }
        }
        out
    }

    /// The curve-aligned field of `curves` (or of the crest lines when `None`) as
    /// streamlines; also the field's solve time and number of singular faces.
    pub fn field_lines(
        &self,
        curves: Option<&[Vec<[f64; 3]>]>,
        seeds: usize,
    ) -> Result<serde_json::Value, (u16, String)> {
        let t0 = Instant::now();
        let crest: Vec<Vec<[f64; 3]>>;
        let curves = match curves {
            Some(c) => c,
            None => {
                crest = self.crest.iter().map(|(p, _)| p.clone()).collect();
                &crest
            }
        };
        for (i, c) in curves.iter().enumerate() {
            if c.iter().flatten().any(|x| !x.is_finite()) {
                return Err((400, format!("curve {i} has a non-finite coordinate")));
            }
        }
        let oriented = orient_curves(
            &self.mesh,
            curves,
            &CurveOrientationOptions::default(),
            &fieldtex::NoProgress,
        )
        .map_err(|e| (400, format!("field: {e}")))?;
        let field_ms = t0.elapsed().as_secs_f64() * 1e3;
        let opts = StreamlineOptions { seeds: seeds.clamp(10, 2000), ..Default::default() };
        let lines = surface_streamlines(&self.mesh, &self.bvh, &oriented.field.vectors, &opts)
            .map_err(|e| (500, format!("streamlines: {e}")))?;
        let lines: Vec<Vec<[f32; 3]>> = lines
            .into_iter()
            .map(|l| l.into_iter().map(|p| p.map(|x| x as f32)).collect())
            .collect();
        Ok(serde_json::json!({
            "lines": lines,
            "curves": curves.len(),
            "field_ms": field_ms,
            "total_ms": t0.elapsed().as_secs_f64() * 1e3,
            "warnings": oriented.warnings.iter().map(|w| w.to_string()).collect::<Vec<_>>(),
        }))
    }
}

impl MeshSession {
    /// The 3-D frame field of `sketch` (paper E §3: `fieldtex_fields::FrameField3d` on
    /// the grid `solid` uses, 20 cells along the shortest side, each curve an edit) at
    /// `samples` Poisson-disk points of the surface: each frame's three local axes.
    pub fn frames(
        &self,
        sketch: &fieldtex_fields::Sketch,
        samples: usize,
    ) -> Result<serde_json::Value, (u16, String)> {
        use fieldtex_fields::{FrameField3d, FrameFieldOptions, FrameGrid, quaternion};
        let t0 = Instant::now();
        sketch.validate().map_err(|e| (400, format!("sketch: {e}")))?;
        let curves = sketch.frame_curves(&self.mesh).map_err(|e| (400, format!("sketch: {e}")))?;
        let (lo, hi) = bbox(&self.mesh);
        let grid = FrameGrid::over_box(lo, hi, 20).map_err(|e| (400, e.to_string()))?;
        let mut field = FrameField3d::new(grid, FrameFieldOptions::default())
            .map_err(|e| (500, format!("frame field: {e}")))?;
        for (i, c) in curves.iter().enumerate() {
            field.add_curve(c).map_err(|e| (400, format!("sketch curve {i}: {e}")))?;
        }
        let errs = field.constraint_errors_deg();
        let solve_ms = t0.elapsed().as_secs_f64() * 1e3;
        let frames =
            frame_samples(&self.mesh, samples, |p| quaternion::to_matrix(field.frame_at(p)))?;
        Ok(serde_json::json!({
            "frames": frames,
            "curves": curves.len(),
            "solve_ms": solve_ms,
            "alignment_error_max_deg": errs.iter().cloned().fold(0.0, f64::max),
            "total_ms": t0.elapsed().as_secs_f64() * 1e3,
        }))
    }
}

/// `frame` (a row-major rotation matrix, local axes as columns) at `samples`
/// Poisson-disk points of `mesh` (seed 1): `{"p": point, "axes": [x, y, z]}` each.
pub fn frame_samples(
    mesh: &TriMesh,
    samples: usize,
    frame: impl Fn([f64; 3]) -> [f64; 9],
) -> Result<Vec<serde_json::Value>, (u16, String)> {
    let popts = fieldtex_mesh::PoissonDiskOptions {
        target_count: Some(samples.clamp(10, 2000)),
        seed: 1,
        ..Default::default()
    };
    let (points, _) = fieldtex_mesh::poisson_disk_sampling(mesh, &popts)
        .map_err(|e| (500, format!("samples: {e}")))?;
    Ok(points
        .samples
        .iter()
        .map(|s| {
            let m = frame(s.position);
            let axes: Vec<[f32; 3]> =
                (0..3).map(|c| [m[c] as f32, m[3 + c] as f32, m[6 + c] as f32]).collect();
            serde_json::json!({ "p": s.position.map(|x| x as f32), "axes": axes })
        })
        .collect())
}

fn bbox(mesh: &TriMesh) -> ([f64; 3], [f64; 3]) {
    mesh.positions.iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
        (std::array::from_fn(|a| lo[a].min(p[a])), std::array::from_fn(|a| hi[a].max(p[a])))
    })
}

/// Checks curves from a request: counts, lengths and finite coordinates.
pub fn check_curves(curves: &[Vec<[f64; 3]>]) -> Result<(), String> {
    if curves.len() > MAX_CURVES {
        return Err(format!("{} curves; at most {MAX_CURVES}", curves.len()));
    }
    for (i, c) in curves.iter().enumerate() {
        if c.len() < 2 || c.len() > MAX_CURVE_POINTS {
            return Err(format!("curve {i} has {} points; give 2..={MAX_CURVE_POINTS}", c.len()));
        }
        if c.iter().flatten().any(|x| !x.is_finite()) {
            return Err(format!("curve {i} has a non-finite coordinate"));
        }
    }
    Ok(())
}
