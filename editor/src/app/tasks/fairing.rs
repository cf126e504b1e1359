//! Fairing the document from the start level (or a baseline method), and the level meshes of
//! the level view, on the compute worker: launch and result.

use std::sync::Arc;
use std::time::Duration;
use web_time::Instant;

use crate::app::compute::FairJob;
use crate::app::generation::GenerationId;
use crate::app::jobs::{Faired, JobKind, JobResult};
use crate::app::kept_results::{KeptResult, ResultKey};
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
                if !self.show_kept(document_generation, level, view) {
                    self.request_fairing(hierarchy, document_generation, level, view)
                }
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

    /// A fairing finished: its result goes on screen unless a newer one is there, and is kept
    /// for its level ([`crate::app::kept_results`]).
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
        let Some(faired) = result else {
            return;
        };
        let kept = kept_result(faired);
        // Asked for under the settings of now (nothing changed since): kept for its level.
        let same_document = self.document.as_ref().map(|d| d.generation) == Some(document);
        if same_document && self.work.view_generation.is_current(view) {
            if let Some(key) = self.result_key() {
                self.work.kept.keep(key, level, kept.clone());
            }
        }
        self.show_faired(document, view, level, kept);
    }

    /// Puts `kept`, the result from `level`, on screen unless a newer one is there, with its
    /// measures when it has them (else they are asked for).
    fn show_faired(
        &mut self,
        document: GenerationId,
        view: GenerationId,
        level: usize,
        kept: KeptResult,
    ) {
        let Some(current) = self.document.as_mut().filter(|d| d.generation == document) else {
            return;
        };
        // Older than what is on screen: stale.
        if view <= self.work.applied_view {
            return;
        }
        self.work.applied_view = view;
        self.work.next_serial += 1;
        // The previous result's measures stay on screen until this one's arrive.
        let previous = current.faired.take();
        let (against_document, against_clean, measure_time, measures_pending) = match kept.measures
        {
            Some((against_document, against_clean, time)) => {
                (against_document, against_clean, time, false)
            }
            None => (
                previous.as_ref().and_then(|p| p.against_document.clone()),
                previous.and_then(|p| p.against_clean),
                Duration::ZERO,
                true,
            ),
        };
        current.faired = Some(FairedResult {
            positions: kept.positions.clone(),
            level,
            method: kept.method,
            volume_change: kept.volume_change,
            rms_displacement: kept.rms_displacement,
            folds_left: kept.folds_left,
            elapsed: kept.elapsed,
            serial: self.work.next_serial,
            against_document,
            against_clean,
            measure_time,
            measures_pending,
        });
        self.work.measure_wanted = measures_pending.then(|| MeasureRequest {
            document,
            serial: self.work.next_serial,
            positions: kept.positions,
            arrived: Instant::now(),
        });
        if !measures_pending {
            self.fair_ahead();
        }
    }

    /// Everything besides the level that the document's faired result depends on now; `None`
    /// without a hierarchy.
    pub(in crate::app) fn result_key(&self) -> Option<ResultKey> {
        let document = self.document.as_ref()?;
        let HierarchyState::Ready { hierarchy, .. } = &document.hierarchy else {
            return None;
        };
        Some(ResultKey {
            document: document.generation,
            hierarchy: Arc::downgrade(hierarchy),
            original: Arc::downgrade(&document.original),
            mask: document.mask.clone(),
            fairing: self.settings.fairing.key(),
        })
    }

    /// Shows the result kept for `level`, if there is one: true when it did (then no fairing
    /// is needed, and one still running for an older slider value stops, its view passed).
    fn show_kept(&mut self, document: GenerationId, level: usize, view: GenerationId) -> bool {
        let Some(key) = self.result_key() else {
            return false;
        };
        let Some(kept) = self.work.kept.take_out(&key, level) else {
            return false;
        };
        self.work.fair_view = view;
        self.work.fair_in_flight = false;
        let on_screen = self.document.as_ref().and_then(|d| d.faired.as_ref());
        if on_screen.is_some_and(|f| Arc::ptr_eq(&f.positions, &kept.positions)) {
            // Already on screen (back from the level mesh, say): nothing to upload again.
            self.work.applied_view = view;
            return true;
        }
        self.frame_stats.log_arrival("a kept result");
        self.show_faired(document, view, level, kept);
        true
    }

    /// While the slider rests (nothing faired or measured for the view any more), fairs the
    /// nearest level next to it that has no kept result, on the compute worker behind anything
    /// else it has to do ([`crate::app::kept_results::AHEAD_REACH`]); each result that comes
    /// back asks for the next. A slider move, a changed setting or another document stops it at
    /// its next level. Not in a page: its fairings run in the engine's worker, one at a time.
    pub(in crate::app) fn fair_ahead(&mut self) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            if self.work.ahead_in_flight
                || self.work.fair_in_flight
                || self.work.measure_wanted.is_some()
                || self.work.applied_view != self.work.view_generation.current()
            {
                return;
            }
            let Some(document) = &self.document else {
                return;
            };
            let HierarchyState::Ready { hierarchy, .. } = &document.hierarchy else {
                return;
            };
            // A baseline smooths the whole mesh whatever the level: nothing to fair ahead.
            if document.applied
                || self.settings.view.view_mode == ViewMode::Level
                || self.settings.fairing.baseline_options().is_some()
            {
                return;
            }
            let hierarchy = hierarchy.clone();
            let (document_id, top) = (document.generation, hierarchy.level_count() - 1);
            let Some(key) = self.result_key() else {
                return;
            };
            let missing = self.work.kept.missing_near(&key, document.level, top);
            let Some(&level) = missing.first() else {
                return;
            };
            if !self.work.kept.room_for(document.original.vertex_count()) {
                return;
            }
            let Some(job) = self.fair_job(hierarchy, level) else {
                return;
            };
            let view = self.work.view_generation.current();
            let document_generation = self.work.document_generation.clone();
            let view_generation = self.work.view_generation.clone();
            let workspace = self.work.workspace.clone();
            // Not counted as work in flight: nobody waits for it, and it stops for anything.
            let (tx, ctx, ticket) = (
                self.workers.results_tx.clone(),
                self.ctx.clone(),
                self.work.ahead_jobs.start(),
            );
            self.work.ahead_in_flight = true;
            self.workers
                .compute
                .submit_idle(JobKind::FairAhead, move || {
                    let current = || {
                        document_generation.is_current(document_id)
                            && view_generation.is_current(view)
                    };
                    let result = if current() {
                        job.run(&workspace, |_| current())
                    } else {
                        None
                    };
                    let message = JobResult::FairedAhead { key, level, result };
                    Self::send_result(&tx, &ctx, message, ticket);
                });
        }
    }

    /// A level faired ahead came back: kept, if nothing it depends on changed meanwhile, and
    /// the next one asked for.
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    pub(in crate::app) fn on_faired_ahead(
        &mut self,
        key: ResultKey,
        level: usize,
        result: Option<Faired>,
    ) {
        self.work.ahead_in_flight = false;
        let Some(faired) = result else {
            return;
        };
        if self.result_key().as_ref() != Some(&key) {
            return;
        }
        self.work.kept.keep_ahead(key, level, kept_result(faired));
        self.fair_ahead();
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

/// A fairing's result as the editor keeps it, not measured yet.
fn kept_result(faired: Faired) -> KeptResult {
    KeptResult {
        positions: Arc::new(faired.positions),
        method: faired.method,
        volume_change: faired.volume_change,
        rms_displacement: faired.rms_displacement,
        folds_left: faired.folds_left,
        elapsed: faired.elapsed,
        measures: None,
    }
}
