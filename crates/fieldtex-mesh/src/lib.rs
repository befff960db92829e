//! Triangle mesh core of fieldtex: the [`TriMesh`] type, its [`Topology`] tables,
//! inspection and repair, and the geometry operators every pipeline uses.
//!
//! Architecture invariant: no file I/O, no printing. Parsers and writers live in
//! `fieldtex-io`; sparse matrices are built here as triplets and handed to
//! `fieldtex-linalg`, which alone knows the solver library.

pub mod error;
pub mod mesh;
pub mod primitives;
pub mod topology;

pub use error::MeshError;
pub use mesh::{Aabb, CornerUvs, TriMesh};
pub use topology::{Csr, Topology, UnionFind};

// Geometry operators.
pub mod areas;
pub mod bvh;
pub mod cotan_laplacian;
pub mod dart_throwing;
pub mod directional_occlusion;
pub mod heat_geodesic;
pub mod mass_matrix;
pub mod mesh_geometry;
pub mod normals;
pub mod plane_cut;
pub mod point_inside;
pub mod poisson_disk_sampling;
pub mod polygon_triangulation;
pub mod principal_curvature;
pub mod solid_angle_curvature;
pub mod spatial_grid;
pub mod sphere_directions;

// Inspection and repair.
pub mod inspect;
pub mod repair;

// Geometry operator helpers and re-exports.
mod checks;
pub use areas::{
    VertexAreaKind, barycentric_vertex_areas, face_areas, mixed_voronoi_vertex_areas, total_area,
    vertex_areas,
};
pub use cotan_laplacian::{
    CotanOptions, CotanStats, HodgeStarClamp, cotan_edge_weights, cotan_face_weights,
    cotan_laplacian, cotan_laplacian_and_mass, cotan_laplacian_triplets, cotan_laplacian_with,
    hodge_star1,
};
pub use mass_matrix::{lumped_mass, mass_matrix};
pub use normals::{NormalWeighting, face_normals, vertex_normals};
pub use principal_curvature::{CurvatureOptions, PrincipalCurvatures, principal_curvatures};
#[cfg(test)]
mod test_meshes;
pub use heat_geodesic::{HeatBoundary, HeatGeodesic, HeatGeodesicOptions, SurfacePoint};

// Inspection and repair building blocks (one algorithm per file).
pub mod boundary_cycles;
pub mod coincident_vertices;
mod inspect_text;
pub mod non_manifold_split;
pub mod orientation;
mod repair_steps;
pub mod triangle_quality;
pub mod vertex_fans;
pub mod vertex_welding;

pub use inspect::{InspectOptions, InspectReport, inspect};
pub use repair::{RepairChange, RepairOptions, RepairResult, repair};

#[cfg(test)]
mod inspect_tests;
#[cfg(test)]
mod repair_tests;
pub use bvh::{Bvh, ClosestPoint, Hit, Ray};
pub use dart_throwing::{DartThrower, dart_throwing, nested_dart_throwing};
pub use directional_occlusion::{DirectionalOcclusionOptions, directional_occlusion_sh};
pub use mesh_geometry::MeshGeometry;
pub use plane_cut::{PlaneCut, cut_with_plane};
pub use point_inside::points_inside;
pub use poisson_disk_sampling::{
    PoissonDiskOptions, PoissonDiskSamples, SurfaceSample, poisson_disk_sampling,
    poisson_disk_sampling_nested,
};
pub use polygon_triangulation::triangulate_polygons;
pub use solid_angle_curvature::{OrientedPoint, solid_angle_curvature, triangle_solid_angle};
pub use spatial_grid::{IncrementalGrid, SpatialGrid};
