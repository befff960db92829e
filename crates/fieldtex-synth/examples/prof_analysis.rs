//! Times the parts of the exemplar analysis per level (development aid).
use std::time::Instant;

use fieldtex_synth::appearance_space::appearance_space;
use fieldtex_synth::gaussian_stack::gaussian_stack;
use fieldtex_synth::k_coherence::k_coherence;

fn main() {
    let path = std::env::args().nth(1).expect("exemplar path");
    let scan: usize = std::env::args().nth(2).and_then(|s| s.parse().ok()).unwrap_or(1024);
    let img = image::open(path).unwrap().to_rgb32f();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let rgb: Vec<[f32; 3]> = img.pixels().map(|p| p.0).collect();
    let levels = (w.max(h) as f64).log2().ceil() as usize;
    {
        let v: Vec<[f32; 8]> =
            (0..16384).map(|i| std::array::from_fn(|d| ((i * 31 + d * 7) % 101) as f32)).collect();
        let t = Instant::now();
        let mut acc = 0.0f32;
        for q in v.iter().take(1000) {
            for x in &v {
                let mut l = [0.0f32; 4];
                for i in 0..4 {
                    let d0 = q[i] - x[i];
                    let d1 = q[i + 4] - x[i + 4];
                    l[i] = d0 * d0 + d1 * d1;
                }
                acc += (l[0] + l[1]) + (l[2] + l[3]);
            }
        }
        println!("micro 16.4M dists {:?} ({acc})", t.elapsed());
    }
    let t = Instant::now();
    let st = gaussian_stack(&rgb, w, h, levels);
    println!("stack {:?}", t.elapsed());
    for (c, level) in st.iter().enumerate() {
        let t = Instant::now();
        let a = appearance_space(level, w, h, 1 << c, c).unwrap();
        let t1 = t.elapsed();
        let t = Instant::now();
        let radius = 3usize.max(1 << c).min(w.min(h) / 4);
        let k = k_coherence(&a.unrotated, w, h, 2, radius, scan, 2);
        let t3 = t.elapsed();
        let exact = k_coherence(&a.unrotated, w, h, 2, radius, usize::MAX, 2);
        let agree = k.iter().zip(&exact).filter(|(a, b)| a == b).count() as f64 / k.len() as f64;
        println!(
            "level {c}: app {t1:?} kcoh {t3:?} explained {:.3} agree-with-exact {agree:.2}",
            a.explained_variance
        );
    }
}

#[allow(dead_code)]
fn micro() {}
