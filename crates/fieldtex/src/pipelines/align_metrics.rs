//! The metrics of an `align` run (paper A's evaluation): texture-optimisation levels,
//! feature-line coverage, orientation error on the surface and contrast, measured on the
//! run's own outputs (so a metric failure is internal).

use super::*;

/// What [`align_metrics`] measures on.
pub(super) struct MetricInputs<'a> {
    pub(super) atlas_mesh: &'a TriMesh,
    pub(super) map: &'a fieldtex_param::TexelMap,
    pub(super) covered: &'a [usize],
    pub(super) carrier_of_texel: &'a [u32],
    pub(super) curve_points: &'a [((u32, [f64; 3]), f64)],
    pub(super) exemplar: &'a Image,
    pub(super) exemplar_features: &'a ExemplarFeatures,
    pub(super) texture: &'a Image,
    pub(super) field: &'a [[f64; 3]],
    pub(super) texels_per_pixel: f64,
    pub(super) seed: u64,
}

/// The metrics of an align run: texture optimisation levels, feature-line coverage,
/// orientation error on the surface and contrast, into `report`.
pub(super) fn align_metrics(
    m: &MetricInputs<'_>,
    result: &fieldtex_texopt::TexOptResult,
    feature_align: bool,
    n_carriers: usize,
    report: &mut Report,
) -> Result<()> {
    let size = m.map.width;
    let coverage_samples: Vec<fieldtex_eval::CurveSample> = m
        .curve_points
        .iter()
        .filter_map(|&((f, b), w)| {
            let texel = m.map.texel_at(m.atlas_mesh, f, b)?;
            let src = m.map.source[texel];
            let k = *m.carrier_of_texel.get(src as usize)?;
            // texopt puts pixel centres at i + 0.5, the distance map at i.
            (k != u32::MAX).then(|| {
                let c = result.source[k as usize];
                fieldtex_eval::CurveSample {
                    exemplar_xy: [c[0] as f64 - 0.5, c[1] as f64 - 0.5],
                    length: w,
                }
            })
        })
        .collect();
    // Per-level wall times belong to the (nondeterministic) timings section.
    let mut levels = serde_json::to_value(&result.levels).unwrap_or_default();
    for (l, stats) in levels.as_array_mut().into_iter().flatten().zip(&result.levels) {
        if let Some(o) = l.as_object_mut() {
            o.remove("seconds");
        }
        report.timings_ms.push((format!("synthesis_w{}", stats.patch_size), stats.seconds * 1e3));
    }
    report.metric(
        "texopt",
        serde_json::json!({
            "pixel_size": result.pixel_size,
            "carriers": n_carriers,
            "histogram_distance": result.histogram_distance,
            "levels": levels,
            "feature_align": feature_align,
            "exemplar_feature_lines": m.exemplar_features.lines.len(),
        }),
    );
    let coverage = fieldtex_eval::feature_line_coverage(
        &coverage_samples,
        &m.exemplar_features.distance,
        m.exemplar_features.width,
        m.exemplar_features.height,
        &fieldtex_eval::FeatureCoverageOptions {
            tolerance_px: 1.0,
            toroidal: m.exemplar_features.toroidal,
        },
    )
    .map_err(|e| Error::internal("feature coverage", e))?;
    report.metric("feature_coverage", &coverage);
    // Orientation error on the surface, by tangent-plane resampling of the baked texture.
    let internal = |e: fieldtex_eval::EvalError| Error::internal("metrics", e);
    let (exemplar, texture) = (m.exemplar, m.texture);
    let orientation = report.time("metrics", || -> Result<_> {
        let ebuf = fieldtex_eval::rgb_buffer(exemplar);
        let eview = fieldtex_eval::ImageView::new(&ebuf, exemplar.width, exemplar.height, 3)
            .map_err(internal)?;
        let (exemplar_angle_deg, exemplar_coherence) =
            fieldtex_eval::dominant_orientation(&eview).map_err(internal)?;
        let tbuf = fieldtex_eval::rgb_buffer(texture);
        let tview = fieldtex_eval::ImageView::new(&tbuf, size, size, 3).map_err(internal)?;
        let uvs =
            m.atlas_mesh.uvs.as_ref().ok_or_else(|| Error::Internal("atlas without UVs".into()))?;
        let opts = fieldtex_eval::SurfaceOrientationOptions {
            exemplar_angle_deg,
            seed: m.seed,
            ..Default::default()
        };
        let r = fieldtex_eval::surface_orientation_error(m.atlas_mesh, uvs, &tview, m.field, &opts)
            .map_err(internal)?;
        Ok(serde_json::json!({
            "exemplar_angle_deg": exemplar_angle_deg,
            "exemplar_coherence": exemplar_coherence,
            "surface": r,
        }))
    })?;
    report.metric("orientation_error", orientation);
    // Contrast and crispness of the covered texels against the exemplar.
    let sharpness = report.time("metrics_contrast", || -> Result<_> {
        let tbuf = fieldtex_eval::rgb_buffer(texture);
        let tview = fieldtex_eval::ImageView::new(&tbuf, size, size, 3).map_err(internal)?;
        let ebuf = fieldtex_eval::rgb_buffer(exemplar);
        let eview = fieldtex_eval::ImageView::new(&ebuf, exemplar.width, exemplar.height, 3)
            .map_err(internal)?;
        let mut mask = vec![false; size * size];
        m.covered.iter().for_each(|&i| mask[i] = true);
        fieldtex_eval::contrast_sharpness(&tview, Some(&mask), &eview, m.texels_per_pixel)
            .map_err(internal)
    })?;
    report.metric("contrast", sharpness);
    Ok(())
}
