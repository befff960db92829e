//! Atomic file writes and the "never overwrite an input" guard.
//!
//! [`atomic_write`] writes to a hidden temporary file in the destination's directory,
//! flushes it to disk (`fsync`), then renames it over the destination. A rename within a
//! directory is atomic on POSIX file systems, so readers see either the old file or the
//! complete new one; an interrupted run leaves at most a stray `.NAME.tmp-*` file, never
//! a half-written `NAME`.

use crate::IoError;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` atomically (temporary file, fsync, rename). Refuses a path
/// that is a file read on this thread ([`crate::ensure_not_read`]).
pub fn atomic_write(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    let file_name = path
        .file_name()
        .ok_or_else(|| IoError::invalid(path, "the output path has no file name"))?;
    crate::ensure_not_read(path)?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let tmp = dir.join(format!(
        ".{}.tmp-{}-{}",
        file_name.to_string_lossy(),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)
            .map_err(|e| IoError::os(path, "create a temporary file beside", e))?;
        f.write_all(bytes).map_err(|e| IoError::os(path, "write", e))?;
        f.sync_all().map_err(|e| IoError::os(path, "flush to disk", e))?;
        drop(f);
        std::fs::rename(&tmp, path)
            .map_err(|e| IoError::os(path, "rename the temporary file onto", e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
        return result;
    }
    // Make the rename itself durable where the platform allows opening directories.
    if let Ok(d) = std::fs::File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Fails with [`IoError::WouldOverwriteInput`] when `output` names the same file as one
/// of `inputs` (compared after resolving `.`/`..` and symbolic links; an output that
/// does not exist yet is resolved through its directory).
pub fn ensure_not_input(output: &Path, inputs: &[&Path]) -> Result<(), IoError> {
    let out = resolve(output);
    for input in inputs {
        if resolve(input) == out {
            return Err(IoError::WouldOverwriteInput { file: output.display().to_string() });
        }
    }
    Ok(())
}

fn resolve(p: &Path) -> PathBuf {
    if let Ok(c) = std::fs::canonicalize(p) {
        return c;
    }
    match (p.parent(), p.file_name()) {
        (Some(dir), Some(name)) => {
            let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
            std::fs::canonicalize(dir).map(|d| d.join(name)).unwrap_or_else(|_| p.to_path_buf())
        }
        _ => p.to_path_buf(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_and_replaces_and_guards_inputs() {
        let dir = std::env::temp_dir().join(format!("fieldtex-io-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.txt");
        atomic_write(&p, b"one").unwrap();
        atomic_write(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        let leftovers = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(leftovers, 1);
        assert!(ensure_not_input(&p, &[&dir.join("./a.txt")]).is_err());
        assert!(ensure_not_input(&dir.join("b.txt"), &[&p]).is_ok());
        assert!(atomic_write(&dir.join("missing/dir/x"), b"x").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
