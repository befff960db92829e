//! Unit quaternions for 3-D frame fields (paper E §3, Zhang et al. 2010).
//!
//! A quaternion is `[w, x, y, z]` (scalar first); the unit quaternion
//! `[cos(α/2), sin(α/2)·a]` turns vectors counter-clockwise by `α` about the unit axis
//! `a`. A *frame* is a rotation matrix whose **columns** are the local x, y and z axes
//! in world coordinates (right-handed, orthonormal), stored row-major:
//! `m[3 * row + col]`. `q` and `−q` are the same rotation; [`align_sign`] picks the one
//! nearer a reference, which is how the frame field keeps its harmonic interpolation
//! continuous.

/// A quaternion `[w, x, y, z]`.
pub type Quat = [f64; 4];

/// The identity rotation.
pub const IDENTITY: Quat = [1.0, 0.0, 0.0, 0.0];

/// Four-dimensional dot product.
#[inline]
pub fn dot(a: Quat, b: Quat) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// `q` scaled to unit length; `None` when its length is below `1e-12` or not finite.
#[inline]
pub fn normalize(q: Quat) -> Option<Quat> {
    let n = dot(q, q).sqrt();
    if !(n.is_finite() && n > 1e-12) {
        return None;
    }
    Some([q[0] / n, q[1] / n, q[2] / n, q[3] / n])
}

/// `q` or `−q`, whichever has a non-negative dot product with `reference`.
#[inline]
pub fn align_sign(q: Quat, reference: Quat) -> Quat {
    if dot(q, reference) < 0.0 { [-q[0], -q[1], -q[2], -q[3]] } else { q }
}

