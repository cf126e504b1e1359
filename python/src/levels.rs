//! `fairmesh.hierarchy`: the decimation hierarchy (paper section 4.1) as a [`Hierarchy`] object
//! that gives its levels as arrays and runs multiresolution fairing (4.2) from any start level
//! again and again, keeping each level's set-up between runs as the editor does.

use crate::arrays::{self, Precision};
use crate::mesh::{from_arrays, Mesh};
use crate::options;
use crate::run::run_detached;
use fairmesh::fairing::{creases::DEFAULT_CREASE_ANGLE, CreaseOptions, FairReport};
use fairmesh::hierarchy::{build_hierarchy_with_topology, HierarchyError, HierarchyOptions};
use fairmesh::multires::{
    fair_multires, folds_left_warning, Denoise, DenoiseOptions, MultiresOptions, MultiresVariant,
    MultiresWorkspace,
};
use fairmesh::Topology;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};
use std::sync::Mutex;

#[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Hierarchy.txt"))]
#[pyclass(name = "Hierarchy", module = "fairmesh", frozen)]
pub struct Hierarchy {
    hierarchy: fairmesh::hierarchy::Hierarchy,
    /// M0's topology, for a mask's falloff.
    topology: Topology,
    workspace: Mutex<MultiresWorkspace>,
    precision: Precision,
    /// With `denoise`: what the denoise before the build did, and the input's own positions
    /// (the hierarchy's level 0 is the denoised mesh; a mask fades results into the input).
    denoised: Option<(FairReport, Vec<[f32; 3]>)>,
}

