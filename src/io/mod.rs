//! Reading and writing meshes: OBJ, glTF/GLB, PLY, STL and OFF.
//!
//! `load(path)` and `save(path, mesh)` dispatch on the file extension ([`Format::from_path`]);
//! [`load_from_bytes`] parses a buffer already in memory (drag and drop, fuzzing). One file per
//! format; this file holds the dispatch, the shared checks and the post-processing.
//!
//! Choices:
//! - Files are read whole into memory and parsed from the slice: it is the fastest way for every
//!   format here and lets binary parsers check lengths before they allocate.
//! - Every parser checks what it reads (finite coordinates, indices in range, lengths) and reports
//!   the line (text formats) or byte offset / element (binary formats) at fault; [`IoError`]'s
//!   `Display` always starts with the path. No parser panics on any input (they are fuzzed, see
//!   `fuzz/`).
//! - After parsing, [`finish`] welds bit-identical positions (seams), drops degenerate triangles
//!   and unused vertices and builds the topology; non-manifold or inconsistently oriented input is
//!   loaded, with a warning in [`LoadReport::warnings`].
//! - Writes are atomic (`atomic.rs`): a temporary file beside the target is renamed into place, so a
//!   failed export never leaves a partial file or damages an existing one. Meshes with non-finite
//!   positions or out-of-range indices are refused before anything is written.
//! - Texture coordinates have one convention inside the library, glTF's (v counted down from the
//!   image's top row); readers of OBJ and PLY turn theirs (v from the bottom row) into it and
//!   writers turn them back (`uv_convention.rs`, [`Format::texture_v_origin`]).

pub(crate) mod atomic;
mod carry;
mod error;
pub(crate) mod files;
mod finish;
mod format;
mod gltf;
mod load;
mod normals;
mod obj;
mod off;
mod origin;
mod ply;
mod report;
mod save;
mod save_source;
pub mod scene;
mod source;
mod stl;
mod text;
mod uv_convention;
mod uv_follow;
mod vertex_list;

pub use atomic::write as write_atomically;
pub use carry::VertexAttributes;
pub use error::{IoError, Location};
pub use files::{exists, MemoryFolder};
pub use finish::{finish, LoadOptions, Loaded};
pub use format::Format;
pub use load::{load, load_from_bytes, load_from_reader, load_with};
pub use report::{LoadReport, SaveReport};
pub use save::{save, save_as, write_to};
pub use save_source::{save_derived_with_source, save_with_source, Derivation};
pub use source::Source;
pub use uv_convention::TextureVOrigin;
pub use uv_follow::{follow_texture_coordinates, FollowedTexture, TextureFollowError};
pub use vertex_list::{loaded_vertices, parse_vertex_list, read_vertex_list, VertexListError};

use crate::mesh::TriMesh;
use std::path::{Path, PathBuf};

/// What a format parser hands back: the raw mesh (indices checked, positions finite), warnings
/// about what it skipped, what the file holds that no writer here carries, and what of the file
/// the format keeps for writing it back, in its own type (`load` makes it part of the
/// [`Source`]).
#[derive(Debug)]
pub(crate) struct Parsed<K = ()> {
    pub mesh: TriMesh,
    pub warnings: Vec<String>,
    /// What the file holds that no writer here carries (an STL's per-facet attribute bytes, an
    /// OFF's colours), in plain words, so that saving says they were not kept.
    pub unkept: Vec<String>,
    pub kept: Option<K>,
}

impl<K> Parsed<K> {
    fn new(mesh: TriMesh) -> Parsed<K> {
        Parsed {
            mesh,
            warnings: Vec::new(),
            unkept: Vec::new(),
            kept: None,
        }
    }
}

/// The folder an output file goes into (`.` for a bare file name) and its name without the
/// extension (`mesh` when it has none): where files written beside it go, and their prefix.
pub(crate) fn folder_and_stem(output: &Path) -> (PathBuf, String) {
    let folder = match output.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let stem = output
        .file_stem()
        .map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned());
    (folder, stem)
}

/// Where a `.gltf` file's buffer goes: `<stem>.bin` beside it.
pub fn gltf_bin_path(gltf_path: &Path) -> PathBuf {
    gltf_path.with_extension("bin")
}
