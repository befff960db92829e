//! Zero points of a holomorphic 1-form: vertices around which the real part's face
//! vector field turns by a non-zero whole number of turns (index −1 for a simple zero;
//! a closed genus-g surface has `2g − 2` of them counted with multiplicity, Wang et al.
//! 2005 §3).
//!
//! The index at vertex `v` walks its triangle fan counter-clockwise, unfolding the fan
//! into the plane (cumulative corner angles); the field's angle in each triangle is
//! measured from the fan edge that starts the triangle, and the index is the rounded
//! sum of the wrapped angle changes over `2π`. Boundary vertices are skipped.

use fieldtex_core::vec3;
use std::f64::consts::PI;

/// `(vertex, index)` for every interior vertex with a non-zero index of the face vector
/// field `x` (`#F` tangent vectors) on the consistently oriented `triangles`.
pub fn vertex_indices(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    vertex_faces: impl Fn(usize) -> Vec<u32>,
    x: &[[f64; 3]],
    keep: &[bool],
) -> Vec<(u32, i32)> {
    let mut out = Vec::new();
    for v in 0..positions.len() {
        let faces = vertex_faces(v);
        if faces.is_empty() || faces.iter().any(|&f| !keep[f as usize]) {
            continue;
        }
        // (face, next ring vertex x, previous ring vertex y) with corner order v, x, y.
        let fan: Vec<(usize, u32, u32)> = faces
            .iter()
            .map(|&f| {
                let t = triangles[f as usize];
                let k = (0..3).find(|&k| t[k] as usize == v).unwrap_or(0);
                (f as usize, t[(k + 1) % 3], t[(k + 2) % 3])
            })
            .collect();
        // Order counter-clockwise: the face after (v, x, y) starts with edge v → y.
        let mut order = Vec::with_capacity(fan.len());
        let mut cur = 0usize;
        let mut ok = true;
        for _ in 0..fan.len() {
            order.push(cur);
            let y = fan[cur].2;
            match fan.iter().position(|c| c.1 == y) {
                Some(n) => cur = n,
                None => {
                    ok = false;
                    break;
                }
            }
        }
        if !ok || cur != 0 {
            continue;
        }
        let pv = positions[v];
        let mut theta = 0.0;
        let mut psi = Vec::with_capacity(order.len());
        for &i in &order {
            let (f, xv, yv) = fan[i];
            let ex = vec3::sub(positions[xv as usize], pv);
            let ey = vec3::sub(positions[yv as usize], pv);
            let n = match vec3::normalize(vec3::cross(ex, ey)) {
                Some(n) => n,
                None => continue,
            };
            let ux = match vec3::normalize(ex) {
                Some(u) => u,
                None => continue,
            };
            let uy = vec3::cross(n, ux);
            let ang = vec3::dot(x[f], uy).atan2(vec3::dot(x[f], ux));
            psi.push(theta + ang);
            let corner = vec3::dot(ey, uy).atan2(vec3::dot(ey, ux));
            theta += corner;
        }
        if psi.len() < 3 {
            continue;
        }
        let mut total = 0.0;
        for k in 0..psi.len() {
            let next = if k + 1 < psi.len() { psi[k + 1] } else { psi[0] + theta };
            total += wrap(next - psi[k]);
        }
        let index = (total / (2.0 * PI)).round() as i32;
        if index != 0 {
            out.push((v as u32, index));
        }
    }
    out
}

fn wrap(a: f64) -> f64 {
    let mut a = a % (2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    } else if a < -PI {
        a += 2.0 * PI;
    }
    a
}
