//! Exact Euclidean distance transform of a binary image.
//!
//! Method: Felzenszwalb & Huttenlocher (2012, "Distance transforms of sampled
//! functions", Theory of Computing 8(19)), §2–3: the squared distance transform
//! `D(p) = min_q (‖p − q‖² + f(q))` with `f = 0` on feature pixels and `+∞` elsewhere is
//! separable; each 1-D pass is the lower envelope of the parabolas `(p − q)² + f(q)`,
//! computed in linear time (their Algorithm 1). Rows first, then columns.
//!
//! **Toroidal mode.** The squared distance on a torus, `min_k (dx + k·W)² + min_l (dy +
//! l·H)²`, is separable too; each 1-D pass runs on three copies of the line
//! (`[−n, 2n)`) and reads the middle copy, which is exact because a nearest copy of
//! any sample lies less than `n` away.
//!
//! Distances are between pixel centres, in pixels (`f32`); `+∞` everywhere when the
//! mask is empty. Each row and column is computed independently, so results do not
//! depend on the thread count.

use rayon::prelude::*;

/// 1-D squared distance transform (Felzenszwalb & Huttenlocher 2012, Algorithm 1) of
/// `f` (`+∞` = no sample), written to `out`. `v` and `z` are scratch buffers.
fn transform_1d(f: &[f64], out: &mut [f64], v: &mut Vec<usize>, z: &mut Vec<f64>) {
    let n = f.len();
    v.clear();
    z.clear();
    for q in 0..n {
        if !f[q].is_finite() {
            continue;
        }
        let fq = f[q] + (q * q) as f64;
        // Pop parabolas hidden by parabola q.
        loop {
            let Some(&p) = v.last() else {
                v.push(q);
                z.push(f64::NEG_INFINITY);
                break;
            };
            let s = (fq - (f[p] + (p * p) as f64)) / (2.0 * (q as f64 - p as f64));
            if s <= *z.last().expect("z mirrors v") {
                v.pop();
                z.pop();
            } else {
                v.push(q);
                z.push(s);
                break;
            }
        }
    }
    if v.is_empty() {
        out.fill(f64::INFINITY);
        return;
    }
    let mut k = 0;
    for (p, o) in out.iter_mut().enumerate() {
        while k + 1 < v.len() && z[k + 1] < p as f64 {
            k += 1;
        }
        let d = p as f64 - v[k] as f64;
        *o = d * d + f[v[k]];
    }
}

/// One 1-D pass over a line of `n` values, toroidal or not; `ext`, `ext_out` scratch.
struct LinePass {
    ext: Vec<f64>,
    ext_out: Vec<f64>,
    v: Vec<usize>,
    z: Vec<f64>,
}

impl LinePass {
    fn new() -> Self {
        Self { ext: Vec::new(), ext_out: Vec::new(), v: Vec::new(), z: Vec::new() }
    }

    fn run(&mut self, line: &[f64], out: &mut [f64], toroidal: bool) {
        if !toroidal {
            transform_1d(line, out, &mut self.v, &mut self.z);
            return;
        }
        let n = line.len();
        self.ext.clear();
        for _ in 0..3 {
            self.ext.extend_from_slice(line);
        }
        self.ext_out.resize(3 * n, 0.0);
        transform_1d(&self.ext, &mut self.ext_out, &mut self.v, &mut self.z);
        out.copy_from_slice(&self.ext_out[n..2 * n]);
    }
}

