//! The error type of every reader and writer in this crate.
//!
//! Every variant names the file (as given by the caller, or `<memory>` for the
//! from-bytes readers), the element or line where the problem was found, and what the
//! user can do about it. Bad files never panic; they end up here.

use std::path::Path;

/// Name used in messages for data that did not come from a file.
pub const MEMORY_NAME: &str = "<memory>";

/// Errors of `fieldtex-io`.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// The operating system refused a read or write.
    #[error("{file}: cannot {action}: {source}. Check that the path exists and is accessible.")]
    Os {
        file: String,
        action: &'static str,
        #[source]
        source: std::io::Error,
    },

    /// The file has no bytes at all.
    #[error("{file}: the file is empty (0 bytes). Re-export it or pick another file.")]
    EmptyFile { file: String },

    /// Neither the content nor the extension identifies a supported format.
    #[error(
        "{file}: unrecognised file format ({detail}). Supported meshes: OBJ, PLY, STL, glTF/GLB; \
         images: PNG, JPEG."
    )]
    UnknownFormat { file: String, detail: String },

    /// Malformed content at a known place (`location` is e.g. `line 12`, `byte 4096`,
    /// `vertex 7`).
    #[error(
        "{file}: {location}: {message}. The file is malformed; re-export it or fix that {location}."
    )]
    Parse { file: String, location: String, message: String },

    /// The file ends before the data its header or structure announces.
    #[error(
        "{file}: truncated: {what} needs at least {needed} bytes but only {available} remain. \
         The file was cut short (interrupted download or copy?); get a complete copy."
    )]
    Truncated { file: String, what: String, needed: u64, available: u64 },

    /// A face refers to a vertex that does not exist.
    #[error(
        "{file}: face {face} uses vertex index {index}, but only {n_vertices} vertices exist \
         (valid: 0..{n_vertices} after converting to 0-based). The file is corrupt; re-export it."
    )]
    IndexOutOfRange { file: String, face: usize, index: i64, n_vertices: usize },

    /// The file parsed but holds no triangle.
    #[error(
        "{file}: the mesh has no triangles ({detail}). Nothing to work on; pick a file with faces."
    )]
    EmptyMesh { file: String, detail: String },

    /// Valid input that this crate does not handle.
    #[error(
        "{file}: unsupported: {what}. Convert the file (e.g. re-export) to a supported variant."
    )]
    Unsupported { file: String, what: String },

    /// An image could not be decoded or encoded.
    #[error("{file}: image error: {message}. Re-save the image as PNG or JPEG.")]
    Image { file: String, message: String },

    /// Image dimensions above [`crate::MAX_IMAGE_SIDE`] / [`crate::MAX_IMAGE_PIXELS`].
    #[error(
        "{file}: image of {width} × {height} pixels is larger than the supported maximum \
         ({max_side} per side, {max_pixels} pixels). Downscale it first."
    )]
    ImageTooLarge { file: String, width: u64, height: u64, max_side: u64, max_pixels: u64 },

    /// A writer was handed data it cannot write (caller's data, not a file problem).
    #[error("{file}: cannot write: {message}")]
    InvalidData { file: String, message: String },

    /// The path is not a regular file (a FIFO, a device, a socket, a directory).
    #[error(
        "{file}: not a regular file ({what}); fieldtex reads only regular files. \
         Copy the data into a file and pass that."
    )]
    NotRegularFile { file: String, what: String },

    /// The file is larger than the cap for its kind.
    #[error(
        "{file}: the file is {size} bytes, more than the {max} bytes fieldtex reads for this \
         kind of input. Use a smaller file."
    )]
    TooLarge { file: String, size: u64, max: u64 },

    /// A file named inside an asset (OBJ `mtllib`/`map_Kd`, glTF URI) is outside the
    /// asset's folder.
    #[error(
        "{file}: the {what} {reference:?} is refused: {why}. Only files inside the asset's \
         folder are read; copy the file next to the asset and name it relatively."
    )]
    OutsideAssetFolder { file: String, what: String, reference: String, why: String },

    /// An output path is one of the inputs; inputs are never overwritten.
    #[error(
        "{file}: refusing to overwrite an input file. Choose another output path or directory."
    )]
    WouldOverwriteInput { file: String },
}

impl IoError {
    pub(crate) fn os(file: &Path, action: &'static str, source: std::io::Error) -> Self {
        IoError::Os { file: file.display().to_string(), action, source }
    }

    pub(crate) fn parse(
        file: &str,
        location: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        IoError::Parse {
            file: file.to_string(),
            location: location.into(),
            message: message.into(),
        }
    }

    pub(crate) fn invalid(file: &Path, message: impl Into<String>) -> Self {
        IoError::InvalidData { file: file.display().to_string(), message: message.into() }
    }
}

/// Every reader and writer error is bad input: each names a file the user can fix,
/// replace or move (the OS refusing a path included).
impl fieldtex_core::HasErrorKind for IoError {
    fn kind(&self) -> fieldtex_core::ErrorKind {
        fieldtex_core::ErrorKind::BadInput
    }
}
