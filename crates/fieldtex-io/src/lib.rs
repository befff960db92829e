//! File formats of fieldtex — the only crate that touches files.
//!
//! - Mesh readers: [`read_mesh`] / [`read_mesh_bytes`] for OBJ (+MTL), PLY, STL, glTF/GLB,
//!   returning a [`LoadedMesh`] (mesh, base-colour texture, warnings, format). The
//!   format is recognised from content first, extension second ([`sniff_mesh_format`]).
//! - Images: [`read_image`] (PNG/JPEG, 8/16-bit, gray/alpha/RGB/RGBA), [`write_png`],
//!   [`write_png_gray16`], [`encode_png`].
//! - Writers: [`write_glb`] (validator-clean GLB), [`write_obj`] (+MTL+PNG),
//!   [`write_ply`] (extra vertex properties), [`write_obj_polylines`].
//! - Arrays: [`write_npy_f32`] / [`read_npy_f32`] (`<f4`, C order).
//! - Atomic output: [`atomic_write`] (temporary file, fsync, rename) and
//!   [`ensure_not_input`].
//!
//! Architecture invariants: readers never panic on bad data, never allocate more than a
//! small multiple of the file size (claimed counts are checked against the file length
//! first), and never loop beyond the file's content; every error is an [`IoError`]
//! naming the file, the place and what to do. Writers only ever write through
//! [`atomic_write`].

mod atomic_write;
mod error;
mod glb_writer;
mod gltf_reader;
mod image_io;
mod input_files;
mod mesh_checks;
mod mesh_format;
mod mtl_reader;
mod npy;
mod nrrd;
mod obj_reader;
mod obj_writer;
mod output_dir;
mod ply_reader;
mod ply_writer;
mod point_ply_writer;
mod polyline_reader;
mod read_mesh;
mod stl_reader;

pub use atomic_write::{atomic_write, ensure_not_input};
pub use error::{IoError, MEMORY_NAME};
pub use glb_writer::{GlbOptions, encode_glb, write_glb};
pub use image_io::{
    MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, encode_jpeg, encode_png, read_image, read_image_bytes,
    write_image, write_png, write_png_gray16,
};
pub use input_files::{
    InputKind, ensure_not_read, files_read, forget_files_read, read_input_file, resolve_confined,
};
pub use mesh_format::{MeshFormat, sniff_mesh_format};
pub use npy::{decode_npy_f32, encode_npy_f32, read_npy_f32, write_npy_f32};
pub use nrrd::{RgbVolume, decode_nrrd_rgb, encode_nrrd_rgb, write_nrrd_rgb};
pub use obj_writer::{write_obj, write_obj_polylines};
pub use output_dir::OutputDir;
pub use ply_writer::{encode_ply, write_ply};
pub use point_ply_writer::{encode_point_ply, write_point_ply};
pub use polyline_reader::{parse_obj_polylines, read_obj_polylines};
pub use read_mesh::{LoadedMesh, read_mesh, read_mesh_bytes};
