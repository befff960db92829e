//! NumPy `.npy` files of little-endian `float32` in C order (used for `H × W × 2`
//! orientation fields: `[row, col] = (dx, dy)`).
//!
//! Written as format version 1.0 with the header padded by spaces to a multiple of 64
//! bytes (what NumPy itself writes). Reading accepts versions 1.0, 2.0 and 3.0 and
//! refuses, with a clear error, any dtype other than `<f4` and Fortran order.

use crate::{IoError, atomic_write};
use std::path::Path;

const MAGIC: &[u8] = b"\x93NUMPY";

/// Encodes `data` with the given shape as `.npy` bytes.
pub fn encode_npy_f32(shape: &[usize], data: &[f32]) -> Result<Vec<u8>, String> {
    let n = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d)).ok_or("shape overflows")?;
    if n != data.len() {
        return Err(format!(
            "shape {shape:?} has {n} elements but {} values were given",
            data.len()
        ));
    }
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape_txt = match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    };
    let mut header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {shape_txt}, }}");
    let unpadded = MAGIC.len() + 2 + 2 + header.len() + 1;
    header.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(MAGIC.len() + 4 + header.len() + 4 * data.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for x in data {
        out.extend_from_slice(&x.to_le_bytes());
    }
    Ok(out)
}

/// Writes a little-endian `float32` C-order array atomically. `data.len()` must equal the
/// product of `shape`.
pub fn write_npy_f32(path: &Path, shape: &[usize], data: &[f32]) -> Result<(), IoError> {
    let bytes = encode_npy_f32(shape, data).map_err(|m| IoError::invalid(path, m))?;
    atomic_write(path, &bytes)
}

/// Reads a `.npy` file of little-endian `float32` in C order; returns `(shape, data)`.
pub fn read_npy_f32(path: &Path) -> Result<(Vec<usize>, Vec<f32>), IoError> {
    let bytes = crate::read_input_file(path, crate::InputKind::Array, "read the array")?;
    decode_npy_f32(&bytes, &path.display().to_string())
}

/// Decodes `.npy` bytes (see [`read_npy_f32`]); `name` is used in messages.
pub fn decode_npy_f32(bytes: &[u8], name: &str) -> Result<(Vec<usize>, Vec<f32>), IoError> {
    let bad = |m: String| IoError::parse(name, "npy header", m);
    if !bytes.starts_with(MAGIC) || bytes.len() < 10 {
        return Err(bad("not a .npy file (missing the \\x93NUMPY magic)".into()));
    }
    let (hlen, hstart): (usize, usize) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => {
            (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12)
        }
        v => return Err(bad(format!("unsupported .npy version {v}"))),
    };
    let header = bytes
        .get(hstart..hstart.saturating_add(hlen))
        .ok_or_else(|| bad("the header is longer than the file".into()))?;
    let header = String::from_utf8_lossy(header);
    let descr = dict_value(&header, "descr").ok_or_else(|| bad("no 'descr' entry".into()))?;
    let descr = descr.trim_matches(|c| c == '\'' || c == '"');
    if descr != "<f4" {
        return Err(IoError::Unsupported {
            file: name.to_string(),
            what: format!(
                "dtype {descr:?} (only little-endian float32 '<f4' is read; convert with arr.astype('<f4'))"
            ),
        });
    }
    let fortran = dict_value(&header, "fortran_order")
        .ok_or_else(|| bad("no 'fortran_order' entry".into()))?;
    if fortran != "False" {
        return Err(IoError::Unsupported {
            file: name.to_string(),
            what: "Fortran-ordered arrays (save with np.ascontiguousarray)".into(),
        });
    }
    let shape_txt = dict_value(&header, "shape").ok_or_else(|| bad("no 'shape' entry".into()))?;
    let inner = shape_txt.trim().trim_start_matches('(').trim_end_matches(')');
    let mut shape = Vec::new();
    for d in inner.split(',').map(str::trim).filter(|d| !d.is_empty()) {
        shape.push(d.parse::<usize>().map_err(|_| bad(format!("bad shape entry {d:?}")))?);
    }
    let n = shape
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .ok_or_else(|| bad(format!("shape {shape:?} overflows")))?;
    let body = &bytes[hstart + hlen..];
    let needed = (n as u64).saturating_mul(4);
    if (body.len() as u64) < needed {
        return Err(IoError::Truncated {
            file: name.to_string(),
            what: format!("a float32 array of shape {shape:?}"),
            needed,
            available: body.len() as u64,
        });
    }
    let data = body[..4 * n]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    Ok((shape, data))
}

/// The text of `key`'s value in a Python dict literal (up to the next top-level comma).
fn dict_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let k = header.find(&format!("'{key}'")).or_else(|| header.find(&format!("\"{key}\"")))?;
    let rest = &header[k + key.len() + 2..];
    let rest = rest.trim_start().strip_prefix(':')?.trim_start();
    let mut depth = 0i32;
    for (i, c) in rest.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' | '}' if depth == 0 => return Some(rest[..i].trim()),
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_refusals() {
        let data: Vec<f32> = (0..24).map(|i| i as f32 * 0.5).collect();
        let b = encode_npy_f32(&[3, 4, 2], &data).unwrap();
        assert_eq!((b.len() - 4 * 24) % 64, 0);
        let (s, d) = decode_npy_f32(&b, "x.npy").unwrap();
        assert_eq!(s, vec![3, 4, 2]);
        assert_eq!(d, data);
        let (s, _) = decode_npy_f32(&encode_npy_f32(&[5], &[0.0; 5]).unwrap(), "x").unwrap();
        assert_eq!(s, vec![5]);
        let swap = |from: &[u8], to: &[u8]| {
            let mut c = b.clone();
            let i = c.windows(from.len()).position(|w| w == from).unwrap();
            c[i..i + to.len()].copy_from_slice(to);
            c
        };
        let f8 = swap(b"<f4", b"<f8");
        assert!(matches!(decode_npy_f32(&f8, "x"), Err(IoError::Unsupported { .. })));
        let fo = swap(b"False", b"True ");
        assert!(matches!(decode_npy_f32(&fo, "x"), Err(IoError::Unsupported { .. })));
        assert!(matches!(decode_npy_f32(&b[..b.len() - 4], "x"), Err(IoError::Truncated { .. })));
        assert!(encode_npy_f32(&[2, 2], &[0.0; 3]).is_err());
    }
}
