//! PLY header parsing and the size check against the file length.

use super::{header_error, quote};
use crate::IoError;

/// The three PLY encodings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PlyEncoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// A PLY scalar type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &[u8]) -> Option<Scalar> {
        Some(match s {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    pub(crate) fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// Value that maps to 1.0 for colour channels.
    pub(crate) fn color_scale(self) -> f64 {
        match self {
            Scalar::U16 | Scalar::I16 => 65535.0,
            Scalar::F32 | Scalar::F64 => 1.0,
            _ => 255.0,
        }
    }
}

/// A property: a scalar or a list with a count type and an item type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PropKind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug, Clone)]
pub(crate) struct Property {
    pub name: String,
    pub kind: PropKind,
}

#[derive(Debug, Clone)]
pub(crate) struct Element {
    pub name: String,
    pub count: u64,
    pub props: Vec<Property>,
}

impl Element {
    pub(crate) fn find(&self, names: &[&str]) -> Option<usize> {
        names.iter().find_map(|n| self.props.iter().position(|p| p.name == *n))
    }
}

/// A parsed PLY header.
#[derive(Debug, Clone)]
pub(crate) struct PlyHeader {
    pub(crate) encoding: PlyEncoding,
    pub(crate) elements: Vec<Element>,
    pub(crate) texture_file: Option<String>,
}

/// Header text is looked for in this many leading bytes at most.
const MAX_HEADER_BYTES: usize = 1 << 20;

/// Parses the header; returns it and the byte offset where the body starts.
pub(crate) fn parse_header(bytes: &[u8], name: &str) -> Result<(PlyHeader, usize), IoError> {
    let search = &bytes[..bytes.len().min(MAX_HEADER_BYTES)];
    let end = find(search, b"end_header").ok_or_else(|| {
        header_error(name, 1, "no `end_header` line found (truncated or not a PLY file)")
    })?;
    // The body starts after the end of the `end_header` line.
    let mut body_start = end + b"end_header".len();
    while body_start < bytes.len() && (bytes[body_start] == b' ' || bytes[body_start] == b'\r') {
        body_start += 1;
    }
    if body_start < bytes.len() && bytes[body_start] == b'\n' {
        body_start += 1;
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut texture_file = None;
    for (i, line) in bytes[..end].split(|&b| b == b'\n').enumerate() {
        let ln = i + 1;
        let line = line.trim_ascii();
        let mut tok = line.split(|b| b.is_ascii_whitespace()).filter(|t| !t.is_empty());
        let Some(kw) = tok.next() else { continue };
        match kw {
            b"ply" if ln == 1 => {}
            _ if ln == 1 => {
                return Err(header_error(name, 1, "the file does not start with `ply`"));
            }
            b"format" => {
                encoding = Some(match tok.next() {
                    Some(b"ascii") => PlyEncoding::Ascii,
                    Some(b"binary_little_endian") => PlyEncoding::BinaryLittleEndian,
                    Some(b"binary_big_endian") => PlyEncoding::BinaryBigEndian,
                    other => {
                        return Err(header_error(
                            name,
                            ln,
                            format!("unknown format {}", quote(other.unwrap_or(b""))),
                        ));
                    }
                });
            }
            b"comment" => {
                let rest = line[7..].trim_ascii();
                if let Some(t) = rest.strip_prefix(b"TextureFile") {
                    let t = t.trim_ascii();
                    if !t.is_empty() {
                        texture_file = Some(String::from_utf8_lossy(t).into_owned());
                    }
                }
            }
            b"obj_info" => {}
            b"element" => {
                let ename =
                    tok.next().ok_or_else(|| header_error(name, ln, "element without a name"))?;
                let count_tok = tok.next().unwrap_or(b"");
                let count = std::str::from_utf8(count_tok)
                    .ok()
                    .and_then(|s| s.parse::<u64>().ok())
                    .ok_or_else(|| {
                        header_error(
                            name,
                            ln,
                            format!(
                                "element count {} is not a non-negative integer",
                                quote(count_tok)
                            ),
                        )
                    })?;
                elements.push(Element {
                    name: String::from_utf8_lossy(ename).into_owned(),
                    count,
                    props: Vec::new(),
                });
            }
            b"property" => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| header_error(name, ln, "property before any element"))?;
                let t1 = tok.next().unwrap_or(b"");
                let bad_type = |t: &[u8]| {
                    header_error(name, ln, format!("unknown property type {}", quote(t)))
                };
                let kind = if t1 == b"list" {
                    let c = tok.next().unwrap_or(b"");
                    let it = tok.next().unwrap_or(b"");
                    let count = Scalar::parse(c).ok_or_else(|| bad_type(c))?;
                    let item = Scalar::parse(it).ok_or_else(|| bad_type(it))?;
                    if count.is_float() {
                        return Err(header_error(
                            name,
                            ln,
                            "a list count must have an integer type",
                        ));
                    }
                    PropKind::List { count, item }
                } else {
                    PropKind::Scalar(Scalar::parse(t1).ok_or_else(|| bad_type(t1))?)
                };
                let pname =
                    tok.next().ok_or_else(|| header_error(name, ln, "property without a name"))?;
                el.props.push(Property { name: String::from_utf8_lossy(pname).into_owned(), kind });
            }
            other => {
                return Err(header_error(
                    name,
                    ln,
                    format!("unknown header keyword {}", quote(other)),
                ));
            }
        }
    }
    let encoding = encoding.ok_or_else(|| header_error(name, 2, "missing `format` line"))?;
    Ok((PlyHeader { encoding, elements, texture_file }, body_start))
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// Checks that every element's claimed count fits in the remaining file, counting the
/// smallest record each could have (lists empty; in ASCII one character and one
/// separator per value). Fails with [`IoError::Truncated`] before anything is allocated.
pub(crate) fn check_sizes(h: &PlyHeader, body_len: u64, name: &str) -> Result<(), IoError> {
    let mut needed: u64 = 0;
    for e in &h.elements {
        let per: u64 = match h.encoding {
            PlyEncoding::Ascii => 2 * e.props.len() as u64,
            _ => e
                .props
                .iter()
                .map(|p| match p.kind {
                    PropKind::Scalar(s) => s.size() as u64,
                    PropKind::List { count, .. } => count.size() as u64,
                })
                .sum(),
        };
        let this = e.count.saturating_mul(per);
        needed = needed.saturating_add(this);
        // ASCII: the last value needs no trailing separator.
        let slack = if h.encoding == PlyEncoding::Ascii { 1 } else { 0 };
        if needed > body_len + slack {
            return Err(IoError::Truncated {
                file: name.to_string(),
                what: format!(
                    "element `{}` with a claimed count of {} ({} bytes per record at least)",
                    e.name, e.count, per
                ),
                needed,
                available: body_len,
            });
        }
    }
    Ok(())
}