/// Squared Euclidean distance (pixels²) from every pixel centre of a `width × height`
/// grid to the nearest pixel with `mask[i] == true` (row-major, top row first);
/// `+∞` everywhere when no pixel is set. `toroidal` wraps both axes.
///
/// # Panics
/// When `mask.len() != width * height` (a programming error of the caller).
pub fn squared_distance_transform(
    mask: &[bool],
    width: usize,
    height: usize,
    toroidal: bool,
) -> Vec<f64> {
    assert_eq!(mask.len(), width * height, "mask must hold width × height values");
    if width == 0 || height == 0 {
        return Vec::new();
    }
    // Rows: distance along x to the nearest feature of the same row.
    let mut rows = vec![0f64; width * height];
    rows.par_chunks_mut(width).enumerate().for_each_init(
        || (LinePass::new(), Vec::with_capacity(width)),
        |(pass, line), (y, out)| {
            line.clear();
            line.extend(
                mask[y * width..(y + 1) * width]
                    .iter()
                    .map(|&m| if m { 0.0 } else { f64::INFINITY }),
            );
            pass.run(line, out, toroidal);
        },
    );
    // Columns: combine the row distances along y.
    let columns: Vec<Vec<f64>> = (0..width)
        .into_par_iter()
        .map_init(
            || (LinePass::new(), Vec::with_capacity(height)),
            |(pass, line), x| {
                line.clear();
                line.extend((0..height).map(|y| rows[y * width + x]));
                let mut out = vec![0f64; height];
                pass.run(line, &mut out, toroidal);
                out
            },
        )
        .collect();
    let mut result = vec![0f64; width * height];
    for (x, col) in columns.iter().enumerate() {
        for (y, &d) in col.iter().enumerate() {
            result[y * width + x] = d;
        }
    }
    result
}

/// Euclidean distance (pixels, `f32`) from every pixel centre to the nearest set
/// pixel: the square root of [`squared_distance_transform`].
///
/// # Panics
/// When `mask.len() != width * height`.
pub fn euclidean_distance_transform(
    mask: &[bool],
    width: usize,
    height: usize,
    toroidal: bool,
) -> Vec<f32> {
    squared_distance_transform(mask, width, height, toroidal)
        .into_iter()
        .map(|d| d.sqrt() as f32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use fieldtex_core::rng::hash_unit;

    fn brute(mask: &[bool], w: usize, h: usize, toroidal: bool) -> Vec<f64> {
        let mut out = vec![f64::INFINITY; w * h];
        for y in 0..h {
            for x in 0..w {
                for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
                    let (qx, qy) = ((i % w) as i64, (i / w) as i64);
                    let mut dx = (x as i64 - qx).abs();
                    let mut dy = (y as i64 - qy).abs();
                    if toroidal {
                        dx = dx.min(w as i64 - dx);
                        dy = dy.min(h as i64 - dy);
                    }
                    let d = (dx * dx + dy * dy) as f64;
                    if d < out[y * w + x] {
                        out[y * w + x] = d;
                    }
                }
            }
        }
        out
    }

    #[test]
    fn equals_brute_force_on_random_point_sets() {
        for trial in 0..40u64 {
            let w = 1 + (hash_unit(7, "edt-width", trial) * 39.0) as usize;
            let h = 1 + (hash_unit(7, "edt-height", trial) * 39.0) as usize;
            let density = [0.002, 0.02, 0.2, 0.7][trial as usize % 4];
            let mask: Vec<bool> =
                (0..w * h).map(|i| hash_unit(trial, "edt-mask", i as u64) < density).collect();
            for toroidal in [false, true] {
                let fast = squared_distance_transform(&mask, w, h, toroidal);
                let slow = brute(&mask, w, h, toroidal);
                assert_eq!(fast, slow, "{w}×{h} density {density} toroidal {toroidal}");
            }
        }
    }

    #[test]
    fn empty_mask_is_infinite_and_full_mask_zero() {
        let d = euclidean_distance_transform(&[false; 12], 4, 3, false);
        assert!(d.iter().all(|v| v.is_infinite()));
        let d = euclidean_distance_transform(&[true; 12], 4, 3, true);
        assert!(d.iter().all(|v| *v == 0.0));
    }

    #[test]
    fn toroidal_wraps_across_the_border() {
        let (w, h) = (10, 1);
        let mut mask = vec![false; w * h];
        mask[0] = true;
        let flat = euclidean_distance_transform(&mask, w, h, false);
        let torus = euclidean_distance_transform(&mask, w, h, true);
        assert_eq!(flat[9], 9.0);
        assert_eq!(torus[9], 1.0);
        assert_eq!(torus[5], 5.0);
    }
}
