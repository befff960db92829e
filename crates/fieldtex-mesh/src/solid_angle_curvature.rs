//! Multi-scale solid-angle curvature (Connolly 1986; paper B, Mertens et al. 2006 §3.2):
//! the fraction of a sphere of radius `r` centred on a surface point `p` that lies
//! inside the object. A plane gives ½; convex places less, concave places more; the
//! radius is the scale.
//!
//! **Analytic computation, as the paper does.** Let `B` be the ball of radius `r`
//! around `p`, `M_r` the part of the (outward-oriented) surface inside `B`, and `C` the
//! part of the sphere `∂B` inside the object. `C ∪ M_r` bounds `object ∩ B`, and `p` lies
//! on that boundary, so the signed solid angles they subtend at `p` add up to `2π`. `C`
//! lies on a sphere centred at `p`, so its solid angle is its area over `r²`, and the
//! wanted fraction is
//!
//! `f = Ω(C) / 4π = ½ − Ω(M_r) / 4π`.
//!
//! `Ω(M_r)` is summed over the triangles clipped to the ball:
//! - a triangle wholly inside contributes its signed solid angle by the closed form of
//!   Van Oosterom & Strackee (1983), `tan(Ω/2) = a·(b×c) / (|a||b||c| + (a·b)|c| +
//!   (a·c)|b| + (b·c)|a|)` with `a, b, c` its corners relative to `p` (positive when `p`
//!   lies behind the triangle, on the side its normal points away from);
//! - a triangle crossing the sphere is clipped: the polygon of its inside corners and its
//!   edges' crossing points is fanned into triangles (this is the spherical-excess area
//!   of the intersection curve with its crossing points joined by great-circle arcs,
//!   the paper's formula), and each stretch of the sphere–plane circle between an exit
//!   and the next entry adds its circular segment exactly: sector solid angle
//!   `φ (1 − |h|/r)` (`h` the plane's distance from `p`, `φ` the arc's angle around the
//!   circle's centre) minus or plus the solid angle of the triangle centre–chord;
//! - a triangle whose plane cuts the ball in a disk lying wholly inside the triangle
//!   contributes the whole cap `2π (1 − |h|/r)`.
//!
//! So the result is exact for the piecewise-planar mesh (up to rounding). The triangle
//! holding `p` is coplanar with it and contributes nothing; so does a plane. Like the
//! paper it assumes consistent outward orientation; on an open mesh the holes are
//! treated as absent surface (a flat open grid still gives ½).
//!
//! Cost: one closed-form solid angle per triangle within the largest radius (triangles
//! found through a [`SpatialGrid`] of triangle boxes), plus a clip per radius for the
//! few triangles the spheres cross. All radii share one pass.
//!
//! Output: row-major `#points × #radii`, values in `[0, 1]`.

use crate::spatial_grid::SpatialGrid;
use crate::{MeshError, TriMesh};
use fieldtex_core::vec3::{self, V3};
use rayon::prelude::*;
use std::f64::consts::PI;

/// A surface point with its outward unit normal (input of
/// [`crate::directional_occlusion_sh`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientedPoint {
    pub position: V3,
    pub normal: V3,
}

