//! Orientation (2-RoSy) fields from doubled-angle vector fields (paper D, §3), and the
//! sampling of designed fields to triangles, vertices and pixels.
//!
//! An orientation `θ` (defined modulo π) is stored as the vector of angle `2θ` in the
//! local frame; in complex notation `z = r e^{2iθ}`. The designed field is that vector
//! field; the orientation is recovered by the complex square root `√z`, normalised.
//! A wedge (+1/2) is a pole of the doubled field (a source/vortex mixture
//! `e^{i(θ + 2α)}`), a trisector (−1/2) a saddle `e^{−i(θ + 2α)}`, so the rotation α of
//! each singularity is explicit ([`crate::design_elements::SingularityKind`]).
//!
//! The square root picks one of the two representatives; across the branch cut the
//! representative flips by 180°, which is what an orientation field is. Interpolation
//! (barycentric on the grid, to pixels) is done on the *doubled* vectors, which are
//! continuous, and the root is taken last.
//!
//! Output convention for images: `Vec<[f32; 2]>`, row-major `H × W`, each entry a unit
//! `(dx, dy)` with x right and y down — `[row][col]` of a `field.npy` (`H×W×2`).
//! Where the field vanishes exactly, `(1, 0)` is written.

use fieldtex_core::vec3::{add, dot, normalize, scale, sub};
use rayon::prelude::*;

use crate::FieldsError;
use crate::design_elements::Symmetry;
use crate::field_design::{FieldDesign, SolvedField};
use crate::singularity_index::{
    DetectedSingularity, cluster_singularities, mesh_singularities, pixel_singularities,
};

/// Unit N-RoSy representative of the design-space complex value `z` (`n = 1`:
/// normalise; `n = 2`: principal square root, normalised). `(1, 0)` for `z = 0`.
#[inline]
pub fn nrosy_root(z: [f64; 2], symmetry: Symmetry) -> [f64; 2] {
    let r = (z[0] * z[0] + z[1] * z[1]).sqrt();
    if !(r > 0.0 && r.is_finite()) {
        return [1.0, 0.0];
    }
    let (c, s) = (z[0] / r, z[1] / r);
    match symmetry {
        Symmetry::Vector => [c, s],
        // √(e^{iφ}) = (√((1+cos φ)/2), sign(sin φ)·√((1−cos φ)/2)), φ ∈ (−π, π].
        Symmetry::Orientation => {
            let x = (0.5 * (1.0 + c)).max(0.0).sqrt();
            let y = (0.5 * (1.0 - c)).max(0.0).sqrt();
            [x, if s < 0.0 { -y } else { y }]
        }
    }
}

/// [`nrosy_root`] in `f32` for pixel output: for `n = 2` the half-angle vector
/// `z + |z|` normalised (`(0, 1)` on the negative real axis, where the principal root is
/// `i`). `(1, 0)` for `z = 0`.
#[inline]
pub fn nrosy_root_f32(z: [f32; 2], symmetry: Symmetry) -> [f32; 2] {
    let r = (z[0] * z[0] + z[1] * z[1]).sqrt();
    if !(r > 0.0 && r.is_finite()) {
        return [1.0, 0.0];
    }
    let w = match symmetry {
        Symmetry::Vector => z,
        Symmetry::Orientation => [z[0] + r, z[1]],
    };
    let m = (w[0] * w[0] + w[1] * w[1]).sqrt();
    if m > 1e-6 * r { [w[0] / m, w[1] / m] } else { [0.0, 1.0] }
}

/// The design-space value of an N-RoSy direction at angle `theta` (`e^{iNθ}`).
#[inline]
pub fn nrosy_power(theta: f64, symmetry: Symmetry) -> [f64; 2] {
    let a = theta * symmetry.n() as f64;
    [a.cos(), a.sin()]
}

/// Per-triangle complex coordinates of the designed vectors in the design's frames.
pub fn face_complex(design: &FieldDesign, field: &SolvedField) -> Vec<[f64; 2]> {
    design
        .frames()
        .par_iter()
        .zip(field.face_vectors.par_iter())
        .map(|((e1, e2), u)| [dot(*u, *e1), dot(*u, *e2)])
        .collect()
}

