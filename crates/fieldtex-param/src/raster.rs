//! Conservative rasterisation of 2-D triangles onto the unit texel lattice.
//!
//! Texel `(x, y)` is the square `[x, x+1] × [y, y+1]`. A triangle *covers* a texel when
//! the closed triangle, grown by `eps` in every direction, meets the closed square.
//! Works for degenerate triangles (segments and points) too. The packer rasterises with
//! a small positive `eps` and the texel map with `eps = 0`, so every texel the texel map
//! covers was reserved by the packer.

/// `⌊x⌋` for finite `x` (saturating outside the `i64` range) without a libm call.
#[inline]
fn floor_i64(x: f64) -> i64 {
    let i = x as i64;
    if (i as f64) > x { i - 1 } else { i }
}

/// Calls `emit(row, x_first, x_last)` for every texel row the triangle touches, with the
/// inclusive range of texel columns it covers in that row.
///
/// Per row, the x extent of the triangle clipped to the strip `[row − eps, row + 1 +
/// eps]` is the extent of: the long edge (lowest to highest corner) and the two-edge
/// chain through the middle corner, each at the strip's two clipped heights, and the
/// middle corner when it lies in the strip (the boundary is piecewise linear in y).
pub fn triangle_row_spans(t: [[f64; 2]; 3], eps: f64, mut emit: impl FnMut(i64, i64, i64)) {
    if !t.iter().all(|p| p[0].is_finite() && p[1].is_finite()) {
        return;
    }
    let mut v = t;
    if v[1][1] < v[0][1] {
        v.swap(0, 1);
    }
    if v[2][1] < v[1][1] {
        v.swap(1, 2);
    }
    if v[1][1] < v[0][1] {
        v.swap(0, 1);
    }
    let [a, b, c] = v;
    let slope = |p: [f64; 2], q: [f64; 2]| {
        if q[1] > p[1] { (q[0] - p[0]) / (q[1] - p[1]) } else { 0.0 }
    };
    let (s_ac, s_ab, s_bc) = (slope(a, c), slope(a, b), slope(b, c));
    let long = |y: f64| a[0] + (y - a[1]) * s_ac;
    let chain =
        |y: f64| if y <= b[1] { a[0] + (y - a[1]) * s_ab } else { b[0] + (y - b[1]) * s_bc };
    let r0 = floor_i64(a[1] - eps);
    let r1 = floor_i64(c[1] + eps);
    for row in r0..=r1 {
        let y0 = (row as f64 - eps).max(a[1]);
        let y1 = (row as f64 + 1.0 + eps).min(c[1]);
        if y0 > y1 {
            continue;
        }
        let (l0, l1, c0, c1) = (long(y0), long(y1), chain(y0), chain(y1));
        let mut lo = l0.min(l1).min(c0.min(c1));
        let mut hi = l0.max(l1).max(c0.max(c1));
        if b[1] >= y0 && b[1] <= y1 {
            lo = lo.min(b[0]);
            hi = hi.max(b[0]);
        }
        emit(row, floor_i64(lo - eps), floor_i64(hi + eps));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The former per-row clipping (every corner and every edge crossing of the strip's
    /// two heights), kept as the oracle of [`triangle_row_spans`].
    fn reference_spans(t: [[f64; 2]; 3], eps: f64) -> Vec<(i64, i64, i64)> {
        let mut out = Vec::new();
        let ymin = t[0][1].min(t[1][1]).min(t[2][1]) - eps;
        let ymax = t[0][1].max(t[1][1]).max(t[2][1]) + eps;
        for row in ymin.floor() as i64..=ymax.floor() as i64 {
            let (y0, y1) = (row as f64 - eps, row as f64 + 1.0 + eps);
            let mut lo = f64::INFINITY;
            let mut hi = f64::NEG_INFINITY;
            for p in &t {
                if p[1] >= y0 && p[1] <= y1 {
                    lo = lo.min(p[0]);
                    hi = hi.max(p[0]);
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
                        let x = p[0] + s * (q[0] - p[0]);
                        lo = lo.min(x);
                        hi = hi.max(x);
                    }
                }
            }
            if lo <= hi {
                out.push((row, (lo - eps).floor() as i64, (hi + eps).floor() as i64));
            }
        }
        out
    }

    #[test]
    fn matches_the_clipping_reference() {
        // Deterministic pseudo-random triangles, including flat and tiny ones.
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut differ = 0;
        for k in 0..20_000 {
            let scale = [0.3, 3.0, 40.0][k % 3];
            let mut t = [[0.0; 2]; 3];
            for p in t.iter_mut() {
                *p = [next() * scale - 1.0, next() * scale - 1.0];
            }
            if k % 7 == 0 {
                t[2][1] = t[0][1]; // a horizontal edge
            }
            for eps in [0.0, 1e-3] {
                let mut got = Vec::new();
                triangle_row_spans(t, eps, |r, a, b| got.push((r, a, b)));
                let want = reference_spans(t, eps);
                if got != want {
                    // Only rounding at a texel boundary may differ, by one column.
                    assert_eq!(got.len(), want.len(), "{t:?}");
                    for (g, w) in got.iter().zip(&want) {
                        assert_eq!(g.0, w.0, "{t:?}");
                        assert!((g.1 - w.1).abs() <= 1 && (g.2 - w.2).abs() <= 1, "{t:?}");
                    }
                    differ += 1;
                }
            }
        }
        assert!(differ < 20, "{differ} of 40000 rasterisations differ");
    }

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
