//! `fairmesh.follow_texture`: texture coordinates that follow their vertices' slide along the
//! surface, as files written back do ([`fairmesh::io::follow_texture_coordinates`]), for a
//! program that keeps its own texture coordinates (one per corner, or one per vertex).

use crate::arrays;
use crate::mesh::warn;
use crate::run::catching;
use numpy::PyReadonlyArray2;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

#[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/follow_texture.txt"))]
#[pyfunction]
#[pyo3(signature = (before, after, faces, uvs, uv_faces=None), text_signature = None)]
pub fn follow_texture<'py>(
    py: Python<'py>,
    before: &Bound<'py, PyAny>,
    after: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    uvs: &Bound<'py, PyAny>,
    uv_faces: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let before = arrays::read_vertices("before", before)?.positions;
    let after = arrays::read_vertices("after", after)?.positions;
    if before.len() != after.len() {
        return Err(PyValueError::new_err(format!(
            "before has {} vertices but after has {}: after must be before's vertices moved",
            before.len(),
            after.len()
        )));
    }
    let triangles = arrays::read_faces("faces", faces, before.len())?;
    let coordinates = read_uvs(uvs)?;
    let texture_triangles = match uv_faces.filter(|f| !f.is_none()) {
        Some(uv_faces) => {
            let texture = arrays::read_faces("uv_faces", uv_faces, coordinates.len())?;
            if texture.len() != triangles.len() {
                return Err(PyValueError::new_err(format!(
                    "uv_faces has {} rows but faces has {}: one row of texture coordinate \
                     indices per face",
                    texture.len(),
                    triangles.len()
                )));
            }
            texture
        }
        None => {
            if coordinates.len() != before.len() {
                return Err(PyValueError::new_err(format!(
                    "uvs has {} rows but there are {} vertices: without uv_faces, uvs holds \
                     one texture coordinate per vertex",
                    coordinates.len(),
                    before.len()
                )));
            }
            triangles.clone()
        }
    };
    let followed = catching(py, move || {
        fairmesh::io::follow_texture_coordinates(
            &before,
            &after,
            &triangles,
            &texture_triangles,
            &coordinates,
        )
        .map_err(|e| PyValueError::new_err(e.to_string()))
    })?;
    if followed.shared > 0 {
        warn(
            py,
            &format!(
                "{} texture coordinates are shared by several moved vertices and cannot follow \
                 them all: they were left as they were",
                followed.shared
            ),
        )?;
    }
    Ok(arrays::pairs_array(py, followed.uvs))
}

/// `uvs`: a (k, 2) array of floats.
fn read_uvs(uvs: &Bound<'_, PyAny>) -> PyResult<Vec<[f64; 2]>> {
    let numpy = uvs.py().import("numpy")?;
    let array = numpy
        .call_method1("asarray", (uvs,))
        .map_err(|e| PyTypeError::new_err(format!("uvs must be a (k, 2) array of floats: {e}")))?;
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u") {
        return Err(PyTypeError::new_err(
            "uvs must be a (k, 2) array of floats (texture coordinates)",
        ));
    }
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 2 {
        return Err(PyValueError::new_err(format!(
            "uvs must have shape (k, 2), not {shape:?}"
        )));
    }
    let converted = array.call_method1("astype", ("float64",))?;
    let values = converted.extract::<PyReadonlyArray2<'_, f64>>()?;
    let values = values.as_array();
    let coordinates: Vec<[f64; 2]> = values.rows().into_iter().map(|r| [r[0], r[1]]).collect();
    if let Some(row) = coordinates
        .iter()
        .position(|c| !c.iter().all(|v| v.is_finite()))
    {
        return Err(PyValueError::new_err(format!(
            "uvs[{row}] is not finite: {:?}",
            coordinates[row]
        )));
    }
    Ok(coordinates)
}
