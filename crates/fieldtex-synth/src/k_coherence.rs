//! k-coherence candidate sets (Tong et al. 2002; Lefebvre & Hoppe 2005, §3.2).
//!
//! For every exemplar pixel `u` the `k` pixels whose appearance vectors are closest to
//! `u`'s (squared Euclidean distance in the 8-D appearance space), excluding pixels
//! within toroidal Chebyshev distance `< radius` of `u` so that the candidates point
//! to *other* places of the exemplar. Ties are broken by the smaller pixel index.
//!
//! The search is exact: pixels are sorted by their first principal component and each
//! query scans outward in that order, stopping once the gap in the first component
//! alone exceeds the current k-th best distance. Each query is independent, so the
//! result does not depend on the thread count.

use rayon::prelude::*;

use crate::exemplar_analysis::APPEARANCE_DIMS;

#[inline]
fn dist2(a: &[f32; APPEARANCE_DIMS], b: &[f32; APPEARANCE_DIMS]) -> f32 {
    let mut s = 0.0f32;
    for i in 0..APPEARANCE_DIMS {
        let d = a[i] - b[i];
        s += d * d;
    }
    s
}

/// The `k` most similar pixels of every pixel of the `width × height` appearance image
/// `app`: `width × height × k` pixel indices, row-major, best first. A pixel with fewer
/// than `k` eligible partners (tiny exemplars) repeats its best one, or itself.
pub fn k_coherence(
    app: &[[f32; APPEARANCE_DIMS]],
    width: usize,
    height: usize,
    k: usize,
    radius: usize,
) -> Vec<u32> {
    let n = width * height;
    assert_eq!(app.len(), n, "k_coherence: app must hold width × height vectors");
    if k == 0 {
        return Vec::new();
    }
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by(|&a, &b| app[a as usize][0].total_cmp(&app[b as usize][0]).then(a.cmp(&b)));
    let mut rank = vec![0usize; n];
    for (r, &i) in order.iter().enumerate() {
        rank[i as usize] = r;
    }
    let key: Vec<f32> = order.iter().map(|&i| app[i as usize][0]).collect();
    let far = |a: usize, b: usize| -> bool {
        let (ax, ay) = ((a % width) as i64, (a / width) as i64);
        let (bx, by) = ((b % width) as i64, (b / width) as i64);
        let dx = (ax - bx).rem_euclid(width as i64);
        let dy = (ay - by).rem_euclid(height as i64);
        let dx = dx.min(width as i64 - dx);
        let dy = dy.min(height as i64 - dy);
        dx.max(dy) >= radius as i64
    };
    let mut out = vec![0u32; n * k];
    out.par_chunks_mut(k).enumerate().for_each(|(i, slot)| {
        // Sorted list of the best (distance, index), ascending.
        let mut best: Vec<(f32, u32)> = Vec::with_capacity(k + 1);
        let q = &app[i];
        let worst =
            |best: &Vec<(f32, u32)>| if best.len() < k { f32::INFINITY } else { best[k - 1].0 };
        let consider = |j: u32, best: &mut Vec<(f32, u32)>| {
            if !far(i, j as usize) {
                return;
            }
            let d = dist2(q, &app[j as usize]);
            if best.len() == k && (d, j) >= best[k - 1] {
                return;
            }
            let pos = best.partition_point(|&e| e < (d, j));
            best.insert(pos, (d, j));
            best.truncate(k);
        };
        let r = rank[i];
        let qk = key[r];
        let (mut up, mut down) = (r + 1, r);
        loop {
            let w = worst(&best);
            let gu = if up < n { (key[up] - qk) * (key[up] - qk) } else { f32::INFINITY };
            let gd =
                if down > 0 { (key[down - 1] - qk) * (key[down - 1] - qk) } else { f32::INFINITY };
            if gu > w && gd > w || (up >= n && down == 0) {
                break;
            }
            if gu <= gd {
                consider(order[up], &mut best);
                up += 1;
            } else {
                down -= 1;
                consider(order[down], &mut best);
            }
        }
        for (t, s) in slot.iter_mut().enumerate() {
            *s = best.get(t).or(best.first()).map_or(i as u32, |e| e.1);
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pruned_search_equals_brute_force() {
        let (w, h) = (13, 11);
        let app: Vec<[f32; 8]> = (0..w * h)
            .map(|i| {
                let mut v = [0.0f32; 8];
                for (d, e) in v.iter_mut().enumerate() {
                    *e = ((i * 7919 + d * 104_729) % 97) as f32 * 0.01 + (d as f32 * 0.3).sin();
                }
                v
            })
            .collect();
        let (k, radius) = (3, 2);
        let fast = k_coherence(&app, w, h, k, radius);
        for i in 0..w * h {
            let mut all: Vec<(f32, u32)> = (0..(w * h) as u32)
                .filter(|&j| {
                    let (dx, dy) = (
                        (i % w) as i64 - (j as usize % w) as i64,
                        (i / w) as i64 - (j as usize / w) as i64,
                    );
                    let dx = dx.rem_euclid(w as i64).min((-dx).rem_euclid(w as i64));
                    let dy = dy.rem_euclid(h as i64).min((-dy).rem_euclid(h as i64));
                    dx.max(dy) >= radius as i64
                })
                .map(|j| (dist2(&app[i], &app[j as usize]), j))
                .collect();
            all.sort_by(|a, b| a.partial_cmp(b).unwrap());
            let expect: Vec<u32> = all[..k].iter().map(|e| e.1).collect();
            assert_eq!(&fast[i * k..(i + 1) * k], &expect[..], "pixel {i}");
        }
    }
}
