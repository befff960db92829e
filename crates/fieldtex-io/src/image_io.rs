//! Image reading (PNG, JPEG, TGA, BMP, TIFF, PNM: the `image` crate's decoders) into the
//! shared [`Image`] (RGBA `f32`, sRGB-encoded, top row first) and PNG writing.
//!
//! Reading accepts 8- and 16-bit gray, gray+alpha, RGB and RGBA PNGs and baseline or
//! progressive JPEGs; integer samples are divided by their maximum (255 or 65535), gray
//! is copied to R, G and B, missing alpha is 1. Dimensions are read from the header
//! first and refused above [`MAX_IMAGE_SIDE`] per side or [`MAX_IMAGE_PIXELS`] in all,
//! before any pixel memory is allocated.
//!
//! Writing quantises to 8 bits (`round(255·clamp(c, 0, 1))`, NaN → 0); an image whose
//! alpha is 1 everywhere is written as RGB, otherwise RGBA. [`write_png_gray16`] writes
//! single-channel 16-bit data (masks, height or distance maps).

use crate::{IoError, atomic_write};
use fieldtex_core::Image;
use image::{DynamicImage, ImageDecoder, ImageEncoder, ImageReader};
use std::io::Cursor;
use std::path::Path;

/// Largest accepted width or height, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 32_768;
/// Largest accepted pixel count (8192², i.e. 1 GiB as RGBA `f32`).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// Reads a PNG or JPEG file (format from content, not extension).
pub fn read_image(path: &Path) -> Result<Image, IoError> {
    let bytes = crate::read_input_file(path, crate::InputKind::Image, "read the image")?;
    read_image_bytes(&bytes, &path.display().to_string())
}

/// Decodes PNG or JPEG bytes; `name` is used in messages.
pub fn read_image_bytes(bytes: &[u8], name: &str) -> Result<Image, IoError> {
    let img_err = |m: String| IoError::Image { file: name.to_string(), message: m };
    if bytes.is_empty() {
        return Err(img_err("the file is empty (0 bytes)".into()));
    }
    let reader = || {
        ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| img_err(format!("cannot read the header: {e}")))
    };
    let r = reader()?;
    if r.format().is_none() {
        return Err(IoError::UnknownFormat {
            file: name.to_string(),
            detail: "not a PNG, JPEG, TGA, BMP, TIFF or PNM image".into(),
        });
    }
    let decoder = r
        .into_decoder()
        .map_err(|e| img_err(format!("corrupt or unsupported image: {}", decoder_words(&e))))?;
    let (w, h) = decoder.dimensions();
    check_dimensions(name, w as u64, h as u64)?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    limits.max_alloc = Some(MAX_IMAGE_PIXELS * 16);
    let mut r = reader()?;
    r.limits(limits);
    let dynimg =
        r.decode().map_err(|e| img_err(format!("corrupt image data: {}", decoder_words(&e))))?;
    Ok(dynamic_to_image(dynimg))
}

/// The decoder's explanation when it is plain words; a generic one when it carries
/// the decoder's internal structures (the PNG decoder prints chunk types as Rust debug
/// text, e.g. `ChunkType { type: … }`).
fn decoder_words(e: &image::ImageError) -> String {
    let text = e.to_string();
    let debug_like = text.contains(['{', '}']) || text.contains("Some(") || text.contains("Err(");
    if !debug_like {
        return text;
    }
    match e {
        image::ImageError::Decoding(d) => match d.format_hint() {
            image::error::ImageFormatHint::Exact(f) => {
                let name = f.extensions_str().first().map_or("image".into(), |x| x.to_uppercase());
                format!("the {name} data is malformed (a broken chunk or a truncated file)")
            }
            _ => "the data is malformed (a broken chunk or a truncated file)".into(),
        },
        _ => "the decoder could not read it".into(),
    }
}

fn check_dimensions(name: &str, w: u64, h: u64) -> Result<(), IoError> {
    if w == 0 || h == 0 {
        return Err(IoError::Image {
            file: name.to_string(),
            message: format!("the image is {w} × {h} pixels (empty)"),
        });
    }
    if w > MAX_IMAGE_SIDE as u64 || h > MAX_IMAGE_SIDE as u64 || w * h > MAX_IMAGE_PIXELS {
        return Err(IoError::ImageTooLarge {
            file: name.to_string(),
            width: w,
            height: h,
            max_side: MAX_IMAGE_SIDE as u64,
            max_pixels: MAX_IMAGE_PIXELS,
        });
    }
    Ok(())
}

fn dynamic_to_image(d: DynamicImage) -> Image {
    let (w, h) = (d.width() as usize, d.height() as usize);
    let pixels: Vec<[f32; 4]> = match d {
        DynamicImage::ImageRgba8(b) => b.pixels().map(|p| p.0.map(|c| c as f32 / 255.0)).collect(),
        DynamicImage::ImageRgb8(b) => b
            .pixels()
            .map(|p| [p.0[0] as f32 / 255.0, p.0[1] as f32 / 255.0, p.0[2] as f32 / 255.0, 1.0])
            .collect(),
        DynamicImage::ImageLuma8(b) => b
            .pixels()
            .map(|p| {
                let g = p.0[0] as f32 / 255.0;
                [g, g, g, 1.0]
            })
            .collect(),
        other => other.to_rgba32f().pixels().map(|p| p.0).collect(),
    };
    Image { width: w, height: h, pixels }
}

#[inline]
fn quantize8(c: f32) -> u8 {
    if c.is_nan() { 0 } else { (c.clamp(0.0, 1.0) * 255.0).round() as u8 }
}

