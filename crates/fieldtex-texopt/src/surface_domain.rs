//! The surface domain: colour carriers with positions and tangent frames.
//!
//! A *colour carrier* is a point on the surface where a colour lives: an atlas texel's
//! surface point (`align` bakes the result into the atlas), or a vertex of a dense mesh.
//! Each carrier is a triangle index plus barycentric coordinates. The domain stores per
//! carrier (all `#C`-long):
//! - `positions` (`#C × 3`): the barycentric interpolation of the triangle's corners;
//! - `normals` (`#C × 3`, unit): the barycentric interpolation of area-weighted vertex
//!   normals, falling back to the face normal;
//! - `tangents` (`#C × 3`, unit): the per-vertex direction field interpolated, projected
//!   to the tangent plane `t ← f − (f·n) n` and normalised; where that vanishes, the
//!   triangle's vertex directions are tried one by one;
//! - `bitangents` (`#C × 3`): `b = n × t`, so `(t, b, n)` is right-handed.
//!
//! The texture orientation convention is in the crate docs: the exemplar's `+x` axis
//! follows `t`, its rows (`+y`, downward in the image) follow `−b`, so the texture is not
//! mirrored when the surface is seen from outside.
//!
//! [`SurfaceDomain::area`] is the surface area the carriers cover (the mesh area), used
//! to estimate the carrier spacing `sqrt(area / #C)`.

use crate::TexOptError;
use fieldtex_core::Warning;
use fieldtex_core::vec3::{self, V3};
use fieldtex_mesh::{NormalWeighting, TriMesh, face_normals, total_area, vertex_normals};
use rayon::prelude::*;

/// A point of the surface carrying a colour: triangle index and barycentric coordinates
/// (weights of the triangle's corners 0, 1, 2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Carrier {
    pub triangle: u32,
    pub barycentric: [f64; 3],
}

/// Colour carriers with positions and tangent frames; see the module docs.
#[derive(Debug, Clone)]
pub struct SurfaceDomain {
    positions: Vec<V3>,
    normals: Vec<V3>,
    tangents: Vec<V3>,
    bitangents: Vec<V3>,
    area: f64,
}

