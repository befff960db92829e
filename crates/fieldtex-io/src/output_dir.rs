//! A run's output folder whose files appear together or not at all.
//!
//! [`OutputDir::create`] makes the folder and a hidden staging folder inside it
//! (`.fieldtex-staging-<pid>-<n>`); a pipeline writes every output into the staging
//! folder ([`OutputDir::staging`], [`OutputDir::path`]), and [`OutputDir::commit`] moves them into place:
//! first the previous `report.json` is removed, then every other output is renamed
//! over its old version, and `report.json` comes last.
//!
//! The guarantee: a run stopped at any point before `commit` (an error, Ctrl-C,
//! `kill -9`) leaves the folder's visible files exactly as they were; the next run in
//! the folder deletes the orphaned staging folder of a process that no longer runs.
//! A run stopped during `commit` itself (a handful of renames) can leave some new and
//! some old files, but then no `report.json`: **a `report.json` in the folder always
//! comes from the same run as every output it lists**, so "report present" is the
//! marker of a complete set. Each file is whole at all times (renames within one file
//! system are atomic).
//!
//! Before anything is computed, `create` checks the declared names against the files
//! the command read ([`crate::ensure_not_read`]), and `commit` checks every name again,
//! so no output ever replaces an input (an exemplar, an MTL texture, a curves file).

use crate::IoError;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);
const STAGING_PREFIX: &str = ".fieldtex-staging-";

/// The outputs of one run (module docs).
#[derive(Debug)]
pub struct OutputDir {
    dir: PathBuf,
    staging: PathBuf,
    committed: bool,
}

impl OutputDir {
    /// Creates `dir` (and parents) and the staging folder; fails when one of `expected`
    /// (file names inside `dir`) is a file this thread read.
    pub fn create(dir: &Path, expected: &[&str]) -> Result<Self, IoError> {
        if dir.exists() && !dir.is_dir() {
            return Err(IoError::invalid(
                dir,
                "the output path exists and is not a directory; pass a directory to --out",
            ));
        }
        std::fs::create_dir_all(dir).map_err(|e| IoError::os(dir, "create the folder", e))?;
        for name in expected {
            crate::ensure_not_read(&dir.join(name))?;
        }
        remove_orphaned_staging(dir);
        let staging = dir.join(format!(
            "{STAGING_PREFIX}{}-{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir(&staging)
            .map_err(|e| IoError::os(&staging, "create the staging folder", e))?;
        Ok(Self { dir: dir.to_path_buf(), staging, committed: false })
    }

    /// The final folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The staging folder: write every output of the run into it.
    pub fn staging(&self) -> &Path {
        &self.staging
    }

    /// Where to write the output `name` now: `staging()/name`.
    pub fn path(&self, name: &str) -> PathBuf {
        self.staging.join(name)
    }

    /// Moves every file written into the staging folder into place (module docs for the
    /// order and the guarantee) and returns the final paths.
    pub fn commit(mut self) -> Result<Vec<PathBuf>, IoError> {
        let mut names: Vec<String> = std::fs::read_dir(&self.staging)
            .map_err(|e| IoError::os(&self.staging, "list the staging folder", e))?
            .flatten()
            .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
            .filter_map(|e| e.file_name().into_string().ok())
            .filter(|n| !n.starts_with('.'))
            .collect();
        names.sort();
        for n in &names {
            crate::ensure_not_read(&self.dir.join(n))?;
        }
        // report.json last: its presence marks a complete set.
        names.sort_by_key(|n| n == "report.json");
        let report = self.dir.join("report.json");
        if report.is_file() {
            std::fs::remove_file(&report)
                .map_err(|e| IoError::os(&report, "remove the previous report", e))?;
        }
        let mut out = Vec::with_capacity(names.len());
        for n in &names {
            let dst = self.dir.join(n);
            std::fs::rename(self.staging.join(n), &dst)
                .map_err(|e| IoError::os(&dst, "move the new output onto", e))?;
            out.push(dst);
        }
        if let Ok(d) = std::fs::File::open(&self.dir) {
            let _ = d.sync_all();
        }
        let _ = std::fs::remove_dir_all(&self.staging);
        self.committed = true;
        Ok(out)
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// Deletes staging folders in `dir` left by processes that no longer run (Linux: no
/// `/proc/<pid>`); elsewhere they are left alone.
fn remove_orphaned_staging(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(rest) = name.to_str().and_then(|n| n.strip_prefix(STAGING_PREFIX)) else {
            continue;
        };
        let Some(pid) = rest.split('-').next().and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        let gone = cfg!(target_os = "linux")
            && pid != std::process::id()
            && !Path::new(&format!("/proc/{pid}")).exists();
        if gone {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_appear_together_and_an_abandoned_run_changes_nothing() {
        let d = std::env::temp_dir().join(format!("fieldtex-io-outdir-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        let o = OutputDir::create(&d, &["a.txt", "report.json"]).unwrap();
        crate::atomic_write(&o.path("a.txt"), b"1").unwrap();
        crate::atomic_write(&o.path("report.json"), b"{}").unwrap();
        assert!(!d.join("a.txt").exists(), "nothing visible before commit");
        o.commit().unwrap();
        assert_eq!(std::fs::read(d.join("a.txt")).unwrap(), b"1");
        // An abandoned second run (error or kill before commit) leaves the first intact.
        {
            let o = OutputDir::create(&d, &["a.txt"]).unwrap();
            crate::atomic_write(&o.path("a.txt"), b"2").unwrap();
        }
        assert_eq!(std::fs::read(d.join("a.txt")).unwrap(), b"1");
        // Orphaned staging of a dead process is removed by the next run.
        std::fs::create_dir_all(d.join(".fieldtex-staging-4000000000-0")).unwrap();
        let o = OutputDir::create(&d, &[]).unwrap();
        drop(o);
        let left: Vec<_> =
            std::fs::read_dir(&d).unwrap().flatten().map(|e| e.file_name()).collect();
        assert_eq!(left.len(), 2, "{left:?}");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
