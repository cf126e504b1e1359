//! Where the readers and writers find files: the file system, or an in-memory folder
//! ([`MemoryFolder`]) standing in for one.
//!
//! A file is more than its own bytes: an OBJ names its `.mtl` libraries and their images, a
//! `.gltf` its `.bin` buffers and images, all found beside it, and writing one back copies them
//! beside the output. A program with no file system (a page in a browser) or one that holds a
//! set of files in memory (an archive's entries, an upload) puts them in a [`MemoryFolder`]: every
//! path under the folder's root is then read from and written to memory, and everything else
//! still goes to the file system. Loading `root/scan.obj` with [`super::load`] finds its
//! `root/scan.mtl` and `root/skin.png`; saving to `other_root/out.obj` stores the OBJ, its `.mtl`
//! and its images in the other folder, where [`MemoryFolder::files`] hands them over.
//!
//! The folders are process-wide (the loaders and writers reach them from any thread); with none
//! made, every path goes to the file system as before, at the cost of one lock check.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, PoisonError, RwLock};

/// The in-memory folders' roots and their files (path to bytes).
#[derive(Default)]
struct Memory {
    roots: Vec<PathBuf>,
    files: BTreeMap<PathBuf, Arc<[u8]>>,
}

/// Set once a folder was made: until then no path needs the lock.
static ANY_FOLDER: AtomicBool = AtomicBool::new(false);
static MEMORY: RwLock<Option<Memory>> = RwLock::new(None);

fn with_memory<T>(f: impl FnOnce(&mut Memory) -> T) -> T {
    let mut guard = MEMORY.write().unwrap_or_else(PoisonError::into_inner);
    f(guard.get_or_insert_with(Memory::default))
}

/// Whether `path` lies under an in-memory folder (then it never reaches the file system).
pub(crate) fn in_memory(path: &Path) -> bool {
    if !ANY_FOLDER.load(Ordering::Acquire) {
        return false;
    }
    let guard = MEMORY.read().unwrap_or_else(PoisonError::into_inner);
    guard
        .as_ref()
        .is_some_and(|memory| memory.roots.iter().any(|root| path.starts_with(root)))
}

fn not_found(path: &Path) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::NotFound,
        format!("{} was not given with the file", path.display()),
    )
}

/// The whole file at `path`, from memory or from the file system.
pub(crate) fn read(path: &Path) -> std::io::Result<Vec<u8>> {
    if in_memory(path) {
        let guard = MEMORY.read().unwrap_or_else(PoisonError::into_inner);
        return guard
            .as_ref()
            .and_then(|memory| memory.files.get(path))
            .map(|bytes| bytes.to_vec())
            .ok_or_else(|| not_found(path));
    }
    std::fs::read(path)
}

/// Whether `path` is a file (in memory or on the file system).
pub(crate) fn is_file(path: &Path) -> bool {
    if in_memory(path) {
        let guard = MEMORY.read().unwrap_or_else(PoisonError::into_inner);
        return guard
            .as_ref()
            .is_some_and(|memory| memory.files.contains_key(path));
    }
    path.is_file()
}

/// Whether anything is at `path`: a file, or (on the file system) a folder. An in-memory folder
/// holds files only; its sub-folders exist as soon as a file is in them.
pub fn exists(path: &Path) -> bool {
    if in_memory(path) {
        let guard = MEMORY.read().unwrap_or_else(PoisonError::into_inner);
        return guard.as_ref().is_some_and(|memory| {
            memory.roots.iter().any(|root| root == path)
                || memory.files.keys().any(|file| file.starts_with(path))
        });
    }
    path.exists()
}

/// Stores `bytes` at `path`, which [`in_memory`] said is in memory.
pub(crate) fn store(path: &Path, bytes: Vec<u8>) {
    with_memory(|memory| {
        memory.files.insert(path.to_owned(), bytes.into());
    });
}

