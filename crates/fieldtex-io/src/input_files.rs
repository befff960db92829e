//! Bounded, confined reads of input files and the record of what a command read.
//!
//! Every reader of this crate opens its file through [`read_input_file`], which
//! - accepts **regular files only** (after following symbolic links): a FIFO, a device
//!   (`/dev/zero`, `/dev/urandom`), a socket or a directory is refused *before* it is
//!   opened, so nothing blocks or streams forever;
//! - reads at most a per-kind cap of bytes ([`InputKind::max_bytes`]), refusing larger
//!   files from their size and never reading past the cap even if the file grows;
//! - records the file's identity (device + inode, and its canonical path) in a
//!   per-thread log.
//!
//! Files a mesh refers to (OBJ `mtllib`/`map_Kd`, PLY `TextureFile`, glTF buffer and
//! image URIs) are resolved by [`resolve_confined`]: they must lie inside the folder of
//! the asset that names them (after resolving `..` and symbolic links); anything else is
//! refused with a message that names the reference but never the content of the file.
//!
//! The log is what the "never overwrite an input" guard checks: [`ensure_not_read`]
//! fails when an output path is a file read on this thread since the last
//! [`forget_files_read`] (same device and inode when the output exists, same canonical
//! parent folder and name when it does not yet). [`crate::atomic_write`] calls it for
//! every file written, and the facade's output stage for every file it moves into place.
//! The log is per thread: each pipeline runs its reads and writes on its calling thread.

use crate::IoError;
use std::cell::RefCell;
use std::io::Read;
use std::path::{Path, PathBuf};

/// What an input file is, which sets its size cap.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// A mesh (OBJ, PLY, STL, glTF/GLB) or a glTF buffer: 4 GiB.
    Mesh,
    /// A PNG or JPEG image: 1 GiB.
    Image,
    /// A `.npy` array: 2 GiB.
    Array,
    /// Small text (MTL, design TOML, curves OBJ): 1 GiB.
    Text,
}

impl InputKind {
    /// The largest file of this kind that is read, in bytes.
    pub fn max_bytes(self) -> u64 {
        match self {
            InputKind::Mesh => 4 << 30,
            InputKind::Image | InputKind::Text => 1 << 30,
            InputKind::Array => 2 << 30,
        }
    }
}

/// Identity of a file that was read.
#[derive(Debug, Clone, PartialEq, Eq)]
struct FileId {
    dev: u64,
    ino: u64,
    canonical: PathBuf,
}

thread_local! {
    static FILES_READ: RefCell<Vec<FileId>> = const { RefCell::new(Vec::new()) };
}

#[cfg(unix)]
fn dev_ino(meta: &std::fs::Metadata) -> (u64, u64) {
    use std::os::unix::fs::MetadataExt;
    (meta.dev(), meta.ino())
}

#[cfg(not(unix))]
fn dev_ino(_meta: &std::fs::Metadata) -> (u64, u64) {
    (0, 0)
}

/// Reads the whole regular file at `path` (at most `limit` bytes; pass
/// `kind.max_bytes()` or a smaller declared size) and records it as read.
/// `action` completes "cannot …" in messages (e.g. "read the mesh").
pub fn read_input_file(
    path: &Path,
    kind: InputKind,
    action: &'static str,
) -> Result<Vec<u8>, IoError> {
    read_input_prefix(path, kind.max_bytes(), kind, action, false)
}

