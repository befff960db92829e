//! The exemplars of `fieldtex solid`: the three plane images from `--exemplar` or
//! `--exemplar-xy/-yz/-zx` (one `--exemplar` serves xy, its transpose yz, and zx at
//! weight 0: paper E §6.1), and their analysis, with the `--feature-mask` channel
//! (paper E §4) when given. Reads files; the analysis itself is
//! [`fieldtex_synth::solid::SolidExemplar`].

use super::*;

/// The three plane exemplars, and whether they all came from `--exemplar`.
pub(crate) fn read_exemplars(options: &SolidOptions) -> Result<([Image; 3], bool)> {
    let planes = [&options.exemplar_xy, &options.exemplar_yz, &options.exemplar_zx];
    let mut out = Vec::with_capacity(3);
    let mut cache: Vec<(PathBuf, Image)> = Vec::new();
    for (p, own) in planes.iter().enumerate() {
        let path = own.as_ref().or(options.exemplar.as_ref()).ok_or_else(|| {
            Error::bad_input(
                None,
                format!(
                    "no exemplar for plane {}: pass --exemplar E (or --exemplar-{})",
                    ["xy", "yz", "zx"][p],
                    ["xy", "yz", "zx"][p]
                ),
            )
        })?;
        if let Some((_, im)) = cache.iter().find(|(q, _)| q == path) {
            out.push(im.clone());
            continue;
        }
        let im = fieldtex_io::read_image(path)?;
        cache.push((path.clone(), im.clone()));
        out.push(im);
    }
    let single = planes.iter().all(|p| p.is_none());
    if single {
        // One exemplar for a layered solid (paper E §6.1): the yz plane shares the local
        // y axis with xy, so it sees the exemplar transposed; the zx plane is dropped
        // from matching and colour (weight 0).
        out[1] = transpose(&out[0]);
    }
    Ok(([out[0].clone(), out[1].clone(), out[2].clone()], single))
}

/// The exemplar analysis of `exemplars` (from [`read_exemplars`]), with the feature
/// masks of `options.feature_mask` when given: the one mask for every plane, transposed
/// for the yz plane when `single` (as the exemplar is).
pub(crate) fn analyse_exemplars(
    options: &SolidOptions,
    exemplars: &[Image; 3],
    single: bool,
    analysis: &SolidAnalysisOptions,
    progress: &dyn Progress,
) -> Result<SolidExemplar> {
    let planes = [&exemplars[0], &exemplars[1], &exemplars[2]];
    let Some(path) = &options.feature_mask else {
        return SolidExemplar::new(planes, analysis, progress).map_err(|e| {
            Error::classify(&e, exemplar_at_fault(options, exemplars, &e), "exemplar")
        });
    };
    let mask = fieldtex_io::read_image(path)?;
    let turned = if single { transpose(&mask) } else { mask.clone() };
    SolidExemplar::with_features(
        planes,
        [Some(&mask), Some(&turned), Some(&mask)],
        analysis,
        progress,
    )
    .map_err(|e| Error::classify(&e, Some(path), "feature mask"))
}

/// The file of the plane exemplar an analysis error is about (its size matches the one
/// the error names), so the message names the input rather than "exemplar".
fn exemplar_at_fault<'a>(
    options: &'a SolidOptions,
    exemplars: &[Image; 3],
    e: &fieldtex_synth::SynthError,
) -> Option<&'a Path> {
    let (w, h) = match e {
        fieldtex_synth::SynthError::ExemplarTooSmall { width, height, .. }
        | fieldtex_synth::SynthError::ExemplarTooLarge { width, height, .. } => (*width, *height),
        _ => return None,
    };
    let own = [&options.exemplar_xy, &options.exemplar_yz, &options.exemplar_zx];
    (0..3)
        .find(|&p| (exemplars[p].width, exemplars[p].height) == (w, h))
        .and_then(|p| own[p].as_ref().or(options.exemplar.as_ref()))
        .map(|p| p.as_path())
}

/// The analysis of the `--interior` exemplar at `path` (paper E Fig. 15): xy, its
/// transpose for yz and zx at weight 0, as a single `--exemplar`; timed as the report's
/// `interior_exemplar_analysis` stage.
pub(crate) fn analyse_interior(
    path: &Path,
    analysis: &SolidAnalysisOptions,
    report: &mut Report,
    progress: &dyn Progress,
) -> Result<SolidExemplar> {
    let im = fieldtex_io::read_image(path)?;
    let images = [im.clone(), transpose(&im), im];
    let mut a = analysis.clone();
    a.plane_weights = [1.0, 1.0, 0.0];
    report
        .stage(progress, "interior_exemplar_analysis", || {
            SolidExemplar::new([&images[0], &images[1], &images[2]], &a, progress)
        })
        .map_err(|e| Error::classify(&e, Some(path), "interior exemplar"))
}

/// The image mirrored about its main diagonal (`(x, y)` → `(y, x)`).
fn transpose(im: &Image) -> Image {
    let mut t = Image::new(im.height, im.width, [0.0; 4]);
    for y in 0..im.height {
        for x in 0..im.width {
            t.set(y, x, im.get(x, y));
        }
    }
    t
}
