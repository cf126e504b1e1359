//! numpy arrays in and out: `vertices` (n, 3) of float32 or float64 read where they lie (a
//! contiguous array is read as one slice, any other through its strides), `faces` (m, 3) of any
//! integer type, checked and turned into the library's `u32` triangles, and results handed to
//! numpy without a copy.

use numpy::ndarray::{Array1, Array2, ArrayView2};
use numpy::{Element, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// The float type of a `vertices` array, which results keep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    F32,
    F64,
}

/// Positions read from a `vertices` array, in the library's f32, and the array's float type.
pub struct Vertices {
    pub positions: Vec<[f32; 3]>,
    pub precision: Precision,
}

/// Reads `vertices` (named `name` in errors): a float32 or float64 array of shape (n, 3), or
/// anything numpy turns into one (a list of triples); other dtypes are refused.
pub fn read_vertices(name: &str, object: &Bound<'_, PyAny>) -> PyResult<Vertices> {
    let array = as_numpy_array(name, object)?;
    check_shape(name, &array, "n")?;
    if let Ok(values) = array.extract::<PyReadonlyArray2<'_, f64>>() {
        let positions = positions_from(name, values.as_array())?;
        return Ok(Vertices {
            positions,
            precision: Precision::F64,
        });
    }
    if let Ok(values) = array.extract::<PyReadonlyArray2<'_, f32>>() {
        let positions = positions_from(name, values.as_array())?;
        return Ok(Vertices {
            positions,
            precision: Precision::F32,
        });
    }
    let kind = dtype_kind(&array)?;
    if kind == "f" {
        // float16 or long double: read through float64.
        let converted = array.call_method1("astype", ("float64",))?;
        let values = converted.extract::<PyReadonlyArray2<'_, f64>>()?;
        let positions = positions_from(name, values.as_array())?;
        return Ok(Vertices {
            positions,
            precision: Precision::F64,
        });
    }
    Err(PyTypeError::new_err(format!(
        "{name} must be an array of floats (float32 or float64), not of {}",
        dtype_name(&array)?
    )))
}

/// The positions of a (n, 3) array, each checked finite (the library's loaders refuse NaN and
/// infinity, and so does this).
fn positions_from<T: Copy + Into<f64>>(
    name: &str,
    view: ArrayView2<'_, T>,
) -> PyResult<Vec<[f32; 3]>> {
    let point = |x: T, y: T, z: T| [x.into() as f32, y.into() as f32, z.into() as f32];
    // One slice in row order (C order) only; a Fortran-order array is read by its strides.
    let positions: Vec<[f32; 3]> = match view.as_slice() {
        Some(flat) => flat
            .chunks_exact(3)
            .map(|c| point(c[0], c[1], c[2]))
            .collect(),
        None => view
            .rows()
            .into_iter()
            .map(|r| point(r[0], r[1], r[2]))
            .collect(),
    };
    if let Some(row) = positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(PyValueError::new_err(format!(
            "{name}[{row}] is not finite (or too large for float32): {:?}",
            view.row(row)
                .iter()
                .map(|&v| v.into())
                .collect::<Vec<f64>>()
        )));
    }
    Ok(positions)
}

/// Reads `faces` (named `name` in errors): an integer array of shape (m, 3) whose values index
/// `vertex_count` vertices.
pub fn read_faces(
    name: &str,
    object: &Bound<'_, PyAny>,
    vertex_count: usize,
) -> PyResult<Vec<[u32; 3]>> {
    let array = as_numpy_array(name, object)?;
    check_shape(name, &array, "m")?;
    macro_rules! try_integer {
        ($($t:ty),*) => {$(
            if let Ok(values) = array.extract::<PyReadonlyArray2<'_, $t>>() {
                return triangles_from(name, values.as_array(), vertex_count);
            }
        )*};
    }
    try_integer!(i64, i32, u32, u64, i16, u16, i8, u8);
    let kind = dtype_kind(&array)?;
    if kind == "i" || kind == "u" {
        // A platform's other integer names (longlong, ...): read through int64.
        let converted = array.call_method1("astype", ("int64",))?;
        let values = converted.extract::<PyReadonlyArray2<'_, i64>>()?;
        return triangles_from(name, values.as_array(), vertex_count);
    }
    Err(PyTypeError::new_err(format!(
        "{name} must be an array of integers (vertex indices), not of {}",
        dtype_name(&array)?
    )))
}

fn triangles_from<T: Copy + TryInto<i64> + Element>(
    name: &str,
    view: ArrayView2<'_, T>,
    vertex_count: usize,
) -> PyResult<Vec<[u32; 3]>> {
    let mut triangles = Vec::with_capacity(view.nrows());
    for (row, corners) in view.rows().into_iter().enumerate() {
        let mut triangle = [0u32; 3];
        for (slot, &value) in triangle.iter_mut().zip(corners.iter()) {
            let index = value.try_into().unwrap_or(i64::MAX);
            match u32::try_from(index) {
                Ok(v) if (v as usize) < vertex_count => *slot = v,
                _ => {
                    let shown = if index == i64::MAX {
                        "a value too large".to_string()
                    } else {
                        index.to_string()
                    };
                    return Err(PyValueError::new_err(format!(
                        "{name}[{row}] names vertex {shown}, but there are {vertex_count} \
                         vertices (indices 0 to {})",
                        vertex_count.saturating_sub(1)
                    )));
                }
            }
        }
        triangles.push(triangle);
    }
    Ok(triangles)
}

/// Reads a per-vertex array of `vertex_count` values or a list of vertex indices (`mask`).
pub enum VertexSelection {
    Weights(Vec<f32>),
    Indices(Vec<usize>),
}

