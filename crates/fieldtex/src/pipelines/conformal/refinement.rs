//! The conformal map with refinement of coarse meshes (`--refine`).
//!
//! A piecewise-linear map cannot be conformal where a coarse mesh bends: every vertex
//! carries its angle defect (the discrete Gaussian curvature), and the triangles of its
//! ring absorb it as angle distortion. This is the floor the holomorphic map and the
//! conformal polish reach on coarse meshes (σ1/σ2 1.055–1.11 on fertility, the
//! armadillo and spot at any polish weight; docs/conformal.md, session 16). Splitting
//! every triangle into four through its edge midpoints
//! (`fieldtex_mesh::primitives::subdivide_midpoint`) leaves the surface as it is (every
//! new vertex lies on an input edge and is flat), but each ring that absorbs a defect
//! covers a quarter of the area, so the map bends less of the surface. The refined mesh
//! is the one written to `model.glb`; it carries the input's vertex normals (or
//! area-weighted ones when it has none) interpolated along the edges, so its shading
//! matches the input's.
//!
//! `auto` (the default): map and polish; while the mean σ1/σ2 away from zero points and
//! slits (per component, averaged over the components by area) exceeds [`REFINE_ABOVE`]
//! or more than [`REFINE_FAILED_SHARE`] of the surface has no valid map, and the refined
//! mesh stays within [`REFINE_MAX_TRIANGLES`], refine once more and map again, at most
//! [`REFINE_MAX_LEVELS`] times; a level that is not better than the one before (less
//! unmapped area, or a lower angle distortion without seams longer by more than
//! [`REFINE_SEAM_GROWTH`]) is dropped and the coarser one kept. Not with the
//! quasi-isometric relaxation, which trades angle distortion for area on purpose.
//! `--refine N` refines exactly `N` times first.
//! Face `f` of the input is faces `4f … 4f + 3` after one level (so face ids in the
//! report refer to the refined mesh); vertex ids of the input are kept.

use super::ConformalOptions;
use crate::{Error, Progress, Report, Result};
use fieldtex_core::Warning;
use fieldtex_mesh::{NormalWeighting, TriMesh, primitives::subdivide_midpoint, vertex_normals};
use fieldtex_param::conformal::conformal_polish::PolishOptions;
use fieldtex_param::conformal::holomorphic_map::LayoutOptions;
use fieldtex_param::conformal::{ConformalComponent, MapOptions, global_conformal_with};
use serde::{Serialize, Serializer};

/// `auto` refines while the components' area-weighted mean σ1/σ2 away from
/// singularities is above this (the target is 1.05; the polish threshold is the
/// same 1.04).
pub const REFINE_ABOVE: f64 = 1.04;

/// `auto` never refines past this many triangles (the 388K-triangle horse ×4 took
/// 18.8 s and 1 GB; 160K keeps a run of the armadillo, 29K → 117K, near 5 s).
pub const REFINE_MAX_TRIANGLES: usize = 160_000;

/// `auto` also refines while more than this share of the surface is in components
/// without a valid map (they would go to the chart atlas).
pub const REFINE_FAILED_SHARE: f64 = 0.005;

/// `auto` keeps a finer level only if its seams are at most this many times as long as
/// the coarser level's (unless it maps more of the surface). A judgement between the
/// two targets (σ1/σ2 ≤ 1.05, seams ≤ 0.25× the atlas's), from the shared meshes: the
/// marble bust's level (1.52×) takes it from 1.056 to 1.036 with seams 0.14 → 0.21×
/// the atlas's; blub's (1.67×) would take its seams from 0.25 to 0.41×; fertility's
/// 1.13×; the avocado's second level 6.5× (docs/conformal.md, session 17).
pub const REFINE_SEAM_GROWTH: f64 = 1.6;

/// `auto` refines at most this many times (×16 triangles).
pub const REFINE_MAX_LEVELS: usize = 2;

