//! Outputs of `fieldtex solid` beyond the shell: cuts (the capped mesh part and the
//! cap's image, `cut-N.glb` / `cut-N.png`), the whole volume (`volume.nrrd`) and the
//! coarse frame field (`frames.ply`). Every voxel comes from the same on-demand
//! synthesizer as the shell, so a cut and the shell agree where they meet.

use super::*;
use fieldtex_core::vec3::{cross, dot, normalize};

/// `a / |a|` (`a` is a non-zero cross product of a unit normal and a helper axis).
fn unit(a: [f64; 3]) -> [f64; 3] {
    normalize(a).unwrap_or(a)
}

/// The axis and voxel index of an axis-aligned plane through voxel centres, if `cut` is one.
pub(super) fn grid_slice(grid: &SolidGrid, cut: [f64; 6]) -> Option<(usize, usize)> {
    let n = [cut[3], cut[4], cut[5]];
    let axis = (0..3).find(|&a| n[a] != 0.0 && (0..3).all(|b| b == a || n[b] == 0.0))?;
    let t = (cut[axis] - grid.origin[axis]) / grid.spacing;
    let k = t.round();
    ((t - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < grid.sizes[axis])
        .then_some((axis, k as usize))
}

/// The voxels a cut image shows, row by row (module docs of `solid`).
pub(crate) struct CutVoxels {
    pub voxels: Vec<[i32; 3]>,
    pub width: usize,
    pub height: usize,
    /// `(axis, column axis, row axis)` for a plane through a plane of voxel centres.
    pub slice: Option<(usize, usize, usize)>,
    /// Where the image lies in space: the outer corner of pixel (0, 0), then the
    /// vectors spanning all columns and all rows (pixel `(c, r)` has its centre at
    /// `corner + (c + ½)/width · u + (r + ½)/height · v`, sampled at the nearest voxel).
    pub placement: [[f64; 3]; 3],
}

/// The pixels of the cut image of plane `cut` (`point`, `normal`): a grid slice, or
/// samples at voxel spacing over the extent of `part` (the mesh's part on the
/// negative side, capped) in the plane, each at its nearest voxel.
pub(crate) fn cut_voxels(grid: &SolidGrid, cut: [f64; 6], part: &TriMesh) -> CutVoxels {
    let point = [cut[0], cut[1], cut[2]];
    let normal = [cut[3], cut[4], cut[5]];
    match grid_slice(grid, cut) {
        Some((axis, k)) => {
            let (a1, a2) = match axis {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            let (w, h) = (grid.sizes[a1], grid.sizes[a2]);
            let mut voxels = Vec::with_capacity(w * h);
            for row in 0..h {
                for col in 0..w {
                    let mut v = [0i32; 3];
                    v[axis] = k as i32;
                    v[a1] = col as i32;
                    v[a2] = row as i32;
                    voxels.push(v);
                }
            }
            let sp = grid.spacing;
            let mut corner = grid.origin;
            corner[axis] += k as f64 * sp;
            corner[a1] -= 0.5 * sp;
            corner[a2] -= 0.5 * sp;
            let (mut u, mut v) = ([0.0; 3], [0.0; 3]);
            u[a1] = w as f64 * sp;
            v[a2] = h as f64 * sp;
            CutVoxels {
                voxels,
                width: w,
                height: h,
                slice: Some((axis, a1, a2)),
                placement: [corner, u, v],
            }
        }
        None => {
            let len =
                (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
            let n = normal.map(|x| x / len);
            let helper = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
            let e1 = unit(cross(helper, n));
            let e2 = cross(n, e1);
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for p in &part.positions {
                let d = [p[0] - point[0], p[1] - point[1], p[2] - point[2]];
                let uv = [dot(d, e1), dot(d, e2)];
                for a in 0..2 {
                    lo[a] = lo[a].min(uv[a]);
                    hi[a] = hi[a].max(uv[a]);
                }
            }
            let w = (((hi[0] - lo[0]) / grid.spacing).ceil() as usize).clamp(1, 4096);
            let h = (((hi[1] - lo[1]) / grid.spacing).ceil() as usize).clamp(1, 4096);
            let mut voxels = Vec::with_capacity(w * h);
            for row in 0..h {
                for col in 0..w {
                    let (u, v) = (
                        lo[0] + (col as f64 + 0.5) * grid.spacing,
                        lo[1] + (row as f64 + 0.5) * grid.spacing,
                    );
                    let p: [f64; 3] = std::array::from_fn(|a| point[a] + u * e1[a] + v * e2[a]);
                    voxels.push(std::array::from_fn(|a| {
                        ((p[a] - grid.origin[a]) / grid.spacing).round() as i32
                    }));
                }
            }
            let corner: [f64; 3] =
                std::array::from_fn(|a| point[a] + lo[0] * e1[a] + lo[1] * e2[a]);
            let u = e1.map(|x| x * w as f64 * grid.spacing);
            let v = e2.map(|x| x * h as f64 * grid.spacing);
            CutVoxels { voxels, width: w, height: h, slice: None, placement: [corner, u, v] }
        }
    }
}

#[allow(clippy::too_many_arguments)]
pub(super) fn write_cut(
    out_dir: &Path,
    index: usize,
    cut: [f64; 6],
    mesh: &TriMesh,
    bvh: &Bvh,
    aopts: &fieldtex_param::AtlasOptions,
    grid: &SolidGrid,
    synth: &mut SolidRegions<'_>,
    keep_field: Option<&FieldFrames<'_>>,
    progress: &dyn Progress,
) -> Result<serde_json::Value> {
    let point = [cut[0], cut[1], cut[2]];
    let normal = [cut[3], cut[4], cut[5]];
    let pc = fieldtex_mesh::cut_with_plane(mesh, point, normal).ok_or_else(|| {
        Error::bad_input(None, format!("--cut {index}: the normal must not be zero"))
    })?;
    if pc.mesh.triangles.is_empty() {
        return Err(Error::bad_input(
            None,
            format!("--cut {index}: the plane leaves nothing of the mesh on its negative side"),
        ));
    }
    // The cap image: one pixel per voxel of the plane.
    let scale = mesh.bounding_box().map_or(1.0, |b| b.diagonal());
    let t0 = Instant::now();
    let mut work = Work::default();
    let cv = cut_voxels(grid, cut, &pc.mesh);
    if let (Some(frames), Some((_, a1, a2))) = (keep_field, cv.slice) {
        // The local x axis in the image plane per pixel (`(dx, dy)`, x along columns,
        // y down the rows), for `fieldtex eval --field`.
        let mut dirs = Vec::with_capacity(2 * cv.voxels.len());
        for v in &cv.voxels {
            let c: [f64; 3] = std::array::from_fn(|a| grid.origin[a] + v[a] as f64 * grid.spacing);
            let m = frames.frame(c);
            let (dx, dy) = (m[3 * a1], m[3 * a2]);
            let l = (dx * dx + dy * dy).sqrt().max(1e-12);
            dirs.extend([(dx / l) as f32, (dy / l) as f32]);
        }
        fieldtex_io::write_npy_f32(
            &out_dir.join(format!("cut-{index}-field.npy")),
            &[cv.height, cv.width, 2],
            &dirs,
        )?;
    }
    let exact = cv.slice.is_some();
    let image =
        slice_image(&cv.voxels, cv.width, cv.height, grid, bvh, scale, synth, progress, &mut work);
    let image_seconds = t0.elapsed().as_secs_f64();
    fieldtex_io::write_png(&out_dir.join(format!("cut-{index}.png")), &image)?;
    // The capped mesh, textured from the same solid.
    let (atlas_mesh, texture, mesh_work) = textured_atlas(&pc.mesh, aopts, grid, synth, progress)?;
    super::super::write_model_named(out_dir, &format!("cut-{index}.glb"), &atlas_mesh, &texture)?;
    Ok(serde_json::json!({
        "plane": cut,
        "grid_slice": exact,
        "image_size": [image.width, image.height],
        "image_seconds": image_seconds,
        "image_voxels_requested": work.requested,
        "image_voxels_computed_finest": work.computed_finest,
        "image_voxels_per_second": work.computed_all_levels as f64 / work.seconds.max(1e-9),
        "cap_loops": pc.loops,
        "open_chains": pc.open_chains,
        "forced_clips": pc.forced_clips,
        "mesh_triangles": pc.mesh.triangles.len(),
        "cap_triangles": pc.mesh.triangles.len() - pc.cap_start,
        "mesh_texture": mesh_work,
    }))
}

/// The cut image of `voxels` (`w × h`, row by row): each voxel centre inside the mesh
/// (ray parity through `bvh`) gets the solid's colour quantised as the PNG writer does,
/// the others are transparent.
#[allow(clippy::too_many_arguments)]
pub(crate) fn slice_image(
    voxels: &[[i32; 3]],
    w: usize,
    h: usize,
    grid: &SolidGrid,
    bvh: &Bvh,
    scale: f64,
    synth: &mut SolidRegions<'_>,
    progress: &dyn Progress,
    work: &mut Work,
) -> Image {
    let centres: Vec<[f64; 3]> = voxels
        .iter()
        .map(|v| std::array::from_fn(|a| grid.origin[a] + v[a] as f64 * grid.spacing))
        .collect();
    let inside = fieldtex_mesh::points_inside(bvh, &centres, scale);
    let wanted: Vec<[i32; 3]> =
        voxels.iter().zip(&inside).filter(|(_, i)| **i).map(|(v, _)| *v).collect();
    let t = Instant::now();
    let (rgb, stats) = synth.colors(&wanted, progress);
    work.add(wanted.len(), &stats, t.elapsed().as_secs_f64());
    let mut image = Image::new(w, h, [0.0; 4]);
    let mut k = 0;
    for (i, ins) in inside.iter().enumerate() {
        if *ins {
            let c = rgb8(rgb[k]);
            image.pixels[i] = [c[0] as f32 / 255.0, c[1] as f32 / 255.0, c[2] as f32 / 255.0, 1.0];
            k += 1;
        }
    }
    image
}

pub(super) fn write_volume(
    out_dir: &Path,
    grid: &SolidGrid,
    synth: &mut SolidRegions<'_>,
    progress: &dyn Progress,
) -> Result<Work> {
    let [nx, ny, nz] = grid.sizes;
    let mut data = Vec::with_capacity(3 * grid.len());
    let mut work = Work::default();
    // Slab by slab along z keeps the request lists small; the cache makes it one pass.
    for z in 0..nz {
        let mut voxels = Vec::with_capacity(nx * ny);
        for y in 0..ny {
            for x in 0..nx {
                voxels.push([x as i32, y as i32, z as i32]);
            }
        }
        let t = Instant::now();
        let (rgb, stats) = synth.colors(&voxels, progress);
        work.add(voxels.len(), &stats, t.elapsed().as_secs_f64());
        data.extend(rgb.iter().flat_map(|c| rgb8(*c)));
    }
    let volume = fieldtex_io::RgbVolume {
        sizes: grid.sizes,
        origin: grid.origin,
        spacing: grid.spacing,
        data,
    };
    fieldtex_io::write_nrrd_rgb(&out_dir.join("volume.nrrd"), &volume)?;
    Ok(work)
}

pub(super) fn write_frames(path: &Path, field: &FrameField3d) -> Result<()> {
    let grid = field.grid();
    let positions: Vec<[f64; 3]> = (0..grid.len()).map(|i| grid.position(i)).collect();
    let mut props: Vec<(String, Vec<f32>)> = Vec::new();
    for (a, name) in ["x", "y", "z"].iter().enumerate() {
        let axes: Vec<[f64; 3]> =
            field.frames().iter().map(|q| quaternion::axis_of(*q, a)).collect();
        for (c, comp) in ["x", "y", "z"].iter().enumerate() {
            props.push((format!("axis{name}_{comp}"), axes.iter().map(|v| v[c] as f32).collect()));
        }
    }
    let refs: Vec<(&str, &[f32])> = props.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect();
    fieldtex_io::write_point_ply(path, &positions, &refs)?;
    Ok(())
}
