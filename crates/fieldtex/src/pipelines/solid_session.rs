//! [`SolidSession`]: the solid pipeline (paper E, Zhang et al. 2010) kept open for
//! interactive use. Built once from the mesh, the sketch, the exemplar(s) and the
//! options of [`crate::solid`] (read, repair, exemplar analysis, frame field, voxel grid
//! — the same building blocks, called the same way), it then answers:
//!
//! - [`SolidSession::cut`]: the cut image of a plane, computed on demand by the lazy
//!   solid synthesizer (only the voxels the image shows and their dependency set). The
//!   synthesizer's computed blocks are kept between cuts ([`SolidCache`]), so a later
//!   cut that shares blocks with an earlier one costs less. The image is the one
//!   `fieldtex solid --cut` writes as `cut-N.png` for the same inputs, options and seed,
//!   byte for byte once quantised (tested), because a voxel's value does not depend on
//!   what else was requested (`fieldtex_synth::solid::lazy_solid_synthesis`).
//! - [`SolidSession::set_sketch`]: a sketch edit, applied to the kept, factored frame
//!   field ([`fieldtex_fields::FrameField3d`]) as curve edits (add / remove / replace,
//!   one factor update and one solve each; unchanged curves are kept). A changed field
//!   changes every voxel, so the synthesizer's blocks are dropped.
//!
//! The voxel grid (`resolution`) is fixed when the session is built: a cut is one pixel
//! per voxel, as in the pipeline; another resolution is another solid and needs another
//! session. One region only (`SolidOptions::interior` is refused); no shell is
//! synthesised (nothing here needs it).

use super::solid::{
    CutVoxels, FieldFrames, SolidGrid, SolidOptions, SolidRegions, Work, analyse_exemplars,
    cut_voxels, read_exemplars, read_inputs, sketch_frame_field, slice_image,
};
use crate::{Error, Progress, Report, Result};
use fieldtex_core::{Image, Warning};
use fieldtex_fields::{FrameCurve, FrameField3d, Sketch};
use fieldtex_mesh::{Bvh, TriMesh};
use fieldtex_synth::solid::{
    FrameSource, SolidCache, SolidExemplar, SolidSynthesisOptions, SolidSynthesizer, VoxelLattice,
};
use std::time::Instant;

/// An open solid (module docs).
pub struct SolidSession {
    mesh: TriMesh,
    bvh: Bvh,
    scale: f64,
    exemplar: SolidExemplar,
    grid: SolidGrid,
    synthesis: SolidSynthesisOptions,
    field_cells: usize,
    /// `None` without a sketch: the constant (identity) field, as in the pipeline.
    field: Option<FrameField3d>,
    /// The field's curves in sketch order, with their ids in `field`.
    curves: Vec<(usize, FrameCurve)>,
    cache: SolidCache,
    /// Read and repair warnings of the mesh.
    pub warnings: Vec<Warning>,
}

/// One cut of [`SolidSession::cut`].
pub struct SolidCut {
    /// RGBA, values `k / 255`; alpha 0 where the voxel centre is outside the mesh.
    pub image: Image,
    /// Whether the plane runs through a plane of voxel centres (the image is that slice).
    pub grid_slice: bool,
    /// Where the image lies in space: `[corner, u, v]`, the outer corner of pixel
    /// (0, 0) and the vectors spanning all columns and all rows.
    pub placement: [[f64; 3]; 3],
    /// Wall time of the whole cut (plane cut of the mesh, inside test, synthesis).
    pub seconds: f64,
    /// Voxels the image needed (inside the mesh).
    pub voxels_requested: u64,
    /// Voxels computed for it over all levels (0 when the cache held them all).
    pub voxels_computed: u64,
}

/// What [`SolidSession::set_sketch`] did to the field.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct SketchEdit {
    pub added: usize,
    pub removed: usize,
    pub replaced: usize,
    pub kept: usize,
    /// Wall time of the edits (factor updates and solves).
    pub seconds: f64,
}

