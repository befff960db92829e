//! STL reader, binary and ASCII.
//!
//! STL stores every triangle with its own three corner positions, so the reader welds
//! corners whose positions are bit-identical (`-0.0` = `+0.0`) into shared vertices and
//! reports it in an `stl-welded` warning; no tolerance is applied (the repair step
//! welds with a tolerance if asked). Stored facet normals are ignored (they are often
//! wrong) and attribute bytes are skipped.
//!
//! Binary layout: 80-byte header, `u32` triangle count `n`, then `n` records of 50 bytes
//! (normal, three corners as `f32` little-endian, `u16` attribute). A file shorter than
//! `84 + 50·n` is an error (never read past the end); extra trailing bytes are ignored
//! with a warning. ASCII: `vertex x y z` lines between `outer loop` and `endloop`; a
//! loop with more than three vertices is triangulated as a fan.

use crate::IoError;
use crate::obj_reader::{lossy, parse_f64};
use fieldtex_core::Warning;
use fieldtex_mesh::TriMesh;

/// Parses STL bytes (binary or ASCII, decided by [`is_binary_stl`]).
pub fn read_stl_bytes(bytes: &[u8], name: &str) -> Result<(TriMesh, Vec<Warning>), IoError> {
    let mut warnings = Vec::new();
    let corners = if is_binary_stl(bytes) {
        read_binary(bytes, name, &mut warnings)?
    } else {
        read_ascii(bytes, name)?
    };
    if corners.is_empty() {
        return Err(IoError::EmptyMesh { file: name.to_string(), detail: "no facets".into() });
    }
    crate::mesh_checks::check_vertex_count(name, corners.len() as u64)?;
    let (positions, remap) = crate::mesh_checks::weld_identical(&corners);
    let triangles: Vec<[u32; 3]> = remap.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    warnings.push(Warning::new(
        "stl-welded",
        format!(
            "{name}: welded {} triangle corners into {} vertices (bit-identical positions)",
            corners.len(),
            positions.len()
        ),
    ));
    crate::mesh_checks::warn_non_finite(name, &positions, &mut warnings);
    Ok((TriMesh::new(positions, triangles), warnings))
}

/// Binary when the length matches the count at byte 80, or when the file does not
/// start with `solid` (ASCII STL must).
pub fn is_binary_stl(bytes: &[u8]) -> bool {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        if 84 + 50 * n == bytes.len() as u64 {
            return true;
        }
    }
    let t = bytes.trim_ascii_start();
    !(t.len() >= 5 && t[..5].eq_ignore_ascii_case(b"solid"))
        || bytes[..bytes.len().min(512)].contains(&0)
}

fn read_binary(
    bytes: &[u8],
    name: &str,
    warnings: &mut Vec<Warning>,
) -> Result<Vec<[f64; 3]>, IoError> {
    if bytes.len() < 84 {
        return Err(IoError::Truncated {
            file: name.to_string(),
            what: "the binary STL header (80 bytes) and triangle count (4 bytes)".into(),
            needed: 84,
            available: bytes.len() as u64,
        });
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    let needed = 84 + 50 * n;
    if needed > bytes.len() as u64 {
        return Err(IoError::Truncated {
            file: name.to_string(),
            what: format!("{n} triangles announced at byte 80"),
            needed,
            available: bytes.len() as u64,
        });
    }
    if needed < bytes.len() as u64 {
        warnings.push(Warning::new(
            "stl-trailing-bytes",
            format!(
                "{name}: {} bytes after the {n} announced triangles were ignored",
                bytes.len() as u64 - needed
            ),
        ));
    }
    let mut corners = Vec::with_capacity(3 * n as usize);
    for rec in bytes[84..needed as usize].chunks_exact(50) {
        for k in 0..3 {
            let o = 12 + 12 * k;
            let f = |i: usize| {
                f32::from_le_bytes([
                    rec[o + 4 * i],
                    rec[o + 4 * i + 1],
                    rec[o + 4 * i + 2],
                    rec[o + 4 * i + 3],
                ]) as f64
            };
            corners.push([f(0), f(1), f(2)]);
        }
    }
    Ok(corners)
}

fn read_ascii(bytes: &[u8], name: &str) -> Result<Vec<[f64; 3]>, IoError> {
    let mut corners = Vec::new();
    let mut loop_pts: Vec<[f64; 3]> = Vec::new();
    let mut in_loop = false;
    let mut facet = 0usize;
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let mut tok = line.split(|b| b.is_ascii_whitespace()).filter(|t| !t.is_empty());
        let Some(kw) = tok.next() else { continue };
        let err = |msg: String| IoError::parse(name, format!("line {}", i + 1), msg);
        match kw.to_ascii_lowercase().as_slice() {
            b"outer" => {
                in_loop = true;
                loop_pts.clear();
            }
            b"vertex" => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    let t = tok.next().ok_or_else(|| {
                        err(format!("facet {facet}: a vertex needs 3 coordinates"))
                    })?;
                    *c = parse_f64(t).ok_or_else(|| {
                        err(format!("facet {facet}: cannot read {:?} as a number", lossy(t)))
                    })?;
                }
                if !in_loop {
                    return Err(err(format!("facet {facet}: `vertex` outside `outer loop`")));
                }
                loop_pts.push(p);
            }
            b"endloop" => {
                in_loop = false;
                if loop_pts.len() < 3 {
                    return Err(err(format!(
                        "facet {facet} has {} vertices (needs 3)",
                        loop_pts.len()
                    )));
                }
                for k in 1..loop_pts.len() - 1 {
                    corners.extend_from_slice(&[loop_pts[0], loop_pts[k], loop_pts[k + 1]]);
                }
                facet += 1;
            }
            b"solid" | b"facet" | b"endfacet" | b"endsolid" => {}
            other => {
                return Err(err(format!("unexpected keyword {:?} in ASCII STL", lossy(other))));
            }
        }
    }
    if in_loop {
        return Err(IoError::parse(
            name,
            format!("facet {facet}"),
            "file ends inside `outer loop` (truncated)",
        ));
    }
    Ok(corners)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_and_binary_agree() {
        let ascii = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
            endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\n\
            endloop\nendfacet\nendsolid t\n";
        let (a, w) = read_stl_bytes(ascii, "a.stl").unwrap();
        assert_eq!(a.n_vertices(), 4);
        assert_eq!(a.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert!(w.iter().any(|w| w.code == "stl-welded"));
        let mut bin = vec![0u8; 80];
        bin.extend_from_slice(&2u32.to_le_bytes());
        for tri in [
            [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        ] {
            bin.extend_from_slice(&[0u8; 12]);
            for p in tri {
                for x in p {
                    bin.extend_from_slice(&x.to_le_bytes());
                }
            }
            bin.extend_from_slice(&[0u8; 2]);
        }
        let (b, _) = read_stl_bytes(&bin, "b.stl").unwrap();
        assert_eq!(a, b);
        let e = read_stl_bytes(&bin[..150], "b.stl").unwrap_err();
        assert!(matches!(e, IoError::Truncated { .. }), "{e}");
    }
}
