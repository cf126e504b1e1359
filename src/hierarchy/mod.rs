//! Volume-preserving decimation hierarchy (paper section 4.1) and moving between its levels.
//! STUB: the API contract; implementation to come.

use crate::mesh::TriMesh;
use crate::Progress;

#[derive(Clone, Debug)]
pub struct HierarchyOptions {
    pub alpha: f64,
    pub beta: f64,
    /// Stop when a level has fewer vertices than this.
    pub min_vertices: usize,
    /// At most this many levels above M0.
    pub max_levels: usize,
    /// Never collapse boundary vertices.
    pub keep_boundary: bool,
}

impl Default for HierarchyOptions {
    fn default() -> Self {
        Self {
            alpha: 1.0,
            beta: 0.01,
            min_vertices: 100,
            max_levels: 64,
            keep_boundary: false,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum HierarchyError {
    #[error("hierarchy build cancelled")]
    Cancelled,
    #[error("cannot build a hierarchy: {0}")]
    Unsupported(String),
}

/// Size of one level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelInfo {
    pub vertices: usize,
    pub faces: usize,
}

/// M0 (the input) and the collapse records that lead to ever coarser levels M1..Mn.
#[derive(Clone, Debug, Default)]
pub struct Hierarchy {
    base: TriMesh,
}

impl Hierarchy {
    /// Number of levels including M0 (so the coarsest is `level_count() - 1`).
    pub fn level_count(&self) -> usize {
        1
    }
    pub fn level_info(&self, _level: usize) -> LevelInfo {
        LevelInfo {
            vertices: self.base.vertex_count(),
            faces: self.base.face_count(),
        }
    }
    /// M0, the mesh the hierarchy was built from.
    pub fn base_mesh(&self) -> &TriMesh {
        &self.base
    }
    /// The mesh of one level, compacted (its own vertex numbering).
    pub fn level_mesh(&self, _level: usize) -> TriMesh {
        self.base.clone()
    }
}

pub fn build_hierarchy(
    mesh: &TriMesh,
    _options: &HierarchyOptions,
    _progress: &mut dyn Progress,
) -> Result<Hierarchy, HierarchyError> {
    Ok(Hierarchy { base: mesh.clone() })
}