/// An explicit `--refine N` may not produce more triangles than this.
pub const REFINE_HARD_LIMIT: usize = 4_000_000;

/// How many times the mesh is split 1→4 before (or while) it is mapped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Refine {
    /// Refine while the map's angle distortion says the mesh is too coarse.
    #[default]
    Auto,
    /// Exactly this many levels (0 keeps the input's triangles).
    Levels(u8),
}

impl Serialize for Refine {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            Refine::Auto => s.serialize_str("auto"),
            Refine::Levels(n) => s.serialize_u8(*n),
        }
    }
}

impl std::str::FromStr for Refine {
    type Err = String;
    fn from_str(text: &str) -> std::result::Result<Self, String> {
        match text.trim() {
            "auto" => Ok(Refine::Auto),
            t => match t.parse::<u8>() {
                Ok(n) if n <= 3 => Ok(Refine::Levels(n)),
                _ => Err(format!("expected auto or a level count 0..=3, got {t:?}")),
            },
        }
    }
}

/// What the refinement did, for the report.
#[derive(Debug, Clone, Serialize)]
pub(super) struct RefinementSummary {
    pub mode: Refine,
    pub levels: usize,
    pub triangles_in: usize,
    pub triangles: usize,
    /// Per mapped level (including a last one that was dropped for not being better):
    /// the components' mean σ1/σ2 away from singularities, weighted by their areas (the
    /// value `auto` compares with [`REFINE_ABOVE`]).
    pub angle_mean_away_by_level: Vec<Option<f64>>,
    /// Per mapped level: the share of the surface in components without a map
    /// (compared with [`REFINE_FAILED_SHARE`]).
    pub unmapped_area_share_by_level: Vec<f64>,
    /// Per mapped level: the 3-D length of the map's seams (compared with
    /// [`REFINE_SEAM_GROWTH`]).
    pub seam_length_by_level: Vec<f64>,
    pub method: &'static str,
}

/// The mapped (and polished) mesh: possibly refined, its components, the map's warnings.
pub(super) struct Mapped {
    pub mesh: TriMesh,
    pub comps: Vec<ConformalComponent>,
    pub warnings: Vec<Warning>,
    pub summary: RefinementSummary,
}

/// Maps `mesh` per component (and polishes unless the options say not to), refining it
/// first or in between as `options.refine` says (module docs).
pub(super) fn map_refined(
    mesh: TriMesh,
    options: &ConformalOptions,
    report: &mut Report,
    progress: &dyn Progress,
) -> Result<Mapped> {
    let triangles_in = mesh.n_triangles();
    let mut mesh = mesh;
    let mut levels = 0usize;
    if let Refine::Levels(n) = options.refine {
        let n = n as usize;
        if triangles_in.saturating_mul(4usize.pow(n as u32)) > REFINE_HARD_LIMIT {
            return Err(Error::bad_input(
                Some(&options.mesh),
                format!(
                    "--refine {n} would make {} triangles from {triangles_in} (limit {REFINE_HARD_LIMIT}); \
                     use a smaller level or --refine auto",
                    triangles_in.saturating_mul(4usize.pow(n as u32))
                ),
            ));
        }
        for _ in 0..n {
            mesh = report.stage(progress, "refine", || refine_once(&mesh));
            levels += 1;
        }
    }
    let auto = options.refine == Refine::Auto && !options.quasi_isometric;
    let mut by_level = Vec::new();
    let mut failed_by_level = Vec::new();
    let mut seam_by_level = Vec::new();
    let mut best: Option<BestLevel> = None;
    loop {
        let (comps, warnings) = map_once(&mesh, options, report, progress, levels)?;
        let (angle, failed) = coarseness(&mesh, &comps);
        let seam = seam_length(&mesh, &comps);
        by_level.push(angle);
        failed_by_level.push(failed);
        seam_by_level.push(seam);
        let current = BestLevel { levels, mesh, comps, warnings, angle, failed, seam };
        if best.as_ref().is_some_and(|b| !current.improves_on(b)) {
            // Refining did not help (e.g. a CAD part whose map folds at any level):
            // keep the coarser level.
            break;
        }
        let coarse = angle.is_some_and(|w| w > REFINE_ABOVE) || failed > REFINE_FAILED_SHARE;
        let room = current.mesh.n_triangles().saturating_mul(4) <= REFINE_MAX_TRIANGLES;
        let go_on = auto && coarse && room && levels < REFINE_MAX_LEVELS;
        let next = go_on.then(|| report.stage(progress, "refine", || refine_once(&current.mesh)));
        best = Some(current);
        match next {
            Some(m) => {
                crate::outputs::check_cancelled(progress)?;
                mesh = m;
                levels += 1;
            }
            None => break,
        }
    }
    let BestLevel { levels, mesh, comps, mut warnings, .. } =
        best.ok_or_else(|| Error::internal("conformal map", "no level was mapped"))?;
    if levels > 0 {
        warnings.push(refined_warning(
            levels,
            triangles_in,
            mesh.n_triangles(),
            &by_level[..=levels],
            &failed_by_level[..=levels],
        ));
    }
    let summary = RefinementSummary {
        mode: options.refine,
        levels,
        triangles_in,
        triangles: mesh.n_triangles(),
        angle_mean_away_by_level: by_level,
        unmapped_area_share_by_level: failed_by_level,
        seam_length_by_level: seam_by_level,
        method: "midpoint subdivision (1→4 per level; same surface)",
    };
    Ok(Mapped { mesh, comps, warnings, summary })
}