/// Per-triangle unit N-RoSy representatives as 3-D tangent vectors (for orientation
/// designs the square root of the doubled field).
pub fn face_directions(design: &FieldDesign, field: &SolvedField) -> Vec<[f64; 3]> {
    let z = face_complex(design, field);
    design
        .frames()
        .par_iter()
        .zip(z.par_iter())
        .map(|((e1, e2), z)| {
            let r = nrosy_root(*z, field.symmetry);
            add(scale(*e1, r[0]), scale(*e2, r[1]))
        })
        .collect()
}

/// Per-vertex design-space complex values: area-weighted mean of the incident
/// triangles' values (on curved patches the frames are assumed to vary slowly).
pub fn vertex_complex(design: &FieldDesign, field: &SolvedField) -> Vec<[f64; 2]> {
    let dec = design.dec();
    let z = face_complex(design, field);
    (0..dec.n_vertices())
        .into_par_iter()
        .map(|v| {
            let mut s = [0.0, 0.0];
            for &f in dec.topology.vertex_faces(v) {
                let a = dec.face_areas[f as usize];
                s[0] += a * z[f as usize][0];
                s[1] += a * z[f as usize][1];
            }
            s
        })
        .collect()
}

/// Per-vertex unit N-RoSy representatives as 3-D vectors in the vertex tangent plane
/// (vertex frame: the mean of the incident triangles' `e1`, projected).
pub fn vertex_directions(design: &FieldDesign, field: &SolvedField) -> Vec<[f64; 3]> {
    let dec = design.dec();
    let zv = vertex_complex(design, field);
    let frames = design.frames();
    (0..dec.n_vertices())
        .into_par_iter()
        .map(|v| {
            let n = dec.vertex_normals[v];
            let mut e = [0.0; 3];
            for &f in dec.topology.vertex_faces(v) {
                e = add(e, frames[f as usize].0);
            }
            let e1 = normalize(sub(e, scale(n, dot(n, e)))).unwrap_or(frames[0].0);
            let e2 = fieldtex_core::vec3::cross(n, e1);
            let r = nrosy_root(zv[v], field.symmetry);
            add(scale(e1, r[0]), scale(e2, r[1]))
        })
        .collect()
}

/// Samples a plane design on a `width × height` pixel grid covering the domain
/// rectangle (pixel `(c, r)` at domain point `((c+½)·W/width, (r+½)·H/height)`):
/// barycentric interpolation of the per-vertex doubled vectors, then the N-RoSy root.
/// Errors for mesh domains. See [`sample_plane_into`] to reuse the output buffer.
pub fn sample_plane(
    design: &FieldDesign,
    field: &SolvedField,
    width: usize,
    height: usize,
) -> Result<Vec<[f32; 2]>, FieldsError> {
    let mut out = Vec::new();
    sample_plane_into(design, field, width, height, &mut out)?;
    Ok(out)
}

