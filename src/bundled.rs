//! The mesh compiled into the library: the Stanford bunny of `assets/bunny00.obj` (37,706
//! vertices, 75,408 faces, closed; credits in the repository's `NOTICE`).
//!
//! It is embedded with `include_bytes!`, so the editor and the command-line tool open it from any
//! copy of the binary, with no file beside it. The command-line tool and the editor's Open box
//! accept the pseudo-path [`BUNNY_PSEUDO_PATH`] (`@bunny`) for it; a real file of that name is
//! reached as `./@bunny`. The bytes take no room in a program that never refers to them (the
//! linker drops them).

use crate::io::{self, Format, IoError, LoadOptions, Loaded};
use std::path::Path;

/// The bunny's OBJ text.
pub const BUNNY_OBJ: &[u8] = include_bytes!("../assets/bunny00.obj");

/// The bunny's file name, which stands for its path in messages and names exports
/// (`bunny00_faired.glb`).
pub const BUNNY_FILE_NAME: &str = "bunny00.obj";

/// The argument that names the bundled bunny wherever a mesh file is read by the command-line
/// tool or typed into the editor's Open box.
pub const BUNNY_PSEUDO_PATH: &str = "@bunny";

/// Whether `path` is exactly [`BUNNY_PSEUDO_PATH`].
pub fn is_bunny_pseudo_path(path: &Path) -> bool {
    path.as_os_str() == BUNNY_PSEUDO_PATH
}

/// The bundled bunny, parsed, welded and cleaned like a file loaded with `options`.
///
/// ```
/// let loaded = fairmesh::bundled::load_bunny(&fairmesh::io::LoadOptions::default())?;
/// assert_eq!(loaded.mesh.vertex_count(), 37_706);
/// assert_eq!(loaded.mesh.face_count(), 75_408);
/// # Ok::<(), fairmesh::io::IoError>(())
/// ```
pub fn load_bunny(options: &LoadOptions) -> Result<Loaded, IoError> {
    io::load_from_bytes(BUNNY_OBJ, Format::Obj, BUNNY_FILE_NAME, options)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bundled_bytes_are_the_asset_file() {
        let on_disk =
            std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny00.obj"))
                .unwrap();
        assert_eq!(on_disk, BUNNY_OBJ);
    }

    #[test]
    fn only_the_exact_pseudo_path_names_the_bunny() {
        assert!(is_bunny_pseudo_path(Path::new("@bunny")));
        assert!(!is_bunny_pseudo_path(Path::new("./@bunny")));
        assert!(!is_bunny_pseudo_path(Path::new("@bunny.obj")));
        assert!(!is_bunny_pseudo_path(Path::new("bunny00.obj")));
    }

    #[test]
    fn the_bunny_loads_closed_with_its_counts() {
        let loaded = load_bunny(&LoadOptions::default()).unwrap();
        assert_eq!(loaded.mesh.vertex_count(), 37_706);
        assert_eq!(loaded.mesh.face_count(), 75_408);
        assert!(loaded.topology.boundary_loops.is_empty());
    }
}
