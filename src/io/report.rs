//! What loading and saving report beyond the mesh: what was done to the file's data, and what is
//! worth a warning.

/// What loading did to the file's data, and what is worth a warning.
#[derive(Clone, Debug, Default)]
pub struct LoadReport {
    pub welded_vertices: usize,
    pub removed_degenerate_faces: usize,
    /// Triangles with the same three corners as an earlier one (see [`crate::mesh::clean`]).
    pub removed_repeated_faces: usize,
    pub removed_unreferenced_vertices: usize,
    pub warnings: Vec<String>,
}

/// What saving did beyond writing the file: what could not be carried through, in plain words.
#[derive(Clone, Debug, Default)]
#[non_exhaustive]
pub struct SaveReport {
    pub warnings: Vec<String>,
    /// The output holds the file's texture coordinates and they followed their vertices' slide
    /// along the surface, so that the texture stays where it was: written back into its own
    /// format (OBJ, glTF/GLB, a PLY with per-vertex texture coordinates) or carried into another
    /// that holds them (OBJ, glTF/GLB, PLY), a coarser level's kept vertices' included.
    /// Otherwise (an output with no texture coordinates, a mesh written bare) they are not kept.
    pub texture_coordinates_follow: bool,
}