/// Encodes an image as an 8-bit PNG (RGB when fully opaque, else RGBA).
pub fn encode_png(image: &Image) -> Result<Vec<u8>, IoError> {
    let name = "<png encoder>";
    if image.width == 0 || image.height == 0 || image.pixels.len() != image.width * image.height {
        return Err(IoError::InvalidData {
            file: name.into(),
            message: format!(
                "image is {} × {} with {} pixels",
                image.width,
                image.height,
                image.pixels.len()
            ),
        });
    }
    let opaque = image.pixels.iter().all(|p| quantize8(p[3]) == 255);
    let data: Vec<u8> = if opaque {
        image
            .pixels
            .iter()
            .flat_map(|p| [quantize8(p[0]), quantize8(p[1]), quantize8(p[2])])
            .collect()
    } else {
        image.pixels.iter().flat_map(|p| p.map(quantize8)).collect()
    };
    let ty = if opaque { image::ExtendedColorType::Rgb8 } else { image::ExtendedColorType::Rgba8 };
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&data, image.width as u32, image.height as u32, ty)
        .map_err(|e| IoError::Image { file: name.into(), message: e.to_string() })?;
    Ok(out)
}

/// Writes an 8-bit PNG (RGB when fully opaque, else RGBA) atomically.
pub fn write_png(path: &Path, image: &Image) -> Result<(), IoError> {
    let bytes = encode_png(image).map_err(|e| rename_file(e, path))?;
    atomic_write(path, &bytes)
}

/// Writes an image in the format named by the extension of `path`: `.png` (8-bit, as
/// [`write_png`]) or `.jpg`/`.jpeg` (baseline JPEG, quality 92, alpha dropped); any
/// other extension is refused with a message naming the supported ones.
pub fn write_image(path: &Path, image: &Image) -> Result<(), IoError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => write_png(path, image),
        Some("jpg" | "jpeg") => {
            let bytes = encode_jpeg(image, 92).map_err(|e| rename_file(e, path))?;
            atomic_write(path, &bytes)
        }
        _ => {
            Err(IoError::invalid(path, "unknown image format: use a .png, .jpg or .jpeg extension"))
        }
    }
}

/// Encodes an image as a baseline 8-bit RGB JPEG of the given quality (1–100).
pub fn encode_jpeg(image: &Image, quality: u8) -> Result<Vec<u8>, IoError> {
    let name = "<jpeg encoder>";
    if image.width == 0 || image.height == 0 || image.pixels.len() != image.width * image.height {
        return Err(IoError::InvalidData {
            file: name.into(),
            message: format!("image is {} × {}", image.width, image.height),
        });
    }
    let data: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|p| [quantize8(p[0]), quantize8(p[1]), quantize8(p[2])])
        .collect();
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, quality.clamp(1, 100))
        .write_image(&data, image.width as u32, image.height as u32, image::ExtendedColorType::Rgb8)
        .map_err(|e| IoError::Image { file: name.into(), message: e.to_string() })?;
    Ok(out)
}

/// Writes a 16-bit single-channel PNG from `width * height` values in `[0, 1]` (row-major,
/// top row first; clamped, NaN → 0) atomically.
pub fn write_png_gray16(
    path: &Path,
    width: usize,
    height: usize,
    values: &[f32],
) -> Result<(), IoError> {
    if width == 0 || height == 0 || values.len() != width * height {
        return Err(IoError::invalid(
            path,
            format!("{} values for a {width} × {height} image", values.len()),
        ));
    }
    let data: Vec<u8> = values
        .iter()
        .flat_map(|&c| {
            let v = if c.is_nan() { 0 } else { (c.clamp(0.0, 1.0) * 65535.0).round() as u16 };
            // PngEncoder takes native-endian 16-bit samples.
            v.to_ne_bytes()
        })
        .collect();
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&data, width as u32, height as u32, image::ExtendedColorType::L16)
        .map_err(|e| IoError::Image { file: path.display().to_string(), message: e.to_string() })?;
    atomic_write(path, &out)
}

fn rename_file(e: IoError, path: &Path) -> IoError {
    match e {
        IoError::InvalidData { message, .. } => IoError::invalid(path, message),
        IoError::Image { message, .. } => {
            IoError::Image { file: path.display().to_string(), message }
        }
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_rgba_and_rgb() {
        let mut im = Image::new(3, 2, [0.2, 0.4, 0.6, 1.0]);
        im.set(2, 1, [1.0, 0.0, 0.5, 1.0]);
        let back = read_image_bytes(&encode_png(&im).unwrap(), "x").unwrap();
        assert_eq!((back.width, back.height), (3, 2));
        for (a, b) in im.pixels.iter().zip(&back.pixels) {
            for k in 0..4 {
                assert!((a[k] - b[k]).abs() <= 0.5 / 255.0 + 1e-6);
            }
        }
        im.set(0, 0, [0.0, 0.0, 0.0, 0.5]);
        let back = read_image_bytes(&encode_png(&im).unwrap(), "x").unwrap();
        assert!((back.get(0, 0)[3] - 128.0 / 255.0).abs() < 1e-6);
    }

    #[test]
    fn corrupt_and_empty_images_are_errors() {
        // Regression: an empty .png was told to "re-export the mesh".
        let e = read_image_bytes(b"", "e.png").unwrap_err();
        assert!(matches!(e, IoError::Image { .. }), "{e:?}");
        assert!(!e.to_string().contains("mesh"), "{e}");
        let mut png = encode_png(&Image::new(4, 4, [0.5; 4])).unwrap();
        png.truncate(png.len() / 2);
        let e = read_image_bytes(&png, "t.png").unwrap_err().to_string();
        assert!(e.contains("t.png"), "{e}");
        let e = read_image_bytes(b"not an image at all", "g.png").unwrap_err().to_string();
        assert!(e.contains("g.png"), "{e}");
    }
}
