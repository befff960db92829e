//! Mesh file formats and how a file's format is recognised.
//!
//! Content decides first ([`sniff_mesh_format`]): magic bytes and structure are more
//! reliable than a name. The extension (or a caller's hint) is used only when the
//! content says nothing, so a `.obj` that really holds a PLY still loads (with a
//! warning), and a file whose content and name both say nothing gets a clear error.

use serde::Serialize;
use std::path::Path;

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum MeshFormat {
    /// Wavefront OBJ (text), with optional MTL material library.
    Obj,
    /// Stanford PLY, ASCII or binary (either endianness).
    Ply,
    /// STL, ASCII or binary.
    Stl,
    /// glTF 2.0 as JSON (`.gltf`) or binary container (`.glb`).
    Gltf,
}

impl MeshFormat {
    /// The format named by a file extension (case-insensitive), if any.
    pub fn from_extension(path: &Path) -> Option<MeshFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(MeshFormat::Obj),
            "ply" => Some(MeshFormat::Ply),
            "stl" => Some(MeshFormat::Stl),
            "gltf" | "glb" => Some(MeshFormat::Gltf),
            _ => None,
        }
    }

    /// Short lower-case name (`"obj"`, `"ply"`, `"stl"`, `"gltf"`).
    pub fn name(self) -> &'static str {
        match self {
            MeshFormat::Obj => "obj",
            MeshFormat::Ply => "ply",
            MeshFormat::Stl => "stl",
            MeshFormat::Gltf => "gltf",
        }
    }
}

impl std::fmt::Display for MeshFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Recognises a mesh format from the bytes alone; `None` when the content is not
/// conclusive.
///
/// Rules, in order: `glTF` magic → GLB; `ply` first line → PLY; a length of exactly
/// `84 + 50·n` with `n` the little-endian count at byte 80 → binary STL (even when the
/// 80-byte header starts with `solid`, as some exporters write); text starting with
/// `solid` → ASCII STL; text starting with `{` that mentions `"asset"` → glTF JSON;
/// text whose first statements are OBJ keywords → OBJ.
pub fn sniff_mesh_format(bytes: &[u8]) -> Option<MeshFormat> {
    if bytes.starts_with(b"glTF") {
        return Some(MeshFormat::Gltf);
    }
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") || bytes == b"ply" {
        return Some(MeshFormat::Ply);
    }
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        if 84 + 50 * n == bytes.len() as u64 {
            return Some(MeshFormat::Stl);
        }
    }
    let text = skip_bom_and_space(bytes);
    if text.len() >= 5 && text[..5].eq_ignore_ascii_case(b"solid") {
        // A binary STL whose header starts with "solid" but whose length is off (it
        // was truncated) has NUL or other control bytes early on.
        let head = &text[..text.len().min(512)];
        if head.iter().all(|&b| b >= 0x20 || b == b'\n' || b == b'\r' || b == b'\t') {
            return Some(MeshFormat::Stl);
        }
    }
    if text.first() == Some(&b'{') {
        let head = &text[..text.len().min(1 << 16)];
        if head.windows(7).any(|w| w == b"\"asset\"") {
            return Some(MeshFormat::Gltf);
        }
    }
    if looks_like_obj(text) {
        return Some(MeshFormat::Obj);
    }
    None
}

fn skip_bom_and_space(bytes: &[u8]) -> &[u8] {
    let b = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(bytes);
    let start = b.iter().position(|c| !c.is_ascii_whitespace()).unwrap_or(b.len());
    &b[start..]
}

/// True when the first few non-comment lines start with OBJ statements and the head of
/// the file is text.
fn looks_like_obj(text: &[u8]) -> bool {
    const KEYWORDS: &[&[u8]] =
        &[b"v", b"vt", b"vn", b"vp", b"f", b"l", b"p", b"o", b"g", b"s", b"mtllib", b"usemtl"];
    let head = &text[..text.len().min(4096)];
    if head.contains(&0) {
        return false;
    }
    let mut statements = 0;
    for line in head.split(|&b| b == b'\n') {
        let line = line.trim_ascii();
        if line.is_empty() || line.starts_with(b"#") {
            continue;
        }
        let kw = line.split(|b| b.is_ascii_whitespace()).next().unwrap_or(b"");
        if !KEYWORDS.contains(&kw) {
            return false;
        }
        statements += 1;
        if statements >= 3 {
            break;
        }
    }
    statements > 0 || (!head.is_empty() && head.starts_with(b"#"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sniffs_each_format() {
        assert_eq!(sniff_mesh_format(b"glTF\x02\0\0\0"), Some(MeshFormat::Gltf));
        assert_eq!(sniff_mesh_format(b"ply\nformat ascii 1.0\n"), Some(MeshFormat::Ply));
        assert_eq!(sniff_mesh_format(b"solid x\nfacet normal 0 0 1\n"), Some(MeshFormat::Stl));
        assert_eq!(sniff_mesh_format(b"{\"asset\":{\"version\":\"2.0\"}}"), Some(MeshFormat::Gltf));
        assert_eq!(sniff_mesh_format(b"# c\nv 0 0 0\nv 1 0 0\nf 1 2 3\n"), Some(MeshFormat::Obj));
        let mut stl = vec![0u8; 84 + 50];
        stl[..5].copy_from_slice(b"solid");
        stl[80] = 1;
        assert_eq!(sniff_mesh_format(&stl), Some(MeshFormat::Stl));
        assert_eq!(sniff_mesh_format(&[0xff, 0x00, 0x13, 0x37]), None);
        assert_eq!(sniff_mesh_format(b"hello world"), None);
    }
}