/// One file as the same file for a copy: the same path in memory, the same file on disk.
pub(crate) fn same_file(a: &Path, b: &Path) -> bool {
    if in_memory(a) || in_memory(b) {
        return a == b;
    }
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// A folder held in memory: files put in it are read by the loaders as if they were on disk,
/// and whatever a save writes under it stays in it. Dropping it forgets its files.
///
/// ```
/// use fairmesh::io::MemoryFolder;
/// let folder = MemoryFolder::new("/uploads/1");
/// folder.insert("tri.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec());
/// let loaded = fairmesh::io::load(folder.path("tri.off"))?;
/// assert_eq!(loaded.mesh.face_count(), 1);
///
/// let out = MemoryFolder::new("/downloads/1");
/// fairmesh::io::save(out.path("tri.stl"), &loaded.mesh)?;
/// assert_eq!(out.files().len(), 1);
/// # Ok::<(), fairmesh::io::IoError>(())
/// ```
pub struct MemoryFolder {
    root: PathBuf,
}

impl MemoryFolder {
    /// A new, empty folder at `root` (replacing what an earlier folder there held); paths under
    /// it no longer reach the file system. `root` should be absolute, and no real folder.
    pub fn new(root: impl Into<PathBuf>) -> Self {
        let root = root.into();
        with_memory(|memory| {
            memory.files.retain(|path, _| !path.starts_with(&root));
            if !memory.roots.contains(&root) {
                memory.roots.push(root.clone());
            }
        });
        ANY_FOLDER.store(true, Ordering::Release);
        Self { root }
    }

    /// The folder's root.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The path of `relative` (a file name, or names joined by `/`) in the folder.
    pub fn path(&self, relative: &str) -> PathBuf {
        self.root.join(relative.trim_start_matches('/'))
    }

    /// Puts a file in the folder (`relative` as in [`MemoryFolder::path`]), replacing one of that
    /// name; returns its path.
    pub fn insert(&self, relative: &str, bytes: Vec<u8>) -> PathBuf {
        let path = self.path(relative);
        store(&path, bytes);
        path
    }

    /// Every file in the folder with its path relative to the root, sorted by path.
    pub fn files(&self) -> Vec<(PathBuf, Vec<u8>)> {
        let guard = MEMORY.read().unwrap_or_else(PoisonError::into_inner);
        guard
            .as_ref()
            .map(|memory| {
                memory
                    .files
                    .iter()
                    .filter_map(|(path, bytes)| {
                        let relative = path.strip_prefix(&self.root).ok()?;
                        Some((relative.to_owned(), bytes.to_vec()))
                    })
                    .collect()
            })
            .unwrap_or_default()
    }

    /// Forgets every file in the folder; the folder stays.
    pub fn clear(&self) {
        with_memory(|memory| memory.files.retain(|path, _| !path.starts_with(&self.root)));
    }
}

impl Drop for MemoryFolder {
    fn drop(&mut self) {
        with_memory(|memory| {
            memory.files.retain(|path, _| !path.starts_with(&self.root));
            memory.roots.retain(|root| root != &self.root);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_outside_a_memory_folder_reach_the_file_system() {
        let folder = MemoryFolder::new("/fairmesh-test-memory/a");
        folder.insert("x.txt", b"memory".to_vec());
        let dir = tempfile::tempdir().unwrap();
        let on_disk = dir.path().join("x.txt");
        std::fs::write(&on_disk, b"disk").unwrap();
        assert_eq!(read(&folder.path("x.txt")).unwrap(), b"memory");
        assert_eq!(read(&on_disk).unwrap(), b"disk");
        assert!(is_file(&folder.path("x.txt")));
        assert!(!is_file(&folder.path("y.txt")));
        let missing = read(&folder.path("y.txt")).unwrap_err();
        assert_eq!(missing.kind(), std::io::ErrorKind::NotFound);
        assert!(missing.to_string().contains("y.txt"), "{missing}");
        drop(folder);
        // Forgotten with the folder, and never looked for on disk.
        assert!(!is_file(Path::new("/fairmesh-test-memory/a/x.txt")));
    }

    #[test]
    fn files_lists_only_its_own_folder() {
        let a = MemoryFolder::new("/fairmesh-test-memory/b");
        let b = MemoryFolder::new("/fairmesh-test-memory/bb");
        a.insert("sub/one.bin", vec![1]);
        b.insert("two.bin", vec![2]);
        assert_eq!(a.files(), vec![(PathBuf::from("sub/one.bin"), vec![1])]);
        assert!(exists(&a.path("sub")));
        a.clear();
        assert!(a.files().is_empty());
        assert_eq!(b.files().len(), 1);
    }
}