/// Solid-angle curvature of every point at every radius (module docs). `points` should
/// lie on the surface of `mesh`. Errors on bad indices or radii that are not positive
/// and finite.
pub fn solid_angle_curvature(
    mesh: &TriMesh,
    points: &[V3],
    radii: &[f64],
) -> Result<Vec<f64>, MeshError> {
    crate::checks::check_indices(mesh)?;
    if radii.iter().any(|r| !(r.is_finite() && *r > 0.0)) {
        return Err(MeshError::Precondition {
            operation: "solid-angle curvature",
            requirement: "positive finite radii",
            found: format!("{radii:?}"),
        });
    }
    let nr = radii.len();
    let mut out = vec![0.5; points.len() * nr];
    if nr == 0 || points.is_empty() || mesh.n_triangles() == 0 {
        return Ok(out);
    }
    let rmax = radii.iter().copied().fold(0.0f64, f64::max);
    let boxes: Vec<(V3, V3)> = (0..mesh.n_triangles())
        .map(|f| {
            let [a, b, c] = mesh.triangle_positions(f);
            let lo = [a[0].min(b[0]).min(c[0]), a[1].min(b[1]).min(c[1]), a[2].min(b[2]).min(c[2])];
            let hi = [a[0].max(b[0]).max(c[0]), a[1].max(b[1]).max(c[1]), a[2].max(b[2]).max(c[2])];
            (lo, hi)
        })
        .collect();
    let grid = SpatialGrid::from_boxes(&boxes, 0.5 * rmax);
    let n_tri = mesh.n_triangles();
    out.par_chunks_mut(nr).enumerate().for_each_init(
        || (vec![u32::MAX; n_tri], vec![0.0f64; nr]),
        |(seen, omega), (i, row)| {
            let p = points[i];
            omega.iter_mut().for_each(|w| *w = 0.0);
            // A box item is reported once per cell it shares with the query: keep the
            // first report (the grid's order is deterministic).
            grid.for_each_candidate(p, rmax, |t| {
                let t = t as usize;
                if seen[t] == i as u32 {
                    return;
                }
                seen[t] = i as u32;
                let (lo, hi) = boxes[t];
                let gap2: f64 = (0..3)
                    .map(|k| {
                        let g = (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0);
                        g * g
                    })
                    .sum();
                if gap2 >= rmax * rmax {
                    return;
                }
                let v = mesh.triangle_positions(t).map(|q| vec3::sub(q, p));
                if !v.iter().all(|q| vec3::is_finite(*q)) {
                    return;
                }
                let len = v.map(vec3::norm);
                let far = len[0].max(len[1]).max(len[2]);
                let mut whole: Option<f64> = None;
                for (k, &r) in radii.iter().enumerate() {
                    if far <= r {
                        omega[k] += *whole.get_or_insert_with(|| triangle_solid_angle(v));
                    } else if gap2 < r * r {
                        omega[k] += clipped_solid_angle(v, len, r);
                    }
                }
            });
            for k in 0..nr {
                row[k] = (0.5 - omega[k] / (4.0 * PI)).clamp(0.0, 1.0);
            }
        },
    );
    Ok(out)
}

/// Signed solid angle of the triangle `v` (corners relative to the viewpoint), Van
/// Oosterom & Strackee (1983). Positive when the viewpoint is behind the triangle
/// (`v[0] · ((v[1] − v[0]) × (v[2] − v[0])) > 0`); in `(−2π, 2π)`. A viewpoint in the
/// triangle's plane (up to rounding, `|a·(b×c)| ≤ 10⁻¹⁰ |a||b||c|`) gives 0: the
/// principal value for a point on the triangle itself, where the two one-sided limits
/// are `±2π`.
pub fn triangle_solid_angle(v: [V3; 3]) -> f64 {
    let [a, b, c] = v;
    let (la, lb, lc) = (vec3::norm(a), vec3::norm(b), vec3::norm(c));
    let num = vec3::dot(a, vec3::cross(b, c));
    let den = la * lb * lc + vec3::dot(a, b) * lc + vec3::dot(a, c) * lb + vec3::dot(b, c) * la;
    if num.abs() <= 1e-10 * la * lb * lc {
        return 0.0;
    }
    2.0 * num.atan2(den)
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Corner,
    Entry,
    Exit,
}

