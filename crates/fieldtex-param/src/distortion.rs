//! Distortion of a parameterisation (DESIGN.md §6, parameterisation quality).
//!
//! For each triangle the map from its 3-D plane to UV is linear with a 2×2 Jacobian
//! `J` (3-D triangle expressed in an orthonormal frame of its plane). Its singular
//! values `σ1 ≥ σ2` give
//! - **angle distortion** `σ1/σ2` (1 for a conformal map): reported as the
//!   area-weighted mean and the area-weighted 95th percentile over triangles;
//! - **area distortion**: with `s = (A_uv / ΣA_uv) / (A_3d / ΣA_3d)` the normalised area
//!   ratio, the area-weighted mean of `max(s, 1/s)` (1 when texel density is uniform);
//! - **flipped triangles**: non-degenerate 3-D triangles whose UV signed area is ≤ 0.
//!
//! Triangles with (near-)zero 3-D area are skipped and counted as degenerate. Works for
//! any per-corner UVs, so every pipeline can use it.

use crate::ParamError;
use fieldtex_core::vec3;
use fieldtex_mesh::TriMesh;
use serde::{Deserialize, Serialize};

/// Summary of [`parameterization_distortion`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DistortionStats {
    /// Area-weighted mean of `σ1/σ2`.
    pub angle_mean: f64,
    /// Area-weighted 95th percentile of `σ1/σ2`.
    pub angle_p95: f64,
    /// Area-weighted mean of `max(s, 1/s)`, `s` the normalised area ratio.
    pub area_distortion: f64,
    /// Non-degenerate triangles with UV signed area ≤ 0.
    pub flipped_triangles: usize,
    /// Triangles skipped for a (near-)zero 3-D area.
    pub degenerate_triangles: usize,
}

/// Per-triangle measures of the 3-D → UV map: `(σ1, σ2, uv signed area, 3-D area)`,
/// or `None` when the 3-D triangle is degenerate (area ≤ `tiny`).
pub fn triangle_jacobian(
    p: [[f64; 3]; 3],
    uv: [[f64; 2]; 3],
    tiny: f64,
) -> Option<(f64, f64, f64, f64)> {
    let e1 = vec3::sub(p[1], p[0]);
    let e2 = vec3::sub(p[2], p[0]);
    let n = vec3::cross(e1, e2);
    let a3 = 0.5 * vec3::norm(n);
    if a3.is_nan() || a3 <= tiny {
        return None;
    }
    let l1 = vec3::norm(e1);
    let x = vec3::scale(e1, 1.0 / l1);
    let y = vec3::normalize(vec3::cross(n, x))?;
    // 3-D triangle in its plane: (0,0), (l1, 0), (bx, by) with by > 0.
    let (bx, by) = (vec3::dot(e2, x), vec3::dot(e2, y));
    let du1 = [uv[1][0] - uv[0][0], uv[1][1] - uv[0][1]];
    let du2 = [uv[2][0] - uv[0][0], uv[2][1] - uv[0][1]];
    // J [l1 bx; 0 by] = [du1 du2]  =>  J = [du1 du2] [l1 bx; 0 by]^-1.
    let inv = [[1.0 / l1, -bx / (l1 * by)], [0.0, 1.0 / by]];
    let j = [
        [du1[0] * inv[0][0], du1[0] * inv[0][1] + du2[0] * inv[1][1]],
        [du1[1] * inv[0][0], du1[1] * inv[0][1] + du2[1] * inv[1][1]],
    ];
    let (s1, s2) = singular_values_2x2(j);
    let uv_area = 0.5 * (du1[0] * du2[1] - du1[1] * du2[0]);
    Some((s1, s2, uv_area, a3))
}

/// Singular values `(σ1, σ2)`, `σ1 ≥ σ2 ≥ 0`, of a 2×2 matrix (rows).
pub fn singular_values_2x2(m: [[f64; 2]; 2]) -> (f64, f64) {
    let (a, b, c, d) = (m[0][0], m[0][1], m[1][0], m[1][1]);
    // Conformal and anti-conformal parts.
    let e = 0.5 * (a + d);
    let f = 0.5 * (a - d);
    let g = 0.5 * (c + b);
    let h = 0.5 * (c - b);
    let q = (e * e + h * h).sqrt();
    let r = (f * f + g * g).sqrt();
    (q + r, (q - r).abs())
}