/// Reads the first `len` bytes of the regular file at `path`; with `exact_cap` the file
/// may be longer (only `len` bytes are read), otherwise a longer file is refused.
pub(crate) fn read_input_prefix(
    path: &Path,
    len: u64,
    kind: InputKind,
    action: &'static str,
    exact_cap: bool,
) -> Result<Vec<u8>, IoError> {
    let meta = std::fs::metadata(path).map_err(|e| IoError::os(path, action, e))?;
    if !meta.is_file() {
        return Err(IoError::NotRegularFile {
            file: path.display().to_string(),
            what: file_type_name(&meta),
        });
    }
    let cap = len.min(kind.max_bytes());
    if !exact_cap && meta.len() > cap {
        return Err(IoError::TooLarge {
            file: path.display().to_string(),
            size: meta.len(),
            max: cap,
        });
    }
    let f = std::fs::File::open(path).map_err(|e| IoError::os(path, action, e))?;
    // The opened file must still be the regular file that was checked.
    let opened = f.metadata().map_err(|e| IoError::os(path, action, e))?;
    if !opened.is_file() || dev_ino(&opened) != dev_ino(&meta) {
        return Err(IoError::NotRegularFile {
            file: path.display().to_string(),
            what: "a file that changed while it was opened".into(),
        });
    }
    record_read(path, &opened);
    let mut bytes = Vec::with_capacity(meta.len().min(cap) as usize);
    f.take(cap.saturating_add(u64::from(!exact_cap)))
        .read_to_end(&mut bytes)
        .map_err(|e| IoError::os(path, action, e))?;
    if bytes.len() as u64 > cap {
        return Err(IoError::TooLarge {
            file: path.display().to_string(),
            size: bytes.len() as u64,
            max: cap,
        });
    }
    Ok(bytes)
}

fn file_type_name(meta: &std::fs::Metadata) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a named pipe (FIFO)".into();
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device".into();
        }
        if t.is_socket() {
            return "a socket".into();
        }
    }
    if meta.is_dir() { "a directory".into() } else { "not a regular file".into() }
}

fn record_read(path: &Path, meta: &std::fs::Metadata) {
    let (dev, ino) = dev_ino(meta);
    let canonical = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    FILES_READ.with(|l| {
        let mut l = l.borrow_mut();
        let id = FileId { dev, ino, canonical };
        if !l.contains(&id) {
            l.push(id);
        }
    });
}

/// Forgets the files read so far on this thread (a pipeline calls it when it starts, so
/// that only its own inputs are protected).
pub fn forget_files_read() {
    FILES_READ.with(|l| l.borrow_mut().clear());
}

/// The canonical paths of the files read on this thread since [`forget_files_read`].
pub fn files_read() -> Vec<PathBuf> {
    FILES_READ.with(|l| l.borrow().iter().map(|f| f.canonical.clone()).collect())
}

/// Fails with [`IoError::WouldOverwriteInput`] when writing `output` would replace a file
/// read on this thread (same device and inode, or, for a file that does not exist yet,
/// the same canonical folder and name).
pub fn ensure_not_read(output: &Path) -> Result<(), IoError> {
    let by_id = std::fs::metadata(output).ok().filter(|m| m.is_file()).map(|m| dev_ino(&m));
    let canonical = canonical_destination(output);
    let hit = FILES_READ.with(|l| {
        l.borrow().iter().any(|f| {
            by_id.is_some_and(|id| id == (f.dev, f.ino) && id != (0, 0))
                || canonical.as_ref().is_some_and(|c| *c == f.canonical)
        })
    });
    if hit {
        return Err(IoError::WouldOverwriteInput { file: output.display().to_string() });
    }
    Ok(())
}

/// The canonical path `output` would have: itself when it exists, its canonical parent
/// joined with its name otherwise.
fn canonical_destination(output: &Path) -> Option<PathBuf> {
    if let Ok(c) = std::fs::canonicalize(output) {
        return Some(c);
    }
    let name = output.file_name()?;
    let dir = match output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::canonicalize(dir).ok().map(|d| d.join(name))
}

