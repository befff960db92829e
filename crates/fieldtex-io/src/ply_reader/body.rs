//! PLY body reading, generic over the encoding (one monomorphised loop per encoding).

use super::RawPly;
use super::header::{Element, PlyEncoding, PlyHeader, PropKind, Scalar};
use crate::IoError;

/// Where one value comes from: binary bytes or ASCII tokens.
trait Source {
    /// Reads one scalar as `f64`; `None` at end of data or on a malformed token.
    fn float(&mut self, s: Scalar) -> Option<f64>;
    /// Reads one scalar as an integer; `None` at end of data or on a non-integer.
    fn int(&mut self, s: Scalar) -> Option<i64>;
    /// True when `n` items of type `s` can still be read (cheap pre-check for lists).
    fn can_read(&self, n: u64, s: Scalar) -> bool;
    /// Skips `n` records of fixed size `bytes` if the encoding allows it.
    fn skip_fixed(&mut self, n: u64, bytes: u64) -> bool;
    fn position(&self) -> usize;
    fn len(&self) -> usize;
}

struct Binary<'a, const BIG: bool> {
    d: &'a [u8],
    pos: usize,
}

impl<const BIG: bool> Binary<'_, BIG> {
    #[inline]
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let b: [u8; N] = self.d.get(self.pos..self.pos + N)?.try_into().ok()?;
        self.pos += N;
        Some(if BIG {
            let mut r = b;
            r.reverse();
            r
        } else {
            b
        })
    }
}

impl<const BIG: bool> Source for Binary<'_, BIG> {
    #[inline]
    fn float(&mut self, s: Scalar) -> Option<f64> {
        Some(match s {
            Scalar::F32 => f32::from_le_bytes(self.take::<4>()?) as f64,
            Scalar::F64 => f64::from_le_bytes(self.take::<8>()?),
            _ => self.int(s)? as f64,
        })
    }
    #[inline]
    fn int(&mut self, s: Scalar) -> Option<i64> {
        Some(match s {
            Scalar::I8 => i8::from_le_bytes(self.take::<1>()?) as i64,
            Scalar::U8 => self.take::<1>()?[0] as i64,
            Scalar::I16 => i16::from_le_bytes(self.take::<2>()?) as i64,
            Scalar::U16 => u16::from_le_bytes(self.take::<2>()?) as i64,
            Scalar::I32 => i32::from_le_bytes(self.take::<4>()?) as i64,
            Scalar::U32 => u32::from_le_bytes(self.take::<4>()?) as i64,
            Scalar::F32 => float_to_int(f32::from_le_bytes(self.take::<4>()?) as f64)?,
            Scalar::F64 => float_to_int(f64::from_le_bytes(self.take::<8>()?))?,
        })
    }
    fn can_read(&self, n: u64, s: Scalar) -> bool {
        n.saturating_mul(s.size() as u64) <= (self.d.len() - self.pos) as u64
    }
    fn skip_fixed(&mut self, n: u64, bytes: u64) -> bool {
        let total = n.saturating_mul(bytes);
        if total > (self.d.len() - self.pos) as u64 {
            return false;
        }
        self.pos += total as usize;
        true
    }
    fn position(&self) -> usize {
        self.pos
    }
    fn len(&self) -> usize {
        self.d.len()
    }
}

fn float_to_int(x: f64) -> Option<i64> {
    (x.fract() == 0.0 && x.abs() < 9.0e15).then_some(x as i64)
}

struct Ascii<'a> {
    d: &'a [u8],
    pos: usize,
}

impl<'a> Ascii<'a> {
    #[inline]
    fn token(&mut self) -> Option<&'a [u8]> {
        let d = self.d;
        while self.pos < d.len() && d[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < d.len() && !d[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        (self.pos > start).then(|| &d[start..self.pos])
    }
}

impl Source for Ascii<'_> {
    fn float(&mut self, _s: Scalar) -> Option<f64> {
        crate::obj_reader::parse_f64(self.token()?)
    }
    fn int(&mut self, _s: Scalar) -> Option<i64> {
        let t = self.token()?;
        crate::obj_reader::parse_i64(t).or_else(|| float_to_int(crate::obj_reader::parse_f64(t)?))
    }
    fn can_read(&self, n: u64, _s: Scalar) -> bool {
        // Each value takes at least one character and one separator.
        n.saturating_mul(2) <= (self.d.len() - self.pos) as u64 + 1
    }
    fn skip_fixed(&mut self, _n: u64, _bytes: u64) -> bool {
        false
    }
    fn position(&self) -> usize {
        self.pos
    }
    fn len(&self) -> usize {
        self.d.len()
    }
}