/// One mapped level of [`map_refined`].
struct BestLevel {
    levels: usize,
    mesh: TriMesh,
    comps: Vec<ConformalComponent>,
    warnings: Vec<Warning>,
    angle: Option<f64>,
    failed: f64,
    seam: f64,
}

impl BestLevel {
    /// Whether this (finer) level is worth its triangles against `coarser`: less of the
    /// surface without a map (by more than half a percent), or as much, a mean angle
    /// distortion lower by more than 0.002 and seams at most [`REFINE_SEAM_GROWTH`]
    /// times as long (the layout of a finer mesh can differ: the avocado's second level
    /// cuts it into patches with 6.5× the seams, blub's first 1.7×).
    fn improves_on(&self, coarser: &BestLevel) -> bool {
        let angle = |l: &BestLevel| l.angle.unwrap_or(f64::INFINITY);
        self.failed < coarser.failed - REFINE_FAILED_SHARE
            || (self.failed <= coarser.failed + REFINE_FAILED_SHARE
                && angle(self) < angle(coarser) - 0.002
                && self.seam <= REFINE_SEAM_GROWTH * coarser.seam)
    }
}

/// How coarse the mapped mesh is: the components' mean σ1/σ2 away from singularities
/// (over all non-slit faces for a component small enough that every face is near a
/// singularity), weighted by their areas, so a small distorted part (a 12-triangle box
/// beside a statue) does not refine the whole mesh; and the share of the area in
/// components without a map (a discrete map that folds or fails on a coarse
/// triangulation goes to the chart atlas; refined, it often maps). `None` for the mean
/// when no component has a map.
fn coarseness(mesh: &TriMesh, comps: &[ConformalComponent]) -> (Option<f64>, f64) {
    let (mut sum, mut weight, mut unmapped, mut total) = (0.0, 0.0, 0.0, 0.0);
    for c in comps {
        let area = super::component_area(mesh, c);
        total += area;
        if !c.has_uv() {
            unmapped += area;
            continue;
        }
        let angle = c
            .angle_mean_away()
            .filter(|a| a.is_finite())
            .or_else(|| c.distortion_non_slit().map(|d| d.angle_mean).filter(|a| a.is_finite()));
        if let Some(a) = angle {
            sum += a * area;
            weight += area;
        }
    }
    let mean = (weight > 0.0).then(|| sum / weight);
    (mean, if total > 0.0 { unmapped / total } else { 0.0 })
}

