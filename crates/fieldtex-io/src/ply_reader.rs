//! Stanford PLY reader (own implementation: ASCII, binary little- and big-endian).
//!
//! Reads the `vertex` element's `x y z` (any numeric type), optional `nx ny nz`,
//! colours `red green blue [alpha]` (also `diffuse_*`; integer types are scaled by their
//! maximum, e.g. uchar / 255, floats are taken as `[0, 1]`), and per-vertex texture
//! coordinates (`u v`, `s t` or `texture_u texture_v`); the `face` element's
//! `vertex_indices` (or `vertex_index`) list of any size and any integer count/index
//! types, triangulated as a fan from the first corner (exact for convex polygons), and a
//! per-face `texcoord` list (MeshLab's per-corner UVs). Every other element and
//! property is parsed for its size and ignored. `comment TextureFile NAME` is reported so
//! the path reader can load the texture.
//!
//! Safety against hostile headers: before reading, each element's claimed count times
//! its smallest possible record size is checked against the bytes left in the file, so a
//! header claiming 10^12 faces fails at once with [`IoError::Truncated`] and nothing is
//! allocated for it. Records are bounds-checked as they are read.

use crate::IoError;
use crate::obj_reader::lossy;
use fieldtex_core::Warning;
use fieldtex_mesh::{CornerUvs, TriMesh};

mod body;
mod header;

/// Side information from a PLY file.
#[derive(Debug, Clone, Default)]
pub struct PlyRefs {
    /// The name given by a `comment TextureFile NAME` line, if any.
    pub texture_file: Option<String>,
}

/// Parses PLY bytes. `name` is used in messages.
pub fn read_ply_bytes(
    bytes: &[u8],
    name: &str,
) -> Result<(TriMesh, PlyRefs, Vec<Warning>), IoError> {
    let (hdr, body_start) = header::parse_header(bytes, name)?;
    header::check_sizes(&hdr, bytes.len() as u64 - body_start as u64, name)?;
    let refs = PlyRefs { texture_file: hdr.texture_file.clone() };
    let raw = body::read_body(&hdr, &bytes[body_start..], name)?;
    let mut warnings = Vec::new();
    let mesh = assemble(raw, name, &mut warnings)?;
    Ok((mesh, refs, warnings))
}

/// What the body reader extracts.
#[derive(Default)]
pub(crate) struct RawPly {
    pub positions: Vec<[f64; 3]>,
    pub normals: Option<Vec<[f64; 3]>>,
    pub colors: Option<Vec<[f32; 4]>>,
    pub vertex_uvs: Option<Vec<[f64; 2]>>,
    pub triangles: Vec<[u32; 3]>,
    /// Per-corner UVs from a face `texcoord` list, one `[u, v]` triple per triangle.
    pub corner_uvs: Vec<[[f64; 2]; 3]>,
    pub faces_with_texcoord: usize,
    pub short_faces: usize,
    pub n_faces: u64,
    pub had_vertex_element: bool,
    pub had_face_element: bool,
}

fn assemble(raw: RawPly, name: &str, warnings: &mut Vec<Warning>) -> Result<TriMesh, IoError> {
    if raw.triangles.is_empty() {
        let detail = if !raw.had_vertex_element {
            "no `vertex` element".to_string()
        } else if !raw.had_face_element {
            format!("{} vertices but no `face` element (a point cloud?)", raw.positions.len())
        } else {
            format!(
                "{} vertices, {} faces, none with 3 or more corners",
                raw.positions.len(),
                raw.n_faces
            )
        };
        return Err(IoError::EmptyMesh { file: name.to_string(), detail });
    }
    if raw.short_faces > 0 {
        warnings.push(Warning::new(
            "ply-short-faces-dropped",
            format!("{name}: dropped {} face(s) with fewer than 3 corners", raw.short_faces),
        ));
    }
    crate::mesh_checks::warn_non_finite(name, &raw.positions, warnings);
    let mut colors = raw.colors;
    if let Some(c) = &mut colors {
        crate::mesh_checks::clamp_colors(name, c, warnings);
    }
    let n_tri = raw.triangles.len();
    let uvs = if raw.faces_with_texcoord > 0 && raw.corner_uvs.len() == n_tri {
        let mut values = Vec::with_capacity(3 * n_tri);
        let mut indices = Vec::with_capacity(n_tri);
        for (f, c) in raw.corner_uvs.iter().enumerate() {
            values.extend_from_slice(c);
            let b = 3 * f as u32;
            indices.push([b, b + 1, b + 2]);
        }
        Some(CornerUvs { values, indices })
    } else if let Some(values) = raw.vertex_uvs {
        Some(CornerUvs { values, indices: raw.triangles.clone() })
    } else {
        None
    };
    Ok(TriMesh {
        positions: raw.positions,
        triangles: raw.triangles,
        uvs,
        vertex_colors: colors,
        vertex_normals: raw.normals,
    })
}

