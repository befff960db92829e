//! Software preview renderer of fieldtex.
//!
//! [`render`] rasterises a [`Scene`] (a [`fieldtex_mesh::TriMesh`] with an optional
//! texture or vertex colours, plus [`Overlay`]s: 3-D polylines, tangent-field glyphs,
//! markers) into a square [`fieldtex_core::Image`]; [`render_image_overlay`] draws
//! markers and lines on a 2-D image (texture previews). Every pipeline's
//! `preview.png` comes from here.
//!
//! Conventions: images are sRGB RGBA `f32`, top row first; shading is computed in
//! linear light. UV (0, 0) is the lower-left of a texture. The camera orbits the
//! bounding sphere: `view = (azimuth°, elevation°)` around the up axis (+Y by default;
//! azimuth 0 looks down −Z with +X to the right).
//!
//! Architecture invariant: no file I/O, no printing; output is byte-identical for any
//! number of rayon threads.

mod camera;
mod draw2d;
pub mod image_overlay;
mod overlay3d;
mod rasterize_mesh;
mod render;
mod scene;
mod srgb_lut;

pub use camera::Camera;
pub use image_overlay::{
    ImageOverlay, ImageOverlayOptions, Marker2, Polyline2, draw_marker, draw_polyline,
    orientation_glyphs, render_image_overlay,
};
pub use render::{render, scene_camera};
pub use scene::{
    FieldGlyphs, GlyphStyle, Light, MarkerShape, Markers, Overlay, Polyline, Polyline3,
    RenderOptions, Scene, Shading, UpAxis,
};
