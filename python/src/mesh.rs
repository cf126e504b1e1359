//! Meshes from arrays ([`from_arrays`]) and from files ([`Mesh`], what `fairmesh.load` returns:
//! the welded mesh, its topology and the file it came from, kept so that `Mesh.save` writes the
//! file back with only the positions changed, as the command line does).

use crate::arrays::{self, Precision};
use crate::errors::io_error;
use crate::run::{catching, run_detached};
use fairmesh::io::{LoadOptions, Loaded};
use fairmesh::{Topology, TriMesh};
use numpy::PyArrayMethods;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::IntoPyDict;
use std::path::PathBuf;
use std::sync::OnceLock;

pyo3::create_exception!(
    fairmesh,
    MeshWarning,
    pyo3::exceptions::PyUserWarning,
    "What loading read leniently or repaired, and what saving could not keep from the file."
);

/// A mesh from `vertices` and `faces` arrays, made ready as loading makes a file's mesh ready,
/// but with the caller's vertices kept as they are (results index them one for one): triangles
/// that repeat a vertex or another triangle's corners are left out, and faces that point the
/// other way from their neighbours are turned (only for the computation: the caller's faces are
/// not changed).
pub fn from_arrays(
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
) -> PyResult<(TriMesh, Topology, Precision)> {
    let read = arrays::read_vertices("vertices", vertices)?;
    let mut triangles = arrays::read_faces("faces", faces, read.positions.len())?;
    if triangles.is_empty() {
        return Err(PyValueError::new_err("faces holds no triangle"));
    }
    triangles.retain(|&[a, b, c]| a != b && b != c && a != c);
    if triangles.is_empty() {
        return Err(PyValueError::new_err(
            "every triangle of faces repeats a vertex: nothing to work on",
        ));
    }
    let positions = read.positions;
    let precision = read.precision;
    let py = vertices.py();
    py.detach(move || {
        catching(move || {
            let mut mesh = TriMesh::new(positions, triangles);
            let mut topology = Topology::build(&mesh);
            if !topology.repeated_triangles.is_empty() {
                let mut repeated = vec![false; mesh.triangles.len()];
                for &t in &topology.repeated_triangles {
                    repeated[t as usize] = true;
                }
                let mut index = 0;
                mesh.triangles.retain(|_| {
                    index += 1;
                    !repeated[index - 1]
                });
                topology = Topology::build(&mesh);
            }
            if topology.inconsistent_edges > 0
                && fairmesh::mesh::orient_consistently(&mut mesh, &topology).flipped_faces > 0
            {
                topology = Topology::build(&mesh);
            }
            Ok((mesh, topology, precision))
        })
    })
}

/// A mesh loaded from a file (`fairmesh.load`): its vertices and faces as arrays, and the file
/// it came from, so that `save` writes it back with only the positions changed.
#[pyclass(name = "Mesh", module = "fairmesh")]
pub struct Mesh {
    pub loaded: Loaded,
    path: PathBuf,
    /// The arrays, made on first use: `fair(mesh)` and `save` need neither.
    vertices: OnceLock<Py<PyAny>>,
    faces: OnceLock<Py<PyAny>>,
}

impl Mesh {
    /// The file's own sharp edges (split normals, material boundaries; OBJ and glTF), which the
    /// command line's `fair` keeps sharp with the creases it finds.
    pub fn file_hard_edges(&self) -> Vec<[u32; 2]> {
        self.loaded.source.hard_edges(&self.loaded.mesh)
    }

    /// The path it was loaded from.
    pub fn path(&self) -> &std::path::Path {
        &self.path
    }
}

#[pymethods]
impl Mesh {
    /// The welded vertices, (n, 3) float64, read-only (a result is a new array).
    #[getter]
    fn vertices(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        if let Some(array) = self.vertices.get() {
            return Ok(array.clone_ref(py));
        }
        let positions = self.loaded.mesh.positions.clone();
        let array = read_only(arrays::positions_array(py, positions, Precision::F64))?;
        Ok(self.vertices.get_or_init(|| array).clone_ref(py))
    }

    /// The triangles, (m, 3) int64 indices into `vertices`, read-only.
    #[getter]
    fn faces(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        if let Some(array) = self.faces.get() {
            return Ok(array.clone_ref(py));
        }
        let array = read_only(arrays::triangles_array(py, &self.loaded.mesh.triangles))?;
        Ok(self.faces.get_or_init(|| array).clone_ref(py))
    }

