//! Where a loaded mesh came from, as the formats need it to write the file back or to carry its
//! data into another format: the file's path and folder, and the map from the file's vertices
//! (an OBJ `v` line, a PLY vertex row, an element of a glTF POSITION accessor as read for one
//! node) to the welded vertices the algorithms work on.

use std::path::PathBuf;

/// The file a mesh was read from and how its vertices became the loaded ones (part of a
/// [`super::Source`]).
#[derive(Debug)]
pub(crate) struct Origin {
    /// The path (or the name given to `load_from_bytes`) of the input.
    pub(crate) path: PathBuf,
    /// The input's folder, where a glTF's external images live; `None` when loaded from memory.
    pub(crate) base_dir: Option<PathBuf>,
    /// Parser vertex -> welded vertex (`u32::MAX` where the vertex was dropped); `None` when the
    /// welded vertices are the parser's, one for one.
    pub(crate) raw_to_welded: Option<Vec<u32>>,
    pub(crate) raw_vertices: usize,
    pub(crate) welded_vertices: usize,
}

impl Origin {
    /// The welded vertex that parser vertex `raw` became, if it was kept.
    #[inline]
    pub(crate) fn welded(&self, raw: usize) -> Option<usize> {
        match &self.raw_to_welded {
            None => Some(raw),
            Some(map) => map
                .get(raw)
                .copied()
                .filter(|&w| w != u32::MAX)
                .map(|w| w as usize),
        }
    }
}
