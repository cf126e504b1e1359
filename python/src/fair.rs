//! `fairmesh.fair`: the command line's `fair` on arrays (or on a loaded [`Mesh`]), with its
//! options as keyword arguments under the same names and defaults, and its `--json` report as a
//! dict with the same fields.

use crate::arrays::{self, Precision, VertexSelection};
use crate::mesh::{from_arrays, Mesh};
use crate::options;
use crate::run::run_detached;
use fairmesh::fairing::{
    self, creases::DEFAULT_CREASE_ANGLE, FairOutcome, Mask, Method, MethodChoices, MethodOptions,
    ReportContext,
};
use fairmesh::{metrics, Topology, TriMesh};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The keyword arguments of `fair`, as the command line's `fair` names them: the library's
/// [`MethodChoices`], which `fairmesh fair` maps its options to as well.
pub type FairArgs = MethodChoices;

/// What one fairing did, for the report: the library's measures of the run, and the result
/// measured against the input when asked for.
struct Outcome {
    faired: FairOutcome,
    measures: Option<metrics::Comparison>,
}

/// Fairs `mesh` (within `mask`) as `fairmesh fair` does ([`fairing::fair_measured`]), timing
/// the fairing alone; `None` when `progress` cancelled it.
fn fair_mesh(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &MethodOptions,
    mask: Option<&Mask>,
    textured: bool,
    measure: bool,
    progress: &mut dyn fairmesh::Progress,
) -> Option<Outcome> {
    let input = measure.then(|| mesh.clone());
    let faired = fairing::fair_measured(mesh, topology, options, mask, textured, progress).ok()?;
    let measures = input.map(|input| metrics::compare(&input, mesh));
    Some(Outcome { faired, measures })
}

/// The mask of `mask` (weights or vertex indices) on `mesh`, faded over `falloff` rings.
pub(crate) fn read_mask(
    mask: Option<&Bound<'_, PyAny>>,
    falloff: usize,
    mesh: &TriMesh,
    topology: &Topology,
) -> PyResult<Option<Mask>> {
    let Some(mask) = mask.filter(|m| !m.is_none()) else {
        if falloff > 0 {
            return Err(PyValueError::new_err("mask_falloff needs a mask"));
        }
        return Ok(None);
    };
    let n = mesh.vertex_count();
    let mask = match arrays::read_selection("mask", mask, n)? {
        VertexSelection::Weights(weights) => {
            Mask::new(weights).map_err(|e| PyValueError::new_err(format!("mask: {e}")))?
        }
        VertexSelection::Indices(vertices) => Mask::from_vertices(n, vertices),
    };
    if mask.painted_count() == 0 {
        return Err(PyValueError::new_err(
            "mask lets no vertex move, so nothing would be faired",
        ));
    }
    Ok(Some(if falloff > 0 {
        mask.with_falloff(topology, falloff)
    } else {
        mask
    }))
}

/// The report: `fairmesh fair --json`'s, from the library's one report
/// ([`FairOutcome::to_json`]), as a dict (`input`/`output`: the loaded file's path and None;
/// `texture_follows`: None, as it depends on where the result is saved).
fn report_dict<'py>(
    py: Python<'py>,
    input: Option<String>,
    mesh: &TriMesh,
    topology: &Topology,
    options: &MethodOptions,
    mask: Option<&Mask>,
    outcome: &Outcome,
) -> PyResult<Bound<'py, PyDict>> {
    let context = ReportContext {
        input: input.as_deref(),
        closed: topology.is_closed(),
        mask,
        measures: outcome.measures.as_ref(),
        ..ReportContext::default()
    };
    let json = outcome.faired.to_json(options, mesh, &context);
    Ok(json_to_python(py, &json)?.cast_into::<PyDict>()?)
}

