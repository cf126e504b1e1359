//! What the compute worker runs, on a desktop thread or in the page's Web Worker alike: the
//! hierarchy's job (denoise, then build) and one fairing of the document. Both take everything
//! they need when they are asked for and read nothing of the app, so the page's worker runs the
//! very code the desktop's threads run.

use std::sync::{Arc, Mutex, PoisonError};
use web_time::Instant;

use crate::app::jobs::Faired;
use crate::app::sharp_edges::SharpEdgeLines;
use crate::app::state::{DenoiseSummary, KeptHierarchy};
use fairmesh::fairing::{Mask, Method, MethodOptions};
use fairmesh::hierarchy::{self, HierarchyError, HierarchyOptions};
use fairmesh::multires::{self, denoise, MultiresOptions, MultiresWorkspace};
use fairmesh::{Topology, TriMesh};

/// Rings of vertices over which a painted mask always fades out at its edge.
const MASK_EDGE_RINGS: usize = 3;

/// Builds the hierarchy on `built_on` (the denoised mesh, or the document's own `mesh`), whose
/// triangles and `topology` are `mesh`'s: the hierarchy, whether its M0 has `mesh`'s triangles,
/// and its sharp edges as lines to draw.
fn build_on(
    built_on: &TriMesh,
    mesh: &TriMesh,
    topology: &Topology,
    options: &HierarchyOptions,
    progress: &mut dyn fairmesh::Progress,
) -> Result<(Arc<hierarchy::Hierarchy>, bool, Arc<SharpEdgeLines>), HierarchyError> {
    let built = hierarchy::build_hierarchy_with_topology(built_on, topology, options, progress)?;
    // Compared here, not on the UI thread (millions of triangles).
    let matches = built.base_mesh().triangles == mesh.triangles;
    let sharp_edges = if matches {
        SharpEdgeLines::new(mesh, built.crease_edges())
    } else {
        SharpEdgeLines::default()
    };
    Ok((Arc::new(built), matches, Arc::new(sharp_edges)))
}

/// Denoises `mesh` (as `denoise_options` ask) and builds the hierarchy on the result, keeping the
/// file's own sharp edges (`source`'s) when sharp edges are kept, as `fairmesh fair` keeps them.
/// Both stages report to `progress` (false cancels); `denoised` is told when the denoise is
/// done, with the denoised mesh (`fair`'s result, which is start level 0's result) when the
/// denoise ran.
pub(in crate::app) fn denoise_and_build(
    mesh: &TriMesh,
    topology: &Topology,
    mut options: HierarchyOptions,
    mut denoise_options: fairmesh::multires::DenoiseOptions,
    file_edges: &dyn Fn(&TriMesh) -> Vec<[u32; 2]>,
    progress: &mut dyn fairmesh::Progress,
    denoised_done: &mut dyn FnMut(Option<&TriMesh>),
) -> Result<KeptHierarchy, HierarchyError> {
    let started = Instant::now();
    let file_edges = if options.creases.is_some() {
        file_edges(mesh)
    } else {
        Vec::new()
    };
    if let Some(creases) = &mut options.creases {
        *creases = creases.clone().with_file_edges(file_edges.clone());
    }
    if let Some(creases) = &mut denoise_options.creases {
        *creases = creases.clone().with_file_edges(file_edges);
    }
    match denoise(mesh, topology, &denoise_options, progress) {
        Err(fairmesh::Cancelled) => Err(HierarchyError::Cancelled),
        Ok(denoised) => {
            let denoise = denoised.as_ref().map(|d| DenoiseSummary {
                report: d.report.clone(),
                time: started.elapsed(),
            });
            denoised_done(denoised.as_ref().map(|d| &d.mesh));
            let built_on = denoised.as_ref().map_or(mesh, |d| &d.mesh);
            build_on(built_on, mesh, topology, &options, progress).map(
                |(hierarchy, base_matches_original, sharp_edges)| KeptHierarchy {
                    hierarchy,
                    build_time: started.elapsed(),
                    base_matches_original,
                    sharp_edges,
                    denoise,
                },
            )
        }
    }
}

