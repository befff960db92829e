//! `fieldtex eval`: the image metrics of DESIGN.md §6 for a synthesised image against
//! its exemplar and, optionally, the guidance field.

use crate::{Error, Result};
use fieldtex_core::Image;
use fieldtex_eval as ev;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The guidance an output is compared with.
#[derive(Debug, Clone)]
pub enum Guidance {
    /// `.npy` H×W×2 float32 `(dx, dy)` field, x right, y down.
    FieldFile(PathBuf),
    /// One direction everywhere, degrees (x right, y down).
    Angle(f64),
}

/// Metrics of one synthesised image (the `metrics` of eval and of `orient` reports).
#[derive(Debug, Clone, Serialize)]
pub struct ImageMetrics {
    pub coherence: ev::PatchDistanceReport,
    /// Coherence with the output patches taken in the guidance field's frame
    /// (`fieldtex_eval::guided_coherence`, default stride 8); only with a field.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub guided_coherence: Option<ev::GuidedCoherenceReport>,
    pub completeness: ev::PatchDistanceReport,
    pub color_sliced_wasserstein: ev::SlicedWassersteinReport,
    pub orientation_error: Option<ev::OrientationErrorReport>,
    /// ±1/2 singularities of the output's own orientation (structure tensor).
    pub singularities: Option<SingularitySummary>,
    pub phase_defects: Option<ev::PhaseDefectReport>,
    /// Metrics that could not be computed, with the reason.
    pub skipped: Vec<String>,
}

/// Counts and positions of the singularities found in an image.
#[derive(Debug, Clone, Serialize)]
pub struct SingularitySummary {
    pub n_positive: usize,
    pub n_negative: usize,
    pub index_sum: f64,
    /// `(x, y, index)` of each merged cluster.
    pub positions: Vec<(f64, f64, f64)>,
}

pub(crate) fn bad(e: ev::EvalError, what: &Path) -> Error {
    Error::bad_input(Some(what), e.to_string())
}

/// Computes every metric; `field` is `H×W×2` of the output's size when present.
/// `exemplar_angle_deg` is the exemplar's own stripe direction for the orientation error
/// (the texture is expected at field angle + this; 0 = stripes along the exemplar's x).
pub(crate) fn image_metrics(
    output: &Image,
    exemplar: &Image,
    field: Option<&[f32]>,
    angle_deg: Option<f64>,
    exemplar_angle_deg: f64,
    seed: u64,
) -> std::result::Result<ImageMetrics, ev::EvalError> {
    let ob = ev::rgb_buffer(output);
    let eb = ev::rgb_buffer(exemplar);
    let o = ev::ImageView::new(&ob, output.width, output.height, 3)?;
    let e = ev::ImageView::new(&eb, exemplar.width, exemplar.height, 3)?;
    let popts = ev::PatchDistanceOptions::default().with_wrap_exemplar(true);
    let coherence = ev::coherence(&o, &e, &popts)?;
    let completeness = ev::completeness(&o, &e, &popts)?;
    let swo = ev::SlicedWassersteinOptions { seed, ..Default::default() };
    let color_sliced_wasserstein = ev::color_sliced_wasserstein(&o, &e, &swo)?;
    let mut skipped = Vec::new();
    let reference = match (field, angle_deg) {
        (Some(f), _) => Some(ev::OrientationReference::Field(ev::FieldView::new(
            f,
            output.width,
            output.height,
        )?)),
        (None, Some(a)) => Some(ev::OrientationReference::ConstantDeg(a)),
        _ => None,
    };
    let guided_coherence = match &reference {
        Some(ev::OrientationReference::Field(f)) => {
            Some(ev::guided_coherence(&o, &e, f, &ev::GuidedCoherenceOptions::default())?)
        }
        _ => None,
    };
    let orientation_error = match reference {
        Some(r) => {
            let opts = ev::OrientationErrorOptions { exemplar_angle_deg, ..Default::default() };
            Some(ev::orientation_error(&o, &r, &opts)?)
        }
        None => {
            skipped.push("orientation_error: no guidance field or angle given".to_string());
            None
        }
    };
    let singularities = match ev::image_orientation(&o, &ev::OrientationOptions::default()) {
        Ok(map) => {
            let r = ev::singularities(&map, &ev::SingularityOptions::default());
            Some(SingularitySummary {
                n_positive: r.n_positive,
                n_negative: r.n_negative,
                index_sum: r.index_sum,
                positions: r.merged.iter().map(|c| (c.x, c.y, c.index)).collect(),
            })
        }
        Err(err) => {
            skipped.push(format!("singularities: {err}"));
            None
        }
    };
    let phase_defects = match ev::phase_defects(&o, &ev::PhaseDefectOptions::default()) {
        Ok(r) => Some(r),
        Err(err) => {
            skipped.push(format!("phase_defects: {err}"));
            None
        }
    };
    Ok(ImageMetrics {
        coherence,
        guided_coherence,
        completeness,
        color_sliced_wasserstein,
        orientation_error,
        singularities,
        phase_defects,
        skipped,
    })
}

/// Reads the images (and field) and computes [`ImageMetrics`].
pub fn eval_files(
    image: &Path,
    exemplar: &Path,
    guidance: Option<&Guidance>,
    seed: u64,
) -> Result<ImageMetrics> {
    let out = fieldtex_io::read_image(image)?;
    let ex = fieldtex_io::read_image(exemplar)?;
    let (field, angle) = match guidance {
        Some(Guidance::FieldFile(p)) => {
            let (shape, data) = fieldtex_io::read_npy_f32(p)?;
            if shape != [out.height, out.width, 2] {
                return Err(Error::bad_input(
                    Some(p),
                    format!(
                        "the field has shape {shape:?} but the image needs [{}, {}, 2] (H×W×2 float32)",
                        out.height, out.width
                    ),
                ));
            }
            (Some(data), None)
        }
        Some(Guidance::Angle(a)) => {
            if !a.is_finite() {
                return Err(Error::bad_input(None, "--angle must be a finite number of degrees"));
            }
            (None, Some(*a))
        }
        None => (None, None),
    };
    image_metrics(&out, &ex, field.as_deref(), angle, 0.0, seed).map_err(|e| bad(e, image))
}
