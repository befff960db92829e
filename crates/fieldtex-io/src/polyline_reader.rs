//! Reader of OBJ polylines (`v` and `l` elements), the format `fieldtex crest` writes
//! and `fieldtex field --curves` reads. Faces and other elements are ignored.

use crate::IoError;
use std::path::Path;

/// Reads the polylines of an OBJ file: one `Vec` of points per `l` element
/// (1-based or negative relative indices, as in OBJ).
pub fn read_obj_polylines(path: &Path) -> Result<Vec<Vec<[f64; 3]>>, IoError> {
    let bytes = crate::read_input_file(path, crate::InputKind::Text, "read the curves")?;
    parse_obj_polylines(&bytes, &path.display().to_string())
}

/// [`read_obj_polylines`] on bytes; `name` appears in messages.
pub fn parse_obj_polylines(bytes: &[u8], name: &str) -> Result<Vec<Vec<[f64; 3]>>, IoError> {
    let text = std::str::from_utf8(bytes).map_err(|_| {
        IoError::parse(name, "start of file", "not UTF-8 text; an OBJ polyline file is plain text")
    })?;
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut lines = Vec::new();
    for (ln, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let mut p = [0.0; 3];
                for (k, slot) in p.iter_mut().enumerate() {
                    let tok = it.next().ok_or_else(|| {
                        IoError::parse(
                            name,
                            format!("line {}", ln + 1),
                            format!("`v` needs 3 coordinates, found {k}"),
                        )
                    })?;
                    *slot = tok.parse::<f64>().map_err(|_| {
                        IoError::parse(
                            name,
                            format!("line {}", ln + 1),
                            format!("`{tok}` is not a number"),
                        )
                    })?;
                    if !slot.is_finite() {
                        return Err(IoError::parse(
                            name,
                            format!("line {}", ln + 1),
                            "non-finite coordinate",
                        ));
                    }
                }
                vertices.push(p);
            }
            Some("l") => {
                let mut pts = Vec::new();
                for tok in it {
                    let first = tok.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| {
                        IoError::parse(
                            name,
                            format!("line {}", ln + 1),
                            format!("`{tok}` is not a vertex index"),
                        )
                    })?;
                    let n = vertices.len() as i64;
                    let idx = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || idx < 0 || idx >= n {
                        return Err(IoError::parse(
                            name,
                            format!("line {}", ln + 1),
                            format!("index {i} is out of range ({n} vertices so far)"),
                        ));
                    }
                    pts.push(vertices[idx as usize]);
                }
                if pts.len() >= 2 {
                    lines.push(pts);
                }
            }
            _ => {}
        }
    }
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_lines_with_negative_indices_and_rejects_bad_ones() {
        let l = parse_obj_polylines(b"v 0 0 0\nv 1 0 0\nv 2 0 0\nl 1 2 3\nl -1 -2\nl 1\n", "t")
            .unwrap();
        assert_eq!(l.len(), 2);
        assert_eq!(l[0].len(), 3);
        assert_eq!(l[1], vec![[2.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
        assert!(parse_obj_polylines(b"v 0 0 0\nl 1 5\n", "t").is_err());
        assert!(parse_obj_polylines(b"v 0 0\n", "t").is_err());
        assert!(parse_obj_polylines(&[0xff, 0xfe], "t").is_err());
    }
}
