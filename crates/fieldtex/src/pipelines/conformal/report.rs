//! Report pieces of the `conformal` pipeline: per-component JSON, texel density and
//! the notes naming every substitute.

use super::ConformalOptions;
use crate::Report;
use fieldtex_param::conformal::{ConformalComponent, ConformalMethod, GeometryImage};
use fieldtex_param::distortion::triangle_jacobian;
use serde::Serialize;
use serde_json::json;

pub(super) use fieldtex_linalg::stats::weighted_quantile;

#[derive(Serialize)]
pub(super) struct TexelDensity {
    /// Area-weighted coefficient of variation of texels per surface area (`τ²`).
    density_cv: f64,
    tau_min: f64,
    tau_median: f64,
    tau_max: f64,
}

pub(super) fn texel_density(tau_w: &[(f64, f64)]) -> TexelDensity {
    let (mut s, mut s2, mut w) = (0.0, 0.0, 0.0);
    for &(t, a) in tau_w {
        let d = t * t;
        s += a * d;
        s2 += a * d * d;
        w += a;
    }
    let mean = s / w.max(f64::MIN_POSITIVE);
    let mut v = tau_w.to_vec();
    TexelDensity {
        density_cv: (s2 / w.max(f64::MIN_POSITIVE) - mean * mean).max(0.0).sqrt()
            / mean.max(f64::MIN_POSITIVE),
        tau_min: tau_w.iter().map(|x| x.0).fold(f64::INFINITY, f64::min),
        tau_median: weighted_quantile(&mut v, 0.5).unwrap_or(f64::NAN),
        tau_max: tau_w.iter().map(|x| x.0).fold(0.0, f64::max),
    }
}

pub(super) fn component_json(
    c: &ConformalComponent,
    img: Option<&GeometryImage>,
) -> serde_json::Value {
    let mut v = json!({
        "component": c.component,
        "triangles": c.faces.len(),
        "genus": c.genus,
        "boundaries": c.boundaries,
        "method": c.method,
        "harmonic_1_forms": c.harmonic_forms,
        "zero_points": c.zero_points.len(),
        "zero_point_indices": c.zero_points.iter().map(|z| json!({"vertex": z.0, "index": z.1})).collect::<Vec<_>>(),
        "conjugate_residual": c.conjugate_residual,
        "conjugate_residual_wedge_system": c.map.conjugate_residual_wedge_system,
        "double_cover_genus": c.double_cover_genus,
        "protrusion_slits": c.protrusion_slits,
        "polish": c.polish,
        "note": c.note,
    });
    if let Some(all) = c.distortion_non_slit() {
        let away = c.angle_mean_away();
        v["patches"] = json!(c.map.n_patches());
        if c.method == ConformalMethod::CriticalTrajectoryPatches {
            v["critical_trajectories"] = json!(c.map.cut_curves.len());
            let count = |cut: &[bool]| cut.iter().filter(|&&x| x).count();
            v["trajectory_cut_edges"] = json!(count(&c.map.trajectory_cut));
            // Homology-basis cut (Erickson & Whittlesey 2005; off by default), a
            // substitute for the paper's closed critical trajectories.
            v["homology_loop_cut_edges"] = json!(count(&c.map.loop_cut));
            v["small_patches_from_overlap_guard"] = json!(c.map.small_patches);
            v["folded_faces_own_chart"] = json!(c.map.folded_faces);
            v["patch_merges"] = json!(c.map.patch_merges);
            v["stretch_cv_best_basis_form"] = json!(c.map.stretch_cv.map(|x| x[0]));
            v["stretch_cv_optimised_form"] = json!(c.map.stretch_cv.map(|x| x[1]));
        }
        // Layouts whose margins are drawn by ghosts: patch layouts, and the polished
        // cylinder (one chart, no longer periodic).
        if c.method == ConformalMethod::CriticalTrajectoryPatches || !c.map.ghosts.is_empty() {
            v["ghost_faces"] = json!(c.map.ghosts.len());
            if let Some(img) = img {
                v["margin_links"] = json!(img.links.len() / 2);
            }
        }
        v["slit_vertices"] = json!(
            c.map
                .slit_vertices
                .iter()
                .map(|&l| c.local_to_global.get(l as usize).copied().unwrap_or(u32::MAX))
                .collect::<Vec<_>>()
        );
        v["lattice"] = json!({"a": c.lattice.a, "b": c.lattice.b});
        v["distortion"] = json!({"angle_mean_away_from_singularities": away, "angle_mean_non_slit": all.angle_mean, "log_area_std": all.log_area_std, "flipped": all.flipped});
        if all.flipped > 0 {
            v["distortion"]["flipped_examples"] = json!(flipped_examples(c, 8));
        }
        if let Some(img) = img {
            v["geometry_image"] = json!({"width": img.width, "height": img.height, "margin": img.margin, "period_x": img.period_x, "period_y": img.period_y});
        }
    } else {
        v["patches"] = json!("fallback atlas");
    }
    v
}

