//! Triangulation of planar polygons with holes by ear clipping (Meisters 1975; holes
//! joined to their outer loop by bridge edges, as in Eberly's "Triangulation by ear
//! clipping", 2002).
//!
//! Input: 2-D points and loops of point indices (closed implicitly). Loops with
//! positive signed area (counter-clockwise) are outer boundaries, loops with negative
//! area are holes and are assigned to the smallest outer loop containing them. Output
//! triangles are counter-clockwise and use only the loops' points, so every loop edge
//! is used by exactly one triangle (bridges by two, in opposite directions): a cap
//! triangulated this way closes a mesh whose boundary is the loops.
//!
//! Degenerate input (self-intersecting loops, collinear runs) never hangs: when no ear
//! is found the most convex corner is clipped anyway and the count of such forced clips
//! is returned.

/// Triangles (point indices, counter-clockwise) and the number of forced clips.
pub fn triangulate_polygons(points: &[[f64; 2]], loops: &[Vec<usize>]) -> (Vec<[usize; 3]>, usize) {
    let area = |l: &[usize]| -> f64 {
        let mut a = 0.0;
        for i in 0..l.len() {
            let (p, q) = (points[l[i]], points[l[(i + 1) % l.len()]]);
            a += p[0] * q[1] - q[0] * p[1];
        }
        0.5 * a
    };
    let mut outers: Vec<(Vec<usize>, f64)> = Vec::new();
    let mut holes: Vec<Vec<usize>> = Vec::new();
    for l in loops.iter().filter(|l| l.len() >= 3) {
        let a = area(l);
        if a > 0.0 {
            outers.push((l.clone(), a));
        } else if a < 0.0 {
            holes.push(l.clone());
        }
    }
    let mut assigned: Vec<Vec<Vec<usize>>> = vec![Vec::new(); outers.len()];
    for h in holes {
        let p = points[h[0]];
        let container = (0..outers.len())
            .filter(|&o| point_in_polygon(points, &outers[o].0, p))
            .min_by(|&a, &b| outers[a].1.total_cmp(&outers[b].1));
        if let Some(o) = container {
            assigned[o].push(h);
        }
    }
    let mut tris = Vec::new();
    let mut forced = 0;
    for (o, (outer, _)) in outers.iter().enumerate() {
        let mut poly = outer.clone();
        let mut hs = std::mem::take(&mut assigned[o]);
        // Rightmost holes first.
        hs.sort_by(|a, b| max_x(points, b).total_cmp(&max_x(points, a)));
        for (hi, h) in hs.iter().enumerate() {
            poly = bridge(points, &poly, h, &hs[hi + 1..]);
        }
        forced += ear_clip(points, &poly, &mut tris);
    }
    (tris, forced)
}

fn max_x(points: &[[f64; 2]], l: &[usize]) -> f64 {
    l.iter().map(|&i| points[i][0]).fold(f64::NEG_INFINITY, f64::max)
}

