//! Times `guided_coherence`: `bench_guided_coherence OUTPUT.png EXEMPLAR.png FIELD.npy`
//! (field: H×W×2 little-endian float32 `.npy`, version 1).

#[path = "common/mod.rs"]
mod common;
use common::*;

use fieldtex_eval::{GuidedCoherenceOptions, guided_coherence};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let run = OrientRun::read_files(&a[1], &a[2], &a[3]);
    let (ov, ev, fv) = run.views();
    let t = std::time::Instant::now();
    let r = guided_coherence(&ov, &ev, &fv, &GuidedCoherenceOptions::default()).unwrap();
    println!("{:.2} s wall: {r:?}", t.elapsed().as_secs_f64());
}
