//! What to draw ([`Scene`], [`Overlay`]) and how ([`RenderOptions`]).

use fieldtex_core::Image;
use fieldtex_mesh::TriMesh;

/// Which world axis points up on screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// +Y up (glTF, most scans). Azimuth 0 looks from +Z towards −Z, +X to the right.
    #[default]
    Y,
    /// +Z up (CAD, many PLY files). Azimuth 0 looks from −Y towards +Y, +X to the right.
    Z,
}

/// How surface normals are chosen for lighting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shading {
    /// Area-weighted vertex normals interpolated over each triangle.
    #[default]
    Smooth,
    /// One normal per triangle (facets visible).
    Flat,
    /// No lighting: the albedo (texture, vertex colour or base colour) as is.
    Unlit,
}

/// Where the light comes from. Lighting is Lambert plus ambient, two-sided.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Light {
    /// A light attached to the camera, raised and moved left by a fixed small angle so
    /// that silhouettes darken and shapes read well from any view.
    #[default]
    Headlight,
    /// A light fixed in the world: unit-free direction *towards* the light.
    Key { direction: [f64; 3] },
}

/// Shape of a 2-D marker.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MarkerShape {
    #[default]
    Disc,
    Ring,
    Square,
    /// Equilateral triangle pointing up.
    Triangle,
    /// Equilateral triangle pointing down.
    TriangleDown,
    /// Diagonal cross (×).
    Cross,
    /// Upright cross (+).
    Plus,
}

/// A polyline in `D` dimensions: [`Polyline3`] is drawn over the mesh (crest lines, user
/// curves, streamlines), [`crate::Polyline2`] on an image.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline<const D: usize> {
    /// Vertices (world coordinates in 3-D, pixel coordinates in 2-D); in 3-D non-finite
    /// ones break the line.
    pub points: Vec<[f64; D]>,
    /// Join the last point back to the first.
    pub closed: bool,
    /// sRGB colour, alpha used for blending.
    pub color: [f32; 4],
    /// Width in output pixels.
    pub width: f64,
}

/// A polyline in 3-D drawn over the mesh.
pub type Polyline3 = Polyline<3>;

impl<const D: usize> Polyline<D> {
    /// An open polyline, dark red, 2 px wide.
    pub fn new(points: Vec<[f64; D]>) -> Self {
        Self { points, closed: false, color: [0.85, 0.1, 0.1, 1.0], width: 2.0 }
    }
    pub fn with_color(mut self, color: [f32; 4]) -> Self {
        self.color = color;
        self
    }
    pub fn with_width(mut self, width: f64) -> Self {
        self.width = width;
        self
    }
    pub fn closed(mut self, closed: bool) -> Self {
        self.closed = closed;
        self
    }
}

/// How a tangent-field glyph is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GlyphStyle {
    /// From the sample point along the direction, with an arrow head (vector fields).
    Arrow,
    /// A segment centred on the sample point, no head (sign-free 2-RoSy fields).
    #[default]
    Segment,
}

/// Tangent-field glyphs: one short arrow or segment per sample point.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldGlyphs {
    /// `#S × 3` sample positions (world).
    pub positions: Vec<[f64; 3]>,
    /// `#S × 3` directions (world; normalised here, zero/non-finite ones skipped).
    pub directions: Vec<[f64; 3]>,
    /// Glyph length in world units; `None` = 2 % of the bounding-box diagonal.
    pub length: Option<f64>,
    pub style: GlyphStyle,
    /// sRGB colour.
    pub color: [f32; 4],
    /// Width in output pixels.
    pub width: f64,
}

impl FieldGlyphs {
    /// Dark blue segments, 1.5 px wide, default length.
    pub fn new(positions: Vec<[f64; 3]>, directions: Vec<[f64; 3]>) -> Self {
        Self {
            positions,
            directions,
            length: None,
            style: GlyphStyle::Segment,
            color: [0.05, 0.1, 0.45, 1.0],
            width: 1.5,
        }
    }
    pub fn with_style(mut self, style: GlyphStyle) -> Self {
        self.style = style;
        self
    }
    pub fn with_length(mut self, length: f64) -> Self {
        self.length = Some(length);
        self
    }
    pub fn with_color(mut self, color: [f32; 4]) -> Self {
        self.color = color;
        self
    }
    pub fn with_width(mut self, width: f64) -> Self {
        self.width = width;
        self
    }
}