/// Signed solid angle of `triangle ∩ ball(0, r)` (module docs). `len[i] = |v[i]|`.
fn clipped_solid_angle(v: [V3; 3], len: [f64; 3], r: f64) -> f64 {
    let nrm = vec3::cross(vec3::sub(v[1], v[0]), vec3::sub(v[2], v[0]));
    let Some(nhat) = vec3::normalize(nrm) else { return 0.0 };
    let h = vec3::dot(v[0], nhat);
    if h.abs() >= r || h.abs() <= 1e-10 * r {
        return 0.0;
    }
    let inside = len.map(|l| l < r);
    let mut poly: [(V3, Kind); 9] = [([0.0; 3], Kind::Corner); 9];
    let mut n = 0;
    let mut push = |q: V3, k: Kind| {
        poly[n] = (q, k);
        n += 1;
    };
    for i in 0..3 {
        let j = (i + 1) % 3;
        if inside[i] {
            push(v[i], Kind::Corner);
        }
        let d = vec3::sub(v[j], v[i]);
        let a = vec3::dot(d, d);
        if a == 0.0 {
            continue;
        }
        let b = vec3::dot(v[i], d);
        let c = len[i] * len[i] - r * r;
        let s = (b * b - a * c).max(0.0).sqrt();
        let at = |t: f64| vec3::add(v[i], vec3::scale(d, t));
        match (inside[i], inside[j]) {
            (true, false) => push(at(((-b + s) / a).clamp(0.0, 1.0)), Kind::Exit),
            (false, true) => push(at(((-b - s) / a).clamp(0.0, 1.0)), Kind::Entry),
            (false, false) => {
                let (t1, t2) = ((-b - s) / a, (-b + s) / a);
                if s > 0.0 && t1 > 0.0 && t2 < 1.0 {
                    push(at(t1), Kind::Entry);
                    push(at(t2), Kind::Exit);
                }
            }
            (true, true) => {}
        }
    }
    let sign = h.signum();
    let cap_rate = 1.0 - h.abs() / r;
    let q = vec3::scale(nhat, h);
    if n == 0 {
        // The circle misses every edge: the disk is inside the triangle or outside it.
        let bary = barycentric_min(v, q);
        return if bary >= 0.0 { sign * 2.0 * PI * cap_rate } else { 0.0 };
    }
    let mut total = 0.0;
    for k in 1..n.saturating_sub(1) {
        total += triangle_solid_angle([poly[0].0, poly[k].0, poly[k + 1].0]);
    }
    let rho = (r * r - h * h).max(0.0).sqrt();
    for k in 0..n {
        let (e, ke) = poly[k];
        let (f, kf) = poly[(k + 1) % n];
        if ke != Kind::Exit || kf != Kind::Entry {
            continue;
        }
        let (u, w) = (vec3::sub(e, q), vec3::sub(f, q));
        let theta = vec3::norm(vec3::cross(u, w)).atan2(vec3::dot(u, w));
        let mid = vec3::scale(vec3::add(u, w), 0.5);
        let dir = vec3::normalize(mid)
            .filter(|_| vec3::norm(mid) > 1e-9 * rho)
            .or_else(|| vec3::normalize(vec3::cross(nhat, vec3::sub(f, e))))
            .unwrap_or([0.0; 3]);
        // The arc runs inside the triangle: through the minor arc's midpoint or the
        // major arc's.
        let minor_mid = vec3::add(q, vec3::scale(dir, rho));
        let major_mid = vec3::sub(q, vec3::scale(dir, rho));
        let minor = barycentric_min(v, minor_mid) >= barycentric_min(v, major_mid);
        let centre_chord = triangle_solid_angle([q, e, f]).abs();
        let segment = if minor {
            theta * cap_rate - centre_chord
        } else {
            (2.0 * PI - theta) * cap_rate + centre_chord
        };
        total += sign * segment;
    }
    total
}

