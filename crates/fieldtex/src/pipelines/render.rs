//! `fieldtex render`: a shaded (and textured, when the model has a texture) preview.

use crate::{Error, Result};
use fieldtex_render::{RenderOptions, Scene, render};
use std::path::Path;

/// Options of [`render_file`].
#[derive(Debug, Clone)]
pub struct RenderCommandOptions {
    /// Square image size in pixels.
    pub size: usize,
    /// `(azimuth°, elevation°)`; `None` uses the renderer's default three-quarter view.
    pub view: Option<(f64, f64)>,
}

impl Default for RenderCommandOptions {
    fn default() -> Self {
        Self { size: 800, view: None }
    }
}

/// Renders the model at `model` to `out` (PNG, or JPEG for `.jpg`/`.jpeg`).
pub fn render_file(model: &Path, out: &Path, options: &RenderCommandOptions) -> Result<()> {
    if options.size == 0 || options.size > 8192 {
        return Err(Error::bad_input(
            None,
            format!("--size must be in 1..=8192, got {}", options.size),
        ));
    }
    crate::outputs::begin_command();
    fieldtex_io::ensure_not_input(out, &[model])?;
    let ext = out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "jpg" | "jpeg")) {
        return Err(Error::bad_input(
            Some(out),
            "unknown image format: name the output .png, .jpg or .jpeg",
        ));
    }
    let loaded = fieldtex_io::read_mesh(model)?;
    let image = preview(&loaded.mesh, loaded.base_color.as_ref(), options.size, options.view);
    // Regression: `--out x.jpg` wrote PNG bytes; the format follows the extension.
    fieldtex_io::write_image(out, &image)?;
    Ok(())
}

/// The preview every pipeline writes as `preview.png`.
pub(crate) fn preview(
    mesh: &fieldtex_mesh::TriMesh,
    texture: Option<&fieldtex_core::Image>,
    size: usize,
    view: Option<(f64, f64)>,
) -> fieldtex_core::Image {
    let mut scene = Scene::new(mesh);
    if let Some(t) = texture {
        scene = scene.with_texture(t);
    }
    let mut opts = RenderOptions { size, ..Default::default() };
    if let Some(v) = view {
        opts.view = v;
    }
    render(&scene, &opts)
}
