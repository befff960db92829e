//! Helpers shared by the transfer crate's integration tests.
#![allow(dead_code)]

use fieldtex_core::Image;
use fieldtex_mesh::{CornerUvs, TriMesh};
use fieldtex_transfer::{DescriptorOptions, ParametricOptions, TransferOptions};

/// `mesh` with a texture holding one texel per triangle, coloured by `f(centroid)`,
/// and UVs that put all corners of a triangle at its texel's centre.
pub fn textured(mesh: &TriMesh, f: impl Fn([f64; 3]) -> [f32; 3]) -> (TriMesh, Image) {
    let nf = mesh.n_triangles();
    let w = (nf as f64).sqrt().ceil() as usize;
    let h = nf.div_ceil(w);
    let mut img = Image::new(w, h, [0.0, 0.0, 0.0, 1.0]);
    let mut values = Vec::with_capacity(nf);
    for t in 0..nf {
        let [a, b, c] = mesh.triangle_positions(t);
        let p =
            [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0, (a[2] + b[2] + c[2]) / 3.0];
        let col = f(p);
        let (x, y) = (t % w, t / w);
        img.set(x, y, [col[0], col[1], col[2], 1.0]);
        values.push([(x as f64 + 0.5) / w as f64, 1.0 - (y as f64 + 0.5) / h as f64]);
    }
    let mut m = mesh.clone();
    m.uvs = Some(CornerUvs { values, indices: (0..nf as u32).map(|t| [t, t, t]).collect() });
    (m, img)
}

pub fn small_options() -> TransferOptions {
    TransferOptions {
        samples: 6000,
        levels: 3,
        descriptors: DescriptorOptions { directions: 24, samples: 3000, ..Default::default() },
        parametric: ParametricOptions { clusters: 12, ..Default::default() },
        ..Default::default()
    }
}

pub use fieldtex_linalg::stats::pearson;

/// `f` run on a fresh pool of `threads` threads.
pub fn with_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}
