//! Times `guided_coherence`: `bench_guided_coherence OUTPUT.png EXEMPLAR.png FIELD.npy`
//! (field: H×W×2 little-endian float32 `.npy`, version 1).

use fieldtex_eval::{FieldView, GuidedCoherenceOptions, ImageView, guided_coherence};

fn rgb(path: &str) -> (Vec<f32>, usize, usize) {
    let img = image::open(path).expect("image").to_rgb8();
    let (w, h) = (img.width() as usize, img.height() as usize);
    (img.as_raw().iter().map(|&v| v as f32 / 255.0).collect(), w, h)
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let (o, ow, oh) = rgb(&a[1]);
    let (e, ew, eh) = rgb(&a[2]);
    let bytes = std::fs::read(&a[3]).expect("field");
    let hl = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let f: Vec<f32> = bytes[10 + hl..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let ov = ImageView::new(&o, ow, oh, 3).unwrap();
    let ev = ImageView::new(&e, ew, eh, 3).unwrap();
    let fv = FieldView::new(&f, ow, oh).unwrap();
    let t = std::time::Instant::now();
    let r = guided_coherence(&ov, &ev, &fv, &GuidedCoherenceOptions::default()).unwrap();
    println!("{:.2} s wall: {r:?}", t.elapsed().as_secs_f64());
}