/// One fairing of the document, as the compute worker runs it: taken from the app when it is
/// asked for, so that the worker reads nothing of the app.
pub(in crate::app) struct FairJob {
    /// Built on the denoised mesh when `denoised`, else on the document's mesh.
    pub(in crate::app) hierarchy: Arc<hierarchy::Hierarchy>,
    /// The document's mesh: what a baseline smooths, what a mask fades the result into, what
    /// the result is measured against.
    pub(in crate::app) original: Arc<TriMesh>,
    /// The hierarchy's M0 is the denoised mesh ("Remove noise first"): start level 0 is that
    /// mesh as it is.
    pub(in crate::app) denoised: bool,
    /// The painted mask, if any (its edge fades out over [`MASK_EDGE_RINGS`] when the job runs).
    pub(in crate::app) mask: Option<Mask>,
    /// The document's connectivity.
    topology: Arc<Topology>,
    options: MultiresOptions,
    /// The baseline method's options; `None` for the paper's method.
    baseline: Option<MethodOptions>,
    method: Method,
}

impl FairJob {
    /// Fairing `original` from `level` of `hierarchy` with `settings`' options.
    pub(in crate::app) fn new(
        hierarchy: Arc<hierarchy::Hierarchy>,
        original: Arc<TriMesh>,
        denoised: bool,
        mask: Option<Mask>,
        topology: Arc<Topology>,
        settings: &crate::app::state::Settings,
        level: usize,
    ) -> Self {
        FairJob {
            hierarchy,
            original,
            denoised,
            mask,
            topology,
            options: settings.fairing.multires_options(level),
            baseline: settings.fairing.baseline_options(),
            method: settings.fairing.method,
        }
    }

    /// Fairs, reporting to `progress` (which returns false to cancel): the result, or `None`
    /// when cancelled.
    pub(in crate::app) fn run(
        self,
        workspace: &Mutex<MultiresWorkspace>,
        mut progress: impl FnMut(f32) -> bool + Send,
    ) -> Option<Faired> {
        let started = Instant::now();
        let FairJob {
            hierarchy,
            original,
            denoised,
            mask,
            topology,
            options,
            baseline,
            method,
        } = self;
        // A few rings of fade inside the painted region's edge, whatever the brush left: where
        // the brush stopped at a silhouette the mask drops from 1 to 0 at once, and the
        // result would show a step there.
        let mask = mask.map(|mask| mask.with_falloff(&topology, MASK_EDGE_RINGS));
        let mut folds_left = 0;
        let mut positions = match &baseline {
            // A baseline smooths the document's mesh itself; the level does not apply.
            Some(method) => {
                let mut mesh = original.as_ref().clone();
                fairmesh::fairing::fair(&mut mesh, &topology, method);
                progress(1.0).then_some(mesh.positions)?
            }
            // Start level 0 of a hierarchy built on the denoised mesh: that mesh.
            None if denoised && options.start_level == 0 => {
                progress(1.0).then(|| hierarchy.base_mesh().positions.clone())?
            }
            None => {
                let mut workspace = workspace.lock().unwrap_or_else(PoisonError::into_inner);
                let positions =
                    multires::fair_multires(&hierarchy, &options, &mut workspace, &mut progress)
                        .ok()?;
                folds_left = workspace.folds_left();
                positions
            }
        };
        // The mask fades the result into the document's mesh (not into the denoised one the
        // levels start from): unpainted vertices keep their positions exactly.
        if let Some(mask) = mask.filter(|mask| mask.check_fits(positions.len()).is_ok()) {
            mask.blend(&original.positions, &mut positions);
        }
        Some(Faired::measured(
            &original,
            positions,
            started.elapsed(),
            method,
            folds_left,
        ))
    }
}
