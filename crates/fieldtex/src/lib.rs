//! fieldtex: texture 3D shapes so the texture follows the shape.
//!
//! This facade owns one function per pipeline; each reads its inputs through
//! `fieldtex-io`, runs the algorithm crates, writes outputs atomically and returns a
//! [`Report`]. The CLI (`fieldtex-cli`) is a thin layer over these functions.
//!
//! | function | command |
//! |---|---|
//! | [`demo`] | `fieldtex demo` — built-in inputs, no files needed |
//! | [`inspect_file`] | `fieldtex inspect` |
//! | [`repair_file`] | `fieldtex repair` |
//! | [`atlas_file`] | `fieldtex atlas` |
//! | [`render_file`] | `fieldtex render` |
//! | [`eval_files`] | `fieldtex eval` |
//! | [`crest_file`] | `fieldtex crest` |
//! | [`field_file`] | `fieldtex field` (paper A §4) |
//! | [`orient`] | `fieldtex orient` (paper D) |
//! | [`align`] | `fieldtex align` (paper A) |
//! | [`transfer_files`] | `fieldtex transfer` (paper B) |
//! | [`solid`] | `fieldtex solid` (paper E) |

mod error;
mod outputs;
mod pipelines;
mod report;

pub use error::{Error, Result};
pub use fieldtex_core::{Image, NoProgress, Progress, Warning};
pub use outputs::{guard_output, write_text};
pub use pipelines::align::{AlignOptions, align, align_in_memory};
pub use pipelines::atlas::{AtlasCommandOptions, atlas_file};
pub use pipelines::conformal::{
    ConformalOptions, REFINE_ABOVE, REFINE_MAX_LEVELS, REFINE_MAX_TRIANGLES, REFINE_SEAM_GROWTH,
    Refine, conformal,
};
pub use pipelines::crest::{CrestCommandOptions, CrestSummary, crest_file};
pub use pipelines::demo::{DemoOptions, demo};
pub use pipelines::eval::{Guidance, ImageMetrics, SeamCoordinates, eval_files};
pub use pipelines::field::{FieldCommandOptions, FieldSummary, field_file};
pub use pipelines::field_texture::{
    FieldTextureOptions, synthesize_field_texture, synthesize_field_texture_with,
};
pub use pipelines::inspect::{RepairCommandOptions, RepairSummary, inspect_file, repair_file};
pub use pipelines::orient::{DesignedSingularity, FieldSource, OrientOptions, orient};
pub use pipelines::render::{RenderCommandOptions, render_file};
pub use pipelines::solid::{SolidGrid, SolidOptions, solid, solid_frame_field};
pub use pipelines::solid_session::{SketchEdit, SolidCut, SolidSession};
pub use pipelines::synthesis::AnalysisCache;
pub use pipelines::transfer as pipelines_transfer;
pub use pipelines::transfer::{TransferCommandOptions, transfer_files};
pub use pipelines::transfer_fidelity::transfer_fidelity_files;
pub use report::Report;

/// The algorithm crates, re-exported for library users.
pub mod crates {
    pub use fieldtex_core as core;
    pub use fieldtex_eval as eval;
    pub use fieldtex_features as features;
    pub use fieldtex_fields as fields;
    pub use fieldtex_io as io;
    pub use fieldtex_linalg as linalg;
    pub use fieldtex_mesh as mesh;
    pub use fieldtex_param as param;
    pub use fieldtex_render as render;
    pub use fieldtex_synth as synth;
    pub use fieldtex_texopt as texopt;
    pub use fieldtex_transfer as transfer;
}
