//! Salient curves on meshes for feature-aligned texturing (paper A, Xu et al.,
//! "Feature-aligned shape texturing"): crest lines (ridges and valleys, Yoshizawa,
//! Belyaev & Seidel 2005) united with sharp creases, curve preprocessing (join, break,
//! drop), user curves on the surface, and the sharp-edge coverage metric.
//!
//! Typical use:
//! ```
//! use fieldtex_features::{CrestOptions, crest_lines};
//! let mesh = fieldtex_mesh::primitives::icosphere(3);
//! let crest = crest_lines(&mesh, &CrestOptions::default()).unwrap();
//! assert!(crest.lines.is_empty()); // a sphere is umbilic everywhere
//! ```
//!
//! Architecture invariant: no file I/O, no printing; curves go out as polylines
//! (`CrestLine::points`, one triangle per point) for the I/O layer to write.

mod crest_crossings;
pub mod crest_lines;
pub mod curve_preprocessing;
pub mod curve_proximity;
pub mod distance_transform;
pub mod error;
pub mod exemplar_feature_lines;
pub mod extremality;
pub mod feature_quality;
pub mod given_curves;
mod line_response;
pub mod mesh_scale;
mod segment_grid;
pub mod sharp_edges;
#[cfg(test)]
mod test_shapes;

pub use crest_lines::{
    CrestLine, CrestLines, CrestOptions, CrestStats, LineKind, LineSource, crest_lines,
    crest_lines_with_geometry, crest_lines_with_progress,
};
pub use curve_preprocessing::{CurvePreprocessOptions, preprocess_lines, preprocess_polylines};
pub use curve_proximity::{curve_surface_points, distance_to_curves};
pub use distance_transform::{euclidean_distance_transform, squared_distance_transform};
pub use error::FeaturesError;
pub use exemplar_feature_lines::{
    ExemplarFeatureOptions, ExemplarFeatures, LinePolarity, detect_exemplar_feature_lines,
    exemplar_features_from_polylines,
};
pub use feature_quality::{SharpEdgeCoverage, sharp_edge_coverage};
pub use given_curves::{GivenCurvesOptions, given_curves};
pub use mesh_scale::mean_edge_length;
pub use sharp_edges::{SharpChain, SharpEdge, salient_creases, sharp_edge_chains, sharp_edges};
