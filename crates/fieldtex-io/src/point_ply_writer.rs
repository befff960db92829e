//! Binary PLY point clouds with per-point float properties (no faces), e.g. the
//! `frames.ply` of `fieldtex solid` (node centres and frame axes).

use crate::{IoError, atomic_write};
use std::fmt::Write as _;
use std::path::Path;

/// Encodes `positions` with the float properties `props` (`(name, one value per point)`)
/// as a little-endian binary PLY with a vertex element only.
pub fn encode_point_ply(
    positions: &[[f64; 3]],
    props: &[(&str, &[f32])],
) -> Result<Vec<u8>, String> {
    let n = positions.len();
    let mut h = String::from("ply\nformat binary_little_endian 1.0\ncomment written by fieldtex\n");
    let _ = writeln!(h, "element vertex {n}");
    h.push_str("property float x\nproperty float y\nproperty float z\n");
    for (name, values) in props {
        if name.is_empty()
            || name.chars().any(char::is_whitespace)
            || ["x", "y", "z"].contains(name)
        {
            return Err(format!(
                "property name {name:?} is empty, has whitespace or repeats x/y/z"
            ));
        }
        if values.len() != n {
            return Err(format!("property {name:?} has {} values for {n} points", values.len()));
        }
        let _ = writeln!(h, "property float {name}");
    }
    h.push_str("end_header\n");
    let mut out = h.into_bytes();
    out.reserve(n * 4 * (3 + props.len()));
    for (i, p) in positions.iter().enumerate() {
        for x in p {
            out.extend_from_slice(&(*x as f32).to_le_bytes());
        }
        for (_, values) in props {
            out.extend_from_slice(&values[i].to_le_bytes());
        }
    }
    Ok(out)
}

/// Writes [`encode_point_ply`] to `path` atomically.
pub fn write_point_ply(
    path: &Path,
    positions: &[[f64; 3]],
    props: &[(&str, &[f32])],
) -> Result<(), IoError> {
    let bytes = encode_point_ply(positions, props).map_err(|m| IoError::invalid(path, m))?;
    atomic_write(path, &bytes)
}

#[cfg(test)]
mod tests {
    #[test]
    fn header_and_size() {
        let b =
            super::encode_point_ply(&[[0.0; 3], [1.0, 2.0, 3.0]], &[("a", &[1.0, 2.0])]).unwrap();
        let text = String::from_utf8_lossy(&b);
        assert!(text.contains("element vertex 2") && text.contains("property float a"));
        let header_len = text.find("end_header\n").unwrap() + "end_header\n".len();
        assert_eq!(b.len() - header_len, 2 * 4 * 4);
    }
}
