//! `fairmesh.noise` and `fairmesh.compare`: the command line's `noise` and `compare` on arrays.

use crate::arrays;
use crate::mesh::from_arrays;
use crate::options;
use crate::run::run_detached;
use fairmesh::metrics;
use fairmesh::noise::{add_noise, NoiseMode, NoiseOptions};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

#[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/noise.txt"))]
#[pyfunction]
#[pyo3(signature = (vertices, faces, *, sigma=0.3, seed=1, mode="normal"), text_signature = None)]
pub fn noise<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    sigma: f64,
    seed: u64,
    mode: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let sigma = options::at_least("sigma", sigma, 0.0)?;
    let mode = match options::choice("mode", mode, &["normal", "direction", "iso"])? {
        0 => NoiseMode::Normal,
        1 => NoiseMode::Direction,
        _ => NoiseMode::Isotropic,
    };
    let (mut mesh, _, precision) = from_arrays(vertices, faces)?;
    let options = NoiseOptions::default()
        .with_sigma(sigma)
        .with_seed(seed)
        .with_mode(mode);
    run_detached(py, None, None, |_| Some(add_noise(&mut mesh, &options)))?;
    Ok(arrays::positions_array(py, mesh.positions, precision))
}

#[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/compare.txt"))]
#[pyfunction]
#[pyo3(signature = (reference_vertices, reference_faces, vertices, faces=None), text_signature = None)]
pub fn compare<'py>(
    py: Python<'py>,
    reference_vertices: &Bound<'py, PyAny>,
    reference_faces: &Bound<'py, PyAny>,
    vertices: &Bound<'py, PyAny>,
    faces: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (reference, ..) = from_arrays(reference_vertices, reference_faces)?;
    let faces = faces.filter(|f| !f.is_none());
    if faces.is_none() {
        // The reference's faces then index `vertices`: say so before they name a vertex beyond.
        if let Ok(rows) = vertices.len() {
            if rows != reference.vertex_count() {
                return Err(PyValueError::new_err(format!(
                    "vertices has {rows} rows but the reference has {} vertices: without \
                     faces, vertices must be the reference's moved; pass faces= for a mesh of \
                     other connectivity",
                    reference.vertex_count()
                )));
            }
        }
    }
    let (other, ..) = from_arrays(vertices, faces.unwrap_or(reference_faces))?;
    let (result, sharpened, edge) = run_detached(py, None, None, |_| {
        Some((
            metrics::compare(&reference, &other),
            metrics::sharpened_edges(&reference, &other),
            metrics::mean_edge_length(&reference),
        ))
    })?;
    let dict = PyDict::new(py);
    dict.set_item("mean_surface_distance", result.mean_surface_distance)?;
    dict.set_item("hausdorff", result.hausdorff)?;
    dict.set_item("volume_change_percent", result.volume_change_percent)?;
    let distance = |d: &metrics::SurfaceDistance| -> PyResult<Bound<'py, PyDict>> {
        let pair = PyDict::new(py);
        pair.set_item("mean", d.mean)?;
        pair.set_item("max", d.max)?;
        Ok(pair)
    };
    dict.set_item("reference_to_other", distance(&result.reference_to_other)?)?;
    dict.set_item("other_to_reference", distance(&result.other_to_reference)?)?;
    dict.set_item("same_connectivity", result.same_connectivity.is_some())?;
    dict.set_item("reference_mean_edge_length", edge)?;
    if let Some(v) = result.same_connectivity {
        dict.set_item("rms", v.rms)?;
        dict.set_item("max_distance", v.max_distance)?;
        dict.set_item("normal_error_deg", v.normal_error_deg)?;
        dict.set_item("barycenter_drift", v.barycenter_drift)?;
    }
    if let Some(count) = sharpened {
        dict.set_item("sharpened_edges", count)?;
    }
    Ok(dict)
}
