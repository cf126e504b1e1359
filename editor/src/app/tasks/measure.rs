//! Measuring a faired result against the input and clean meshes (surface distances, on the
//! measuring worker and its own one-thread pool; in a page, in the page's measuring worker), once
//! the result has rested on screen: launch and result.

use std::sync::Arc;
use std::time::Duration;
use web_time::Instant;

use crate::app::generation::GenerationId;
use crate::app::jobs::{JobKind, JobResult};
use crate::app::state::{HierarchyState, Measures};
use crate::app::App;
use fairmesh::TriMesh;

/// A faired result is measured once it has been on screen this long with no fairing in flight:
/// measuring takes a core for 0.1-0.3 s on the bunny (seconds on a 1M-face mesh), and while the
/// slider is dragged it would compete with the next value's fairing for the cores. The numbers
/// follow when the user pauses.
pub(in crate::app) const MEASURE_DELAY: Duration = Duration::from_millis(100);

/// A faired result waiting to be measured.
pub(in crate::app) struct MeasureRequest {
    pub(in crate::app) document: GenerationId,
    pub(in crate::app) serial: u64,
    pub(in crate::app) positions: Arc<Vec<[f32; 3]>>,
    /// When the result arrived.
    pub(in crate::app) arrived: Instant,
}

impl App {
    /// Hands the waiting result to the measuring worker once no fairing is in flight and it has
    /// waited [`MEASURE_DELAY`]; until then asks for a frame when the delay is up.
    pub(in crate::app) fn start_waiting_measure(&mut self) {
        let Some(request) = &self.work.measure_wanted else {
            return;
        };
        let waited = request.arrived.elapsed();
        if self.work.fair_in_flight {
            return;
        }
        if waited < MEASURE_DELAY {
            self.ctx.request_repaint_after(MEASURE_DELAY - waited);
            return;
        }
        if let Some(request) = self.work.measure_wanted.take() {
            self.request_measures(request.document, request.serial, request.positions);
        }
    }

    /// Measures the faired result `serial` against the document's mesh and the clean one on the
    /// measuring worker (a newer result replaces a waiting request).
    pub(in crate::app) fn request_measures(
        &mut self,
        document: GenerationId,
        serial: u64,
        positions: Arc<Vec<[f32; 3]>>,
    ) {
        let Some(current) = self.document.as_ref().filter(|d| d.generation == document) else {
            return;
        };
        if !matches!(current.hierarchy, HierarchyState::Ready { .. }) {
            return;
        }
        // Measured against the document's mesh (the hierarchy's M0 may be its denoised copy),
        // with its triangles.
        let base = current.original.clone();
        let clean = current.clean.clone();
        let pool = self.workers.measure_pool.clone();
        let document_generation = self.work.document_generation.clone();
        // A slider move, an option or a view change bumps the view generation: the result
        // being measured is then about to be replaced, so measuring it stops and gives the
        // cores to the next fairing.
        let (view_generation, view) = (
            self.work.view_generation.clone(),
            self.work.view_generation.current(),
        );
        let (tx, ctx, ticket) = (
            self.workers.results_tx.clone(),
            self.ctx.clone(),
            self.workers.jobs.start(),
        );
        // In a page the measuring runs in a worker of its own, so that the page goes on
        // answering and a fairing does not wait for it.
        #[cfg(target_arch = "wasm32")]
        let (tx, ctx, ticket) = {
            use crate::app::web::engine::{post_measure, MeasurePost, Sending};
            let post = MeasurePost {
                document,
                document_generation: document_generation.clone(),
                serial,
                positions: positions.clone(),
                base: base.clone(),
                clean: clean.clone(),
                view_generation: view_generation.clone(),
                view,
            };
            match post_measure(post, Sending { tx, ctx, ticket }) {
                Ok(()) => return,
                Err(back) => (back.tx, back.ctx, back.ticket),
            }
        };
        self.workers
            .measure
            .submit_latest(JobKind::Measure, move || {
                if !document_generation.is_current(document) {
                    return;
                }
                let started = Instant::now();
                let base = base.as_ref();
                let faired = TriMesh {
                    positions: positions.as_ref().clone(),
                    triangles: base.triangles.clone(),
                };
                let stop = || {
                    !view_generation.is_current(view) || !document_generation.is_current(document)
                };
                let measure = || {
                    let against_document = Measures::of_unless(base, &faired, &stop)?;
                    let against_clean = match clean.as_deref() {
                        Some(clean) => Some(Measures::of_unless(clean, &faired, &stop)?),
                        None => None,
                    };
                    Some((against_document, against_clean))
                };
                let measured = match &pool {
                    Some(pool) => pool.install(measure),
                    None => measure(),
                };
                let message = match measured {
                    Some((against_document, against_clean)) => JobResult::Measured {
                        document,
                        serial,
                        against_document: Some(against_document),
                        against_clean,
                        measure_time: started.elapsed(),
                    },
                    None => JobResult::MeasureStopped {
                        document,
                        serial,
                        positions,
                    },
                };
                Self::send_result(&tx, &ctx, message, ticket);
            });
    }

    /// A result's measures arrived.
    pub(in crate::app) fn on_measured(
        &mut self,
        document: GenerationId,
        serial: u64,
        against_document: Option<Measures>,
        against_clean: Option<Measures>,
        measure_time: Duration,
    ) {
        let Some(faired) = self
            .document
            .as_mut()
            .filter(|d| d.generation == document)
            .and_then(|d| d.faired.as_mut())
            .filter(|f| f.serial == serial)
        else {
            return;
        };
        self.work.kept.add_measures(
            &faired.positions,
            (
                against_document.clone(),
                against_clean.clone(),
                measure_time,
            ),
        );
        faired.against_document = against_document;
        faired.against_clean = against_clean;
        faired.measure_time = measure_time;
        faired.measures_pending = false;
        self.fair_ahead();
    }

    /// A measuring stopped because the view moved on: measured again later if still shown.
    pub(in crate::app) fn on_measure_stopped(
        &mut self,
        document: GenerationId,
        serial: u64,
        positions: Arc<Vec<[f32; 3]>>,
    ) {
        self.work.measures_stopped += 1;
        let still_shown = self
            .document
            .as_ref()
            .filter(|d| d.generation == document)
            .and_then(|d| d.faired.as_ref())
            .is_some_and(|f| f.serial == serial);
        // A newer result has its own request already; this one is measured again.
        if still_shown && self.work.measure_wanted.is_none() {
            self.work.measure_wanted = Some(MeasureRequest {
                document,
                serial,
                positions,
                arrived: Instant::now(),
            });
        }
    }
}