impl SurfaceDomain {
    /// Builds the domain of `carriers` on `mesh` with the per-vertex direction `field`
    /// (`#V × 3`, need not be unit or tangent). Returns warnings when some carriers had a
    /// vanishing field (they get an arbitrary tangent direction).
    ///
    /// Errors: no carriers, an empty mesh, a carrier naming a missing triangle or with
    /// invalid barycentric coordinates, a field of the wrong length or with non-finite
    /// values, and a field that vanishes at more than half of the carriers.
    pub fn new(
        mesh: &TriMesh,
        field: &[V3],
        carriers: &[Carrier],
    ) -> Result<(Self, Vec<Warning>), TexOptError> {
        if carriers.is_empty() {
            return Err(TexOptError::NoCarriers);
        }
        if mesh.triangles.is_empty() {
            return Err(TexOptError::EmptyMesh);
        }
        let nv = mesh.positions.len();
        if field.len() != nv {
            return Err(TexOptError::Length {
                what: "direction field",
                expected: nv,
                found: field.len(),
                shape: "#V × 3, one direction per mesh vertex",
            });
        }
        if let Some(i) = field.iter().position(|f| !vec3::is_finite(*f)) {
            return Err(TexOptError::NonFinite {
                what: "direction field vertex",
                index: i,
                value: field[i],
            });
        }
        if let Some(i) = mesh.positions.iter().position(|p| !vec3::is_finite(*p)) {
            return Err(TexOptError::NonFinite {
                what: "mesh vertex",
                index: i,
                value: mesh.positions[i],
            });
        }
        for (t, tri) in mesh.triangles.iter().enumerate() {
            if let Some(&v) = tri.iter().find(|&&v| v as usize >= nv) {
                return Err(TexOptError::TriangleVertex { triangle: t, vertex: v, vertices: nv });
            }
        }
        for (c, car) in carriers.iter().enumerate() {
            if car.triangle as usize >= mesh.triangles.len() {
                return Err(TexOptError::CarrierTriangle {
                    carrier: c,
                    triangle: car.triangle,
                    triangles: mesh.triangles.len(),
                });
            }
            let b = car.barycentric;
            let ok = b.iter().all(|v| v.is_finite() && (-1e-6..=1.0 + 1e-6).contains(v))
                && (b[0] + b[1] + b[2] - 1.0).abs() < 1e-6;
            if !ok {
                return Err(TexOptError::CarrierBarycentric { carrier: c, barycentric: b });
            }
        }
        let fnormals = face_normals(mesh);
        let (vnormals, _) = vertex_normals(mesh, NormalWeighting::Area);
        let frames: Vec<(V3, V3, V3, bool)> = carriers
            .par_iter()
            .map(|car| {
                let tri = mesh.triangles[car.triangle as usize];
                let b = car.barycentric;
                let interp = |a: &[V3]| {
                    let mut s = [0.0; 3];
                    for k in 0..3 {
                        s = vec3::add(s, vec3::scale(a[tri[k] as usize], b[k]));
                    }
                    s
                };
                let pos = interp(&mesh.positions);
                let fnrm = fnormals[car.triangle as usize];
                let n = vec3::normalize(interp(&vnormals))
                    .filter(|n| vec3::is_finite(*n))
                    .or_else(|| vec3::normalize(fnrm))
                    .unwrap_or([0.0, 0.0, 1.0]);
                let project =
                    |f: V3| vec3::normalize(vec3::sub(f, vec3::scale(n, vec3::dot(f, n))));
                let mut t = project(interp(field));
                for k in 0..3 {
                    if t.is_some() {
                        break;
                    }
                    t = project(field[tri[k] as usize]);
                }
                let degenerate = t.is_none();
                let t = t.unwrap_or_else(|| vec3::any_orthonormal(n));
                (pos, n, t, degenerate)
            })
            .collect();
        let zero = frames.iter().filter(|f| f.3).count();
        if zero * 2 > carriers.len() {
            return Err(TexOptError::DegenerateField { zero, total: carriers.len() });
        }
        let mut warnings = Vec::new();
        if zero > 0 {
            warnings.push(Warning::new(
                "texopt-zero-field",
                format!(
                    "the direction field vanishes at {zero} of {} carriers (singularities or zero vectors); those carriers use an arbitrary tangent direction",
                    carriers.len()
                ),
            ));
        }
        let area = total_area(mesh);
        let domain = Self::assemble(frames.into_iter().map(|(p, n, t, _)| (p, n, t)), area);
        Ok((domain, warnings))
    }

    /// One carrier per mesh vertex (the vertex itself, on the first triangle using it),
    /// for synthesis on dense vertices. Unreferenced vertices get no carrier, so carrier
    /// `i` is vertex `result.1[i]`.
    pub fn at_vertices(
        mesh: &TriMesh,
        field: &[V3],
    ) -> Result<(Self, Vec<u32>, Vec<Warning>), TexOptError> {
        let carriers = vertex_carriers(mesh);
        let vertices: Vec<u32> = carriers
            .iter()
            .map(|c| {
                let k = c.barycentric.iter().position(|&v| v == 1.0).unwrap_or(0);
                mesh.triangles[c.triangle as usize][k]
            })
            .collect();
        let (d, w) = Self::new(mesh, field, &carriers)?;
        Ok((d, vertices, w))
    }

