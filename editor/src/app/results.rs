//! Background jobs' results coming back to the UI thread: [`App::send_result`] (the workers'
//! side) and [`App::poll_results`], which hands each to its task's handler.

use std::sync::mpsc::Sender;

use super::jobs::{JobKind, JobResult, JobTicket};
use super::state::HierarchyState;
use super::App;

impl App {
    /// Sends a job's result to the UI thread and wakes it.
    pub(super) fn send_result(
        tx: &Sender<(JobResult, JobTicket)>,
        ctx: &egui::Context,
        result: JobResult,
        ticket: JobTicket,
    ) {
        // The receiver is gone only when the app closed; nothing left to tell.
        let _ = tx.send((result, ticket));
        ctx.request_repaint();
    }

    /// Applies every result that has come back since the last frame.
    pub(super) fn poll_results(&mut self) {
        while let Ok((result, ticket)) = self.workers.results_rx.try_recv() {
            self.frame_stats.log_arrival(result.describe());
            self.apply_result(result);
            // The job counts as finished only once its result is applied.
            drop(ticket);
        }
    }

    fn apply_result(&mut self, result: JobResult) {
        match result {
            JobResult::Loaded {
                load_generation,
                path,
                result,
                elapsed,
            } => self.on_loaded(load_generation, path, result, elapsed),
            JobResult::Hierarchy {
                document,
                hierarchy,
                result,
            } => self.on_hierarchy(document, hierarchy, result),
            JobResult::Faired {
                document,
                view,
                level,
                result,
            } => self.on_faired(document, view, level, result),
            JobResult::FairedAhead { key, level, result } => {
                self.on_faired_ahead(key, level, result)
            }
            JobResult::Measured {
                document,
                serial,
                against_document,
                against_clean,
                measure_time,
            } => self.on_measured(
                document,
                serial,
                against_document,
                against_clean,
                measure_time,
            ),
            JobResult::MeasureStopped {
                document,
                serial,
                positions,
            } => self.on_measure_stopped(document, serial, positions),
            JobResult::LevelMesh {
                document,
                view,
                level,
                mesh,
            } => self.on_level_mesh(document, view, level, mesh),
            JobResult::Noised {
                document,
                label,
                noisy,
                clean,
                against_clean,
            } => self.on_noised(document, label, noisy, clean, *against_clean),
            JobResult::Exported {
                path,
                result,
                elapsed,
            } => self.on_exported(path, result, elapsed),
            JobResult::LevelsExported {
                folder,
                result,
                elapsed,
            } => self.on_levels_exported(folder, result, elapsed),
            JobResult::DialogPicked { purpose, path } => self.on_dialog_picked(purpose, path),
            JobResult::ViewCaptured {
                image,
                rect,
                pixels_per_point,
                beside,
            } => self.on_view_captured(image, rect, pixels_per_point, beside),
            JobResult::ViewImageSaved { result } => self.on_view_image_saved(result),
            JobResult::JobFailed { kind, message } => self.on_job_failed(kind, message),
        }
    }

    /// A job panicked: what it held is cleared so that the editor carries on (the slider fairs
    /// again, another file loads, the hierarchy can be built again), and the error says what
    /// stopped. The document and the result on screen stay.
    pub(in crate::app) fn on_job_failed(&mut self, kind: JobKind, message: String) {
        match kind {
            JobKind::Load => self.work.loading = None,
            JobKind::Fair => self.work.fair_in_flight = false,
            JobKind::FairAhead => self.work.ahead_in_flight = false,
            JobKind::Hierarchy => {
                if let Some(document) = &mut self.document {
                    if matches!(document.hierarchy, HierarchyState::Building) {
                        document.hierarchy =
                            HierarchyState::Failed(format!("an internal error: {message}"));
                    }
                }
            }
            JobKind::Measure => {
                let measured = self.document.as_mut().and_then(|d| d.faired.as_mut());
                if let Some(faired) = measured {
                    faired.measures_pending = false;
                }
            }
            JobKind::Free
            | JobKind::Noise
            | JobKind::LevelSetUp
            | JobKind::LevelMesh
            | JobKind::Export
            | JobKind::LevelChain
            | JobKind::ViewImage => {}
        }
        self.error = Some(format!(
            "An internal error stopped the editor while {}: {message}. This is a bug in fairmesh; \
             your file is untouched.",
            kind.doing()
        ));
    }
}
