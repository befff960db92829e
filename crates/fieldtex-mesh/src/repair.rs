//! Mesh repair for `fieldtex repair`: a fixed sequence of conservative steps, each
//! listed in the result with counts and examples, so the report says exactly what
//! changed.
//!
//! Steps, in order (each can be switched off unless noted):
//! 1. *Sanitise* (always): attribute tables of the wrong length are dropped (UVs with a
//!    bad index table as a whole); triangles with an index `≥ #V` are dropped.
//! 2. *Non-finite vertices* (always): vertices with a NaN/Inf coordinate are dropped
//!    with every triangle using them.
//! 3. *Weld* ([`crate::vertex_welding`]): coincident vertices (exactly, or within
//!    `weld_epsilon_relative · diagonal`) are merged where that stitches the surface,
//!    never where it would create a pinch. Steps 3–6 run again when a pass dropped
//!    triangles (see [`repair`]).
//! 4. *Degenerate triangles*: repeated-index triangles (always) and zero-area ones
//!    (area `≤ zero_area_relative · diagonal²`) are dropped. Holes left behind are not
//!    filled.
//! 5. *Duplicate triangles*: later triangles with the vertex set of an earlier one
//!    (either orientation) are dropped.
//! 6. *Non-manifold* ([`crate::non_manifold_split`]): vertices joining several fans are
//!    split, non-manifold edges keep one consistently oriented pair of triangles and
//!    the others are detached.
//! 7. *Orientation* ([`crate::orientation`]): in each orientable patch the minority of
//!    triangles is flipped to agree with the rest; non-orientable patches (Möbius) are
//!    left as they are, with a warning. Optionally closed patches are then reversed as a
//!    whole when their signed volume is negative, so that normals face outward.
//! 8. *Compaction*: unreferenced vertices are dropped (always those emptied by steps
//!    2–3) and unused UV values removed; indices are remapped.
//!
//! Per-corner UVs follow their triangles, vertex colours and normals follow their
//! vertices (a split copy duplicates them). Repair is idempotent: repairing its output
//! lists no change (tested). The output satisfies [`TriMesh::validate`] unless no
//! triangle survives, which is reported as the warning `mesh-empty`.
//!
//! Not implemented: hole filling, sliver removal by edge collapse or flip, cutting
//! non-orientable surfaces into orientable ones, self-intersection removal.

use crate::repair_steps::{
    compact, drop_degenerate, drop_duplicates, drop_non_finite, orient, sanitise, split, weld,
};
use crate::triangle_quality::DEFAULT_ZERO_AREA_RELATIVE;
use crate::{CornerUvs, TriMesh};
use fieldtex_core::{Warning, Warnings};
use serde::Serialize;

/// Options of [`repair`].
#[derive(Debug, Clone, Serialize)]
pub struct RepairOptions {
    /// Weld coincident vertices. Default `true`.
    pub weld: bool,
    /// Weld distance relative to the bounding-box diagonal; `0` welds exactly equal
    /// positions only. Default `0`.
    pub weld_epsilon_relative: f64,
    /// Drop zero-area triangles. Default `true`.
    pub drop_zero_area: bool,
    /// Zero-area tolerance relative to the squared diagonal. Default `1e-12`.
    pub zero_area_relative: f64,
    /// Drop duplicate triangles. Default `true`.
    pub drop_duplicate_triangles: bool,
    /// Split non-manifold vertices and detach non-manifold edges. Default `true`.
    pub split_non_manifold: bool,
    /// Make orientation consistent within each orientable patch. Default `true`.
    pub orient_consistently: bool,
    /// Reverse closed patches with negative signed volume. Default `true`.
    pub orient_outward: bool,
    /// Drop vertices no triangle uses. Default `true`.
    pub drop_unreferenced: bool,
    /// Examples listed per change. Default 10.
    pub max_examples: usize,
}

impl Default for RepairOptions {
    fn default() -> Self {
        Self {
            weld: true,
            weld_epsilon_relative: 0.0,
            drop_zero_area: true,
            zero_area_relative: DEFAULT_ZERO_AREA_RELATIVE,
            drop_duplicate_triangles: true,
            split_non_manifold: true,
            orient_consistently: true,
            orient_outward: true,
            drop_unreferenced: true,
            max_examples: 10,
        }
    }
}

/// One kind of change made by [`repair`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RepairChange {
    /// Stable code, e.g. `"vertices-welded"`.
    pub code: String,
    /// How many elements were changed (what they are is in `message`).
    pub count: usize,
    /// A sentence for people.
    pub message: String,
    /// First few elements concerned, as indices into the *input* mesh (vertices or
    /// triangles, as `message` says).
    pub examples: Vec<u32>,
}

/// Result of [`repair`].
#[derive(Debug, Clone)]
pub struct RepairResult {
    pub mesh: TriMesh,
    /// Every change made, in step order; empty when the mesh needed nothing.
    pub changes: Vec<RepairChange>,
    /// What could not be repaired.
    pub warnings: Warnings,
}

impl RepairResult {
    /// `true` when at least one change was made.
    pub fn changed(&self) -> bool {
        !self.changes.is_empty()
    }
}