impl SolidSession {
    /// Reads, repairs and analyses as [`crate::solid`] does. `sketch` overrides
    /// `options.sketch` (a sketch already in memory); with neither, or a sketch without
    /// curves, the field is constant. `options.cuts`, `volume`, `keep` and `atlas_size`
    /// are not used.
    pub fn new(
        options: &SolidOptions,
        sketch: Option<&Sketch>,
        progress: &dyn Progress,
    ) -> Result<Self> {
        if !(8..=2048).contains(&options.resolution) {
            return Err(Error::bad_input(
                None,
                format!("--resolution must be in 8..=2048, got {}", options.resolution),
            ));
        }
        if options.interior.is_some() {
            return Err(Error::bad_input(
                None,
                "a solid session has one region: run `fieldtex solid --interior` instead",
            ));
        }
        let mut report = Report::new("solid-session", options.seed, serde_json::Value::Null);
        let (mesh, _) = read_inputs(options, &mut report)?;
        let (exemplars, single) = read_exemplars(options)?;
        let mut analysis = options.analysis.clone();
        if single {
            analysis.plane_weights = [1.0, 1.0, 0.0];
        }
        let bbox = mesh
            .bounding_box()
            .ok_or_else(|| Error::bad_input(Some(&options.mesh), "the mesh has no vertex"))?;
        let (field, curves) = match (sketch, &options.sketch) {
            (Some(s), _) if s.curves.is_empty() => (None, Vec::new()),
            (Some(s), _) => {
                s.validate().map_err(|e| Error::bad_input(None, format!("sketch: {e}")))?;
                let (f, c) = sketch_frame_field(&mesh, s, options.field_cells, None)?;
                (Some(f), c)
            }
            (None, Some(path)) => {
                let (f, c) = super::solid::solid_frame_field(&mesh, path, options.field_cells)?;
                (Some(f), c)
            }
            (None, None) => (None, Vec::new()),
        };
        let ids = field.as_ref().map_or(Vec::new(), |f| f.curve_ids());
        crate::outputs::check_cancelled(progress)?;
        let exemplar = analyse_exemplars(options, &exemplars, single, &analysis, progress)?;
        let grid = SolidGrid::over_box(bbox.min, bbox.max, options.resolution);
        let bvh = Bvh::build(&mesh).map_err(|e| Error::internal("bvh", e))?;
        let session = Self {
            scale: bbox.diagonal(),
            mesh,
            bvh,
            exemplar,
            grid,
            synthesis: options.synthesis.clone(),
            field_cells: options.field_cells,
            field,
            curves: ids.into_iter().zip(curves).collect(),
            cache: SolidCache::default(),
            warnings: report.warnings,
        };
        // Checks the synthesis options once (the same check every cut repeats).
        let frames = FieldFrames(session.field.as_ref());
        synthesizer(&session.exemplar, &session.grid, &frames, &session.synthesis, None)?;
        Ok(session)
    }

    /// The repaired mesh the solid is cut from.
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// The voxel grid.
    pub fn grid(&self) -> SolidGrid {
        self.grid
    }

    /// The editable frame field (`None` without a sketch).
    pub fn field(&self) -> Option<&FrameField3d> {
        self.field.as_ref()
    }

    /// The frame at `p` as a row-major rotation matrix (columns = local axes).
    pub fn frame_at(&self, p: [f64; 3]) -> [f64; 9] {
        FieldFrames(self.field.as_ref()).frame(p)
    }

