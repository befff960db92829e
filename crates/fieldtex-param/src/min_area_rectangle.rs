//! Minimum-area enclosing rectangle of a 2-D point set (the optimal rectangle has a
//! side along an edge of the convex hull; Freeman & Shapira 1975). Used to turn charts
//! so that their bounding boxes are tight before packing.

/// Convex hull (Andrew's monotone chain), counter-clockwise, without collinear points.
pub fn convex_hull(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut p: Vec<[f64; 2]> =
        points.iter().copied().filter(|q| q[0].is_finite() && q[1].is_finite()).collect();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> =
            if pass == 0 { Box::new(p.iter()) } else { Box::new(p.iter().rev()) };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// Angle `θ` such that rotating the points by `−θ` makes their axis-aligned bounding
/// box the minimum-area enclosing rectangle; 0 for fewer than three hull points.
pub fn min_area_rectangle_angle(points: &[[f64; 2]]) -> f64 {
    let hull = convex_hull(points);
    if hull.len() < 3 {
        return 0.0;
    }
    let mut best = (f64::INFINITY, 0.0);
    for k in 0..hull.len() {
        let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
        if len.is_nan() || len <= 0.0 {
            continue;
        }
        let (c, s) = (d[0] / len, d[1] / len);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for q in &hull {
            let x = c * q[0] + s * q[1];
            let y = -s * q[0] + c * q[1];
            lo = [lo[0].min(x), lo[1].min(y)];
            hi = [hi[0].max(x), hi[1].max(y)];
        }
        let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
        if area < best.0 {
            best = (area, s.atan2(c));
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotated_rectangle_is_found() {
        let t: f64 = 0.4;
        let (c, s) = (t.cos(), t.sin());
        let pts: Vec<[f64; 2]> = [[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [0.0, 1.0], [2.0, 0.5]]
            .iter()
            .map(|p| [c * p[0] - s * p[1], s * p[0] + c * p[1]])
            .collect();
        assert_eq!(convex_hull(&pts).len(), 4);
        let a = min_area_rectangle_angle(&pts);
        let m = (a - t).rem_euclid(std::f64::consts::FRAC_PI_2);
        assert!(m < 1e-9 || (std::f64::consts::FRAC_PI_2 - m) < 1e-9, "angle {a}");
    }
}
