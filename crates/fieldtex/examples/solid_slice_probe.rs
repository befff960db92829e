//! Probe of `bench/solid_quality.sh`'s bent-box slice without the shell: the middle z
//! slice of a unit box through a [`fieldtex::SolidSession`] (the same image as the
//! bench's `cut-1.png`, byte for byte), its guided coherence against the exemplar with
//! the slice's own field (approximate search, seed 1, as `fieldtex eval`), and the
//! distance of most queries (one crop per query, so each is the number the
//! whole-image metric averages; the row and column nearest the top and left borders
//! are left out). Prints one line per seed and the worst queries.
//!
//! `cargo run --release -p fieldtex --example solid_slice_probe -- BOX.obj SKETCH.json
//! EXEMPLAR.png RES OUTDIR SEEDS [key=value …]` with SEEDS like `1,2,3` and keys
//! `passes`, `level_passes` (`2/4/4/4/4`), `integrate`, `trilinear`,
//! `projected` (0/1), `subpart` (K), `integrated` (0/1), `constant=1` (no sketch).

use fieldtex::{SolidOptions, SolidSession};
use fieldtex_core::NoProgress;
use fieldtex_eval as ev;
use std::path::PathBuf;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let (mesh, sketch, exemplar) = (&a[1], &a[2], &a[3]);
    let res: usize = a[4].parse().unwrap();
    let out = PathBuf::from(&a[5]);
    let seeds: Vec<u64> = a[6].split(',').map(|s| s.parse().unwrap()).collect();
    std::fs::create_dir_all(&out).unwrap();
    let mut opts = SolidOptions {
        mesh: mesh.into(),
        sketch: Some(sketch.into()),
        exemplar: Some(exemplar.into()),
        resolution: res,
        ..Default::default()
    };
    for kv in &a[7..] {
        let (k, v) = kv.split_once('=').unwrap();
        let s = &mut opts.synthesis;
        match k {
            "passes" => s.passes = v.parse().unwrap(),
            "level_passes" => s.level_passes = v.split('/').map(|x| x.parse().unwrap()).collect(),
            "integrate" => s.integrate_levels = v.parse().unwrap(),
            "trilinear" => s.trilinear_levels = v.parse().unwrap(),
            "constant" => opts.sketch = None,
            "projected" => s.projected_predictions = v == "1",
            "subpart" => s.subpart = v.parse().unwrap(),
            "integrated" => s.integrated_init = v == "1",
            _ => panic!("unknown key {k}"),
        }
    }
    let ex = fieldtex_io::read_image(std::path::Path::new(exemplar)).unwrap();
    let eb = ev::rgb_buffer(&ex);
    let ev_view = ev::ImageView::new(&eb, ex.width, ex.height, 3).unwrap();
    let k = res / 2;
    let z = -0.5 + 0.5 / res as f64 + k as f64 / res as f64;
    let mut means = Vec::new();
    for &seed in &seeds {
        opts.seed = seed;
        opts.synthesis.seed = seed;
        let t0 = std::time::Instant::now();
        let mut session = SolidSession::new(&opts, None, &NoProgress).unwrap();
        let cut = session.cut([0.0, 0.0, z, 0.0, 0.0, 1.0], &NoProgress).unwrap();
        let secs = t0.elapsed().as_secs_f64();
        let img = cut.image;
        let (w, h) = (img.width, img.height);
        fieldtex_io::write_png(&out.join(format!("slice-seed{seed}.png")), &img).unwrap();
        // The field of the slice: the local x axis projected into the image.
        let spacing = 1.0 / res as f64;
        let mut dirs = Vec::with_capacity(2 * w * h);
        for row in 0..h {
            for col in 0..w {
                let p =
                    [-0.5 + (col as f64 + 0.5) * spacing, -0.5 + (row as f64 + 0.5) * spacing, z];
                let m = session.frame_at(p);
                let (dx, dy) = (m[0], m[3]);
                let l = (dx * dx + dy * dy).sqrt().max(1e-12);
                dirs.extend([(dx / l) as f32, (dy / l) as f32]);
            }
        }
        let ob = ev::rgb_buffer(&img);
        let approximate = Some(ev::ApproximateSearchOptions { seed: 1, ..Default::default() });
        let gopts = ev::GuidedCoherenceOptions { approximate, ..Default::default() };
        let ov = ev::ImageView::new(&ob, w, h, 3).unwrap();
        let fv = ev::FieldView::new(&dirs, w, h).unwrap();
        let whole = ev::guided_coherence(&ov, &ev_view, &fv, &gopts).unwrap();
        // Per query: a crop holding exactly that query at the same place.
        let s = gopts.stride;
        let mut per = Vec::new();
        for qy in (s / 2..h).step_by(s) {
            for qx in (s / 2..w).step_by(s) {
                let (x0, y0) = (qx.saturating_sub(5), qy.saturating_sub(5));
                let (x1, y1) = ((qx + 6).min(w), (qy + 6).min(h));
                let (cw, ch) = (x1 - x0, y1 - y0);
                let mut cb = Vec::with_capacity(cw * ch * 3);
                let mut cf = Vec::with_capacity(cw * ch * 2);
                for y in y0..y1 {
                    cb.extend_from_slice(&ob[(y * w + x0) * 3..(y * w + x1) * 3]);
                    cf.extend_from_slice(&dirs[(y * w + x0) * 2..(y * w + x1) * 2]);
                }
                // Stride whose half is the query's offset in the crop, long enough that
                // no second query falls inside.
                let (lx, ly) = (qx - x0, qy - y0);
                let stride_for =
                    |l: usize, len: usize| (2 * l..=2 * l + 1).find(|st| l + st >= len);
                let (Some(sx), Some(sy)) = (stride_for(lx, cw), stride_for(ly, ch)) else {
                    continue;
                };
                // One stride for both axes: queries at 4 px from a corner-side border
                // (a crop of 10 on one axis, 11 on the other) are left out.
                if sx != sy {
                    continue;
                }
                let st = sx;
                let o = ev::GuidedCoherenceOptions { stride: st, ..gopts.clone() };
                let cv = ev::ImageView::new(&cb, cw, ch, 3).unwrap();
                let cfv = ev::FieldView::new(&cf, cw, ch).unwrap();
                if let Ok(r) = ev::guided_coherence(&cv, &ev_view, &cfv, &o)
                    && r.queries == 1
                {
                    per.push((r.mean, qx, qy));
                }
            }
        }
        per.sort_by(|a, b| b.0.total_cmp(&a.0));
        let worst: Vec<String> =
            per.iter().take(5).map(|(d, x, y)| format!("({x},{y}) {d:.5}")).collect();
        let per_mean = per.iter().map(|p| p.0).sum::<f64>() / per.len().max(1) as f64;
        println!(
            "seed {seed}: guided mean {:.6} median {:.6} max {:.5} queries {} (per-query {} mean {:.6}) {secs:.1}s | worst {}",
            whole.mean,
            whole.median,
            whole.max,
            whole.queries,
            per.len(),
            per_mean,
            worst.join(" ")
        );
        means.push(whole.mean);
    }
    let m = means.iter().sum::<f64>() / means.len() as f64;
    println!("MEAN over seeds {m:.6} ({} seeds)", means.len());
}