/// Distortion of per-corner `uvs` on `mesh` (module docs). Fails when the UV table
/// does not match the mesh or a triangle index is out of range.
pub fn parameterization_distortion(
    mesh: &TriMesh,
    uvs: &fieldtex_mesh::CornerUvs,
) -> Result<DistortionStats, ParamError> {
    let nf = mesh.n_triangles();
    let nv = mesh.n_vertices();
    for (f, t) in mesh.triangles.iter().enumerate() {
        if let Some(&i) = t.iter().find(|&&i| i as usize >= nv) {
            return Err(fieldtex_mesh::MeshError::IndexOutOfRange {
                triangle: f,
                index: i as u64,
                n_vertices: nv,
            }
            .into());
        }
    }
    if uvs.indices.len() != nf {
        return Err(ParamError::AttributeLength {
            what: "uv indices",
            expected: nf,
            found: uvs.indices.len(),
        });
    }
    let mut max_len = 0.0f64;
    for t in &mesh.triangles {
        let p = [
            mesh.positions[t[0] as usize],
            mesh.positions[t[1] as usize],
            mesh.positions[t[2] as usize],
        ];
        for k in 0..3 {
            max_len = max_len.max(vec3::norm(vec3::sub(p[(k + 1) % 3], p[k])));
        }
    }
    let tiny = 1e-14 * max_len * max_len;
    let mut rows: Vec<(f64, f64, f64, f64)> = Vec::with_capacity(nf); // (ratio, a3, auv, s)
    let mut flipped = 0;
    let mut degenerate = 0;
    for f in 0..nf {
        let idx = uvs.indices[f];
        let mut uv = [[0.0; 2]; 3];
        for k in 0..3 {
            match uvs.values.get(idx[k] as usize) {
                Some(v) => uv[k] = *v,
                None => {
                    return Err(ParamError::AttributeLength {
                        what: "uv values",
                        expected: idx[k] as usize + 1,
                        found: uvs.values.len(),
                    });
                }
            }
        }
        match triangle_jacobian(mesh.triangle_positions(f), uv, tiny) {
            None => degenerate += 1,
            Some((s1, s2, auv, a3)) => {
                if auv.is_nan() || auv <= 0.0 {
                    flipped += 1;
                }
                let ratio = if s2 > 0.0 { s1 / s2 } else { f64::INFINITY };
                rows.push((ratio, a3, auv.abs(), 0.0));
            }
        }
    }
    let sum3: f64 = rows.iter().map(|r| r.1).sum();
    let sumuv: f64 = rows.iter().map(|r| r.2).sum();
    if rows.is_empty() || sum3.is_nan() || sum3 <= 0.0 || sumuv.is_nan() || sumuv <= 0.0 {
        return Ok(DistortionStats {
            angle_mean: f64::NAN,
            angle_p95: f64::NAN,
            area_distortion: f64::NAN,
            flipped_triangles: flipped,
            degenerate_triangles: degenerate,
        });
    }
    let mut area_acc = 0.0;
    let mut angle_acc = 0.0;
    let mut angle_w = 0.0;
    for r in &rows {
        let s = (r.2 / sumuv) / (r.1 / sum3);
        let d = if s > 0.0 { s.max(1.0 / s) } else { f64::INFINITY };
        if d.is_finite() {
            area_acc += r.1 * d;
        }
        if r.0.is_finite() {
            angle_acc += r.1 * r.0;
            angle_w += r.1;
        }
    }
    let mut sorted: Vec<(f64, f64)> = rows.iter().map(|r| (r.0, r.1)).collect();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut acc = 0.0;
    let mut p95 = sorted.last().map_or(f64::NAN, |r| r.0);
    for &(v, a) in &sorted {
        acc += a;
        if acc >= 0.95 * sum3 {
            p95 = v;
            break;
        }
    }
    Ok(DistortionStats {
        angle_mean: if angle_w > 0.0 { angle_acc / angle_w } else { f64::NAN },
        angle_p95: p95,
        area_distortion: area_acc / sum3,
        flipped_triangles: flipped,
        degenerate_triangles: degenerate,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn singular_values_of_known_matrices() {
        let (a, b) = singular_values_2x2([[2.0, 0.0], [0.0, 0.5]]);
        assert!((a - 2.0).abs() < 1e-12 && (b - 0.5).abs() < 1e-12);
        let (a, b) = singular_values_2x2([[0.0, -3.0], [3.0, 0.0]]); // rotation * 3
        assert!((a - 3.0).abs() < 1e-12 && (b - 3.0).abs() < 1e-12);
        let (a, b) = singular_values_2x2([[1.0, 1.0], [0.0, 1.0]]); // shear
        assert!(
            (a * b - 1.0).abs() < 1e-12 && (a - (1.5f64 + 1.25f64.sqrt()).sqrt()).abs() < 1e-12
        );
    }

    #[test]
    fn similarity_has_no_distortion_and_mirror_flips() {
        let mesh = fieldtex_mesh::primitives::grid(3, 2, 3.0, 2.0);
        let mk = |sign: f64| fieldtex_mesh::CornerUvs {
            values: mesh.positions.iter().map(|p| [sign * 0.1 * p[0], 0.1 * p[1]]).collect(),
            indices: mesh.triangles.clone(),
        };
        let d = parameterization_distortion(&mesh, &mk(1.0)).unwrap();
        assert!((d.angle_mean - 1.0).abs() < 1e-9 && (d.angle_p95 - 1.0).abs() < 1e-9);
        assert!((d.area_distortion - 1.0).abs() < 1e-9);
        assert_eq!(d.flipped_triangles, 0);
        let m = parameterization_distortion(&mesh, &mk(-1.0)).unwrap();
        assert_eq!(m.flipped_triangles, mesh.n_triangles());
        // Stretch x by 2: every triangle has ratio 2.
        let st = fieldtex_mesh::CornerUvs {
            values: mesh.positions.iter().map(|p| [2.0 * p[0], p[1]]).collect(),
            indices: mesh.triangles.clone(),
        };
        let s = parameterization_distortion(&mesh, &st).unwrap();
        assert!((s.angle_mean - 2.0).abs() < 1e-9);
    }
}