/// Hamilton product `a ⊗ b` (apply `b`, then `a`).
#[inline]
pub fn mul(a: Quat, b: Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The rotation matrix of the unit quaternion `q` (row-major, columns = local axes).
#[inline]
pub fn to_matrix(q: Quat) -> [f64; 9] {
    let [w, x, y, z] = q;
    [
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    ]
}

/// The unit quaternion of the rotation matrix `m` (row-major, orthonormal,
/// determinant +1), with `w ≥ 0` (Shepperd's method: the largest diagonal term decides
/// which component is computed from a square root).
pub fn from_matrix(m: [f64; 9]) -> Quat {
    let (m00, m11, m22) = (m[0], m[4], m[8]);
    let trace = m00 + m11 + m22;
    let q = if trace > 0.0 {
        let s = (trace + 1.0).sqrt() * 2.0;
        [0.25 * s, (m[7] - m[5]) / s, (m[2] - m[6]) / s, (m[3] - m[1]) / s]
    } else if m00 > m11 && m00 > m22 {
        let s = (1.0 + m00 - m11 - m22).sqrt() * 2.0;
        [(m[7] - m[5]) / s, 0.25 * s, (m[1] + m[3]) / s, (m[2] + m[6]) / s]
    } else if m11 > m22 {
        let s = (1.0 + m11 - m00 - m22).sqrt() * 2.0;
        [(m[2] - m[6]) / s, (m[1] + m[3]) / s, 0.25 * s, (m[5] + m[7]) / s]
    } else {
        let s = (1.0 + m22 - m00 - m11).sqrt() * 2.0;
        [(m[3] - m[1]) / s, (m[2] + m[6]) / s, (m[5] + m[7]) / s, 0.25 * s]
    };
    let q = normalize(q).unwrap_or(IDENTITY);
    if q[0] < 0.0 { [-q[0], -q[1], -q[2], -q[3]] } else { q }
}

/// Local axis `axis` (0 = x, 1 = y, 2 = z) of the frame `q`, in world coordinates.
#[inline]
pub fn axis_of(q: Quat, axis: usize) -> [f64; 3] {
    let m = to_matrix(q);
    [m[axis], m[3 + axis], m[6 + axis]]
}

/// The smallest rotation taking the unit vector `a` to the unit vector `b`.
pub fn rotation_between(a: [f64; 3], b: [f64; 3]) -> Quat {
    let c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    if c < -1.0 + 1e-12 {
        // Opposite vectors: half a turn about any axis orthogonal to `a`.
        let helper = if a[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
        let o = [
            a[1] * helper[2] - a[2] * helper[1],
            a[2] * helper[0] - a[0] * helper[2],
            a[0] * helper[1] - a[1] * helper[0],
        ];
        return normalize([0.0, o[0], o[1], o[2]]).unwrap_or(IDENTITY);
    }
    normalize([1.0 + c, cross[0], cross[1], cross[2]]).unwrap_or(IDENTITY)
}

/// Rotation angle between two frames, degrees, in `[0, 180]` (sign-independent).
pub fn angle_between_deg(a: Quat, b: Quat) -> f64 {
    let d = dot(a, b).abs().min(1.0);
    2.0 * d.acos().to_degrees()
}

/// The frame with local axis `axis` along `tangent` and local axis `(axis + 2) % 3`
/// along the part of `normal` orthogonal to the tangent; the third axis completes a
/// right-handed frame (`normal × tangent`). `None` when the tangent is degenerate or
/// parallel to the normal.
pub fn frame_from_tangent_normal(tangent: [f64; 3], normal: [f64; 3], axis: usize) -> Option<Quat> {
    let t = unit3(tangent)?;
    let tn = normal[0] * t[0] + normal[1] * t[1] + normal[2] * t[2];
    let n = unit3([normal[0] - tn * t[0], normal[1] - tn * t[1], normal[2] - tn * t[2]])?;
    let b = [n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]];
    let mut cols = [[0.0; 3]; 3];
    cols[axis % 3] = t;
    cols[(axis + 2) % 3] = n;
    cols[(axis + 1) % 3] = b;
    let m = [
        cols[0][0], cols[1][0], cols[2][0], cols[0][1], cols[1][1], cols[2][1], cols[0][2],
        cols[1][2], cols[2][2],
    ];
    Some(from_matrix(m))
}

fn unit3(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (n.is_finite() && n > 1e-12).then(|| [v[0] / n, v[1] / n, v[2] / n])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrix_round_trip_and_sign() {
        let q = normalize([0.3, -0.5, 0.7, 0.2]).unwrap();
        let back = from_matrix(to_matrix(q));
        assert!(angle_between_deg(q, back) < 1e-6);
        // The same rotation with the opposite sign is 0° away.
        let neg = [-q[0], -q[1], -q[2], -q[3]];
        assert!(angle_between_deg(q, neg) < 1e-6);
        assert!(dot(align_sign(neg, q), q) > 0.0);
        assert!(back[0] >= 0.0);
    }

    #[test]
    fn tangent_normal_frames_are_right_handed() {
        for axis in 0..3 {
            let q = frame_from_tangent_normal([1.0, 1.0, 0.0], [0.0, 0.2, 1.0], axis).unwrap();
            let t = axis_of(q, axis);
            assert!((t[0] - t[1]).abs() < 1e-9 && t[2].abs() < 1e-9);
            let (x, y, z) = (axis_of(q, 0), axis_of(q, 1), axis_of(q, 2));
            let c =
                [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]];
            assert!((c[0] - z[0]).abs() + (c[1] - z[1]).abs() + (c[2] - z[2]).abs() < 1e-9);
        }
        assert!(frame_from_tangent_normal([0.0, 0.0, 1.0], [0.0, 0.0, 2.0], 0).is_none());
    }

    #[test]
    fn rotation_between_maps_a_to_b() {
        let a = [0.0, 0.0, 1.0];
        for b in [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.6, 0.0, 0.8]] {
            let q = rotation_between(a, b);
            let m = to_matrix(q);
            let r = [m[2], m[5], m[8]];
            assert!((r[0] - b[0]).abs() + (r[1] - b[1]).abs() + (r[2] - b[2]).abs() < 1e-9);
        }
        let q = mul(rotation_between([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), IDENTITY);
        assert!((angle_between_deg(q, IDENTITY) - 90.0).abs() < 1e-9);
    }
}