/// 3-D length of the mapped components' seams (`fieldtex_param::conformal::seam_length`
/// over the edges inside one component; slits included; the chart atlas of unmapped
/// parts is made later and not counted).
fn seam_length(mesh: &TriMesh, comps: &[ConformalComponent]) -> f64 {
    let nf = mesh.n_triangles();
    let mut owner = vec![u32::MAX; nf];
    let mut corner = vec![[[0.0f64; 2]; 3]; nf];
    for (ci, c) in comps.iter().enumerate().filter(|(_, c)| c.has_uv()) {
        for (&f, uv) in c.faces.iter().zip(&c.corner_uv) {
            owner[f as usize] = ci as u32;
            corner[f as usize] = *uv;
        }
    }
    fieldtex_param::conformal::seam_length::seam_length(mesh, &corner, &|f, g| {
        owner[f] != u32::MAX && owner[f] == owner[g]
    })
}

/// The warning that says the output has more triangles than the input, and why.
fn refined_warning(
    levels: usize,
    triangles_in: usize,
    triangles: usize,
    angle: &[Option<f64>],
    unmapped: &[f64],
) -> Warning {
    let why = match (angle.first().copied().flatten(), unmapped.first().copied()) {
        (_, Some(u)) if u > REFINE_FAILED_SHARE => format!(
            "{:.0} % of its area had no valid conformal map on the input's triangles",
            100.0 * u
        ),
        (Some(a), _) => format!(
            "the conformal map's mean angle distortion on the input's triangles was {a:.3} \
             (above {REFINE_ABOVE})"
        ),
        _ => "the map needed it".to_string(),
    };
    let after = match angle.last().copied().flatten() {
        Some(a) => format!(", {a:.3} after"),
        None => String::new(),
    };
    Warning::new(
        "conformal-refined",
        format!(
            "the mesh was refined {levels}× by midpoint subdivision ({triangles_in} → {triangles} \
             triangles, same surface; model.glb holds the refined mesh) because {why}{after}; \
             --refine 0 keeps the input's triangles"
        ),
    )
}

/// One level of midpoint subdivision, with vertex normals carried (area-weighted ones
/// computed first when the mesh has none, as `model.glb` would get).
fn refine_once(mesh: &TriMesh) -> TriMesh {
    if mesh.vertex_normals.is_some() {
        return subdivide_midpoint(mesh);
    }
    let mut with_normals = mesh.clone();
    with_normals.vertex_normals = Some(vertex_normals(mesh, NormalWeighting::Area).0);
    subdivide_midpoint(&with_normals)
}

/// The global conformal map of every component of `mesh`, polished unless
/// `options.polish` is off or the run is quasi-isometric. Stages are timed as
/// `conformal-map` / `conformal-polish`, with `-refined-N` after `N` refinements.
fn map_once(
    mesh: &TriMesh,
    options: &ConformalOptions,
    report: &mut Report,
    progress: &dyn Progress,
    levels: usize,
) -> Result<(Vec<ConformalComponent>, Vec<Warning>)> {
    let suffix = if levels == 0 { String::new() } else { format!("-refined-{levels}") };
    let (mut comps, warnings) = report
        .stage(progress, &format!("conformal-map{suffix}"), || {
            // Quasi-isometric relaxation wants the freedom of more charts: no spanning cut.
            let layout =
                LayoutOptions { spanning_cut: !options.quasi_isometric, ..Default::default() };
            let map = MapOptions { protrusion_slits: options.protrusion_slits, layout };
            global_conformal_with(mesh, &map, progress)
        })
        .map_err(|e| Error::classify(&e, None, "conformal map"))?;
    crate::outputs::check_cancelled(progress)?;
    if options.polish && !options.quasi_isometric {
        report.stage(progress, &format!("conformal-polish{suffix}"), || {
            for c in comps.iter_mut() {
                c.polish_conformal(&PolishOptions::default());
            }
        });
    }
    Ok((comps, warnings))
}
