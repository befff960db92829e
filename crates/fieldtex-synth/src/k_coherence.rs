//! k-coherence candidate sets (Tong et al. 2002; Lefebvre & Hoppe 2005, §3.2).
//!
//! For every exemplar pixel `u` the `k` pixels whose appearance vectors are closest to
//! `u`'s (squared Euclidean distance in the 8-D appearance space), excluding pixels
//! within toroidal Chebyshev distance `< radius` of `u` so that the candidates point
//! to *other* places of the exemplar. Ties are broken by the smaller pixel index.
//!
//! Pixels are sorted by their first principal component (the direction of largest
//! appearance variance) and each query examines the `max_scan` pixels nearest to it in
//! that order (all pixels when `max_scan ≥ W·H`, which makes the search exact). This is
//! the "coarse PCA-1 window" approximation: candidates far away in the first component
//! are far in appearance. Each query is independent, so the result does not depend on
//! the thread count.

use rayon::prelude::*;

use crate::exemplar_analysis::APPEARANCE_DIMS;

/// Squared distance of two appearance vectors, summed in a fixed lane order (SIMD
/// friendly and deterministic).
#[inline]
pub(crate) fn dist2(a: &[f32; APPEARANCE_DIMS], b: &[f32; APPEARANCE_DIMS]) -> f32 {
    let mut l = [0.0f32; 4];
    for i in 0..4 {
        let d0 = a[i] - b[i];
        let d1 = a[i + 4] - b[i + 4];
        l[i] = d0 * d0 + d1 * d1;
    }
    (l[0] + l[1]) + (l[2] + l[3])
}

/// The `k` most similar pixels of every pixel of the `width × height` appearance image
/// `app`: `width × height × k` pixel indices, row-major, best first. Only pixels at
/// least `margin` pixels from the border are eligible partners (0: all). A pixel with
/// fewer than `k` eligible partners (tiny exemplars) repeats its best one, or itself.
pub fn k_coherence(
    app: &[[f32; APPEARANCE_DIMS]],
    width: usize,
    height: usize,
    k: usize,
    radius: usize,
    max_scan: usize,
    margin: usize,
) -> Vec<u32> {
    let n = width * height;
    assert_eq!(app.len(), n, "k_coherence: app must hold width × height vectors");
    assert!(k <= 16, "k_coherence: k must be at most 16");
    if k == 0 {
        return Vec::new();
    }
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by(|&a, &b| app[a as usize][0].total_cmp(&app[b as usize][0]).then(a.cmp(&b)));
    let mut rank = vec![0usize; n];
    for (r, &i) in order.iter().enumerate() {
        rank[i as usize] = r;
    }
    // The appearance vectors and pixel positions in sort order, for sequential scans.
    let sorted: Vec<[f32; APPEARANCE_DIMS]> = order.iter().map(|&i| app[i as usize]).collect();
    let pos: Vec<[i32; 2]> =
        order.iter().map(|&i| [(i as usize % width) as i32, (i as usize / width) as i32]).collect();
    let (wi, he, ri) = (width as i32, height as i32, radius as i32);
    let mi = margin as i32;
    let inside = |p: [i32; 2]| p[0] >= mi && p[1] >= mi && p[0] < wi - mi && p[1] < he - mi;
    let window = max_scan.min(n);
    let mut out = vec![0u32; n * k];
    out.par_chunks_mut(k).enumerate().for_each_init(
        || vec![0.0f32; window],
        |dists, (i, slot)| {
            let r = rank[i];
            let q = sorted[r];
            let qp = pos[r];
            // A window of `max_scan` pixels around the query in sort order.
            let lo = r.saturating_sub(window / 2).min(n - window);
            // Pass 1: all distances (branch-free, vectorisable).
            for (d, v) in dists.iter_mut().zip(&sorted[lo..lo + window]) {
                *d = dist2(&q, v);
            }
            // Pass 2: the k best eligible (distance, pixel), ascending.
            let mut best = [(f32::INFINITY, u32::MAX); 16];
            let best = &mut best[..k];
            for (o, &d) in dists.iter().enumerate() {
                if d > best[k - 1].0 {
                    continue;
                }
                let t = lo + o;
                let j = order[t];
                if t == r || (d == best[k - 1].0 && j >= best[k - 1].1) {
                    continue;
                }
                let dx = (pos[t][0] - qp[0]).abs();
                let dy = (pos[t][1] - qp[1]).abs();
                if dx.min(wi - dx).max(dy.min(he - dy)) < ri || !inside(pos[t]) {
                    continue;
                }
                let mut at = k - 1;
                while at > 0 && (d < best[at - 1].0 || (d == best[at - 1].0 && j < best[at - 1].1))
                {
                    best[at] = best[at - 1];
                    at -= 1;
                }
                best[at] = (d, j);
            }
            let first = if best[0].1 == u32::MAX { i as u32 } else { best[0].1 };
            for (s, b) in slot.iter_mut().zip(best.iter()) {
                *s = if b.1 == u32::MAX { first } else { b.1 };
            }
        },
    );
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
        let fast = k_coherence(&app, w, h, k, radius, usize::MAX, 0);
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