/// The smallest barycentric coordinate of `x` (projected on the triangle's plane) in the
/// triangle `v`: ≥ 0 inside.
fn barycentric_min(v: [V3; 3], x: V3) -> f64 {
    let e1 = vec3::sub(v[1], v[0]);
    let e2 = vec3::sub(v[2], v[0]);
    let d = vec3::sub(x, v[0]);
    let (d11, d12, d22) = (vec3::dot(e1, e1), vec3::dot(e1, e2), vec3::dot(e2, e2));
    let (d1, d2) = (vec3::dot(d, e1), vec3::dot(d, e2));
    let det = d11 * d22 - d12 * d12;
    if det <= 0.0 {
        return -1.0;
    }
    let b1 = (d22 * d1 - d12 * d2) / det;
    let b2 = (d11 * d2 - d12 * d1) / det;
    (1.0 - b1 - b2).min(b1).min(b2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitives;

    fn centroids(mesh: &TriMesh, every: usize) -> Vec<V3> {
        (0..mesh.n_triangles())
            .step_by(every)
            .map(|f| {
                let [a, b, c] = mesh.triangle_positions(f);
                vec3::scale(vec3::add(vec3::add(a, b), c), 1.0 / 3.0)
            })
            .collect()
    }

    /// The closed form against the octant: a triangle spanning the three unit axes
    /// subtends 4π / 8 from the origin.
    #[test]
    fn octant_triangle_subtends_an_eighth_of_the_sphere() {
        let w = triangle_solid_angle([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!((w - PI / 2.0).abs() < 1e-12, "{w}");
        let w = triangle_solid_angle([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]);
        assert!((w + PI / 2.0).abs() < 1e-12, "{w}");
    }

    /// A flat triangle cut by a sphere, against a fine numerical integral of
    /// `h / |x|³` over the part of the triangle inside the ball (all three cases: corner
    /// inside, edge crossing twice, disk inside the triangle).
    #[test]
    fn clipped_triangle_matches_numerical_integration() {
        let cases: [([V3; 3], f64); 4] = [
            ([[-0.2, -0.3, 0.4], [1.5, -0.2, 0.4], [0.1, 1.4, 0.4]], 0.8),
            ([[-2.0, 0.5, 0.3], [2.0, 0.5, 0.3], [0.0, 3.0, 0.3]], 0.9),
            ([[-3.0, -3.0, -0.5], [3.0, -3.0, -0.5], [0.0, 3.0, -0.5]], 1.0),
            ([[0.3, -0.5, 0.2], [0.5, 1.2, 0.6], [-0.9, 0.4, 0.1]], 0.7),
        ];
        for (v, r) in cases {
            let len = v.map(vec3::norm);
            let got = clipped_solid_angle(v, len, r);
            // Midpoint rule on a fine barycentric lattice.
            let m = 1200;
            let nrm = vec3::cross(vec3::sub(v[1], v[0]), vec3::sub(v[2], v[0]));
            let area = 0.5 * vec3::norm(nrm);
            let nhat = vec3::normalize(nrm).unwrap();
            let h = vec3::dot(v[0], nhat);
            let mut sum = 0.0;
            let cell = area / (m * m) as f64;
            for i in 0..m {
                for j in 0..m - i {
                    // Two sub-triangles per lattice cell; use the upright one's centroid
                    // and the inverted one's where it exists.
                    let mut add = |b1: f64, b2: f64| {
                        let x = vec3::add(
                            v[0],
                            vec3::add(
                                vec3::scale(vec3::sub(v[1], v[0]), b1),
                                vec3::scale(vec3::sub(v[2], v[0]), b2),
                            ),
                        );
                        let d = vec3::norm(x);
                        if d < r {
                            sum += h / (d * d * d) * cell;
                        }
                    };
                    let (fi, fj, mf) = (i as f64, j as f64, m as f64);
                    add((fi + 1.0 / 3.0) / mf, (fj + 1.0 / 3.0) / mf);
                    if i + j + 1 < m {
                        add((fi + 2.0 / 3.0) / mf, (fj + 2.0 / 3.0) / mf);
                    }
                }
            }
            assert!((got - sum).abs() < 2e-3 * sum.abs().max(0.1), "r {r}: {got} vs {sum}");
        }
    }

    /// On a sphere of radius R the exact value is ½ − r/(4R) (the cap of the small sphere
    /// inside the large one). A level-5 icosphere is within 0.1 % of the round sphere.
    #[test]
    fn sphere_matches_the_analytic_fraction() {
        let mesh = primitives::icosphere(5);
        let pts = centroids(&mesh, 97);
        let radii = [0.1, 0.4, 1.0, 1.6];
        let v = solid_angle_curvature(&mesh, &pts, &radii).unwrap();
        for (k, &r) in radii.iter().enumerate() {
            let exact = 0.5 - r / 4.0;
            for i in 0..pts.len() {
                let got = v[i * radii.len() + k];
                assert!((got - exact).abs() < 5e-4, "r = {r}, point {i}: {got} vs {exact}");
            }
        }
    }

    /// On a plane (an open grid) the value is ½ at every radius, exactly.
    #[test]
    fn plane_gives_one_half() {
        let mesh = primitives::grid(20, 20, 4.0, 4.0);
        let pts: Vec<V3> = centroids(&mesh, 1)
            .into_iter()
            .filter(|p| (p[0] - 2.0).abs() < 0.5 && (p[1] - 2.0).abs() < 0.5)
            .collect();
        assert!(pts.len() >= 40, "{} points", pts.len());
        let v = solid_angle_curvature(&mesh, &pts, &[0.05, 0.2, 0.5, 1.0]).unwrap();
        for x in &v {
            assert!((x - 0.5).abs() < 1e-12, "{x}");
        }
    }

    /// On a cube: ½ inside a face and, for points on a face 10⁻⁸ from an edge or a
    /// corner, ¼ and ⅛ (the value is continuous in the point; radii below the distance
    /// to the next feature); a convex shape never exceeds ½.
    #[test]
    fn cube_face_edge_and_corner() {
        let mesh = primitives::cube(4);
        let e = 1.0 - 1e-8;
        let pts = [[0.1, 0.2, 1.0], [1.0, e, 0.2], [e, e, 1.0]];
        let v = solid_angle_curvature(&mesh, &pts, &[0.3, 0.6]).unwrap();
        for (i, want) in [0.5, 0.25, 0.125].into_iter().enumerate() {
            for k in 0..2 {
                assert!(
                    (v[i * 2 + k] - want).abs() < 1e-6,
                    "point {i}: {} vs {want}",
                    v[i * 2 + k]
                );
            }
        }
        let all = solid_angle_curvature(&mesh, &centroids(&mesh, 5), &[0.5, 1.5, 3.0]).unwrap();
        assert!(all.iter().all(|&x| x <= 0.5 + 1e-9));
    }

    #[test]
    fn bad_radii_are_refused() {
        let mesh = primitives::icosphere(1);
        assert!(solid_angle_curvature(&mesh, &[[1.0, 0.0, 0.0]], &[0.0]).is_err());
        assert!(solid_angle_curvature(&mesh, &[[1.0, 0.0, 0.0]], &[f64::NAN]).is_err());
    }
}
