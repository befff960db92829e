//! Parameterisation for fieldtex: texture atlases (chart segmentation, LSCM, packing),
//! the texel → surface map, baking, and distortion measures.
//!
//! Entry points:
//! - [`build_atlas`]: mesh → per-corner UVs in `[0, 1]²` (v up: `v = 0` is the bottom
//!   row of the image; the glTF writer flips it), chart id per triangle, [`AtlasStats`];
//! - [`build_texel_map`]: UVs → which triangle and barycentric coordinates each texel
//!   shows (conservative coverage, deterministic ties), with dilation into the gutters;
//! - [`bake_vertex_colors`] / [`bake_surface`]: colours → texture via a texel map;
//! - [`parameterization_distortion`]: angle/area distortion and flips of any UVs.
//!
//! ```
//! use fieldtex_core::NoProgress;
//! use fieldtex_param::{AtlasOptions, bake_surface, build_atlas, build_texel_map};
//!
//! let mesh = fieldtex_mesh::primitives::icosphere(2);
//! let opts = AtlasOptions { resolution: 256, ..Default::default() };
//! let atlas = build_atlas(&mesh, &opts, &NoProgress).unwrap();
//! assert_eq!(atlas.stats.flipped_triangles, 0);
//! let map = build_texel_map(&atlas.mesh, 256, 256, opts.gutter).unwrap();
//! // Colour = position; gutter texels copy their nearest chart texel.
//! let image = bake_surface(&atlas.mesh, &map, [0.0; 4], |_tri, _bary, p| {
//!     [0.5 + 0.5 * p[0] as f32, 0.5 + 0.5 * p[1] as f32, 0.5 + 0.5 * p[2] as f32, 1.0]
//! })
//! .unwrap();
//! assert_eq!((image.width, image.height), (256, 256));
//! ```
//!
//! Architecture invariant: no file I/O, no printing; long work reports through
//! [`fieldtex_core::Progress`]; sparse solves go through `fieldtex-linalg`; bad data
//! gives a [`ParamError`] or a warning, never a panic.

pub mod atlas;
pub mod bake;
mod chart_footprint;
mod chart_merging;
pub mod chart_segmentation;
pub mod chart_topology;
pub mod conformal;
pub mod distortion;
pub mod error;
pub mod face_graph;
pub mod lscm;
pub mod min_area_rectangle;
pub mod packing;
mod packing_grid;
mod packing_scale_search;
mod planar_units;
pub mod raster;
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