/// Up to `max` flipped (or collapsed) triangles of `c`'s map: global face, whether it is
/// a slit face or near a singularity, its UV signed area and its 3-D centroid.
fn flipped_examples(c: &ConformalComponent, max: usize) -> Vec<serde_json::Value> {
    let mut out = Vec::new();
    for f in 0..c.faces.len() {
        let p = c.local_mesh.triangle_positions(f);
        let Some((_, _, auv, _)) = triangle_jacobian(p, c.corner_uv[f], 0.0) else { continue };
        if auv <= 0.0 || auv.is_nan() {
            let g: Vec<f64> = (0..3).map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0).collect();
            out.push(json!({"face": c.faces[f], "slit": c.slit[f], "near_singularity": c.near_singularity[f], "uv_area": auv, "centroid": g}));
            if out.len() == max {
                break;
            }
        }
    }
    out
}

pub(super) fn add_notes(
    report: &mut Report,
    comps: &[ConformalComponent],
    options: &ConformalOptions,
) {
    let n = &mut report.notes;
    if comps.iter().any(|c| c.double_cover_genus.is_some()) {
        n.push("Open surfaces whose double cover has genus ≥ 2: the double cover (two copies glued along the boundary, the second reversed; paper §3) is parameterised and the first copy kept; zero points on the double cover are reported at their first-copy vertex (mirror pairs appear twice).".into());
    }
    if comps.iter().any(|c| c.boundaries > 0 && c.double_cover_genus.is_none()) {
        n.push("Open disks and annuli (double cover of genus 0 or 1): holes are capped with fans and the capped closed surface is parameterised (caps dropped afterwards); a disk's boundary and an annulus's two boundaries become the ends of the cylinder, which for an annulus is the map its double cover (a torus) gives.".into());
    }
    if comps.iter().any(|c| c.protrusion_slits.is_some()) {
        n.push("Genus 0 with protrusions (protrusion_slits; our construction, the paper is silent): the two-point slit cylinder shrinks a protrusion that holds neither end by orders of magnitude, so where its area scale falls more than 144× (12× in length, the largest exemplar enlargement) below the median over at least 0.2 % of the surface, each such region's tip (and each cylinder end) whose cap has a rim (the first geodesic circle no longer than 4 × its radius, within 0.3 √area) gets a slit of half the rim's length; with three openings or more (slits and large holes) the double cover of the slit surface is parameterised as for genus ≥ 2 and its first copy kept, with two the cylinder runs between them; kept only when the log-area std over the input's faces is lower than the two-point cylinder's (both reported). A slit is a seam of the layout; its two ends are branch points of the double cover. Its two sides' charts differ by a similarity (not a translation), so the faces across a slit are drawn as ghosts in the margin by the similarity that maps their shared edge, and linked texel to texel like the other margins.".into());
    }
    if comps.iter().any(|c| c.method == ConformalMethod::SlitCylinder) {
        n.push("Genus 0 (the paper is silent): two point slits (vertex stars) at extremal vertices; harmonic u = 0/1 on their rings and its conjugate from the annulus's harmonic 1-form give one cylinder image, periodic across one seam.".into());
    }
    if comps.iter().any(|c| c.method == ConformalMethod::CriticalTrajectoryPatches) {
        n.push("Genus ≥ 2: the critical horizontal trajectories are traced from every zero point across triangles and snapped to edge paths (cuts lie within one triangle of the exact curves); a trajectory stops at a zero point, at an earlier cut or after 0.15 √(area) of length, because on a discrete form they spiral instead of closing (the paper picks a form with finite trajectories). Besides them (our addition), the openings of the kept surface (slits, holes) and the zero points are joined by a minimum spanning tree of shortest edge paths, so that patches do not close around an opening wherever their own fronts happen to meet. Patches grow over faces without crossing cuts and are mapped by integrating the form; a face that would overlap its patch seeds a new patch (overlap guard); then patches whose charts differ by a translation across a shared edge are merged, longest shared seam first, whenever the union stays injective (patch_merges), and folded faces next to zero points join a neighbouring patch as a similar triangle on their shared edge where it fits (the rest: folded_faces_own_chart); single faces then move across a seam to their translate when that shortens the seams around them and overlaps nothing (a greedy local descent). Patches are packed without rotation into one image; faces up to 2 rings across each cut are drawn as ghosts in the margins, linked texel to texel (nearest texel after the translation, ≤ ½ texel misregistration) for boundary consistency.".into());
        if comps.iter().any(|c| c.map.loop_cut.iter().any(|&x| x)) {
            n.push("Genus ≥ 2: the surface was also cut along a short homology basis (Erickson & Whittlesey 2005: greedy Z₂-independent loops pooled from the shortest-path-tree loop systems of the zero points and 32 sampled base vertices), a substitute for the paper's closed critical trajectories; trajectories stop at these loops (homology_loop_cut_edges).".into());
        }
        n.push("The genus ≥ 2 holomorphic form minimises the area-weighted CV of |φ|² over all holomorphic forms by a compass search from the best basis form — a substitute for Jin et al. 2004's own solver (both CVs reported).".into());
        if options.quasi_isometric {
            n.push("Quasi-isometric relaxation of a patch layout (our extension): every chart gets its own copies of its vertices and the relaxation below runs on all charts at once with free chart boundaries (one gauge vertex per chart); the charts are then repacked, and since they no longer differ by translations across their seams, every seam's margin is drawn by similarity ghosts (the far face placed by the similarity that maps the shared edge).".into());
        }
    }
    if comps.iter().any(|c| c.polish.is_some_and(|p| p.applied)) {
        n.push("Conformal polish (our addition; --no-polish keeps the integrated map): each chart (the slit cylinder cut along its seam, or each patch) is re-solved as a free-boundary least squares conformal map (Lévy et al. 2002) plus a weak area-weighted pull (weight 3e-4 of the LSCM energy) towards the holomorphic map, which keeps its conformal factor and the charts' placement while removing the piecewise-linear angle error at the scale of a few triangles; a chart whose solve folds a triangle keeps its holomorphic corners, and the polish is dropped when it does not lower the mean angle distortion (polish.before / polish.after, non-slit faces). The charts no longer differ by translations across their seams (and the cylinder is no longer periodic), so every seam's margin is drawn by similarity ghosts.".into());
    }
    if comps.iter().any(|c| !c.has_uv()) {
        n.push("Failed components are textured through a chart atlas (LSCM charts) without boundary consistency across chart seams.".into());
    }
    if options.seam_feather {
        n.push("Seam feathering (our addition; --no-seam-feather): after the margins are copied, every pair of real texels that are neighbours across a cut (a texel next to a margin texel and the texel that margin texel continues, and the seam pairs) meets halfway, the correction fading into both sides over 4 texels; it removes the colour step the copy leaves where the quilting wrote both sides of a cut differently (quilting[].feathered_pairs).".into());
    }
    n.push("τ per texel: barycentric interpolation of per-vertex τ (substitute for the paper's Gaussian RBF).".into());
    n.push("Quilting: random candidate subset per patch (not exhaustive), old seams not re-cut; colours compared in sRGB.".into());
    if options.quasi_isometric {
        n.push("Quasi-isometric relaxation by implicit steps instead of the paper's explicit mass-spring steps (eq. 2; a substitute for speed and reach): each step's targets are the triangles' own 3-D shapes at the image's scale, rotated into place (ARAP's local step), weighted per face by the symmetric Dirichlet weight of its current stretch (SLIM's weights, made isotropic), one sparse solve and a flip-free backtracking line search per step; stopped when the mean angle distortion would exceed 1.3 or the area distortion stops falling.".into());
    }
}