    /// A domain from explicit frames (for domains that are not built on a mesh, e.g. the
    /// transfer pipeline's samples): positions, unit normals and tangent directions
    /// (projected and normalised here), and the covered surface `area` (> 0).
    pub fn from_frames(
        positions: &[V3],
        normals: &[V3],
        tangents: &[V3],
        area: f64,
    ) -> Result<Self, TexOptError> {
        if positions.is_empty() {
            return Err(TexOptError::NoCarriers);
        }
        for (what, a) in [("normals", normals), ("tangents", tangents)] {
            if a.len() != positions.len() {
                return Err(TexOptError::Length {
                    what,
                    expected: positions.len(),
                    found: a.len(),
                    shape: "#C × 3, one per carrier",
                });
            }
        }
        if !(area.is_finite() && area > 0.0) {
            return Err(TexOptError::InvalidOption {
                name: "area",
                value: area,
                reason: "must be positive and finite",
            });
        }
        let mut frames = Vec::with_capacity(positions.len());
        let mut zero = 0;
        for i in 0..positions.len() {
            for (what, v) in [
                ("carrier position", positions[i]),
                ("carrier normal", normals[i]),
                ("carrier tangent", tangents[i]),
            ] {
                if !vec3::is_finite(v) {
                    return Err(TexOptError::NonFinite { what, index: i, value: v });
                }
            }
            let n = vec3::normalize(normals[i]).unwrap_or([0.0, 0.0, 1.0]);
            let f = tangents[i];
            let t = vec3::normalize(vec3::sub(f, vec3::scale(n, vec3::dot(f, n)))).unwrap_or_else(
                || {
                    zero += 1;
                    vec3::any_orthonormal(n)
                },
            );
            frames.push((positions[i], n, t));
        }
        if zero * 2 > positions.len() {
            return Err(TexOptError::DegenerateField { zero, total: positions.len() });
        }
        Ok(Self::assemble(frames.into_iter(), area))
    }

    fn assemble(frames: impl Iterator<Item = (V3, V3, V3)>, area: f64) -> Self {
        let mut d = Self {
            positions: Vec::new(),
            normals: Vec::new(),
            tangents: Vec::new(),
            bitangents: Vec::new(),
            area,
        };
        for (p, n, t) in frames {
            d.positions.push(p);
            d.normals.push(n);
            d.tangents.push(t);
            d.bitangents.push(vec3::cross(n, t));
        }
        d
    }

    /// Number of carriers `#C`.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True when there are no carriers (never for a constructed domain).
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Carrier positions, `#C × 3`.
    pub fn positions(&self) -> &[V3] {
        &self.positions
    }

    /// Unit carrier normals, `#C × 3`.
    pub fn normals(&self) -> &[V3] {
        &self.normals
    }

    /// Unit tangent directions (texture `+x`), `#C × 3`.
    pub fn tangents(&self) -> &[V3] {
        &self.tangents
    }

    /// `n × t` per carrier, `#C × 3` (texture `−y`).
    pub fn bitangents(&self) -> &[V3] {
        &self.bitangents
    }

    /// Surface area covered by the carriers.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Estimated distance between neighbouring carriers, `sqrt(area / #C)`.
    pub fn carrier_spacing(&self) -> f64 {
        (self.area / self.len().max(1) as f64).sqrt()
    }

    /// Replaces the tangent directions (e.g. a rotated field), keeping positions and
    /// normals; `tangents` is `#C × 3` and is projected and normalised.
    pub fn with_tangents(&self, tangents: &[V3]) -> Result<Self, TexOptError> {
        Self::from_frames(&self.positions, &self.normals, tangents, self.area)
    }
}

/// One carrier per referenced vertex: the vertex as a corner of the first triangle that
/// uses it, in increasing vertex order.
pub fn vertex_carriers(mesh: &TriMesh) -> Vec<Carrier> {
    let mut first = vec![u32::MAX; mesh.positions.len()];
    let mut corner = vec![0u8; mesh.positions.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            if let Some(f) = first.get_mut(v as usize)
                && *f == u32::MAX
            {
                *f = t as u32;
                corner[v as usize] = k as u8;
            }
        }
    }
    first
        .iter()
        .zip(&corner)
        .filter(|(f, _)| **f != u32::MAX)
        .map(|(&t, &k)| {
            let mut barycentric = [0.0; 3];
            barycentric[k as usize] = 1.0;
            Carrier { triangle: t, barycentric }
        })
        .collect()
}