/// A JSON value as Python's `json.loads` would give it (objects keep their keys' order).
fn json_to_python<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match (n.as_u64(), n.as_i64()) {
            (Some(u), _) => u.into_pyobject(py)?.into_any(),
            (None, Some(i)) => i.into_pyobject(py)?.into_any(),
            _ => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(text) => text.into_pyobject(py)?.into_any(),
        Value::Array(items) => {
            let list = pyo3::types::PyList::empty(py);
            for item in items {
                list.append(json_to_python(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (key, item) in map {
                dict.set_item(key, json_to_python(py, item)?)?;
            }
            dict.into_any()
        }
    })
}

#[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/fair.txt"))]
#[pyfunction]
#[pyo3(signature = (
    vertices, faces=None, *, method="constrained", iterations=10, rounds=None,
    crease_angle=DEFAULT_CREASE_ANGLE, no_creases=false, tangential=None,
    no_volume_correction=false, tolerance=None, boundary="curve", variant="improved",
    lambda_=None, mu=None, alpha=None, beta=None, mask=None, mask_falloff=0, hard_edges=None,
    measure=false, progress=None, threads=None
), text_signature = None)]
#[allow(clippy::too_many_arguments)]
pub fn fair<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: Option<&Bound<'py, PyAny>>,
    method: &str,
    iterations: i64,
    rounds: Option<i64>,
    crease_angle: f64,
    no_creases: bool,
    tangential: Option<f64>,
    no_volume_correction: bool,
    tolerance: Option<f64>,
    boundary: &str,
    variant: &str,
    lambda_: Option<f64>,
    mu: Option<f64>,
    alpha: Option<f64>,
    beta: Option<f64>,
    mask: Option<&Bound<'py, PyAny>>,
    mask_falloff: i64,
    hard_edges: Option<&Bound<'py, PyAny>>,
    measure: bool,
    progress: Option<&Bound<'py, PyAny>>,
    threads: Option<i64>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let threads = options::threads(threads)?;
    let method = match options::choice(
        "method",
        method,
        &["constrained", "laplacian", "taubin", "hc"],
    )? {
        0 => Method::Constrained,
        1 => Method::Laplacian,
        2 => Method::Taubin,
        _ => Method::Hc,
    };
    let args = FairArgs {
        method,
        iterations: options::count("iterations", iterations)?,
        rounds: rounds.map(|r| options::count("rounds", r)).transpose()?,
        crease_angle: options::number_in("crease_angle", crease_angle, 0.0, 180.0)?,
        no_creases,
        tangential: tangential
            .map(|t| options::number_in("tangential", t, 0.0, 1.0))
            .transpose()?,
        no_volume_correction,
        tolerance: tolerance
            .map(|t| options::at_least("tolerance", t, 0.0))
            .transpose()?,
        boundary: options::boundary(boundary)?,
        paper_variant: options::choice_or_old_name(
            "variant",
            variant,
            &["improved", "paper"],
            &[("normal-projected", 0), ("projected", 0)],
        )? == 1,
        lambda: lambda_.map(|v| options::finite("lambda_", v)).transpose()?,
        mu: mu.map(|v| options::finite("mu", v)).transpose()?,
        alpha: alpha
            .map(|v| options::number_in("alpha", v, 0.0, 1.0))
            .transpose()?,
        beta: beta
            .map(|v| options::number_in("beta", v, 0.0, 1.0))
            .transpose()?,
    };
    let mask_falloff = options::count("mask_falloff", mask_falloff)?;
    if let Ok(loaded) = vertices.cast::<Mesh>() {
        if faces.is_some_and(|f| !f.is_none()) {
            return Err(PyTypeError::new_err(
                "faces must be left out when vertices is a fairmesh.Mesh (its faces are used)",
            ));
        }
        let mut loaded = loaded.borrow_mut();
        let file_edges = match hard_edges {
            Some(edges) if !edges.is_none() => {
                read_edges(edges, loaded.loaded.mesh.vertex_count())?
            }
            _ => loaded.file_hard_edges(),
        };
        let input = Some(loaded.path().display().to_string());
        let textured = loaded.loaded.source.has_texture_coordinates();
        let state = &mut loaded.loaded;
        let mask = read_mask(mask, mask_falloff, &state.mesh, &state.topology)?;
        let edge = metrics::mean_edge_length(&state.mesh);
        let options = args.options(edge, || file_edges);
        // The loaded mesh is faired in place on a copy of its positions, which are put back.
        let mut positions = state.mesh.positions.clone();
        let (mesh, topology) = (&mut state.mesh, &state.topology);
        let outcome = run_detached(py, progress, threads, |hook| {
            std::mem::swap(&mut mesh.positions, &mut positions);
            let outcome = fair_mesh(
                mesh,
                topology,
                &options,
                mask.as_ref(),
                textured,
                measure,
                hook,
            );
            std::mem::swap(&mut mesh.positions, &mut positions);
            outcome
        })?;
        let report = report_dict(
            py,
            input,
            &state.mesh,
            &state.topology,
            &options,
            mask.as_ref(),
            &outcome,
        )?;
        return Ok((
            arrays::positions_array(py, positions, Precision::F64),
            report,
        ));
    }
    let Some(faces) = faces.filter(|f| !f.is_none()) else {
        return Err(PyTypeError::new_err(
            "faces is needed (an (m, 3) integer array) unless vertices is a fairmesh.Mesh",
        ));
    };
    let (mut mesh, topology, precision) = from_arrays(vertices, faces)?;
    let file_edges = match hard_edges {
        Some(edges) if !edges.is_none() => read_edges(edges, mesh.vertex_count())?,
        _ => Vec::new(),
    };
    let mask = read_mask(mask, mask_falloff, &mesh, &topology)?;
    let options = args.options(metrics::mean_edge_length(&mesh), || file_edges);
    let outcome = run_detached(py, progress, threads, |hook| {
        fair_mesh(
            &mut mesh,
            &topology,
            &options,
            mask.as_ref(),
            false,
            measure,
            hook,
        )
    })?;
    let report = report_dict(
        py,
        None,
        &mesh,
        &topology,
        &options,
        mask.as_ref(),
        &outcome,
    )?;
    Ok((
        arrays::positions_array(py, mesh.positions, precision),
        report,
    ))
}

/// `hard_edges`: (k, 2) vertex pairs.
pub(crate) fn read_edges(edges: &Bound<'_, PyAny>, vertex_count: usize) -> PyResult<Vec<[u32; 2]>> {
    let pairs: Vec<[i64; 2]> = edges.extract().map_err(|_| {
        PyTypeError::new_err("hard_edges must be a (k, 2) array of vertex index pairs")
    })?;
    pairs
        .iter()
        .enumerate()
        .map(|(i, &[a, b])| match (u32::try_from(a), u32::try_from(b)) {
            (Ok(a), Ok(b)) if (a as usize) < vertex_count && (b as usize) < vertex_count => {
                Ok([a.min(b), a.max(b)])
            }
            _ => Err(PyValueError::new_err(format!(
                "hard_edges[{i}] = [{a}, {b}] names a vertex beyond the {vertex_count} vertices"
            ))),
        })
        .collect()
}
