//! Multi-scale exemplars for multi-scale quilting (Wang et al. 2005 §4.2): the exemplar
//! resampled by bicubic (Catmull–Rom) interpolation to a set of scale factors whose
//! neighbouring ratio is not a power of two.

use fieldtex_core::Image;

/// `n` scale factors from `low` to `high`, geometrically spaced (`n ≥ 1`; one level is
/// `low`).
pub fn scale_levels(low: f64, high: f64, n: usize) -> Vec<f64> {
    if n <= 1 || high <= low {
        return vec![low];
    }
    let r = (high / low).powf(1.0 / (n - 1) as f64);
    (0..n).map(|k| low * r.powi(k as i32)).collect()
}

fn catmull_rom(t: f32) -> [f32; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

/// `image` resampled by `scale` (output `round(w·scale) × round(h·scale)`, at least 1),
/// bicubic with clamped borders; a box prefilter of width `1/scale` when minifying.
pub fn resample(image: &Image, scale: f64) -> Image {
    let w = ((image.width as f64 * scale).round() as usize).max(1);
    let h = ((image.height as f64 * scale).round() as usize).max(1);
    let src =
        if scale < 1.0 { box_blur(image, (0.5 / scale).floor() as i64) } else { image.clone() };
    let sx = image.width as f64 / w as f64;
    let sy = image.height as f64 / h as f64;
    let mut out = Image::new(w, h, [0.0; 4]);
    for y in 0..h {
        let fy = (y as f64 + 0.5) * sy - 0.5;
        let iy = fy.floor() as i64;
        let wy = catmull_rom((fy - iy as f64) as f32);
        for x in 0..w {
            let fx = (x as f64 + 0.5) * sx - 0.5;
            let ix = fx.floor() as i64;
            let wx = catmull_rom((fx - ix as f64) as f32);
            let mut acc = [0.0f32; 4];
            for (j, wyj) in wy.iter().enumerate() {
                for (i, wxi) in wx.iter().enumerate() {
                    let p = src.get_clamped(ix + i as i64 - 1, iy + j as i64 - 1);
                    let wgt = wyj * wxi;
                    for c in 0..4 {
                        acc[c] += wgt * p[c];
                    }
                }
            }
            out.set(x, y, acc.map(|v| v.clamp(0.0, 1.0)));
        }
    }
    out
}

fn box_blur(image: &Image, r: i64) -> Image {
    if r <= 0 {
        return image.clone();
    }
    let mut out = image.clone();
    let n = (2 * r + 1) as f32;
    for pass in 0..2 {
        let src = out.clone();
        for y in 0..image.height as i64 {
            for x in 0..image.width as i64 {
                let mut acc = [0.0f32; 4];
                for k in -r..=r {
                    let p = if pass == 0 {
                        src.get_clamped(x + k, y)
                    } else {
                        src.get_clamped(x, y + k)
                    };
                    for c in 0..4 {
                        acc[c] += p[c];
                    }
                }
                out.set(x as usize, y as usize, acc.map(|v| v / n));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_and_resampling() {
        let l = scale_levels(0.5, 4.0, 5);
        assert_eq!(l.len(), 5);
        assert!((l[4] - 4.0).abs() < 1e-12 && (l[1] / l[0] - 2f64.powf(0.75)).abs() < 1e-12);
        let im = Image::new(20, 10, [0.3, 0.5, 0.7, 1.0]);
        let r = resample(&im, 1.5);
        assert_eq!((r.width, r.height), (30, 15));
        assert!(r.pixels.iter().all(|p| (p[0] - 0.3).abs() < 1e-5));
    }
}
