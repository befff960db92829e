//! Parameterisation for fieldtex: texture atlases (chart segmentation, LSCM, packing),
//! the texel → surface map, baking, and distortion measures.
//!
//! Architecture invariant: no file I/O, no printing; long work reports through
//! [`fieldtex_core::Progress`]; sparse solves go through `fieldtex-linalg`.

pub mod bake;
pub mod chart_segmentation;
pub mod chart_topology;
pub mod distortion;
pub mod error;
pub mod face_graph;
pub mod min_area_rectangle;
pub mod packing;
mod raster;
pub mod texel_map;

pub use bake::{bake_surface, bake_vertex_colors};
pub use chart_segmentation::{Segmentation, SegmentationOptions, segment_charts};
pub use distortion::{DistortionStats, parameterization_distortion};
pub use error::ParamError;
pub use packing::{PackChart, Packing, PackingOptions, pack_charts};
pub use texel_map::{TexelEntry, TexelMap, build_texel_map};
