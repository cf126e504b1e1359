//! Fairing the document from the start level (or a baseline method), and the level meshes of
//! the level view, on the compute worker: launch and result.

use std::sync::Arc;
use std::time::Duration;
use web_time::Instant;

use crate::app::compute::FairJob;
use crate::app::generation::GenerationId;
use crate::app::jobs::{Faired, JobKind, JobResult};
use crate::app::state::{FairedResult, HierarchyState, ViewMode};
use crate::app::tasks::measure::MeasureRequest;
use crate::app::App;
use fairmesh::{hierarchy, TriMesh};

impl App {
    /// Asks for what the current view mode needs at the current level and options.
    pub(in crate::app) fn refresh_view(&mut self) {
        let Some(document) = &self.document else {
            return;
        };
        let HierarchyState::Ready { hierarchy, .. } = &document.hierarchy else {
            return;
        };
        let hierarchy = hierarchy.clone();
        let level = document.level;
        let document_generation = document.generation;
        let applied = document.applied;
        let view = self.work.view_generation.bump();
        match self.settings.view.view_mode {
            ViewMode::Level => self.request_level_mesh(hierarchy, document_generation, level, view),
            // An applied result is shown as it is until a setting changes.
            ViewMode::Faired | ViewMode::Original if applied => {}
            ViewMode::Faired | ViewMode::Original => {
                self.request_fairing(hierarchy, document_generation, level, view)
            }
        }
    }

    /// Fairs the document from `level` (or with the baseline method) on the compute worker, the
    /// result coming back as [`JobResult::Faired`] for `view`.
    pub(in crate::app) fn request_fairing(
        &mut self,
        hierarchy: Arc<hierarchy::Hierarchy>,
        document: GenerationId,
        level: usize,
        view: GenerationId,
    ) {
        let Some(job) = self.fair_job(hierarchy, level) else {
            return;
        };
        let document_generation = self.work.document_generation.clone();
        let view_generation = self.work.view_generation.clone();
        let progress_out = self.work.fair_progress.clone();
        let workspace = self.work.workspace.clone();
        let (tx, ctx, ticket) = (
            self.workers.results_tx.clone(),
            self.ctx.clone(),
            self.workers.jobs.start(),
        );
        self.work.fair_in_flight = true;
        self.work.fair_view = view;
        self.work.fair_progress.set(0.0);
        // In a page the fairing runs in the engine's worker, which holds the hierarchy.
        #[cfg(target_arch = "wasm32")]
        let (tx, ctx, ticket) = {
            use crate::app::web::engine::{post_fair, FairPost, Sending};
            let post = FairPost {
                settings: self.settings.clone(),
                hierarchy: job.hierarchy.clone(),
                original: job.original.clone(),
                denoised: job.denoised,
                mask: job.mask.clone(),
                level,
                document,
                document_generation: document_generation.clone(),
                view,
                progress: progress_out.clone(),
            };
            match post_fair(post, Sending { tx, ctx, ticket }) {
                Ok(()) => return,
                Err(back) => (back.tx, back.ctx, back.ticket),
            }
        };
        self.workers.compute.submit_latest(JobKind::Fair, move || {
            if !document_generation.is_current(document) {
                return;
            }
            // A newer request (another slider value, a changed option, a new document) makes
            // this run stale: it stops at its next level and gives no result, so that a drag
            // computes the level it rests on, not every level it crossed, and the view keeps the
            // last finished result until then.
            let progress = |fraction: f32| {
                progress_out.set(fraction);
                document_generation.is_current(document) && view_generation.is_current(view)
            };
            let result = job.run(&workspace, progress);
            let message = JobResult::Faired {
                document,
                view,
                level,
                result,
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// What fairing the document from `level` with the current settings needs.
    fn fair_job(&self, hierarchy: Arc<hierarchy::Hierarchy>, level: usize) -> Option<FairJob> {
        let document = self.document.as_ref()?;
        let denoised = matches!(
            document.hierarchy,
            HierarchyState::Ready {
                denoise: Some(_),
                ..
            }
        );
        Some(FairJob::new(
            hierarchy,
            document.original.clone(),
            denoised,
            document.mask.clone(),
            document.topology.clone(),
            &self.settings,
            level,
        ))
    }

    pub(in crate::app) fn request_level_mesh(
        &mut self,
        hierarchy: Arc<hierarchy::Hierarchy>,
        document: GenerationId,
        level: usize,
        view: GenerationId,
    ) {
        let document_generation = self.work.document_generation.clone();
        let (tx, ctx, ticket) = (
            self.workers.results_tx.clone(),
            self.ctx.clone(),
            self.workers.jobs.start(),
        );
        self.workers
            .compute
            .submit_latest(JobKind::LevelMesh, move || {
                if !document_generation.is_current(document) {
                    return;
                }
                let mesh = Arc::new(hierarchy.level_mesh(level));
                let message = JobResult::LevelMesh {
                    document,
                    view,
                    level,
                    mesh,
                };
                Self::send_result(&tx, &ctx, message, ticket);
            });
    }

    /// A fairing finished: its result goes on screen unless a newer one is there.
    pub(in crate::app) fn on_faired(
        &mut self,
        document: GenerationId,
        view: GenerationId,
        level: usize,
        result: Option<Faired>,
    ) {
        // The newest fairing asked for has answered (a view change to the level mesh
        // since does not make it any less finished).
        if view >= self.work.fair_view {
            self.work.fair_in_flight = false;
        }
        let Some(current) = self.document.as_mut().filter(|d| d.generation == document) else {
            return;
        };
        // Older than what is on screen: stale.
        if view <= self.work.applied_view {
            return;
        }
        if let Some(faired) = result {
            self.work.applied_view = view;
            self.work.next_serial += 1;
            // The previous result's measures stay on screen until this one's arrive.
            let previous = current.faired.take();
            let positions = Arc::new(faired.positions);
            current.faired = Some(FairedResult {
                positions: positions.clone(),
                level,
                method: faired.method,
                volume_change: faired.volume_change,
                rms_displacement: faired.rms_displacement,
                folds_left: faired.folds_left,
                elapsed: faired.elapsed,
                serial: self.work.next_serial,
                against_document: previous.as_ref().and_then(|p| p.against_document.clone()),
                against_clean: previous.and_then(|p| p.against_clean),
                measure_time: Duration::ZERO,
                measures_pending: true,
            });
            self.work.measure_wanted = Some(MeasureRequest {
                document,
                serial: self.work.next_serial,
                positions,
                arrived: Instant::now(),
            });
        }
    }

    /// A level mesh for the level view arrived.
    pub(in crate::app) fn on_level_mesh(
        &mut self,
        document: GenerationId,
        view: GenerationId,
        level: usize,
        mesh: Arc<TriMesh>,
    ) {
        let Some(current) = self.document.as_mut().filter(|d| d.generation == document) else {
            return;
        };
        if view <= self.work.applied_level_view {
            return;
        }
        self.work.applied_level_view = view;
        current.level_mesh = Some((level, mesh));
    }
}
