//! The shared output stage of the pipelines: every command's outputs pass through here.
//!
//! - **Inputs are never overwritten.** `fieldtex-io` records the identity (device +
//!   inode, canonical path) of every file a command reads, including the files a mesh
//!   names (MTL libraries and textures, glTF buffers and images), exemplars, curves,
//!   fields and design files. [`begin_outputs`] refuses a run whose declared outputs
//!   are among them before any work is done; every write ([`fieldtex_io::atomic_write`])
//!   and every move into the output folder ([`commit_outputs`]) checks again
//!   ([`guard_output`] for commands that write single files).
//! - **Outputs appear together or not at all.** A folder-writing pipeline writes into a
//!   staging folder inside its output folder and [`commit_outputs`] moves the files into
//!   place at the very end, `report.json` last, after removing the previous report: a
//!   run stopped before then leaves the folder untouched, and a `report.json` always
//!   comes from the same run as every file it lists (see [`fieldtex_io::OutputDir`]).

use crate::{Error, Report, Result};
use std::path::Path;

/// Creates `dir` (and parents) if needed; a clear error if it is a file. (Pipelines that
/// write a folder use [`begin_outputs`], which calls it.)
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

/// Starts a command: only the files it reads from now on are protected from its writes.
pub(crate) fn begin_command() {
    fieldtex_io::forget_files_read();
}

/// Fails when `path` is a file this command read.
pub fn guard_output(path: &Path) -> Result<()> {
    fieldtex_io::ensure_not_read(path)?;
    Ok(())
}

/// Opens the output folder `dir` of a run whose outputs will be `expected` (file names):
/// refuses it now when one of them is an input, and returns the staging folder to write
/// into (module docs).
pub(crate) fn begin_outputs(dir: &Path, expected: &[&str]) -> Result<fieldtex_io::OutputDir> {
    prepare_out_dir(dir)?;
    fieldtex_io::OutputDir::create(dir, expected).map_err(|e| match e {
        fieldtex_io::IoError::InvalidData { message, .. } => Error::bad_input(Some(dir), message),
        e => e.into(),
    })
}

/// Lists the staged outputs in the report, writes `report.json` into the staging folder
/// and moves everything into place.
pub(crate) fn commit_outputs(out: fieldtex_io::OutputDir, report: &mut Report) -> Result<()> {
    let mut names: Vec<String> = std::fs::read_dir(out.staging())
        .map(|it| {
            it.flatten()
                .filter_map(|e| e.file_name().into_string().ok())
                .filter(|n| !n.starts_with('.') && n != "report.json")
                .collect()
        })
        .unwrap_or_default();
    names.push("report.json".to_string());
    names.sort();
    report.outputs = names;
    write_text(&out.path("report.json"), &report.to_json_pretty())?;
    out.commit()?;
    Ok(())
}

/// Writes UTF-8 text atomically (never over a file this command read).
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    fieldtex_io::atomic_write(path, text.as_bytes())?;
    Ok(())
}

/// `Err(Error::Cancelled)` once the caller's progress asks to stop; pipelines call it
/// between stages, so a cancelled run stops at the next stage boundary and its staged
/// outputs are dropped uncommitted.
pub(crate) fn check_cancelled(progress: &dyn crate::Progress) -> Result<()> {
    if progress.cancelled() { Err(Error::Cancelled) } else { Ok(()) }
}
