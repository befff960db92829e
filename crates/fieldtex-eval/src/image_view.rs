//! Borrowed views of images and fields as flat `f32` buffers with a shape.

use crate::EvalError;
use fieldtex_core::Image;

/// An interleaved `height × width × channels` `f32` image, row-major, top row first
/// (x right, y down), usually sRGB values in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageView<'a> {
    pub data: &'a [f32],
    pub width: usize,
    pub height: usize,
    pub channels: usize,
}

impl<'a> ImageView<'a> {
    /// Checks the buffer length and that every value is finite.
    pub fn new(
        data: &'a [f32],
        width: usize,
        height: usize,
        channels: usize,
    ) -> Result<Self, EvalError> {
        let expected = width.checked_mul(height).and_then(|n| n.checked_mul(channels));
        if expected != Some(data.len()) || channels == 0 {
            return Err(EvalError::BufferSize {
                what: "image",
                width,
                height,
                channels,
                expected: expected.unwrap_or(usize::MAX),
                found: data.len(),
            });
        }
        if let Some((index, &value)) = data.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(EvalError::NonFinite { what: "image", index, value });
        }
        Ok(Self { data, width, height, channels })
    }

    /// Value of channel `c` at pixel `(x, y)`.
    #[inline]
    pub fn at(&self, x: usize, y: usize, c: usize) -> f32 {
        self.data[(y * self.width + x) * self.channels + c]
    }

    /// Per-pixel luminance: Rec. 709 weights on the first three channels (on the values
    /// as stored, i.e. sRGB-encoded), the single channel of a grey image, or the mean
    /// of two channels.
    pub fn luminance(&self) -> Vec<f32> {
        let c = self.channels;
        self.data
            .chunks_exact(c)
            .map(|p| match c {
                1 => p[0],
                2 => 0.5 * (p[0] + p[1]),
                _ => 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2],
            })
            .collect()
    }
}

/// The RGB channels of an [`Image`] as an interleaved buffer for [`ImageView::new`]
/// with 3 channels (alpha dropped).
pub fn rgb_buffer(image: &Image) -> Vec<f32> {
    image.pixels.iter().flat_map(|p| [p[0], p[1], p[2]]).collect()
}

/// A 2-D direction field `height × width × 2`: `[row, col] = (dx, dy)` in pixel
/// coordinates (x right, y down), the layout of fieldtex's `field.npy`. Vectors need
/// not be unit; zero or non-finite vectors mean "no direction here".
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldView<'a> {
    pub data: &'a [f32],
    pub width: usize,
    pub height: usize,
}

impl<'a> FieldView<'a> {
    /// Checks the buffer length (non-finite vectors are allowed and skipped).
    pub fn new(data: &'a [f32], width: usize, height: usize) -> Result<Self, EvalError> {
        let expected = width.checked_mul(height).and_then(|n| n.checked_mul(2));
        if expected != Some(data.len()) {
            return Err(EvalError::BufferSize {
                what: "field",
                width,
                height,
                channels: 2,
                expected: expected.unwrap_or(usize::MAX),
                found: data.len(),
            });
        }
        Ok(Self { data, width, height })
    }

    /// The vector at pixel `(x, y)`.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> [f32; 2] {
        let i = 2 * (y * self.width + x);
        [self.data[i], self.data[i + 1]]
    }
}
