//! Conservative rasterisation of 2-D triangles onto the unit texel lattice.
//!
//! Texel `(x, y)` is the square `[x, x+1] × [y, y+1]`. A triangle *covers* a texel when
//! the closed triangle, grown by `eps` in every direction, meets the closed square.
//! Works for degenerate triangles (segments and points) too. The packer rasterises with
//! a small positive `eps` and the texel map with `eps = 0`, so every texel the texel map
//! covers was reserved by the packer.

/// Calls `emit(row, x_first, x_last)` for every texel row the triangle touches, with the
/// inclusive range of texel columns it covers in that row.
pub fn triangle_row_spans(t: [[f64; 2]; 3], eps: f64, mut emit: impl FnMut(i64, i64, i64)) {
    if !t.iter().all(|p| p[0].is_finite() && p[1].is_finite()) {
        return;
    }
    let ymin = t[0][1].min(t[1][1]).min(t[2][1]) - eps;
    let ymax = t[0][1].max(t[1][1]).max(t[2][1]) + eps;
    let r0 = ymin.floor() as i64;
    let r1 = ymax.floor() as i64;
    for row in r0..=r1 {
        let y0 = row as f64 - eps;
        let y1 = row as f64 + 1.0 + eps;
        if let Some((xa, xb)) = strip_extent(&t, y0, y1) {
            let c0 = (xa - eps).floor() as i64;
            let c1 = (xb + eps).floor() as i64;
            emit(row, c0, c1);
        }
    }
}

/// The x extent of the triangle clipped to the horizontal strip `y0 ≤ y ≤ y1`.
fn strip_extent(t: &[[f64; 2]; 3], y0: f64, y1: f64) -> Option<(f64, f64)> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut take = |x: f64| {
        lo = lo.min(x);
        hi = hi.max(x);
    };
    for p in t {
        if p[1] >= y0 && p[1] <= y1 {
            take(p[0]);
        }
    }
    for k in 0..3 {
        let (p, q) = (t[k], t[(k + 1) % 3]);
        if p[1] == q[1] {
            continue;
        }
        for y in [y0, y1] {
            let s = (y - p[1]) / (q[1] - p[1]);
            if (0.0..=1.0).contains(&s) {
                take(p[0] + s * (q[0] - p[0]));
            }
        }
    }
    (lo <= hi).then_some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covers_touched_texels() {
        let mut cells = Vec::new();
        triangle_row_spans([[0.5, 0.5], [2.5, 0.5], [0.5, 2.5]], 0.0, |r, a, b| {
            for x in a..=b {
                cells.push((x, r));
            }
        });
        // Row 0: x in [0.5, 2.5] -> columns 0..=2; row 1: x in [0.5, 2.0] -> 0..=2
        // (touching the left edge of column 2 counts); row 2: x in [0.5, 1.0] -> 0..=1.
        let expect = vec![(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1), (0, 2), (1, 2)];
        assert_eq!(cells, expect);
    }

    #[test]
    fn degenerate_segment_and_nan() {
        let mut n = 0;
        triangle_row_spans([[0.2, 0.2], [3.7, 0.2], [1.0, 0.2]], 0.0, |_, a, b| n += b - a + 1);
        assert_eq!(n, 4);
        let mut m = 0;
        triangle_row_spans([[f64::NAN, 0.0], [1.0, 0.0], [0.0, 1.0]], 0.0, |_, _, _| m += 1);
        assert_eq!(m, 0);
    }
}