pub(crate) fn read_body(h: &PlyHeader, body: &[u8], name: &str) -> Result<RawPly, IoError> {
    match h.encoding {
        PlyEncoding::Ascii => read_elements(h, &mut Ascii { d: body, pos: 0 }, name),
        PlyEncoding::BinaryLittleEndian => {
            read_elements(h, &mut Binary::<false> { d: body, pos: 0 }, name)
        }
        PlyEncoding::BinaryBigEndian => {
            read_elements(h, &mut Binary::<true> { d: body, pos: 0 }, name)
        }
    }
}

/// What a vertex property is used for.
#[derive(Clone, Copy, PartialEq)]
enum Role {
    Pos(usize),
    Normal(usize),
    Color(usize, f64),
    Uv(usize),
    FaceIndices,
    FaceTexcoord,
    Ignore,
}

fn truncated(name: &str, src: &dyn Source, element: &Element, record: u64, prop: &str) -> IoError {
    IoError::Parse {
        file: name.to_string(),
        location: format!(
            "`{}` {} (property `{}`, body byte {})",
            element.name,
            record,
            prop,
            src.position()
        ),
        message: format!(
            "the data ends or is malformed here (the header announces {} `{}` records; the body \
             has {} bytes)",
            element.count,
            element.name,
            src.len()
        ),
    }
}

fn read_elements<S: Source>(h: &PlyHeader, src: &mut S, name: &str) -> Result<RawPly, IoError> {
    let mut raw = RawPly::default();
    let n_vertices = h.elements.iter().find(|e| e.name == "vertex").map_or(0, |e| e.count);
    crate::mesh_checks::check_vertex_count(name, n_vertices)?;
    let mut corners: Vec<i64> = Vec::new();
    let mut tex: Vec<f64> = Vec::new();
    for e in &h.elements {
        let is_vertex = e.name == "vertex";
        let is_face = e.name == "face";
        let roles: Vec<Role> =
            e.props.iter().map(|p| role(p.name.as_str(), p.kind, is_vertex, is_face)).collect();
        if e.props.is_empty() {
            continue;
        }
        if roles.iter().all(|r| *r == Role::Ignore) {
            let fixed: Option<u64> = e
                .props
                .iter()
                .map(|p| match p.kind {
                    PropKind::Scalar(s) => Some(s.size() as u64),
                    PropKind::List { .. } => None,
                })
                .sum();
            if let Some(bytes) = fixed
                && src.skip_fixed(e.count, bytes)
            {
                continue;
            }
        }
        if is_vertex {
            for axis in ["x", "y", "z"] {
                if e.find(&[axis]).is_none() {
                    return Err(IoError::Unsupported {
                        file: name.to_string(),
                        what: format!("a `vertex` element without an `{axis}` property"),
                    });
                }
            }
            raw.had_vertex_element = true;
            let n = e.count as usize; // bounded by the file length (checked in the header)
            raw.positions.reserve_exact(n);
            let has = |f: &dyn Fn(&Role) -> bool| roles.iter().filter(|r| f(r)).count();
            let n_normal = has(&|r| matches!(r, Role::Normal(_)));
            let n_color = has(&|r| matches!(r, Role::Color(k, _) if *k < 3));
            let n_uv = has(&|r| matches!(r, Role::Uv(_)));
            if n_normal == 3 {
                raw.normals = Some(Vec::with_capacity(n));
            }
            if n_color == 3 {
                raw.colors = Some(Vec::with_capacity(n));
            }
            if n_uv == 2 {
                raw.vertex_uvs = Some(Vec::with_capacity(n));
            }
        }
        if is_face {
            raw.had_face_element = true;
            raw.n_faces = e.count;
            raw.triangles.reserve(e.count as usize);
        }
        for rec in 0..e.count {
            let mut p = [0.0f64; 3];
            let mut nrm = [0.0f64; 3];
            let mut col = [0.0f32, 0.0, 0.0, 1.0];
            let mut uv = [0.0f64; 2];
            corners.clear();
            tex.clear();
            for (prop, &r) in e.props.iter().zip(&roles) {
                match prop.kind {
                    PropKind::Scalar(s) => {
                        let x =
                            src.float(s).ok_or_else(|| truncated(name, src, e, rec, &prop.name))?;
                        match r {
                            Role::Pos(k) => p[k] = x,
                            Role::Normal(k) => nrm[k] = x,
                            Role::Color(k, scale) => col[k] = (x / scale) as f32,
                            Role::Uv(k) => uv[k] = x,
                            _ => {}
                        }
                    }
                    PropKind::List { count, item } => {
                        let n = src
                            .int(count)
                            .ok_or_else(|| truncated(name, src, e, rec, &prop.name))?;
                        if n < 0 || !src.can_read(n as u64, item) {
                            return Err(truncated(name, src, e, rec, &prop.name));
                        }
                        for _ in 0..n {
                            match r {
                                Role::FaceIndices => corners.push(
                                    src.int(item)
                                        .ok_or_else(|| truncated(name, src, e, rec, &prop.name))?,
                                ),
                                Role::FaceTexcoord => tex.push(
                                    src.float(item)
                                        .ok_or_else(|| truncated(name, src, e, rec, &prop.name))?,
                                ),
                                _ => {
                                    src.float(item)
                                        .ok_or_else(|| truncated(name, src, e, rec, &prop.name))?;
                                }
                            }
                        }
                    }
                }
            }
            if is_vertex {
                raw.positions.push(p);
                if let Some(v) = &mut raw.normals {
                    v.push(nrm);
                }
                if let Some(v) = &mut raw.colors {
                    v.push(col);
                }
                if let Some(v) = &mut raw.vertex_uvs {
                    v.push(uv);
                }
            } else if is_face {
                add_face(&mut raw, &corners, &tex, rec, n_vertices, name)?;
            }
        }
    }
    Ok(raw)
}

