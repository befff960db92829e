//! Tangent vector fields and orientation (2-RoSy) fields for fieldtex: DEC operators,
//! field design with the natural boundary term, singularity indices, design files and
//! the fingerprint presets.
//!
//! Papers: Fisher, Schröder, Desbrun & Hoppe 2007 ("Design of tangent vector fields")
//! and Liu et al., "Orientation field guided texture synthesis" (paper D, §2–3).
//!
//! Map:
//! - [`dec`]: `d0`, `d1`, `⋆0/⋆1/⋆2`, Whitney interpolation and its inverse.
//! - [`natural_boundary`]: the boundary term that turns div² + curl² into the
//!   Dirichlet energy (paper D §2.2).
//! - [`singular_model_field`]: exact 1-forms of poles and saddles.
//! - [`stroke_constraints`]: polylines → weighted edge constraints.
//! - [`field_design`]: [`FieldDesign`], the editable design with a kept factorisation
//!   ([`design_factor`]: stroke edits by multiple-rank updates);
//!   [`normal_equations`]: its matrix and right-hand side; [`reference_frames`]: frames
//!   on curved patches.
//! - [`orientation_field`]: doubled angles, complex roots, sampling to pixels.
//! - [`singularity_index`]: N-RoSy indices on meshes and pixel grids.
//! - [`design_file`]: the TOML design format; [`presets`]: fingerprint classes.
//! - [`domain`]: plane grids, point location, disk meshes.
//!
//! Interactive use (a front end keeps one [`FieldDesign`] per domain):
//!
//! ```
//! use fieldtex_fields::orientation_field::{detect_pixel_singularities, sample_plane};
//! use fieldtex_fields::{Singularity, SingularityKind, Stroke, Symmetry, presets};
//!
//! let file = presets::preset("left-loop", 256.0, 256.0, 64)?; // or DesignFile::from_toml_str
//! let mut design = file.build(None)?; // operators, matrix, symbolic analysis (once)
//! let field = design.solve()?; // numeric factorisation on the first solve, then solves
//! let pixels: Vec<[f32; 2]> = sample_plane(&design, &field, 256, 256)?; // (dx, dy), y down
//! let found = detect_pixel_singularities(&pixels, 256, 256, Symmetry::Orientation, 6.0)?;
//! assert_eq!(found.len(), 2);
//!
//! let (core, s) = design.singularities()[0];
//! design.move_singularity(core, [s.position[0] + 8.0, s.position[1], 0.0])?; // b only
//! let extra = design.add_singularity(Singularity::at_pixel(SingularityKind::Wedge, 60.5, 70.5))?;
//! design.remove_singularity(extra)?;
//! let stroke = design.add_stroke(Stroke::from_pixels(&[[20.0, 200.0], [230.0, 210.0]]))?; // rank-1 updates
//! let field = design.solve()?;
//! # let _ = (field, stroke);
//! # Ok::<(), fieldtex_fields::FieldsError>(())
//! ```
//!
//! Architecture invariant: no file I/O, no printing, no environment; everything is
//! deterministic for any thread count (parallel loops write disjoint outputs, and the
//! linear algebra is deterministic).

// Index loops over the 3 corners/edges of a triangle read like the maths.
#![allow(clippy::needless_range_loop)]

pub mod dec;
pub mod design_elements;
pub mod design_factor;
pub mod design_file;
pub mod domain;
pub mod error;
pub mod field_design;
pub mod field_design_options;
pub mod frame_field_3d;
mod frame_grid;
pub mod natural_boundary;
pub mod normal_equations;
pub mod orientation_field;
pub mod presets;
pub mod quaternion;
pub mod reference_frames;
pub mod singular_model_field;
pub mod singularity_index;
pub mod sketch;
pub mod stroke_constraints;

pub use dec::Dec;
pub use design_elements::{Singularity, SingularityKind, Stroke, Symmetry, zero_pole_angles};
pub use design_file::DesignFile;
pub use domain::{PlaneGrid, disk_mesh};
pub use error::FieldsError;
pub use field_design::{
    Domain, FieldDesign, FieldDesignOptions, SingularityId, SingularityModel, SolvedField, StrokeId,
};
pub use frame_field_3d::{FrameCurve, FrameField3d, FrameFieldOptions, FrameGrid};
pub use singularity_index::DetectedSingularity;
pub use sketch::Sketch;

// Paper A §4: curve-constrained harmonic diffusion, greedy curve orientation, metrics.
mod curve_constraint_sampling;
mod curve_field_blocks;
mod curve_field_types;
pub mod greedy_curve_orientation;
pub mod harmonic_diffusion;
pub mod nested_dissection;
pub mod smoothest_field;
pub mod surface_field_metrics;
pub mod surface_streamlines;
pub use greedy_curve_orientation::{
    CurveOrientationOptions, CurveOrientationResult, OrientationMode, OrientationScore,
    OrientationStep, orient_curves, orient_curves_with_geometry, orient_curves_with_signs,
    orientation_score,
};
pub use harmonic_diffusion::{
    AddReport, CurveConstraints, CurveField, CurveFieldOptions, CurveFieldSolver, OverlapPolicy,
    SolveReport, UnconstrainedFallback, VertexFieldStatus,
};
pub use smoothest_field::{SmoothestField, smoothest_field};
pub use surface_field_metrics::{
    AlignmentError, FieldSingularity, SurfaceFieldMetrics, surface_field_metrics,
    surface_field_metrics_with,
};