fn point_in_polygon(points: &[[f64; 2]], l: &[usize], p: [f64; 2]) -> bool {
    let mut inside = false;
    for i in 0..l.len() {
        let (a, b) = (points[l[i]], points[l[(i + 1) % l.len()]]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Whether segments `pq` and `rs` cross at a point interior to both.
fn proper_cross(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2]) -> bool {
    let d1 = cross(p, q, r);
    let d2 = cross(p, q, s);
    let d3 = cross(r, s, p);
    let d4 = cross(r, s, q);
    (d1 > 0.0) != (d2 > 0.0)
        && (d3 > 0.0) != (d4 > 0.0)
        && d1 != 0.0
        && d2 != 0.0
        && d3 != 0.0
        && d4 != 0.0
}

/// `poly` with hole `h` joined through a bridge from the hole's rightmost point to the
/// nearest visible polygon point (`others`: holes not yet joined, which bridges must
/// not cross either).
fn bridge(points: &[[f64; 2]], poly: &[usize], h: &[usize], others: &[Vec<usize>]) -> Vec<usize> {
    let hs = (0..h.len()).max_by(|&a, &b| points[h[a]][0].total_cmp(&points[h[b]][0])).unwrap_or(0);
    let hp = points[h[hs]];
    let mut order: Vec<usize> = (0..poly.len()).collect();
    let d2 = |i: usize| {
        let p = points[poly[i]];
        (p[0] - hp[0]).powi(2) + (p[1] - hp[1]).powi(2)
    };
    order.sort_by(|&a, &b| d2(a).total_cmp(&d2(b)));
    let edges_cross = |l: &[usize], vp: [f64; 2]| {
        (0..l.len()).any(|i| proper_cross(hp, vp, points[l[i]], points[l[(i + 1) % l.len()]]))
    };
    let chosen = order
        .iter()
        .copied()
        .find(|&i| {
            let vp = points[poly[i]];
            !edges_cross(poly, vp)
                && !edges_cross(h, vp)
                && !others.iter().any(|o| edges_cross(o, vp))
        })
        .unwrap_or(order[0]);
    let mut out = Vec::with_capacity(poly.len() + h.len() + 2);
    out.extend_from_slice(&poly[..=chosen]);
    for k in 0..=h.len() {
        out.push(h[(hs + k) % h.len()]);
    }
    out.push(poly[chosen]);
    out.extend_from_slice(&poly[chosen + 1..]);
    out
}

fn ear_clip(points: &[[f64; 2]], poly: &[usize], tris: &mut Vec<[usize; 3]>) -> usize {
    let mut v: Vec<usize> = poly.to_vec();
    let mut forced = 0;
    while v.len() > 3 {
        let n = v.len();
        let mut found = None;
        for i in 0..n {
            let (a, b, c) = (v[(i + n - 1) % n], v[i], v[(i + 1) % n]);
            let (pa, pb, pc) = (points[a], points[b], points[c]);
            if cross(pa, pb, pc) <= 0.0 {
                continue;
            }
            let blocked = v.iter().any(|&k| {
                if k == a || k == b || k == c {
                    return false;
                }
                let p = points[k];
                if p == pa || p == pb || p == pc {
                    return false;
                }
                cross(pa, pb, p) >= 0.0 && cross(pb, pc, p) >= 0.0 && cross(pc, pa, p) >= 0.0
            });
            if !blocked {
                found = Some(i);
                break;
            }
        }
        let i = found.unwrap_or_else(|| {
            forced += 1;
            (0..n)
                .max_by(|&x, &y| {
                    let cx =
                        cross(points[v[(x + n - 1) % n]], points[v[x]], points[v[(x + 1) % n]]);
                    let cy =
                        cross(points[v[(y + n - 1) % n]], points[v[y]], points[v[(y + 1) % n]]);
                    cx.total_cmp(&cy)
                })
                .unwrap_or(0)
        });
        let t = [v[(i + n - 1) % n], v[i], v[(i + 1) % n]];
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            tris.push(t);
        }
        v.remove(i);
    }
    if v.len() == 3 && v[0] != v[1] && v[1] != v[2] && v[0] != v[2] {
        tris.push([v[0], v[1], v[2]]);
    }
    forced
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_with_a_hole_covers_its_area() {
        let pts = vec![
            [0.0, 0.0],
            [4.0, 0.0],
            [4.0, 4.0],
            [0.0, 4.0],
            [1.0, 1.0],
            [1.0, 3.0],
            [3.0, 3.0],
            [3.0, 1.0],
        ];
        let (tris, forced) = triangulate_polygons(&pts, &[vec![0, 1, 2, 3], vec![4, 5, 6, 7]]);
        assert_eq!(forced, 0);
        let area: f64 = tris.iter().map(|t| 0.5 * cross(pts[t[0]], pts[t[1]], pts[t[2]])).sum();
        assert!((area - 12.0).abs() < 1e-9, "area {area}");
        assert!(tris.iter().all(|t| cross(pts[t[0]], pts[t[1]], pts[t[2]]) > 0.0));
    }

    #[test]
    fn concave_polygon() {
        let pts = vec![[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [2.0, 1.0], [1.0, 1.0], [0.0, 3.0]];
        let (tris, forced) = triangulate_polygons(&pts, &[vec![0, 1, 2, 3, 4, 5]]);
        assert_eq!((tris.len(), forced), (4, 0));
        let area: f64 = tris.iter().map(|t| 0.5 * cross(pts[t[0]], pts[t[1]], pts[t[2]])).sum();
        assert!((area - 5.0).abs() < 1e-9);
    }
}
