//! The editor's workers: its named background threads (one of each of
//! [`super::priority::WORKER_NAMES`], the list the background pool is sized from), the count of
//! jobs in flight and the channel their results come back on.

use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::Arc;

use super::jobs::{JobCounter, JobResult, JobTicket, PanicReport, Worker};

/// The worker threads an app runs its jobs on, and where their results arrive.
pub(in crate::app) struct Workers {
    /// Loading and exporting files (`fairmesh-io`).
    pub(in crate::app) io: Worker,
    /// The hierarchy, fairing and level meshes (`fairmesh-compute`).
    pub(in crate::app) compute: Worker,
    /// Measures faired results (surface distances need two BVHs per reference: 0.1-0.3 s on the
    /// bunny), so that the compute worker hands each result to the view at once and is free for
    /// the next slider value (`fairmesh-measure`).
    pub(in crate::app) measure: Worker,
    /// The measuring worker's own one-thread rayon pool (`None` if it could not be started: it
    /// then shares the global pool), so that the next slider value's fairing keeps the global
    /// pool (sharing it doubled the time to the next result on the bunny).
    pub(in crate::app) measure_pool: Option<Arc<rayon::ThreadPool>>,
    /// Jobs submitted and not finished (each holds a ticket).
    pub(in crate::app) jobs: JobCounter,
    pub(in crate::app) results_tx: Sender<(JobResult, JobTicket)>,
    pub(in crate::app) results_rx: Receiver<(JobResult, JobTicket)>,
}

impl Workers {
    /// Starts the editor's named threads and the measuring worker's one-thread pool. A job
    /// that panics comes back as [`JobResult::JobFailed`], and `ctx` repaints to show it.
    pub(in crate::app) fn spawn(ctx: &egui::Context) -> Self {
        let (results_tx, results_rx) = mpsc::channel();
        let jobs = JobCounter::default();
        let on_panic = || -> PanicReport {
            let (tx, jobs, ctx) = (results_tx.clone(), jobs.clone(), ctx.clone());
            Box::new(move |kind, message| {
                // The receiver is gone only when the app closed; nothing left to tell.
                let _ = tx.send((JobResult::JobFailed { kind, message }, jobs.start()));
                ctx.request_repaint();
            })
        };
        // Without threads the editor cannot work at all; failing to start one is fatal.
        let [io, compute, measure] = super::priority::WORKER_NAMES.map(|name| {
            Worker::spawn(name, on_panic())
                .unwrap_or_else(|error| panic!("cannot start the {name} thread: {error}"))
        });
        let measure_pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .thread_name(|_| "fairmesh-measure-pool".into())
            .start_handler(|_| super::priority::lower_this_thread())
            .build()
            .ok()
            .map(Arc::new);
        Self {
            io,
            compute,
            measure,
            measure_pool,
            jobs,
            results_tx,
            results_rx,
        }
    }
}
