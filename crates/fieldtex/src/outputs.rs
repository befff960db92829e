//! Output-directory helpers shared by the pipelines.

use crate::{Error, Report, Result};
use std::path::{Path, PathBuf};

/// Creates `dir` (and parents) if needed; a clear error if it is a file.
pub(crate) fn prepare_out_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(Error::bad_input(
            Some(dir),
            "the output path exists and is not a directory; pass a directory to --out",
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        Error::bad_input(Some(dir), format!("cannot create the output directory: {e}"))
    })
}

/// Writes UTF-8 text atomically.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    fieldtex_io::atomic_write(path, text.as_bytes())?;
    Ok(())
}

/// Writes `report.json` into `dir`.
pub(crate) fn write_report(dir: &Path, report: &Report) -> Result<PathBuf> {
    let p = dir.join("report.json");
    write_text(&p, &report.to_json_pretty())?;
    Ok(p)
}