#[pymethods]
impl Hierarchy {
    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Hierarchy.level_count.txt"))]
    #[getter]
    fn level_count(&self) -> usize {
        self.hierarchy.level_count()
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Hierarchy.coarsest_level.txt"))]
    #[getter]
    fn coarsest_level(&self) -> usize {
        self.hierarchy.coarsest_level()
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Hierarchy.denoise.txt"))]
    #[getter]
    fn denoise<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some((report, _)) = &self.denoised else {
            return Ok(None);
        };
        let dict = PyDict::new(py);
        dict.set_item("rounds_run", report.rounds_run)?;
        dict.set_item("noise_estimate", report.noise_estimate)?;
        dict.set_item("crease_edges", report.crease_edges)?;
        Ok(Some(dict))
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Hierarchy.level_sizes.txt"))]
    #[getter]
    fn level_sizes(&self) -> Vec<(usize, usize)> {
        (0..self.hierarchy.level_count())
            .map(|level| {
                let info = self.hierarchy.level_info(level);
                (info.vertices, info.faces)
            })
            .collect()
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Hierarchy.level.txt"))]
    #[pyo3(text_signature = None)]
    fn level<'py>(
        &self,
        py: Python<'py>,
        level: i64,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let level = options::count("level", level)?;
        if level > self.hierarchy.coarsest_level() {
            return Err(PyValueError::new_err(format!(
                "level must be from 0 to {} (the coarsest), not {level}",
                self.hierarchy.coarsest_level()
            )));
        }
        let (mesh, origins, _) = self.hierarchy.level_for_export(level);
        let original: Vec<i64> = origins.into_iter().map(i64::from).collect();
        Ok((
            arrays::positions_array(py, mesh.positions, self.precision),
            arrays::triangles_array(py, &mesh.triangles),
            arrays::vector(py, original),
        ))
    }

    #[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/Hierarchy.multires.txt"))]
    #[pyo3(signature = (
        start_level, *, iterations=5, rounds=1, boundary="curve", fair_finest=true,
        variant="improved", mask=None, mask_falloff=0, progress=None, threads=None
    ), text_signature = None)]
    #[allow(clippy::too_many_arguments)]
    fn multires<'py>(
        &self,
        py: Python<'py>,
        start_level: i64,
        iterations: i64,
        rounds: i64,
        boundary: &str,
        fair_finest: bool,
        variant: &str,
        mask: Option<&Bound<'py, PyAny>>,
        mask_falloff: i64,
        progress: Option<&Bound<'py, PyAny>>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let threads = options::threads(threads)?;
        let variant = match options::choice("variant", variant, &["improved", "paper"])? {
            0 => MultiresVariant::Improved,
            _ => MultiresVariant::Paper,
        };
        let mask_falloff = options::count("mask_falloff", mask_falloff)?;
        let mask = crate::fair::read_mask(
            mask,
            mask_falloff,
            self.hierarchy.base_mesh(),
            &self.topology,
        )?;
        // After a denoise the mask fades the result into the input itself, below.
        let (mask, fade_into) = match &self.denoised {
            Some((_, input)) => (None, mask.map(|mask| (mask, input))),
            None => (mask, None),
        };
        let start_level = options::count("start_level", start_level)?;
        let options = MultiresOptions::default()
            .with_start_level(start_level)
            .with_iterations(options::count("iterations", iterations)?)
            .with_rounds(options::count("rounds", rounds)?)
            .with_boundary(options::boundary(boundary)?)
            .with_fair_finest(fair_finest)
            .with_variant(variant)
            .with_mask(mask);
        let hierarchy = &self.hierarchy;
        let workspace = &self.workspace;
        let denoised_level_0 = self.denoised.is_some() && start_level == 0;
        let (mut positions, folds_left) = run_detached(py, progress, threads, |hook| {
            if denoised_level_0 {
                // Level 0 is the denoised mesh itself, `fair`'s result.
                return Some((hierarchy.base_mesh().positions.clone(), 0));
            }
            // A run cancelled half way leaves the workspace fit for the next one.
            let mut workspace = workspace
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            let positions = fair_multires(hierarchy, &options, &mut workspace, hook).ok()?;
            Some((positions, workspace.folds_left()))
        })?;
        if folds_left > 0 {
            let start = start_level.min(hierarchy.coarsest_level());
            crate::mesh::warn(py, &folds_left_warning(start, folds_left))?;
        }
        if let Some((mask, input)) = fade_into {
            mask.blend(input, &mut positions);
        }
        Ok(arrays::positions_array(py, positions, self.precision))
    }

    fn __repr__(&self) -> String {
        let base = self.hierarchy.base_mesh();
        format!(
            "<fairmesh.Hierarchy of {} vertices, {} faces: {} levels, the coarsest {} vertices>",
            base.vertex_count(),
            base.face_count(),
            self.hierarchy.level_count(),
            self.hierarchy
                .level_info(self.hierarchy.coarsest_level())
                .vertices
        )
    }
}