/// Working copy with provenance (`orig_*`: input index of each element).
pub(crate) struct Work {
    pub(crate) positions: Vec<[f64; 3]>,
    pub(crate) colors: Option<Vec<[f32; 4]>>,
    pub(crate) normals: Option<Vec<[f64; 3]>>,
    /// Input vertex of each vertex (copies name their source).
    pub(crate) orig_vertex: Vec<u32>,
    /// Vertex removed by a step (welded away, non-finite); compaction drops it.
    pub(crate) dead: Vec<bool>,
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) uv: Option<CornerUvs>,
    pub(crate) orig_face: Vec<u32>,
    pub(crate) changes: Vec<RepairChange>,
    pub(crate) warnings: Warnings,
    pub(crate) max_examples: usize,
}

impl Work {
    /// Records a change; a second change with the same code (from a later pass) is
    /// merged into the first.
    pub(crate) fn change(&mut self, code: &str, count: usize, message: String, examples: Vec<u32>) {
        if count == 0 {
            return;
        }
        if let Some(c) = self.changes.iter_mut().find(|c| c.code == code) {
            c.count += count;
            c.message = format!("{}; then in a further pass, {message}", c.message);
            c.examples.extend(examples);
            c.examples.truncate(self.max_examples);
            return;
        }
        let mut examples = examples;
        examples.truncate(self.max_examples);
        self.changes.push(RepairChange { code: code.into(), count, message, examples });
    }

    /// Keeps triangles with `keep[f]`; returns the input indices of the dropped ones.
    pub(crate) fn retain_triangles(&mut self, keep: &[bool]) -> Vec<u32> {
        let dropped: Vec<u32> =
            (0..keep.len()).filter(|&f| !keep[f]).map(|f| self.orig_face[f]).collect();
        if dropped.is_empty() {
            return dropped;
        }
        let filt = |v: &mut Vec<[u32; 3]>| {
            let mut k = 0;
            v.retain(|_| {
                k += 1;
                keep[k - 1]
            });
        };
        filt(&mut self.triangles);
        if let Some(uv) = &mut self.uv {
            filt(&mut uv.indices);
        }
        let mut k = 0;
        self.orig_face.retain(|_| {
            k += 1;
            keep[k - 1]
        });
        dropped
    }

    pub(crate) fn flip(&mut self, f: usize) {
        self.triangles[f].swap(1, 2);
        if let Some(uv) = &mut self.uv {
            uv.indices[f].swap(1, 2);
        }
    }

    /// Bounding-box diagonal of the finite positions.
    fn diagonal(&self) -> f64 {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in self.positions.iter().filter(|p| fieldtex_core::vec3::is_finite(**p)) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if lo[0] > hi[0] {
            return 0.0;
        }
        fieldtex_core::vec3::norm(fieldtex_core::vec3::sub(hi, lo))
    }
}

/// Repairs `mesh` (see the module docs for the steps); never panics.
pub fn repair(mesh: &TriMesh, options: &RepairOptions) -> RepairResult {
    let nv = mesh.n_vertices();
    let mut w = Work {
        positions: mesh.positions.clone(),
        colors: mesh.vertex_colors.clone(),
        normals: mesh.vertex_normals.clone(),
        orig_vertex: (0..nv as u32).collect(),
        dead: vec![false; nv],
        triangles: mesh.triangles.clone(),
        uv: mesh.uvs.clone(),
        orig_face: (0..mesh.n_triangles() as u32).collect(),
        changes: Vec::new(),
        warnings: Vec::new(),
        max_examples: options.max_examples,
    };
    sanitise(&mut w);
    drop_non_finite(&mut w);
    let diagonal = w.diagonal();
    // Steps 3-6 repeat while a pass drops triangles after welding: the weld decides
    // from the surface as it is, so a surface that lost triangles may now stitch where
    // it could not before. Without this a second repair could still weld (not
    // idempotent). Each extra pass welds at least one vertex, and in practice one extra
    // pass is the most ever seen; five is a safety bound.
    for pass in 0..5 {
        let n_tris = w.triangles.len();
        let welded = if options.weld {
            weld(&mut w, options.weld_epsilon_relative.max(0.0) * diagonal, pass)
        } else {
            0
        };
        if pass > 0 && welded == 0 {
            break;
        }
        drop_degenerate(&mut w, options, diagonal);
        if options.drop_duplicate_triangles {
            drop_duplicates(&mut w);
        }
        if options.split_non_manifold {
            split(&mut w);
        }
        if w.triangles.len() == n_tris || !options.weld {
            break;
        }
    }
    if options.orient_consistently || options.orient_outward {
        orient(&mut w, options);
    }
    compact(&mut w, options.drop_unreferenced);
    if w.triangles.is_empty() {
        w.warnings.push(Warning::new(
            "mesh-empty",
            "no triangle is left after repair; the input has no usable surface",
        ));
    }
    let mesh = TriMesh {
        positions: w.positions,
        triangles: w.triangles,
        uvs: w.uv,
        vertex_colors: w.colors,
        vertex_normals: w.normals,
    };
    RepairResult { mesh, changes: w.changes, warnings: w.warnings }
}