    /// The file's sharp edges ((k, 2) int64 vertex pairs): split normals and material
    /// boundaries of an OBJ or glTF; `fair(mesh)` keeps them sharp, as the command line does.
    #[getter]
    fn hard_edges<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let edges: Vec<i64> = self
            .file_hard_edges()
            .iter()
            .flat_map(|e| e.map(i64::from))
            .collect();
        let rows = edges.len() / 2;
        numpy::PyArray1::from_vec(py, edges)
            .reshape([rows, 2])
            .expect("two values a row")
            .into_any()
    }

    /// The path the mesh was loaded from.
    #[getter(path)]
    fn path_text(&self) -> String {
        self.path().display().to_string()
    }

    /// The file's format: "obj", "gltf", "glb", "ply", "stl" or "off".
    #[getter]
    fn format(&self) -> String {
        self.loaded.source.format().extension().to_string()
    }

    /// What loading read leniently or repaired, in words (also given as `MeshWarning`s).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.loaded.report.warnings.clone()
    }

    /// What the file holds beyond positions and triangles (UVs, normals, materials, ...),
    /// kept when it is saved back into its format.
    #[getter]
    fn contents(&self) -> Vec<String> {
        self.loaded.source.contents()
    }

    /// How many vertices loading merged because they had the same position.
    #[getter]
    fn welded_vertices(&self) -> usize {
        self.loaded.report.welded_vertices
    }

    /// Whether every edge has two triangles (the volume change then means something).
    #[getter]
    fn closed(&self) -> bool {
        self.loaded.topology.is_closed()
    }

    /// Writes the mesh with `vertices` (the loaded ones when None) as its positions into
    /// `path` (format by extension). Into the file's own format the file comes back with only
    /// the positions (and what follows them: normals, texture coordinates) changed; into
    /// another, what that format can hold is carried. What could not be kept is given as a
    /// `MeshWarning`. The write is atomic: a failed save leaves no file.
    #[pyo3(signature = (path, vertices=None))]
    fn save(
        &mut self,
        py: Python<'_>,
        path: PathBuf,
        vertices: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let mut positions = match vertices {
            Some(vertices) => {
                let read = arrays::read_vertices("vertices", vertices)?;
                if read.positions.len() != self.loaded.mesh.vertex_count() {
                    return Err(PyValueError::new_err(format!(
                        "vertices has {} rows but the mesh has {} vertices",
                        read.positions.len(),
                        self.loaded.mesh.vertex_count()
                    )));
                }
                Some(read.positions)
            }
            None => None,
        };
        let loaded = &mut self.loaded;
        let outcome = py.detach(|| {
            catching(|| {
                // The new positions stand in for the loaded ones while the file is written.
                if let Some(new) = &mut positions {
                    std::mem::swap(&mut loaded.mesh.positions, new);
                }
                let saved = fairmesh::io::save_with_source(&path, &loaded.mesh, &loaded.source);
                if let Some(new) = &mut positions {
                    std::mem::swap(&mut loaded.mesh.positions, new);
                }
                Ok(saved)
            })
        })?;
        let report = outcome.map_err(|e| io_error(py, &e))?;
        for warning in &report.warnings {
            warn(py, &format!("{}: {warning}", path.display()))?;
        }
        Ok(())
    }

    fn __repr__(&self) -> String {
        format!(
            "<fairmesh.Mesh {}: {} vertices, {} faces>",
            self.path().display(),
            self.loaded.mesh.vertex_count(),
            self.loaded.mesh.face_count()
        )
    }
}

/// `warnings.warn(message, MeshWarning)`.
pub fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    PyErr::warn(
        py,
        &py.get_type::<MeshWarning>(),
        &std::ffi::CString::new(message).unwrap_or_default(),
        1,
    )
}

/// `fairmesh.load`: reads a mesh file (or `@bunny`, the bundled Stanford bunny).
#[pyfunction]
#[pyo3(signature = (path, *, weld=true, progress=None))]
pub fn load(
    py: Python<'_>,
    path: PathBuf,
    weld: bool,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Mesh> {
    let options = LoadOptions { weld };
    let loaded = run_detached(py, progress, None, |_| {
        Some(if fairmesh::bundled::is_bunny_pseudo_path(&path) {
            fairmesh::bundled::load_bunny(&options)
        } else {
            fairmesh::io::load_with(&path, &options)
        })
    })?
    .map_err(|e| io_error(py, &e))?;
    for warning in &loaded.report.warnings {
        warn(py, &format!("{}: {warning}", path.display()))?;
    }
    Ok(Mesh {
        loaded,
        path,
        vertices: OnceLock::new(),
        faces: OnceLock::new(),
    })
}

/// `fairmesh.save`: writes a bare mesh from arrays (format by extension).
#[pyfunction]
pub fn save(
    py: Python<'_>,
    path: PathBuf,
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let read = arrays::read_vertices("vertices", vertices)?;
    let triangles = arrays::read_faces("faces", faces, read.positions.len())?;
    let mesh = TriMesh::new(read.positions, triangles);
    py.detach(|| catching(|| Ok(fairmesh::io::save(&path, &mesh))))?
        .map_err(|e| io_error(py, &e))
}

/// `array` made read-only, as a handle.
fn read_only(array: Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
    array.call_method(
        "setflags",
        (),
        Some(&[("write", false)].into_py_dict(array.py())?),
    )?;
    Ok(array.unbind())
}
