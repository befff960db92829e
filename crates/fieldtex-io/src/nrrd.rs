//! NRRD volumes of RGB voxels (the `fieldtex solid --volume` output).
//!
//! Layout written: `type: uint8`, `dimension: 4`, `sizes: 3 NX NY NZ`, `kinds: RGB-color
//! domain domain domain`, `encoding: raw`, `space dimension: 3`, `space origin` and
//! `space directions` (`none` for the colour axis, then `spacing` along x, y, z) in
//! world units. Voxel `(i, j, k)` has its centre at `origin + (i, j, k) · spacing`;
//! data is `3 · NX · NY · NZ` bytes, the colour channel fastest, then x, y, z.
//! [`decode_nrrd_rgb`] reads exactly this layout back (raw encoding only).

use crate::{IoError, atomic_write};
use std::path::Path;

/// An RGB uint8 volume with its placement.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbVolume {
    /// Voxels along x, y, z.
    pub sizes: [usize; 3],
    /// Centre of voxel (0, 0, 0), world units.
    pub origin: [f64; 3],
    /// Voxel size, world units (cubic voxels).
    pub spacing: f64,
    /// `3 · NX · NY · NZ` bytes (RGB fastest, then x, y, z).
    pub data: Vec<u8>,
}

/// Encodes `volume` as a raw NRRD file (module docs).
pub fn encode_nrrd_rgb(volume: &RgbVolume) -> Result<Vec<u8>, IoError> {
    let [nx, ny, nz] = volume.sizes;
    let expected = 3 * nx * ny * nz;
    if volume.data.len() != expected {
        return Err(IoError::InvalidData {
            file: crate::MEMORY_NAME.to_string(),
            message: format!(
                "the volume holds {} bytes; {nx}×{ny}×{nz} RGB voxels need {expected}",
                volume.data.len()
            ),
        });
    }
    if !(volume.spacing.is_finite() && volume.spacing > 0.0)
        || volume.origin.iter().any(|v| !v.is_finite())
    {
        return Err(IoError::InvalidData {
            file: crate::MEMORY_NAME.to_string(),
            message: "the volume needs a finite origin and a spacing > 0".into(),
        });
    }
    let [ox, oy, oz] = volume.origin;
    let s = volume.spacing;
    let header = format!(
        "NRRD0004\n# written by fieldtex solid\ntype: uint8\ndimension: 4\nsizes: 3 {nx} {ny} {nz}\n\
kinds: RGB-color domain domain domain\nencoding: raw\nspace dimension: 3\n\
space origin: ({ox:?},{oy:?},{oz:?})\nspace directions: none ({s:?},0,0) (0,{s:?},0) (0,0,{s:?})\n\n"
    );
    let mut out = header.into_bytes();
    out.extend_from_slice(&volume.data);
    Ok(out)
}

/// Writes `volume` to `path` atomically.
pub fn write_nrrd_rgb(path: &Path, volume: &RgbVolume) -> Result<(), IoError> {
    atomic_write(path, &encode_nrrd_rgb(volume)?)
}

/// Decodes a file in the layout of [`encode_nrrd_rgb`] (`name` names it in errors).
pub fn decode_nrrd_rgb(bytes: &[u8], name: &str) -> Result<RgbVolume, IoError> {
    let end = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .ok_or_else(|| IoError::parse(name, "header", "no blank line ends the NRRD header"))?;
    let header = std::str::from_utf8(&bytes[..end])
        .map_err(|_| IoError::parse(name, "header", "the header is not UTF-8"))?;
    if !header.starts_with("NRRD") {
        return Err(IoError::parse(name, "line 1", "not an NRRD file (no NRRD magic)"));
    }
    let mut sizes = None;
    let mut origin = None;
    let mut spacing = None;
    for (ln, line) in header.lines().enumerate() {
        let Some((key, value)) = line.split_once(':') else { continue };
        let value = value.trim();
        let loc = || format!("line {}", ln + 1);
        let nums = |v: &str| -> Vec<f64> {
            v.replace(['(', ')', ','], " ")
                .split_whitespace()
                .filter_map(|t| t.parse().ok())
                .collect()
        };
        match key.trim() {
            "type" if value != "uint8" => {
                return Err(IoError::parse(
                    name,
                    loc(),
                    format!("type {value} (only uint8 is read)"),
                ));
            }
            "encoding" if value != "raw" => {
                return Err(IoError::parse(
                    name,
                    loc(),
                    format!("encoding {value} (only raw is read)"),
                ));
            }
            "sizes" => {
                let v: Vec<usize> =
                    value.split_whitespace().filter_map(|t| t.parse().ok()).collect();
                if v.len() != 4 || v[0] != 3 {
                    return Err(IoError::parse(name, loc(), "sizes must be `3 NX NY NZ`"));
                }
                sizes = Some([v[1], v[2], v[3]]);
            }
            "space origin" => {
                let v = nums(value);
                if v.len() != 3 {
                    return Err(IoError::parse(name, loc(), "space origin needs 3 numbers"));
                }
                origin = Some([v[0], v[1], v[2]]);
            }
            "space directions" => {
                let v = nums(value.trim_start_matches("none"));
                if v.len() != 9 {
                    return Err(IoError::parse(
                        name,
                        loc(),
                        "space directions need three 3-vectors",
                    ));
                }
                spacing = Some(v[0]);
            }
            _ => {}
        }
    }
    let sizes = sizes.ok_or_else(|| IoError::parse(name, "header", "no sizes field"))?;
    let data = bytes[end + 2..].to_vec();
    let expected = 3 * sizes[0] * sizes[1] * sizes[2];
    if data.len() != expected {
        return Err(IoError::Truncated {
            file: name.to_string(),
            what: "voxel data".into(),
            needed: expected as u64,
            available: data.len() as u64,
        });
    }
    Ok(RgbVolume {
        sizes,
        origin: origin.unwrap_or([0.0; 3]),
        spacing: spacing.unwrap_or(1.0),
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nrrd_round_trip() {
        let data: Vec<u8> = (0..3 * 4 * 3 * 2).map(|i| (i * 7 % 256) as u8).collect();
        let v = RgbVolume { sizes: [4, 3, 2], origin: [0.1, -2.5, 3.0], spacing: 0.125, data };
        let bytes = encode_nrrd_rgb(&v).unwrap();
        let text = String::from_utf8_lossy(&bytes[..200.min(bytes.len())]).to_string();
        assert!(
            text.contains("sizes: 3 4 3 2")
                && text.contains("kinds: RGB-color domain domain domain")
        );
        let back = decode_nrrd_rgb(&bytes, "mem").unwrap();
        assert_eq!(back, v);
        let short = RgbVolume { data: vec![0; 5], ..v.clone() };
        assert!(encode_nrrd_rgb(&short).is_err());
        assert!(decode_nrrd_rgb(&bytes[..bytes.len() - 1], "mem").is_err());
    }
}
