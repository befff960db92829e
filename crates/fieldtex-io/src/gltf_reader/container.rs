//! The GLB container (12-byte header, JSON chunk, optional BIN chunk), `data:` URIs and
//! external files, all bounds-checked.

use crate::IoError;
use std::path::Path;

/// Splits a GLB into its JSON text and BIN chunk.
pub(crate) fn split_glb<'a>(
    bytes: &'a [u8],
    name: &str,
) -> Result<(&'a [u8], Option<&'a [u8]>), IoError> {
    let u32_at = |o: usize| -> Option<u32> {
        Some(u32::from_le_bytes(bytes.get(o..o + 4)?.try_into().ok()?))
    };
    let trunc = |what: &str, needed: u64| IoError::Truncated {
        file: name.to_string(),
        what: what.to_string(),
        needed,
        available: bytes.len() as u64,
    };
    if bytes.len() < 20 {
        return Err(trunc("the GLB header and first chunk header", 20));
    }
    let version = u32_at(4).unwrap_or(0);
    if version != 2 {
        return Err(IoError::Unsupported {
            file: name.to_string(),
            what: format!("GLB version {version} (only 2 is supported)"),
        });
    }
    let total = u32_at(8).unwrap_or(0) as u64;
    if total > bytes.len() as u64 {
        return Err(trunc("the GLB length announced at byte 8", total));
    }
    let bytes = &bytes[..total.max(20) as usize];
    let json_len = u32_at(12).unwrap_or(0) as u64;
    if u32_at(16) != Some(0x4E4F_534A) {
        return Err(IoError::parse(name, "GLB byte 16", "the first chunk is not the JSON chunk"));
    }
    let json_end = 20 + json_len;
    if json_end > bytes.len() as u64 {
        return Err(trunc("the GLB JSON chunk", json_end));
    }
    let json = &bytes[20..json_end as usize];
    let mut bin = None;
    let o = json_end as usize;
    if bytes.len() >= o + 8 {
        let len = u32_at(o).unwrap_or(0) as u64;
        if u32_at(o + 4) == Some(0x004E_4942) {
            let end = o as u64 + 8 + len;
            if end > bytes.len() as u64 {
                return Err(trunc("the GLB BIN chunk", end));
            }
            bin = Some(&bytes[o + 8..end as usize]);
        }
    }
    Ok((json, bin))
}

/// Resolves a glTF URI: `data:` URIs are decoded; anything else must be a relative path
/// inside the glTF file's folder (percent-escapes decoded; [`crate::resolve_confined`]),
/// read up to `max_len` bytes (a buffer's `byteLength`). `base` is `None` for in-memory
/// data.
pub(crate) fn load_uri(
    uri: &str,
    base: Option<&Path>,
    name: &str,
    max_len: Option<u64>,
) -> Result<Vec<u8>, IoError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (meta, data) = rest.split_once(',').ok_or_else(|| {
            IoError::parse(name, "data URI", "no `,` separating the header from the data")
        })?;
        if !meta.ends_with(";base64") {
            return Err(IoError::Unsupported {
                file: name.to_string(),
                what: "a data URI that is not base64".into(),
            });
        }
        return decode_base64(data.as_bytes())
            .ok_or_else(|| IoError::parse(name, "data URI", "invalid base64 data"));
    }
    let Some(base) = base else {
        return Err(IoError::Unsupported {
            file: name.to_string(),
            what: format!(
                "the external file {uri:?} when reading from memory (read the file by path)"
            ),
        });
    };
    let rel = percent_decode(uri);
    let path = crate::resolve_confined(base, &rel, name, "glTF URI")?;
    // A buffer is read up to its declared byteLength only; images up to the image cap.
    match max_len {
        Some(len) => crate::input_files::read_input_prefix(
            &path,
            len,
            crate::InputKind::Mesh,
            "read a file the glTF refers to",
            true,
        ),
        None => {
            crate::read_input_file(&path, crate::InputKind::Image, "read a file the glTF refers to")
        }
    }
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (with or without `=` padding, whitespace ignored).
pub(crate) fn decode_base64(data: &[u8]) -> Option<Vec<u8>> {
    fn val(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    }
    let mut out = Vec::with_capacity(data.len() / 4 * 3);
    let mut acc = 0u32;
    let mut bits = 0;
    for &c in data {
        if c == b'=' {
            break;
        }
        if c.is_ascii_whitespace() {
            continue;
        }
        acc = (acc << 6) | val(c)?;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_and_percent() {
        assert_eq!(decode_base64(b"aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64(b"aGVsbG8h").unwrap(), b"hello!");
        assert!(decode_base64(b"a$b").is_none());
        assert_eq!(percent_decode("a%20b.png"), "a b.png");
        assert_eq!(percent_decode("a%2"), "a%2");
    }

    #[test]
    fn glb_bounds() {
        assert!(split_glb(b"glTF", "x").is_err());
        let mut g = b"glTF".to_vec();
        g.extend_from_slice(&2u32.to_le_bytes());
        g.extend_from_slice(&1000u32.to_le_bytes());
        g.extend_from_slice(&[0u8; 12]);
        assert!(matches!(split_glb(&g, "x"), Err(IoError::Truncated { .. })));
    }
}