    /// Makes `sketch` the session's sketch: each curve that changed is replaced in the
    /// factored field, new ones added, dropped ones removed (module docs).
    /// A sketch without curves returns the session to the constant field (no sketch).
    pub fn set_sketch(&mut self, sketch: &Sketch) -> Result<SketchEdit> {
        if sketch.curves.is_empty() {
            let removed = self.curves.len();
            if self.field.take().is_some() {
                self.cache = SolidCache::default();
            }
            self.curves.clear();
            return Ok(SketchEdit { removed, ..Default::default() });
        }
        sketch.validate().map_err(|e| Error::bad_input(None, format!("sketch: {e}")))?;
        let t0 = Instant::now();
        let new = sketch
            .frame_curves(&self.mesh)
            .map_err(|e| Error::bad_input(None, format!("sketch: {e}")))?;
        let mut edit = SketchEdit::default();
        let Some(field) = self.field.as_mut() else {
            let (f, c) = sketch_frame_field(&self.mesh, sketch, self.field_cells, None)?;
            edit.added = c.len();
            self.curves = f.curve_ids().into_iter().zip(c).collect();
            self.field = Some(f);
            self.cache = SolidCache::default();
            edit.seconds = t0.elapsed().as_secs_f64();
            return Ok(edit);
        };
        let fail = |i: usize, e: &dyn std::fmt::Display| {
            Error::bad_input(None, format!("sketch curve {i}: {e}"))
        };
        let mut kept: Vec<(usize, FrameCurve)> = Vec::with_capacity(new.len());
        for (i, c) in new.into_iter().enumerate() {
            match self.curves.get(i) {
                Some((id, old)) if *old == c => {
                    edit.kept += 1;
                    kept.push((*id, c));
                }
                Some((id, _)) => {
                    field.replace_curve(*id, &c).map_err(|e| fail(i, &e))?;
                    edit.replaced += 1;
                    kept.push((*id, c));
                }
                None => {
                    let id = field.add_curve(&c).map_err(|e| fail(i, &e))?;
                    edit.added += 1;
                    kept.push((id, c));
                }
            }
        }
        for (i, (id, _)) in self.curves.iter().enumerate().skip(kept.len()) {
            field.remove_curve(*id).map_err(|e| fail(i, &e))?;
            edit.removed += 1;
        }
        self.curves = kept;
        if edit.added + edit.removed + edit.replaced > 0 {
            self.cache = SolidCache::default();
        }
        edit.seconds = t0.elapsed().as_secs_f64();
        Ok(edit)
    }

    /// The cut image of plane `[x, y, z, nx, ny, nz]` (the module docs of
    /// [`crate::solid`] say which pixels), computed on demand.
    pub fn cut(&mut self, plane: [f64; 6], progress: &dyn Progress) -> Result<SolidCut> {
        if plane.iter().any(|v| !v.is_finite()) {
            return Err(Error::bad_input(None, "the cut plane needs six finite numbers"));
        }
        let t0 = Instant::now();
        let point = [plane[0], plane[1], plane[2]];
        let normal = [plane[3], plane[4], plane[5]];
        let pc = fieldtex_mesh::cut_with_plane(&self.mesh, point, normal)
            .ok_or_else(|| Error::bad_input(None, "the cut normal must not be zero"))?;
        if pc.mesh.triangles.is_empty() {
            return Err(Error::bad_input(
                None,
                "the cut plane leaves nothing of the mesh on its negative side",
            ));
        }
        let CutVoxels { voxels, width, height, slice, placement } =
            cut_voxels(&self.grid, plane, &pc.mesh);
        let grid = self.grid;
        let scale = self.scale;
        let mut work = Work::default();
        let frames = FieldFrames(self.field.as_ref());
        let kept = std::mem::take(&mut self.cache);
        let outer = synthesizer(&self.exemplar, &grid, &frames, &self.synthesis, Some(kept))?;
        let mut regions = SolidRegions { outer, inner: None, grid };
        let image = slice_image(
            &voxels,
            width,
            height,
            &grid,
            &self.bvh,
            scale,
            &mut regions,
            progress,
            &mut work,
        );
        let cache = regions.outer.into_cache();
        self.cache = cache;
        Ok(SolidCut {
            image,
            grid_slice: slice.is_some(),
            placement,
            seconds: t0.elapsed().as_secs_f64(),
            voxels_requested: work.requested,
            voxels_computed: work.computed_all_levels,
        })
    }
}

/// A synthesizer over `exemplar`, the grid's lattice and `frames`, with `cache`'s blocks.
fn synthesizer<'a>(
    exemplar: &'a SolidExemplar,
    grid: &SolidGrid,
    frames: &'a FieldFrames<'a>,
    options: &SolidSynthesisOptions,
    cache: Option<SolidCache>,
) -> Result<SolidSynthesizer<'a>> {
    let lattice = VoxelLattice { origin: grid.origin, spacing: grid.spacing };
    let s = SolidSynthesizer::new(exemplar, lattice, frames, options.clone())
        .map_err(|e| Error::classify(&e, None, "synthesis options"))?
        .with_extent(grid.sizes);
    Ok(match cache {
        Some(c) => s.with_cache(c),
        None => s,
    })
}
