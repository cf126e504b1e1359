//! Atomic file writes: the data goes to a temporary file in the target's directory
//! (`.<name>.tmp-<pid>-<n>`), is flushed and synced, then renamed over the target. On any error the
//! temporary file is removed, so a failed export leaves nothing behind and an existing target is
//! untouched. Rename within one directory is atomic on POSIX file systems and on NTFS.
//!
//! [`stage`] and [`Staged::commit`] split the two steps so that a pair of files (`.gltf` + `.bin`)
//! is only renamed into place once both are complete; a staged file that is dropped uncommitted is
//! removed.
//!
//! A target in an in-memory folder (`files.rs`) is written to memory the same way: the content is
//! made whole first and stored only on commit.

use super::IoError;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The temporary sibling of `path` that is written before renaming: `.<name>.tmp-<pid>-<n>`, `n`
/// counting the writes of this process, so that two threads saving to one path do not share it.
pub(crate) fn temp_path(path: &Path) -> PathBuf {
    static WRITES: AtomicUsize = AtomicUsize::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh".into());
    let n = WRITES.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()))
}

/// A complete, synced temporary file waiting to be renamed over its target.
pub(crate) struct Staged {
    temp: PathBuf,
    target: PathBuf,
    committed: bool,
    /// The content, for a target in an in-memory folder (no temporary file then).
    in_memory: Option<Vec<u8>>,
}

impl Staged {
    /// Rename the temporary file over the target.
    pub(crate) fn commit(mut self) -> Result<(), IoError> {
        if let Some(bytes) = self.in_memory.take() {
            super::files::store(&self.target, bytes);
            self.committed = true;
            return Ok(());
        }
        std::fs::rename(&self.temp, &self.target).map_err(|source| IoError::Write {
            path: self.target.clone(),
            source,
        })?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed && self.in_memory.is_none() {
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

/// Write the temporary file for `path` with `fill`, which writes the whole content.
pub(crate) fn stage(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<Staged, IoError> {
    if super::files::in_memory(path) {
        let mut bytes = Vec::new();
        fill(&mut bytes).map_err(|source| IoError::Write {
            path: path.to_owned(),
            source,
        })?;
        return Ok(Staged {
            temp: path.to_owned(),
            target: path.to_owned(),
            committed: false,
            in_memory: Some(bytes),
        });
    }
    let staged = Staged {
        temp: temp_path(path),
        target: path.to_owned(),
        committed: false,
        in_memory: None,
    };
    let result = (|| {
        let file = File::create(&staged.temp).map_err(|e| explain_create_error(e, path))?;
        let mut writer = BufWriter::with_capacity(1 << 20, file);
        fill(&mut writer)?;
        let file = writer.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()
    })();
    // On error, dropping `staged` removes the temporary file.
    result.map_err(|source| IoError::Write {
        path: path.to_owned(),
        source,
    })?;
    Ok(staged)
}

/// Say which folder is missing or not writable, instead of the bare OS message.
fn explain_create_error(error: std::io::Error, path: &Path) -> std::io::Error {
    let folder = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let message = match error.kind() {
        std::io::ErrorKind::NotFound if !folder.exists() => {
            format!("the folder {} does not exist", folder.display())
        }
        std::io::ErrorKind::NotFound => format!("{} is not a folder", folder.display()),
        std::io::ErrorKind::PermissionDenied => {
            format!("no permission to write in the folder {}", folder.display())
        }
        _ => return error,
    };
    std::io::Error::new(error.kind(), message)
}

/// Stage a copy of the file `from` at `to`.
pub(crate) fn stage_copy(from: &Path, to: &Path) -> Result<Staged, IoError> {
    let bytes = super::files::read(from).map_err(|source| IoError::Read {
        path: from.to_owned(),
        source,
    })?;
    stage(to, |w| w.write_all(&bytes))
}

/// Writes `path` atomically with `fill`, which writes the whole content: into a temporary file
/// beside it, renamed over `path` once complete, so that a failure leaves an existing `path` as it
/// was and nothing behind (exported as `fairmesh::io::write_atomically`, for files that front
/// ends write themselves, such as a picture of the view).
pub fn write(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), IoError> {
    stage(path, fill)?.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_leaves_existing_file_and_no_temp() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.obj");
        std::fs::write(&path, b"original").unwrap();
        let err = write(&path, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("out.obj"), "{err}");
        assert!(err.to_string().contains("disk full"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"original");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

        write(&path, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

        // A missing folder is named.
        let nowhere = dir.path().join("no such folder").join("out.obj");
        let err = write(&nowhere, |w| w.write_all(b"x"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("the folder")
                && err.contains("no such folder")
                && err.contains("does not exist"),
            "{err}"
        );

        // A staged file dropped without commit disappears.
        let staged = stage(&dir.path().join("other.obj"), |w| w.write_all(b"x")).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
        drop(staged);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