fn role(pname: &str, kind: PropKind, is_vertex: bool, is_face: bool) -> Role {
    match (kind, is_vertex, is_face) {
        (PropKind::Scalar(s), true, _) => match pname {
            "x" => Role::Pos(0),
            "y" => Role::Pos(1),
            "z" => Role::Pos(2),
            "nx" => Role::Normal(0),
            "ny" => Role::Normal(1),
            "nz" => Role::Normal(2),
            "red" | "diffuse_red" | "r" => Role::Color(0, s.color_scale()),
            "green" | "diffuse_green" | "g" => Role::Color(1, s.color_scale()),
            "blue" | "diffuse_blue" | "b" => Role::Color(2, s.color_scale()),
            "alpha" | "diffuse_alpha" | "a" => Role::Color(3, s.color_scale()),
            "u" | "s" | "texture_u" | "texture_s" => Role::Uv(0),
            "v" | "t" | "texture_v" | "texture_t" => Role::Uv(1),
            _ => Role::Ignore,
        },
        (PropKind::List { .. }, _, true) => match pname {
            "vertex_indices" | "vertex_index" => Role::FaceIndices,
            "texcoord" => Role::FaceTexcoord,
            _ => Role::Ignore,
        },
        _ => Role::Ignore,
    }
}

fn add_face(
    raw: &mut RawPly,
    corners: &[i64],
    tex: &[f64],
    face: u64,
    n_vertices: u64,
    name: &str,
) -> Result<(), IoError> {
    if let Some(&bad) = corners.iter().find(|&&i| i < 0 || i as u64 >= n_vertices) {
        return Err(IoError::IndexOutOfRange {
            file: name.to_string(),
            face: face as usize,
            index: bad,
            n_vertices: n_vertices as usize,
        });
    }
    if corners.len() < 3 {
        raw.short_faces += 1;
        return Ok(());
    }
    let has_tex = tex.len() == 2 * corners.len();
    if has_tex {
        raw.faces_with_texcoord += 1;
    }
    let uv = |k: usize| if has_tex { [tex[2 * k], tex[2 * k + 1]] } else { [0.0, 0.0] };
    for k in 1..corners.len() - 1 {
        raw.triangles.push([corners[0] as u32, corners[k] as u32, corners[k + 1] as u32]);
        if !tex.is_empty() || !raw.corner_uvs.is_empty() {
            // Keep corner UVs aligned with triangles once any face has them.
            if raw.corner_uvs.len() + 1 < raw.triangles.len() {
                raw.corner_uvs.resize(raw.triangles.len() - 1, [[0.0; 2]; 3]);
            }
            raw.corner_uvs.push([uv(0), uv(k), uv(k + 1)]);
        }
    }
    Ok(())
}
