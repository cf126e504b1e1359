//! Reading and writing meshes. `load(path)` and `save(path, mesh)` dispatch on the extension.
//! PROVISIONAL: OBJ only through tobj; the full set of formats and errors is to come.

use crate::mesh::{self, Topology, TriMesh};
use std::path::{Path, PathBuf};

#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Merge vertices with identical positions (seams in OBJ and glTF files).
    pub weld: bool,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self { weld: true }
    }
}

/// What loading did to the file's data, and what is worth a warning.
#[derive(Clone, Debug, Default)]
pub struct LoadReport {
    pub welded_vertices: usize,
    pub removed_degenerate_faces: usize,
    pub removed_unreferenced_vertices: usize,
    pub warnings: Vec<String>,
}

/// A loaded, welded and cleaned mesh with its topology.
#[derive(Clone, Debug)]
pub struct Loaded {
    pub mesh: TriMesh,
    pub topology: Topology,
    pub report: LoadReport,
}

#[derive(Debug, thiserror::Error)]
pub enum IoError {
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

pub fn load(path: &Path) -> Result<Loaded, IoError> {
    load_with(path, &LoadOptions::default())
}

pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Loaded, IoError> {
    let (models, _) = tobj::load_obj(
        path,
        &tobj::LoadOptions {
            triangulate: true,
            single_index: false,
            ..Default::default()
        },
    )
    .map_err(|e| IoError::Invalid {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    let mut raw = TriMesh::default();
    for m in models {
        let base = raw.positions.len() as u32;
        raw.positions
            .extend(m.mesh.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        raw.triangles.extend(
            m.mesh
                .indices
                .chunks_exact(3)
                .map(|c| [c[0] + base, c[1] + base, c[2] + base]),
        );
    }
    Ok(finish(raw, options))
}

/// Weld, clean and build the topology of a freshly parsed mesh.
pub fn finish(mut mesh: TriMesh, options: &LoadOptions) -> Loaded {
    let mut report = LoadReport::default();
    if options.weld {
        report.welded_vertices = mesh::weld(&mut mesh).merged_vertices;
    }
    let cleaned = mesh::clean(&mut mesh);
    report.removed_degenerate_faces = cleaned.removed_degenerate_faces;
    report.removed_unreferenced_vertices = cleaned.removed_unreferenced_vertices;
    let topology = Topology::build(&mesh);
    Loaded {
        mesh,
        topology,
        report,
    }
}

pub fn save(path: &Path, _mesh: &TriMesh) -> Result<(), IoError> {
    Err(IoError::Invalid {
        path: path.to_owned(),
        message: "saving is not implemented yet".into(),
    })
}
