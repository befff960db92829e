//! Times `guided_coherence`: `bench_guided_coherence OUTPUT.png EXEMPLAR.png FIELD.npy`
//! (field: H×W×2 little-endian float32 `.npy`, version 1).

#[path = "common/mod.rs"]
mod common;
use common::*;

use fieldtex_eval::{FieldView, GuidedCoherenceOptions, ImageView, guided_coherence};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let (o, ow, oh) = rgb(&a[1]);
    let (e, ew, eh) = rgb(&a[2]);
    let f = npy(&a[3]);
    let ov = ImageView::new(&o, ow, oh, 3).unwrap();
    let ev = ImageView::new(&e, ew, eh, 3).unwrap();
    let fv = FieldView::new(&f, ow, oh).unwrap();
    let t = std::time::Instant::now();
    let r = guided_coherence(&ov, &ev, &fv, &GuidedCoherenceOptions::default()).unwrap();
    println!("{:.2} s wall: {r:?}", t.elapsed().as_secs_f64());
}
