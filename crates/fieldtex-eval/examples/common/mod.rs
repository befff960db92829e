//! Readers shared by this crate's examples (not part of the library).

#![allow(dead_code)] // each example takes a subset

/// An image file as RGB floats in `[0, 1]`, with its width and height.
pub fn rgb(path: &str) -> (Vec<f32>, usize, usize) {
    let img = image::open(path).unwrap_or_else(|e| panic!("{path}: {e}")).to_rgb8();
    let (w, h) = (img.width() as usize, img.height() as usize);
    (img.as_raw().iter().map(|&v| v as f32 / 255.0).collect(), w, h)
}

/// The little-endian float32 payload of a version-1 `.npy` file (e.g. orient's
/// `field.npy`, H×W×2).
pub fn npy(path: &str) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let hl = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    bytes[10 + hl..].chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
}

/// An `orient` output folder (`texture.png`, `field.npy`) and its exemplar, read.
pub struct OrientRun {
    pub out: (Vec<f32>, usize, usize),
    pub exemplar: (Vec<f32>, usize, usize),
    pub field: Vec<f32>,
}

impl OrientRun {
    pub fn read(out_dir: &str, exemplar: &str) -> Self {
        let (texture, field) = (format!("{out_dir}/texture.png"), format!("{out_dir}/field.npy"));
        Self::read_files(&texture, exemplar, &field)
    }

    /// An output image, its exemplar and its field (H×W×2 `.npy`) named one by one.
    pub fn read_files(texture: &str, exemplar: &str, field: &str) -> Self {
        Self { out: rgb(texture), exemplar: rgb(exemplar), field: npy(field) }
    }

    /// Views of the output, the exemplar and the field.
    pub fn views(
        &self,
    ) -> (fieldtex_eval::ImageView<'_>, fieldtex_eval::ImageView<'_>, fieldtex_eval::FieldView<'_>)
    {
        let (o, ow, oh) = (&self.out.0, self.out.1, self.out.2);
        let (e, ew, eh) = (&self.exemplar.0, self.exemplar.1, self.exemplar.2);
        (
            fieldtex_eval::ImageView::new(o, ow, oh, 3).unwrap(),
            fieldtex_eval::ImageView::new(e, ew, eh, 3).unwrap(),
            fieldtex_eval::FieldView::new(&self.field, ow, oh).unwrap(),
        )
    }
}