/// Resolves `reference` (a relative file name found inside the asset `name`, `/` or `\`
/// separated) against the asset's folder `base`; refuses absolute names, URLs and any
/// name that leaves `base` once `..` and symbolic links are resolved. `what` says what
/// names the file (e.g. "glTF buffer URI") for messages.
pub fn resolve_confined(
    base: &Path,
    reference: &str,
    name: &str,
    what: &str,
) -> Result<PathBuf, IoError> {
    let refused = |why: &str| IoError::OutsideAssetFolder {
        file: name.to_string(),
        what: what.to_string(),
        reference: shorten(reference),
        why: why.to_string(),
    };
    let rel = reference.replace('\\', "/");
    if rel.contains("://") || rel.starts_with('/') || (rel.contains(':') && rel.len() > 1) {
        return Err(refused("absolute paths and URLs are not read"));
    }
    let root =
        std::fs::canonicalize(base).map_err(|e| IoError::os(base, "open the folder of", e))?;
    let joined = root.join(&rel);
    // Lexical check first, so a missing file outside the folder is still refused.
    let mut depth: i64 = 0;
    for c in Path::new(&rel).components() {
        match c {
            std::path::Component::ParentDir => depth -= 1,
            std::path::Component::Normal(_) => depth += 1,
            std::path::Component::CurDir => {}
            _ => return Err(refused("absolute paths are not read")),
        }
        if depth < 0 {
            return Err(refused("it leaves the asset's folder"));
        }
    }
    match std::fs::canonicalize(&joined) {
        Ok(c) if c.starts_with(&root) => Ok(c),
        Ok(_) => Err(refused("it leads outside the asset's folder (through a symbolic link)")),
        // A missing file: the readers report it (as a warning or an OS error).
        Err(_) => Ok(joined),
    }
}

fn shorten(s: &str) -> String {
    let clean: String = s.chars().filter(|c| !c.is_control()).take(120).collect();
    if clean.len() < s.len() { format!("{clean}…") } else { clean }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("fieldtex-io-input-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn devices_and_directories_are_refused_without_reading() {
        let e = read_input_file(Path::new("/dev/zero"), InputKind::Mesh, "read the mesh");
        assert!(matches!(e, Err(IoError::NotRegularFile { .. })), "{e:?}");
        let d = tmp("dir");
        let e = read_input_file(&d, InputKind::Mesh, "read the mesh");
        assert!(matches!(e, Err(IoError::NotRegularFile { .. })), "{e:?}");
        #[cfg(unix)]
        {
            let link = d.join("zero.obj");
            std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
            let e = read_input_file(&link, InputKind::Mesh, "read the mesh");
            assert!(matches!(e, Err(IoError::NotRegularFile { .. })), "{e:?}");
        }
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn read_files_are_guarded_by_identity() {
        let d = tmp("guard");
        let p = d.join("a.png");
        std::fs::write(&p, b"x").unwrap();
        forget_files_read();
        assert!(ensure_not_read(&p).is_ok());
        read_input_file(&p, InputKind::Image, "read the image").unwrap();
        assert!(ensure_not_read(&p).is_err());
        assert!(ensure_not_read(&d.join(".").join("a.png")).is_err());
        #[cfg(unix)]
        {
            let hard = d.join("hard.png");
            std::fs::hard_link(&p, &hard).unwrap();
            assert!(ensure_not_read(&hard).is_err(), "a hard link is the same file");
        }
        assert!(ensure_not_read(&d.join("b.png")).is_ok());
        forget_files_read();
        assert!(ensure_not_read(&p).is_ok());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn references_outside_the_folder_are_refused() {
        let d = tmp("confined");
        std::fs::create_dir_all(d.join("tex")).unwrap();
        std::fs::write(d.join("tex/a.png"), b"x").unwrap();
        assert!(resolve_confined(&d, "tex/a.png", "m.obj", "map_Kd").is_ok());
        assert!(resolve_confined(&d, "tex\\a.png", "m.obj", "map_Kd").is_ok());
        for bad in ["../../../../etc/passwd", "/etc/passwd", "tex/../../x", "file:///etc/passwd"] {
            let e = resolve_confined(&d, bad, "m.obj", "map_Kd").unwrap_err().to_string();
            assert!(e.contains("is refused"), "{bad}: {e}");
            assert!(!e.contains("root:"), "{e}");
        }
        std::fs::remove_dir_all(&d).unwrap();
    }
}