#[doc = include_str!(concat!(env!("OUT_DIR"), "/doc/hierarchy.txt"))]
#[pyfunction]
#[pyo3(signature = (
    vertices, faces=None, *, alpha=1.0, beta=0.01, min_vertices=100, max_levels=64,
    keep_boundary=false, keep_orientation=true, keep_creases=false, crease_angle=None,
    hard_edges=None, denoise=None, progress=None, threads=None
), text_signature = None)]
#[allow(clippy::too_many_arguments)]
pub fn hierarchy(
    py: Python<'_>,
    vertices: &Bound<'_, PyAny>,
    faces: Option<&Bound<'_, PyAny>>,
    alpha: f64,
    beta: f64,
    min_vertices: i64,
    max_levels: i64,
    keep_boundary: bool,
    keep_orientation: bool,
    keep_creases: bool,
    crease_angle: Option<f64>,
    hard_edges: Option<&Bound<'_, PyAny>>,
    denoise: Option<&Bound<'_, PyAny>>,
    progress: Option<&Bound<'_, PyAny>>,
    threads: Option<i64>,
) -> PyResult<Hierarchy> {
    let threads = options::threads(threads)?;
    let denoise_choice = denoise_choice(denoise)?;
    let crease_angle = crease_angle
        .map(|a| options::number_in("crease_angle", a, 0.0, 180.0))
        .transpose()?;
    let hard_edges = hard_edges.filter(|e| !e.is_none());
    let mut options = HierarchyOptions::default()
        .with_alpha(options::finite("alpha", alpha)?)
        .with_beta(options::finite("beta", beta)?)
        .with_min_vertices(options::count("min_vertices", min_vertices)?)
        .with_max_levels(options::count("max_levels", max_levels)?)
        .with_keep_boundary(keep_boundary)
        .with_keep_orientation(keep_orientation)
        .with_creases(
            (keep_creases || crease_angle.is_some() || hard_edges.is_some()).then(|| {
                CreaseOptions::default()
                    .with_angle_degrees(crease_angle.unwrap_or(DEFAULT_CREASE_ANGLE))
            }),
        );
    let (mesh, topology, precision, file_edges) = match vertices.cast::<Mesh>() {
        Ok(loaded) => {
            if faces.is_some_and(|f| !f.is_none()) {
                return Err(PyTypeError::new_err(
                    "faces must be left out when vertices is a fairmesh.Mesh (its faces are used)",
                ));
            }
            let loaded = loaded.borrow();
            let edges = match hard_edges {
                Some(edges) => crate::fair::read_edges(edges, loaded.loaded.mesh.vertex_count())?,
                None => loaded.file_hard_edges(),
            };
            let state = &loaded.loaded;
            (
                state.mesh.clone(),
                state.topology.clone(),
                Precision::F64,
                edges,
            )
        }
        Err(_) => {
            let Some(faces) = faces.filter(|f| !f.is_none()) else {
                return Err(PyTypeError::new_err(
                    "faces is needed (an (m, 3) integer array) unless vertices is a fairmesh.Mesh",
                ));
            };
            let (mesh, topology, precision) = from_arrays(vertices, faces)?;
            let edges = match hard_edges {
                Some(edges) => crate::fair::read_edges(edges, mesh.vertex_count())?,
                None => Vec::new(),
            };
            (mesh, topology, precision, edges)
        }
    };
    if let Some(creases) = &mut options.creases {
        *creases = creases.clone().with_file_edges(file_edges);
    }
    // The denoise keeps the creases the hierarchy keeps, as `fairmesh multires` does.
    let denoise_options = denoise_choice.map(|choice| DenoiseOptions {
        denoise: choice,
        creases: options.creases.clone(),
        boundary: fairmesh::fairing::BoundaryMode::Curve,
    });
    let (built, report) = run_detached(py, progress, threads, |hook| {
        let denoised = match &denoise_options {
            Some(denoise_options) => {
                fairmesh::multires::denoise(&mesh, &topology, denoise_options, hook).ok()?
            }
            None => None,
        };
        let built_on = denoised.as_ref().map_or(&mesh, |d| &d.mesh);
        match build_hierarchy_with_topology(built_on, &topology, &options, hook) {
            Err(HierarchyError::Cancelled) => None,
            other => Some((other, denoised.map(|d| d.report))),
        }
    })?;
    let built = built.map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(Hierarchy {
        hierarchy: built,
        topology,
        workspace: Mutex::new(MultiresWorkspace::new()),
        precision,
        denoised: report.map(|report| (report, mesh.positions)),
    })
}

/// `denoise=`: None or "off" (none), "auto" (the automatic strength), or a number of rounds.
fn denoise_choice(value: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Denoise>> {
    const EXPECTED: &str = "denoise must be None, \"auto\", \"off\" or a number of rounds";
    let Some(value) = value.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    if let Ok(text) = value.extract::<String>() {
        return match text.as_str() {
            "auto" => Ok(Some(Denoise::Automatic)),
            "off" => Ok(None),
            _ => Err(PyValueError::new_err(format!("{EXPECTED}, not {text:?}"))),
        };
    }
    if value.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(EXPECTED));
    }
    let rounds: i64 = value
        .extract()
        .map_err(|_| PyTypeError::new_err(EXPECTED))?;
    Ok(Some(Denoise::Rounds(options::count("denoise", rounds)?)))
}