/// The builder setters of a marker's look (`shape`, `radius`, `color`, `outline`),
/// shared by the 3-D [`Markers`] and the 2-D [`crate::Marker2`], whose fields carry
/// the same names and meanings. A macro because the setters are methods of two types.
macro_rules! marker_style_setters {
    () => {
        pub fn with_shape(mut self, shape: $crate::MarkerShape) -> Self {
            self.shape = shape;
            self
        }
        pub fn with_radius(mut self, radius: f64) -> Self {
            self.radius = radius;
            self
        }
        pub fn with_color(mut self, color: [f32; 4]) -> Self {
            self.color = color;
            self
        }
        pub fn with_outline(mut self, outline: Option<[f32; 4]>) -> Self {
            self.outline = outline;
            self
        }
    };
}
pub(crate) use marker_style_setters;

/// Screen-space markers at 3-D points (singularities, picked points).
#[derive(Debug, Clone, PartialEq)]
pub struct Markers {
    /// `#M × 3` world positions.
    pub positions: Vec<[f64; 3]>,
    pub shape: MarkerShape,
    /// Radius in output pixels.
    pub radius: f64,
    /// sRGB fill colour.
    pub color: [f32; 4],
    /// Optional outline colour (1 px wide) for contrast on any background.
    pub outline: Option<[f32; 4]>,
    /// When false the markers are drawn on top even if hidden by the surface.
    pub depth_test: bool,
}

impl Markers {
    /// Red discs, radius 5 px, black outline, depth tested.
    pub fn new(positions: Vec<[f64; 3]>) -> Self {
        Self {
            positions,
            shape: MarkerShape::Disc,
            radius: 5.0,
            color: [0.9, 0.1, 0.1, 1.0],
            outline: Some([0.0, 0.0, 0.0, 1.0]),
            depth_test: true,
        }
    }
    marker_style_setters!();
    pub fn with_depth_test(mut self, depth_test: bool) -> Self {
        self.depth_test = depth_test;
        self
    }
}

/// Something drawn over the shaded mesh, in the order given.
#[derive(Debug, Clone, PartialEq)]
pub enum Overlay {
    Polyline(Polyline3),
    Glyphs(FieldGlyphs),
    Markers(Markers),
}

/// The mesh and what colours it, plus overlays.
///
/// Albedo precedence: `texture` (when the mesh has corner UVs), else the mesh's vertex
/// colours, else `base_color`. Textures are sampled bilinearly with repeat wrapping at
/// the perspective-correct UV; UV (0, 0) is the lower-left of the image (the bottom
/// row), as in [`fieldtex_mesh::CornerUvs`].
#[derive(Debug, Clone)]
pub struct Scene<'a> {
    pub mesh: &'a TriMesh,
    pub texture: Option<&'a Image>,
    /// sRGB albedo used when neither texture nor vertex colours apply.
    pub base_color: [f32; 4],
    /// Use the mesh's vertex colours when no texture applies (default true).
    pub use_vertex_colors: bool,
    pub overlays: Vec<Overlay>,
}

impl<'a> Scene<'a> {
    /// A scene with the mesh only, light grey.
    pub fn new(mesh: &'a TriMesh) -> Self {
        Self {
            mesh,
            texture: None,
            base_color: [0.78, 0.78, 0.76, 1.0],
            use_vertex_colors: true,
            overlays: Vec::new(),
        }
    }
    pub fn with_texture(mut self, texture: &'a Image) -> Self {
        self.texture = Some(texture);
        self
    }
    pub fn with_base_color(mut self, color: [f32; 4]) -> Self {
        self.base_color = color;
        self
    }
    pub fn with_vertex_colors(mut self, use_them: bool) -> Self {
        self.use_vertex_colors = use_them;
        self
    }
    pub fn with_overlay(mut self, overlay: Overlay) -> Self {
        self.overlays.push(overlay);
        self
    }
}

