//! Parameterisation for fieldtex: texture atlases (chart segmentation, LSCM, packing),
//! the texel → surface map, baking, and distortion measures.
//!
//! Entry points:
//! - [`build_atlas`]: mesh → per-corner UVs in `[0, 1]²` (v up), chart ids, [`AtlasStats`];
//! - [`build_texel_map`]: UVs → which triangle and barycentric coordinates each texel
//!   shows, with dilation into the gutters;
//! - [`bake_vertex_colors`] / [`bake_surface`]: colours → texture via a texel map;
//! - [`parameterization_distortion`]: angle/area distortion and flips of any UVs.
//!
//! Architecture invariant: no file I/O, no printing; long work reports through
//! [`fieldtex_core::Progress`]; sparse solves go through `fieldtex-linalg`.

pub mod atlas;
pub mod bake;
mod chart_footprint;
pub mod chart_segmentation;
pub mod chart_topology;
pub mod distortion;
pub mod error;
pub mod face_graph;
pub mod lscm;
pub mod min_area_rectangle;
pub mod packing;
mod raster;
pub mod texel_map;

pub use atlas::{Atlas, AtlasOptions, AtlasStats, build_atlas};
pub use bake::{bake_surface, bake_vertex_colors};
pub use chart_segmentation::{Segmentation, SegmentationOptions, segment_charts};
pub use distortion::{DistortionStats, parameterization_distortion};
pub use error::ParamError;
pub use packing::{PackChart, Packing, PackingOptions, pack_charts};
pub use texel_map::{TexelEntry, TexelMap, build_texel_map};

#[cfg(test)]
mod tests;