/// [`sample_plane`] into a caller-kept buffer (resized to `width · height`), for
/// interactive re-sampling without a fresh 2 MB allocation per frame (512²).
///
/// Point location is separable on the regular grid: each column's cell and `u`, and
/// each row's cell and `v`, are computed once; rows are sampled in parallel (disjoint
/// outputs, so the result does not depend on the thread count), as one job in the rayon
/// pool (see [`FieldDesign::solve_and_sample_into`] for a whole frame).
pub fn sample_plane_into(
    design: &FieldDesign,
    field: &SolvedField,
    width: usize,
    height: usize,
    out: &mut Vec<[f32; 2]>,
) -> Result<(), FieldsError> {
    crate::field_design::in_pool(|| {
        let grid = *design.plane().ok_or(FieldsError::InvalidOption {
            name: "sample_plane domain",
            value: 0.0,
            expected: "a plane design (mesh designs are sampled per vertex or triangle)",
        })?;
        if width == 0 || height == 0 {
            return Err(FieldsError::FieldSize { width, height, expected: 1, found: 0 });
        }
        let zv = vertex_complex(design, field);
        let symmetry = field.symmetry;
        let (nx, ny) = (grid.nx, grid.ny);
        // Pixel → grid coordinates: g = (pixel + ½) · (cells / pixels); cell index and the
        // local coordinate in [0, 1], per column and per row.
        let axis = |pixels: usize, cells: usize| -> Vec<(usize, f64)> {
            let k = cells as f64 / pixels as f64;
            (0..pixels)
                .map(|p| {
                    let g = (p as f64 + 0.5) * k;
                    let i = (g as usize).min(cells - 1);
                    (i, (g - i as f64).clamp(0.0, 1.0))
                })
                .collect()
        };
        let (cols, rows) = (axis(width, nx), axis(height, ny));
        // every pixel is written below: no clearing of a kept buffer of the right size
        out.resize(width * height, [0.0; 2]);
        // Rows in fixed groups (disjoint outputs), enough work per task to hide rayon's cost.
        let group = (1 << 14) / width.max(1) + 1;
        out.par_chunks_mut(width * group).zip(rows.par_chunks(group)).for_each(|(block, rows)| {
            // Two passes per row: interpolate (gathers), then the root on plain arrays, a
            // branch-free loop the compiler vectorises.
            let (mut xs, mut ys) = (vec![0.0f32; width], vec![0.0f32; width]);
            for (row, &(j, v)) in block.chunks_mut(width).zip(rows) {
                let lower = &zv[j * (nx + 1)..(j + 1) * (nx + 1)];
                let upper = &zv[(j + 1) * (nx + 1)..(j + 2) * (nx + 1)];
                for ((x, y), &(i, u)) in xs.iter_mut().zip(ys.iter_mut()).zip(&cols) {
                    // Corners a=(i,j) b=(i+1,j) c=(i+1,j+1) d=(i,j+1); triangles as in
                    // PlaneGrid::locate.
                    let (za, zb, zc, zd) = (lower[i], lower[i + 1], upper[i + 1], upper[i]);
                    let (w, p, q, r) = if (i + j) % 2 == 0 {
                        if u >= v {
                            ([1.0 - u, u - v, v], za, zb, zc)
                        } else {
                            ([1.0 - v, u, v - u], za, zc, zd)
                        }
                    } else if u + v <= 1.0 {
                        ([1.0 - u - v, u, v], za, zb, zd)
                    } else {
                        ([1.0 - v, u + v - 1.0, 1.0 - u], zb, zc, zd)
                    };
                    *x = (w[0] * p[0] + w[1] * q[0] + w[2] * r[0]) as f32;
                    *y = (w[0] * p[1] + w[1] * q[1] + w[2] * r[1]) as f32;
                }
                roots_f32(&xs, &ys, symmetry, row);
            }
        });
        Ok(())
    })
}

/// [`nrosy_root_f32`] of `(xs[k], ys[k])` into `out[k]` (bit-identical), written without
/// branches so that it vectorises.
fn roots_f32(xs: &[f32], ys: &[f32], symmetry: Symmetry, out: &mut [[f32; 2]]) {
    let half = symmetry == Symmetry::Orientation;
    for ((o, &x), &y) in out.iter_mut().zip(xs).zip(ys) {
        let r = (x * x + y * y).sqrt();
        let valid = r > 0.0 && r <= f32::MAX;
        let wx = if half { x + r } else { x };
        let m = (wx * wx + y * y).sqrt();
        // NaN-safe: a NaN `m` counts as tiny, as in nrosy_root_f32
        let large = m > 1e-6 * r;
        let (a, b) = (wx / m, y / m);
        let a = if large { a } else { 0.0 };
        let b = if large { b } else { 1.0 };
        *o = if valid { [a, b] } else { [1.0, 0.0] };
    }
}

/// Singularities of the solved field on the design mesh (per-vertex index of the
/// per-triangle representatives), merged within `radius` (domain units; e.g. 1.5 grid
/// cells). Indices are in orientation units for orientation designs (±1/2).
pub fn detect_design_singularities(
    design: &FieldDesign,
    field: &SolvedField,
    radius: f64,
) -> Vec<DetectedSingularity> {
    let dirs = face_directions(design, field);
    let found = mesh_singularities(design.dec(), &dirs, field.symmetry.n());
    cluster_singularities(&found, radius)
}

/// Singularities of a pixel field (`width × height`, `(dx, dy)` per pixel) merged within
/// `radius` pixels. `symmetry` says whether `v` and `−v` are the same direction.
pub fn detect_pixel_singularities(
    pixels: &[[f32; 2]],
    width: usize,
    height: usize,
    symmetry: Symmetry,
    radius: f64,
) -> Result<Vec<DetectedSingularity>, FieldsError> {
    if pixels.len() != width * height {
        return Err(FieldsError::FieldSize {
            width,
            height,
            expected: width * height,
            found: pixels.len(),
        });
    }
    let found = pixel_singularities(pixels, width, height, symmetry.n());
    Ok(cluster_singularities(&found, radius))
}