/// `mask`: a float or bool array of one weight (0 to 1) per vertex, or an integer array of the
/// vertex indices to fair. An integer array that could be either (one 0 or 1 per vertex) is
/// refused, with how to write each: read as indices it would name at most two vertices.
pub fn read_selection(
    name: &str,
    object: &Bound<'_, PyAny>,
    vertex_count: usize,
) -> PyResult<VertexSelection> {
    let array = as_numpy_array(name, object)?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    if shape.len() != 1 {
        return Err(PyValueError::new_err(format!(
            "{name} must be one-dimensional (one weight per vertex, or vertex indices), not of \
             shape {shape:?}"
        )));
    }
    match dtype_kind(&array)?.as_str() {
        "b" | "f" => {
            let weights: Vec<f32> = array.call_method1("astype", ("float32",))?.extract()?;
            if weights.len() != vertex_count {
                return Err(PyValueError::new_err(format!(
                    "{name} has {} weights but there are {vertex_count} vertices",
                    weights.len()
                )));
            }
            Ok(VertexSelection::Weights(weights))
        }
        "i" | "u" => {
            let indices: Vec<i64> = array.call_method1("astype", ("int64",))?.extract()?;
            if indices.len() == vertex_count && indices.iter().all(|&i| i == 0 || i == 1) {
                return Err(PyValueError::new_err(format!(
                    "{name} is an integer array of {vertex_count} values, each 0 or 1, one per \
                     vertex: it could be weights or vertex indices. For one weight per vertex \
                     pass bools or floats ({name}.astype(bool)); for the vertices to fair pass \
                     their indices ({name}.nonzero()[0])"
                )));
            }
            let mut vertices = Vec::with_capacity(indices.len());
            for (i, &index) in indices.iter().enumerate() {
                match usize::try_from(index) {
                    Ok(v) if v < vertex_count => vertices.push(v),
                    _ => {
                        return Err(PyValueError::new_err(format!(
                            "{name}[{i}] names vertex {index}, but there are {vertex_count} \
                             vertices"
                        )))
                    }
                }
            }
            Ok(VertexSelection::Indices(vertices))
        }
        _ => Err(PyTypeError::new_err(format!(
            "{name} must be an array of weights (floats or bools) or of vertex indices \
             (integers), not of {}",
            dtype_name(&array)?
        ))),
    }
}

/// `object` as a numpy array: itself when it is one (no copy), else `numpy.asarray(object)`.
fn as_numpy_array<'py>(name: &str, object: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    if object.is_none() {
        return Err(PyTypeError::new_err(format!(
            "{name} must be an array, not None"
        )));
    }
    let py = object.py();
    let numpy = py.import("numpy")?;
    let ndarray = numpy.getattr("ndarray")?;
    if object.is_instance(&ndarray)? {
        return Ok(object.clone());
    }
    numpy.call_method1("asarray", (object,)).map_err(|error| {
        PyTypeError::new_err(format!(
            "{name} must be an array (numpy.asarray could not read it: {error})"
        ))
    })
}

fn check_shape(name: &str, array: &Bound<'_, PyAny>, rows: &str) -> PyResult<()> {
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape ({rows}, 3), not {}",
            shape_text(&shape)
        )));
    }
    Ok(())
}

fn shape_text(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

fn dtype_kind(array: &Bound<'_, PyAny>) -> PyResult<String> {
    array.getattr("dtype")?.getattr("kind")?.extract()
}

fn dtype_name(array: &Bound<'_, PyAny>) -> PyResult<String> {
    array.getattr("dtype")?.getattr("name")?.extract()
}

/// Positions as a new (n, 3) array of `precision`: the result, and the only copy.
pub fn positions_array<'py>(
    py: Python<'py>,
    positions: Vec<[f32; 3]>,
    precision: Precision,
) -> Bound<'py, PyAny> {
    let n = positions.len();
    match precision {
        Precision::F64 => {
            let flat: Vec<f64> = positions.iter().flat_map(|p| p.map(f64::from)).collect();
            owned_rows(py, flat, n)
        }
        Precision::F32 => {
            let flat: Vec<f32> = positions.into_iter().flatten().collect();
            owned_rows(py, flat, n)
        }
    }
}

/// Triangles as a new (m, 3) int64 array.
pub fn triangles_array<'py>(py: Python<'py>, triangles: &[[u32; 3]]) -> Bound<'py, PyAny> {
    let flat: Vec<i64> = triangles.iter().flat_map(|t| t.map(i64::from)).collect();
    owned_rows(py, flat, triangles.len())
}

/// Pairs (texture coordinates) as a new (k, 2) float64 array.
pub fn pairs_array(py: Python<'_>, pairs: Vec<[f64; 2]>) -> Bound<'_, PyAny> {
    let rows = pairs.len();
    let flat: Vec<f64> = pairs.into_iter().flatten().collect();
    let array = Array2::from_shape_vec((rows, 2), flat).expect("two values a row");
    PyArray2::from_owned_array(py, array).into_any()
}

/// A (rows, 3) array that takes over `flat` (no copy).
fn owned_rows<T: Element>(py: Python<'_>, flat: Vec<T>, rows: usize) -> Bound<'_, PyAny> {
    let array = Array2::from_shape_vec((rows, 3), flat).expect("three values a row");
    PyArray2::from_owned_array(py, array).into_any()
}

/// A one-dimensional array that takes over `values`.
pub fn vector<T: Element>(py: Python<'_>, values: Vec<T>) -> Bound<'_, PyAny> {
    PyArray1::from_owned_array(py, Array1::from(values)).into_any()
}