/// Camera, quality and look of a render. Validated (clamped) once in `render`.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Output width and height in pixels (square). Default 800; clamped to 1..=4096.
    pub size: usize,
    /// `(azimuth°, elevation°)` of the camera around the up axis. Default `(35, 25)`,
    /// a three-quarter view from the front right and slightly above. Elevation is
    /// clamped to ±89.5°.
    pub view: (f64, f64),
    /// Default [`UpAxis::Y`].
    pub up: UpAxis,
    /// Vertical (= horizontal) field of view in degrees. Default 30; clamped to 1..=120.
    pub fov_deg: f64,
    /// Samples per pixel along each axis (box-filtered down). Default 2; clamped to
    /// 1..=4 and so that `size · supersample ≤ 4096` (bounded memory: ~20 bytes per
    /// sample).
    pub supersample: usize,
    /// Default [`Shading::Smooth`].
    pub shading: Shading,
    /// Default [`Light::Headlight`].
    pub light: Light,
    /// Ambient fraction in `[0, 1]`; lit colour = albedo·(ambient + (1−ambient)·max(0, n·l)).
    /// Default 0.3.
    pub ambient: f32,
    /// Albedo factor for back faces (seen through holes of open meshes), so that the
    /// inside reads as such. Default 0.8.
    pub backface_factor: f32,
    /// sRGB background colour. Default light grey `[0.94, 0.94, 0.95, 1]`.
    pub background: [f32; 4],
    /// The bounding sphere fills `1/margin` of the view. Default 1.08.
    pub margin: f64,
    /// Overlay depth bias as a fraction of the bounding-box diagonal: overlay
    /// fragments up to this much behind the surface still show. Default 0.004.
    pub depth_bias: f64,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            size: 800,
            view: (35.0, 25.0),
            up: UpAxis::Y,
            fov_deg: 30.0,
            supersample: 2,
            shading: Shading::Smooth,
            light: Light::Headlight,
            ambient: 0.3,
            backface_factor: 0.8,
            background: [0.94, 0.94, 0.95, 1.0],
            margin: 1.08,
            depth_bias: 0.004,
        }
    }
}

impl RenderOptions {
    pub fn with_size(mut self, size: usize) -> Self {
        self.size = size;
        self
    }
    pub fn with_view(mut self, azimuth_deg: f64, elevation_deg: f64) -> Self {
        self.view = (azimuth_deg, elevation_deg);
        self
    }
    pub fn with_up(mut self, up: UpAxis) -> Self {
        self.up = up;
        self
    }
    pub fn with_supersample(mut self, supersample: usize) -> Self {
        self.supersample = supersample;
        self
    }
    pub fn with_shading(mut self, shading: Shading) -> Self {
        self.shading = shading;
        self
    }
    pub fn with_light(mut self, light: Light) -> Self {
        self.light = light;
        self
    }
    pub fn with_background(mut self, background: [f32; 4]) -> Self {
        self.background = background;
        self
    }

    /// A copy with every field brought into its documented range (non-finite values
    /// replaced by defaults).
    pub fn validated(&self) -> Self {
        let d = Self::default();
        let fin = |v: f64, dflt: f64| if v.is_finite() { v } else { dflt };
        let finf = |v: f32, dflt: f32| if v.is_finite() { v } else { dflt };
        let mut bg = self.background;
        for (c, dc) in bg.iter_mut().zip(d.background) {
            *c = finf(*c, dc).clamp(0.0, 1.0);
        }
        Self {
            size: self.size.clamp(1, 4096),
            view: (fin(self.view.0, d.view.0), fin(self.view.1, d.view.1).clamp(-89.5, 89.5)),
            up: self.up,
            fov_deg: fin(self.fov_deg, d.fov_deg).clamp(1.0, 120.0),
            supersample: self.supersample.clamp(1, 4).min((4096 / self.size.clamp(1, 4096)).max(1)),
            shading: self.shading,
            light: self.light,
            ambient: finf(self.ambient, d.ambient).clamp(0.0, 1.0),
            backface_factor: finf(self.backface_factor, d.backface_factor).clamp(0.0, 1.0),
            background: bg,
            margin: fin(self.margin, d.margin).clamp(1.0, 100.0),
            depth_bias: fin(self.depth_bias, d.depth_bias).clamp(0.0, 1.0),
        }
    }
}
