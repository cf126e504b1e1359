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
    include_str!(concat!(env!("OUT_DIR"), "/doc/MeshWarning.txt"))
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
    catching(py, move || {
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
}

#[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.txt"))]
#[pyclass(name = "Mesh", module = "fairmesh")]
pub struct Mesh {
    pub loaded: Loaded,
    path: PathBuf,
    /// `load`'s `weld`, to load it again when unpickled.
    weld: bool,
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
    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.vertices.txt"))]
    #[getter]
    fn vertices(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        if let Some(array) = self.vertices.get() {
            return Ok(array.clone_ref(py));
        }
        let positions = self.loaded.mesh.positions.clone();
        let array = read_only(arrays::positions_array(py, positions, Precision::F64))?;
        Ok(self.vertices.get_or_init(|| array).clone_ref(py))
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.faces.txt"))]
    #[getter]
    fn faces(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        if let Some(array) = self.faces.get() {
            return Ok(array.clone_ref(py));
        }
        let array = read_only(arrays::triangles_array(py, &self.loaded.mesh.triangles))?;
        Ok(self.faces.get_or_init(|| array).clone_ref(py))
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.hard_edges.txt"))]
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

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.path.txt"))]
    #[getter(path)]
    fn path_text(&self) -> String {
        self.path().display().to_string()
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.format.txt"))]
    #[getter]
    fn format(&self) -> String {
        self.loaded.source.format().extension().to_string()
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.warnings.txt"))]
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.loaded.report.warnings.clone()
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.contents.txt"))]
    #[getter]
    fn contents(&self) -> Vec<String> {
        self.loaded.source.contents()
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.welded_vertices.txt"))]
    #[getter]
    fn welded_vertices(&self) -> usize {
        self.loaded.report.welded_vertices
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.closed.txt"))]
    #[getter]
    fn closed(&self) -> bool {
        self.loaded.topology.is_closed()
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Mesh.save.txt"))]
    #[pyo3(signature = (path, vertices=None), text_signature = None)]
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
        let outcome = catching(py, || {
            // The new positions stand in for the loaded ones while the file is written.
            if let Some(new) = &mut positions {
                std::mem::swap(&mut loaded.mesh.positions, new);
            }
            let saved = fairmesh::io::save_with_source(&path, &loaded.mesh, &loaded.source);
            if let Some(new) = &mut positions {
                std::mem::swap(&mut loaded.mesh.positions, new);
            }
            Ok(saved)
        })?;
        let report = outcome.map_err(|e| io_error(py, &e))?;
        for warning in &report.warnings {
            warn(py, &format!("{}: {warning}", path.display()))?;
        }
        Ok(())
    }

    /// Pickles as its file, read again when unpickled (so the file must be readable there, as
    /// the same path); a file that changed since is refused when unpickled.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let path = if fairmesh::bundled::is_bunny_pseudo_path(&self.path) {
            self.path.clone()
        } else {
            std::path::absolute(&self.path).unwrap_or_else(|_| self.path.clone())
        };
        let reload = py.import("fairmesh._fairmesh")?.getattr("_load_pickled")?;
        let mesh = &self.loaded.mesh;
        let arguments = (
            path,
            self.weld,
            mesh.vertex_count(),
            mesh.face_count(),
            fingerprint(mesh),
        );
        Ok((reload, arguments.into_pyobject(py)?.into_any()))
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

#[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/load.txt"))]
#[pyfunction]
#[pyo3(signature = (path, *, weld=true, progress=None), text_signature = None)]
pub fn load(
    py: Python<'_>,
    path: PathBuf,
    weld: bool,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Mesh> {
    let mesh = load_file(py, path, weld, progress)?;
    for warning in &mesh.loaded.report.warnings {
        warn(py, &format!("{}: {warning}", mesh.path.display()))?;
    }
    Ok(mesh)
}

/// `path` read as `load` reads it, without the warnings.
fn load_file(
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
    Ok(Mesh {
        loaded,
        path,
        weld,
        vertices: OnceLock::new(),
        faces: OnceLock::new(),
    })
}

/// A pickled `Mesh` (see `Mesh.__reduce__`): its file read again (its warnings were given when
/// it was first loaded), refused if it is no longer the mesh that was pickled.
#[pyfunction]
#[pyo3(name = "_load_pickled")]
pub fn load_pickled(
    py: Python<'_>,
    path: PathBuf,
    weld: bool,
    vertices: usize,
    faces: usize,
    fingerprint_then: u64,
) -> PyResult<Mesh> {
    let mesh = load_file(py, path, weld, None)?;
    let now = &mesh.loaded.mesh;
    if now.vertex_count() != vertices
        || now.face_count() != faces
        || fingerprint(now) != fingerprint_then
    {
        return Err(PyValueError::new_err(format!(
            "{} changed since this fairmesh.Mesh was pickled ({vertices} vertices, {faces} \
             faces then; {} vertices, {} faces now): a Mesh pickles as its file, read again \
             when unpickled",
            mesh.path.display(),
            now.vertex_count(),
            now.face_count()
        )));
    }
    Ok(mesh)
}

/// A hash of `mesh`'s positions and triangles (the same in every process of one build).
fn fingerprint(mesh: &TriMesh) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    for p in &mesh.positions {
        p.map(f32::to_bits).hash(&mut hasher);
    }
    mesh.triangles.hash(&mut hasher);
    hasher.finish()
}

#[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/save.txt"))]
#[pyfunction]
#[pyo3(text_signature = None)]
pub fn save(
    py: Python<'_>,
    path: PathBuf,
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let read = arrays::read_vertices("vertices", vertices)?;
    let triangles = arrays::read_faces("faces", faces, read.positions.len())?;
    let mesh = TriMesh::new(read.positions, triangles);
    catching(py, || Ok(fairmesh::io::save(&path, &mesh)))?.map_err(|e| io_error(py, &e))
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
