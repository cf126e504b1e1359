//! Building the decimation hierarchy (on the compute worker) and setting up its levels: launch
//! and result.

use std::sync::atomic::Ordering;
use std::sync::{Arc, PoisonError};

use crate::app::compute::denoise_and_build;
use crate::app::generation::GenerationId;
use crate::app::jobs::{Faired, JobKind, JobResult, JobTicket};
use crate::app::state::{HierarchyState, KeptHierarchy, ViewMode};
use crate::app::App;
use fairmesh::hierarchy::{self, HierarchyError};
use fairmesh::TriMesh;
use web_time::Instant;

/// Start level 0's result sent when the denoise ends ([`App::start_hierarchy`]): the view it is
/// for, the method it is reported as, and its job ticket.
struct EarlyResult {
    view: GenerationId,
    method: fairmesh::fairing::Method,
    ticket: JobTicket,
}

impl App {
    /// Denoises the document's mesh ([`fairmesh::multires::denoise`], as the settings ask) and
    /// builds the hierarchy on the result, on the compute worker; both report to the
    /// hierarchy's progress (the denoise first, flagged in `hierarchy_denoising`) and are
    /// cancelled together.
    pub(in crate::app) fn start_hierarchy(&mut self) {
        self.work.hierarchy_built_with = Some(self.settings.hierarchy_key());
        let Some(document) = &mut self.document else {
            return;
        };
        let generation = self.work.hierarchy_generation.bump();
        document.hierarchy = HierarchyState::Building;
        self.work.hierarchy_progress.set(0.0);
        let mesh = document.original.clone();
        let topology = document.topology.clone();
        let options = self.settings.hierarchy.options();
        let denoise_options = self.settings.denoise_options();
        let source = document.source.clone();
        let document_generation = document.generation;
        let hierarchy_generation = self.work.hierarchy_generation.clone();
        let progress_out = self.work.hierarchy_progress.clone();
        let denoising = self.work.hierarchy_denoising.clone();
        denoising.store(denoise_options.fair_options().is_some(), Ordering::Relaxed);
        // Start level 0's result is the denoised mesh as it is (`fair`'s result): when the
        // document opens at level 0, or is there, it is shown as soon as the denoise ends, not
        // when the levels are built too (a 1.2M-face scan: 1.1 s later). Not with a painted
        // mask, a baseline method, an applied result or the level view, whose pictures are not
        // that mesh.
        let opens_at = if document.pick_start_level {
            self.settings
                .files
                .start_level_for(&document.path, usize::MAX)
        } else {
            document.level
        };
        let early = (opens_at == 0
            && denoise_options.fair_options().is_some()
            && !document.applied
            && document.mask.is_none()
            && self.settings.fairing.baseline_options().is_none()
            && matches!(
                self.settings.view.view_mode,
                ViewMode::Faired | ViewMode::Original
            ))
        .then(|| EarlyResult {
            view: self.work.view_generation.bump(),
            method: self.settings.fairing.method,
            ticket: self.workers.jobs.start(),
        });
        let (tx, ctx, ticket) = (
            self.workers.results_tx.clone(),
            self.ctx.clone(),
            self.workers.jobs.start(),
        );
        // In a page the job runs in the engine's worker, so that the page goes on answering.
        #[cfg(target_arch = "wasm32")]
        let (tx, ctx, ticket) = {
            use crate::app::web::engine::{post_hierarchy, HierarchyPost, Sending};
            let file_edges = if options.creases.is_some() {
                source.hard_edges(&mesh)
            } else {
                Vec::new()
            };
            let post = HierarchyPost {
                settings: self.settings.clone(),
                mesh: mesh.clone(),
                file_edges,
                document: document_generation,
                document_generation: self.work.document_generation.clone(),
                generation,
                hierarchy_generation: hierarchy_generation.clone(),
                progress: progress_out.clone(),
                denoising: denoising.clone(),
            };
            match post_hierarchy(post, Sending { tx, ctx, ticket }) {
                Ok(()) => return,
                Err(back) => (back.tx, back.ctx, back.ticket),
            }
        };
        self.workers.compute.submit(JobKind::Hierarchy, move || {
            if !hierarchy_generation.is_current(generation) {
                return;
            }
            let started = Instant::now();
            let mut progress = |fraction: f32| {
                progress_out.set(fraction);
                hierarchy_generation.is_current(generation)
            };
            let mut early = early;
            let mut denoised = |denoised: Option<&TriMesh>| {
                denoising.store(false, Ordering::Relaxed);
                progress_out.set(0.0);
                let Some((early, denoised)) = early.take().zip(denoised) else {
                    return;
                };
                if !hierarchy_generation.is_current(generation) {
                    return;
                }
                let result = Faired::measured(
                    &mesh,
                    denoised.positions.clone(),
                    started.elapsed(),
                    early.method,
                    0,
                );
                let message = JobResult::Faired {
                    document: document_generation,
                    view: early.view,
                    level: 0,
                    result: Some(result),
                };
                Self::send_result(&tx, &ctx, message, early.ticket);
            };
            let result = denoise_and_build(
                &mesh,
                &topology,
                options,
                denoise_options,
                &|m: &TriMesh| source.hard_edges(m),
                &mut progress,
                &mut denoised,
            );
            let message = JobResult::Hierarchy {
                document: document_generation,
                hierarchy: generation,
                result,
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// Sets up every level of a new hierarchy (connectivity and fairing operator) on the compute
    /// worker, after the view's first fairing (already queued), so that moving the level slider
    /// later never waits for a level's set-up (bunny00: about 0.2 s for all 20 levels; a
    /// 1.2M-face mesh: about 2 s). One idle job per level, finest first: a fairing the user asks
    /// for meanwhile runs before the next level's set-up, so it waits for one level at most.
    pub(in crate::app) fn prepare_levels(
        &mut self,
        hierarchy: Arc<hierarchy::Hierarchy>,
        document: GenerationId,
    ) {
        // In a page the levels are set up in the engine's worker, which fairs them.
        #[cfg(target_arch = "wasm32")]
        if let Some(current) = self.document.as_ref().filter(|d| d.generation == document) {
            use crate::app::web::engine::{post_prepare, Sending};
            let denoised = matches!(
                current.hierarchy,
                HierarchyState::Ready {
                    denoise: Some(_),
                    ..
                }
            );
            let sending = Sending {
                tx: self.workers.results_tx.clone(),
                ctx: self.ctx.clone(),
                ticket: self.workers.jobs.start(),
            };
            let state = (hierarchy.clone(), current.original.clone(), denoised);
            let generation = self.work.document_generation.clone();
            if post_prepare(&self.settings, state, document, generation, sending).is_ok() {
                return;
            }
        }
        for level in 1..hierarchy.level_count() {
            let options = self.settings.fairing.multires_options(level);
            let document_generation = self.work.document_generation.clone();
            let workspace = self.work.workspace.clone();
            let hierarchy = hierarchy.clone();
            let ticket = self.workers.jobs.start();
            self.workers
                .compute
                .submit_idle(JobKind::LevelSetUp, move || {
                    let _ticket = ticket;
                    if !document_generation.is_current(document) {
                        return;
                    }
                    let mut workspace = workspace.lock().unwrap_or_else(PoisonError::into_inner);
                    // Levels below `level` are there already (the first fairing or the jobs
                    // before this one): this builds `level` and its fairing operator.
                    workspace.prepare_for(&hierarchy, &options);
                });
        }
    }

    /// The hierarchy build finished: the view asks for its first result, the levels are set up.
    pub(in crate::app) fn on_hierarchy(
        &mut self,
        document: GenerationId,
        hierarchy: GenerationId,
        result: Result<KeptHierarchy, HierarchyError>,
    ) {
        if !self.work.hierarchy_generation.is_current(hierarchy) {
            return;
        }
        let Some(current) = self.document.as_mut().filter(|d| d.generation == document) else {
            return;
        };
        match result {
            Ok(kept) => {
                let levels = (0..kept.hierarchy.level_count())
                    .map(|l| kept.hierarchy.level_info(l))
                    .collect::<Vec<_>>();
                current.level = if current.pick_start_level {
                    current.pick_start_level = false;
                    self.settings
                        .files
                        .start_level_for(&current.path, levels.len())
                } else {
                    current.level.min(levels.len().saturating_sub(1))
                };
                let warm = kept.hierarchy.clone();
                current.hierarchy = HierarchyState::Ready {
                    base_matches_original: kept.base_matches_original,
                    sharp_edges: kept.sharp_edges,
                    hierarchy: kept.hierarchy,
                    levels,
                    build_time: kept.build_time,
                    denoise: kept.denoise,
                };
                self.refresh_view();
                self.prepare_levels(warm, document);
            }
            Err(HierarchyError::Cancelled) => {
                current.hierarchy = HierarchyState::Failed("cancelled".into());
            }
            Err(error) => {
                let text = error.to_string();
                current.hierarchy = HierarchyState::Failed(text.clone());
                self.error = Some(text);
            }
        }
    }
}