pub(crate) fn header_error(name: &str, line: usize, msg: impl Into<String>) -> IoError {
    IoError::parse(name, format!("PLY header line {line}"), msg)
}

pub(crate) fn quote(b: &[u8]) -> String {
    format!("{:?}", lossy(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\nproperty float x\n\
        property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n\
        property uchar blue\nproperty int flags\nelement face 2\nproperty list uchar int vertex_indices\n\
        end_header\n0 0 0 255 0 0 7\n1 0 0 0 255 0 7\n1 1 0 0 0 255 7\n0 1 0 0 0 0 7\n4 0 1 2 3\n2 0 1\n";

    #[test]
    fn ascii_quad_colors_extra_props() {
        let (m, _, w) = read_ply_bytes(ASCII.as_bytes(), "t.ply").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.vertex_colors.as_ref().unwrap()[1], [0.0, 1.0, 0.0, 1.0]);
        assert_eq!(w.len(), 1, "{w:?}");
    }

    fn binary(big: bool, count_ty: &str, idx_ty: &str) -> Vec<u8> {
        let fmt = if big { "binary_big_endian" } else { "binary_little_endian" };
        let mut b = format!(
            "ply\nformat {fmt} 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
             property double z\nproperty float nx\nproperty float ny\nproperty float nz\n\
             element face 1\nproperty list {count_ty} {idx_ty} vertex_indices\nend_header\n"
        )
        .into_bytes();
        let put = |b: &mut Vec<u8>, bytes: &[u8]| {
            if big { b.extend(bytes.iter().rev()) } else { b.extend_from_slice(bytes) }
        };
        for p in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for x in p {
                put(&mut b, &x.to_le_bytes());
            }
            for x in [0.0f32, 0.0, 1.0] {
                put(&mut b, &x.to_le_bytes());
            }
        }
        match count_ty {
            "uchar" => b.push(3),
            _ => put(&mut b, &3u32.to_le_bytes()),
        }
        for i in [0i16, 1, 2] {
            match idx_ty {
                "short" => put(&mut b, &i.to_le_bytes()),
                _ => put(&mut b, &(i as i32).to_le_bytes()),
            }
        }
        b
    }

    #[test]
    fn binary_both_endians_and_int_sizes() {
        for big in [false, true] {
            for (c, i) in [("uchar", "int"), ("uint", "short"), ("int", "int")] {
                let (m, _, _) = read_ply_bytes(&binary(big, c, i), "t.ply").unwrap();
                assert_eq!(m.positions[1], [1.0, 0.0, 0.0]);
                assert_eq!(m.triangles, vec![[0, 1, 2]]);
                assert_eq!(m.vertex_normals.as_ref().unwrap()[2], [0.0, 0.0, 1.0]);
            }
        }
    }

    #[test]
    fn huge_claim_fails_fast() {
        let h = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
            property float y\nproperty float z\nelement face 1000000000000\n\
            property list uchar int vertex_indices\nend_header\n";
        let mut b = h.as_bytes().to_vec();
        b.extend_from_slice(&[0u8; 36 + 13]);
        let e = read_ply_bytes(&b, "big.ply").unwrap_err();
        assert!(matches!(e, IoError::Truncated { .. }), "{e}");
        assert!(e.to_string().contains("1000000000000"), "{e}");
    }

    #[test]
    fn bad_index_names_face() {
        let s = ASCII.replace("4 0 1 2 3\n", "3 0 1 9\n");
        let e = read_ply_bytes(s.as_bytes(), "t.ply").unwrap_err().to_string();
        assert!(e.contains("face 0") && e.contains("index 9"), "{e}");
        let s = ASCII.replace("4 0 1 2 3\n", "3 0 -1 2\n");
        let e = read_ply_bytes(s.as_bytes(), "t.ply").unwrap_err().to_string();
        assert!(e.contains("-1"), "{e}");
    }
}
