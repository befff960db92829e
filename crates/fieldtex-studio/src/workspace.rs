//! File access confined to a root directory. Every path from a request is relative,
//! made of plain components only (no `..`, `.`, roots, drive prefixes, backslashes or
//! NUL), and is checked again after canonicalisation so that a symbolic link cannot
//! lead outside the root. Writes go through `fieldtex_io::atomic_write` into a
//! directory that canonicalises inside the root, and never through an existing link.

use std::path::{Component, Path, PathBuf};

/// A confined directory; `writable` roots accept writes.
#[derive(Debug, Clone)]
pub struct Root {
    /// The canonical root path.
    pub dir: PathBuf,
    pub writable: bool,
}

/// Why a path was refused: `(status, message)`.
pub type PathError = (u16, String);

impl Root {
    /// Canonicalises `dir`, which must exist and be a directory.
    pub fn new(dir: &Path, writable: bool) -> Result<Self, String> {
        let dir = dir
            .canonicalize()
            .map_err(|e| format!("{}: cannot open the directory: {e}", dir.display()))?;
        if !dir.is_dir() {
            return Err(format!("{} is not a directory", dir.display()));
        }
        Ok(Self { dir, writable })
    }

    /// Checks the shape of a relative request path and joins it to the root (no file
    /// system access).
    pub fn join_checked(&self, rel: &str) -> Result<PathBuf, PathError> {
        if rel.is_empty() || rel.len() > 1024 {
            return Err((400, "give a relative path of 1 to 1024 bytes".into()));
        }
        if rel.contains('\\') || rel.contains('\0') || rel.contains(':') {
            return Err((400, format!("path {rel:?}: backslashes, ':' and NUL are not allowed")));
        }
        let p = Path::new(rel);
        if p.is_absolute() {
            return Err((
                403,
                format!("path {rel:?} is absolute; give a path inside the workspace"),
            ));
        }
        for c in p.components() {
            match c {
                Component::Normal(_) => {}
                _ => {
                    return Err((
                        403,
                        format!(
                            "path {rel:?} leaves or names the workspace itself ('..', '.' or a root)"
                        ),
                    ));
                }
            }
        }
        Ok(self.dir.join(p))
    }

    /// An existing file inside the root, canonicalised (links resolved and checked).
    pub fn existing_file(&self, rel: &str) -> Result<PathBuf, PathError> {
        let joined = self.join_checked(rel)?;
        let canon = joined
            .canonicalize()
            .map_err(|_| (404, format!("no file {rel:?} in the workspace")))?;
        if !canon.starts_with(&self.dir) {
            return Err((403, format!("path {rel:?} resolves outside the workspace (a link?)")));
        }
        if !canon.is_file() {
            return Err((404, format!("{rel:?} is not a file")));
        }
        Ok(canon)
    }

    /// A directory inside the root, created (one component at a time, each checked to
    /// stay inside after canonicalisation) if missing.
    pub fn dir_for_writing(&self, rel: &str) -> Result<PathBuf, PathError> {
        if !self.writable {
            return Err((403, "this directory is read-only".into()));
        }
        let joined = self.join_checked(rel)?;
        let tail = joined.strip_prefix(&self.dir).map_err(|_| (403, "outside".to_string()))?;
        let mut cur = self.dir.clone();
        for c in tail.components() {
            cur.push(c);
            if !cur.exists() {
                std::fs::create_dir(&cur).map_err(|e| {
                    (500, format!("cannot create the directory {rel:?} in the workspace: {e}"))
                })?;
            }
            let canon = cur.canonicalize().map_err(|e| (500, format!("{rel:?}: {e}")))?;
            if !canon.starts_with(&self.dir) || !canon.is_dir() {
                return Err((
                    403,
                    format!("{rel:?} resolves outside the workspace or is not a directory"),
                ));
            }
            cur = canon;
        }
        Ok(cur)
    }

    /// A file path for writing: its directory via [`Root::dir_for_writing`], the name a
    /// plain file name, and no existing link or directory of that name.
    pub fn file_for_writing(&self, dir_rel: &str, name: &str) -> Result<PathBuf, PathError> {
        check_file_name(name)?;
        let dir = self.dir_for_writing(dir_rel)?;
        let p = dir.join(name);
        if let Ok(meta) = std::fs::symlink_metadata(&p)
            && !meta.file_type().is_file()
        {
            return Err((403, format!("{dir_rel}/{name} exists and is not a plain file")));
        }
        Ok(p)
    }

    /// Image files (`.png`, `.jpg`, `.jpeg`) under the root, relative paths sorted, at
    /// most `limit`, skipping hidden directories and `target`, at most 4 levels deep.
    pub fn list_images(&self, limit: usize) -> Vec<String> {
        self.list_matching(limit, is_image_name)
    }

    /// Files under the root whose name passes `keep`, as [`Root::list_images`].
    pub fn list_matching(&self, limit: usize, keep: impl Fn(&str) -> bool) -> Vec<String> {
        let mut out = Vec::new();
        let mut stack = vec![(self.dir.clone(), 0usize)];
        while let Some((dir, depth)) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&dir) else { continue };
            let mut entries: Vec<_> = entries.flatten().collect();
            entries.sort_by_key(|e| e.file_name());
            for e in entries {
                let name = e.file_name().to_string_lossy().into_owned();
                let Ok(ft) = e.file_type() else { continue };
                if ft.is_dir() && depth < 4 && !name.starts_with('.') && name != "target" {
                    stack.push((e.path(), depth + 1));
                } else if ft.is_file()
                    && keep(&name)
                    && let Ok(rel) = e.path().strip_prefix(&self.dir)
                    && let Some(s) = rel.to_str()
                {
                    out.push(s.to_string());
                }
            }
            if out.len() >= limit {
                break;
            }
        }
        out.sort();
        out.truncate(limit);
        out
    }
}

/// `.png`, `.jpg` or `.jpeg`, any case.
pub fn is_image_name(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    lower.ends_with(".png") || lower.ends_with(".jpg") || lower.ends_with(".jpeg")
}

/// A mesh file the readers take from an upload or the workspace: `.obj`, `.ply`,
/// `.stl`, `.glb` (not `.gltf`, whose buffers are separate files), any case.
pub fn is_mesh_name(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    [".obj", ".ply", ".stl", ".glb"].iter().any(|e| lower.ends_with(e))
}

/// A plain file name: 1–128 bytes of `A–Z a–z 0–9 . _ -`, not starting with a dot.
pub fn check_file_name(name: &str) -> Result<(), PathError> {
    let ok = !name.is_empty()
        && name.len() <= 128
        && !name.starts_with('.')
        && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'.' || b == b'_' || b == b'-');
    if ok {
        Ok(())
    } else {
        Err((
            400,
            format!("file name {name:?}: use 1–128 of A–Z a–z 0–9 . _ - (not starting with '.')"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_plain_paths_only() {
        let root = Root::new(&std::env::temp_dir(), false).unwrap();
        assert!(root.join_checked("a/b.png").is_ok());
        for bad in ["", "../a", "a/../b", "./a", "/etc/passwd", "a\\b", "C:x", "a\0b"] {
            assert!(root.join_checked(bad).is_err(), "{bad:?}");
        }
        assert!(root.dir_for_writing("x").is_err(), "read-only root");
        assert!(check_file_name("ok-name_1.png").is_ok());
        for bad in ["", ".x", "a/b", "a b", "é.png"] {
            assert!(check_file_name(bad).is_err(), "{bad:?}");
        }
    }
}
