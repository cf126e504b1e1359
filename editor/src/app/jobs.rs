//! Background work for the editor: named worker threads with a job queue, and the generation
//! numbers that let the UI drop stale results and cancel work nobody needs any more.
//!
//! - [`Worker`] runs boxed jobs one after another on its own named thread. A job submitted with
//!   [`Worker::submit_latest`] replaces any job of the same slot still waiting, so a slider being
//!   dragged queues at most one fairing run behind the one in flight. A job submitted with
//!   [`Worker::submit_idle`] runs only when no other job waits: work for later (setting up the
//!   hierarchy's levels) never delays what the user asked for by more than the idle job in hand.
//! - A `Generation` (`generation.rs`) is a shared counter. A job remembers the value it was
//!   started under; when the UI bumps the counter (a new file, a newer slider value) the job's
//!   progress hook sees the change and cancels, and the UI ignores a result whose generation is
//!   not the current one.
//! - Jobs send a [`JobResult`] over a channel and call `request_repaint`, so the UI wakes up even
//!   when nothing else moves. A job that panics sends nothing; its worker survives it and tells
//!   its [`PanicReport`] which kind of job it was ([`JobKind`]) and what the panic said, so that
//!   the UI can say so and clear what the job held (see [`JobResult::JobFailed`]).
//! - In a web page (`wasm32`, no threads) a worker is its queue alone: the UI thread runs one
//!   waiting job between two frames (`Worker::run_next`), in the same order a thread would.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::time::Duration;

use fairmesh::hierarchy::HierarchyError;
use fairmesh::io::{IoError, LoadReport};
use fairmesh::TriMesh;

use super::generation::GenerationId;
use super::state::{KeptHierarchy, Measures};

type Job = Box<dyn FnOnce() + Send + 'static>;

/// What a background job does: a worker keeps one waiting job of a kind submitted with
/// [`Worker::submit_latest`], and a job that panics is reported by its kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JobKind {
    Load,
    /// Freeing a replaced document's mesh and hierarchy.
    Free,
    Noise,
    Hierarchy,
    /// Setting up the hierarchy's levels for fairing, while nothing else waits.
    LevelSetUp,
    Fair,
    /// Fairing a level next to the one on screen while the slider rests.
    FairAhead,
    LevelMesh,
    Measure,
    Export,
    LevelChain,
    ViewImage,
}

impl JobKind {
    /// What the job was doing, in words that follow "while".
    pub fn doing(self) -> &'static str {
        match self {
            JobKind::Load => "loading the file",
            JobKind::Free => "freeing the previous file",
            JobKind::Noise => "adding noise",
            JobKind::Hierarchy => "building the hierarchy",
            JobKind::LevelSetUp => "setting up the levels",
            JobKind::Fair => "fairing",
            JobKind::FairAhead => "fairing the next levels ahead",
            JobKind::LevelMesh => "making the level's mesh",
            JobKind::Measure => "measuring the result",
            JobKind::Export => "exporting",
            JobKind::LevelChain => "exporting the level chain",
            JobKind::ViewImage => "saving the image of the view",
        }
    }
}

/// Told, on the worker's thread, when a job panicked: the job's kind and the panic's message.
pub type PanicReport = Box<dyn Fn(JobKind, String) + Send + 'static>;

/// A loaded mesh as the UI takes it, with the loader's connectivity (shared, never rebuilt:
/// noise and Apply move positions only, and the hierarchy build and baseline or masked
/// fairings read it; ~185 ms to build again on a 1.2M-face mesh).
pub struct LoadedMesh {
    pub mesh: TriMesh,
    pub topology: Arc<fairmesh::Topology>,
    pub report: LoadReport,
    /// The file the mesh came from, for writing it back on export.
    pub source: Arc<fairmesh::io::Source>,
}

struct Queued {
    /// What the job is.
    kind: JobKind,
    job: Job,
    /// Runs only when no other job waits.
    idle: bool,
}

#[derive(Default)]
struct Queue {
    jobs: VecDeque<Queued>,
    running: usize,
    shutdown: bool,
}

struct Shared {
    queue: Mutex<Queue>,
    wake: Condvar,
}

/// One named background thread and its queue.
pub struct Worker {
    shared: Arc<Shared>,
}

impl Worker {
    /// Starts the thread `name`; a job that panics is reported to `on_panic`.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn spawn(name: &str, on_panic: PanicReport) -> std::io::Result<Self> {
        let shared = Arc::new(Shared {
            queue: Mutex::new(Queue::default()),
            wake: Condvar::new(),
        });
        let thread_shared = shared.clone();
        std::thread::Builder::new()
            .name(name.to_owned())
            .spawn(move || worker_loop(&thread_shared, &on_panic))?;
        Ok(Self { shared })
    }

    /// The queue alone: a page has no threads, so [`Worker::run_next`] runs the jobs (a panic
    /// aborts the page's module there, so `on_panic` is never called).
    #[cfg(target_arch = "wasm32")]
    pub fn spawn(_name: &str, _on_panic: PanicReport) -> std::io::Result<Self> {
        Ok(Self {
            shared: Arc::new(Shared {
                queue: Mutex::new(Queue::default()),
                wake: Condvar::new(),
            }),
        })
    }

    /// Runs the job a worker thread would take next, on the calling thread; false when none
    /// waits.
    #[cfg(target_arch = "wasm32")]
    pub fn run_next(&self) -> bool {
        let next = {
            let mut queue = self.lock();
            let next = queue.jobs.iter().position(|queued| !queued.idle);
            let next = queue.jobs.remove(next.unwrap_or(0));
            if next.is_some() {
                queue.running += 1;
            }
            next
        };
        let Some(Queued { job, .. }) = next else {
            return false;
        };
        job();
        self.lock().running -= 1;
        true
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Queue> {
        self.shared
            .queue
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
    }

    /// Queues `job`, a job of `kind`, behind the others.
    pub fn submit(&self, kind: JobKind, job: impl FnOnce() + Send + 'static) {
        self.push(kind, false, job, false);
    }

    /// Queues `job` to run when no other job waits (idle jobs run in the order submitted).
    pub fn submit_idle(&self, kind: JobKind, job: impl FnOnce() + Send + 'static) {
        self.push(kind, false, job, true);
    }

    /// Queues `job`, dropping any job of the same `kind` that has not started yet.
    pub fn submit_latest(&self, kind: JobKind, job: impl FnOnce() + Send + 'static) {
        self.push(kind, true, job, false);
    }

    /// Queues `job` (`idle` or not) and wakes the thread; with `latest`, first drops the jobs
    /// of that kind that have not started yet.
    fn push(&self, kind: JobKind, latest: bool, job: impl FnOnce() + Send + 'static, idle: bool) {
        let mut queue = self.lock();
        if latest {
            queue.jobs.retain(|queued| queued.kind != kind);
        }
        queue.jobs.push_back(Queued {
            kind,
            job: Box::new(job),
            idle,
        });
        drop(queue);
        self.shared.wake.notify_one();
    }

    /// Whether a job is running or waiting.
    pub fn is_busy(&self) -> bool {
        let queue = self.lock();
        queue.running > 0 || !queue.jobs.is_empty()
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        // The thread finishes the job in hand (cancelled through its generation by the owner)
        // and exits; nobody waits for it.
        let mut queue = self.lock();
        queue.shutdown = true;
        queue.jobs.clear();
        drop(queue);
        self.shared.wake.notify_all();
    }
}

#[cfg_attr(target_arch = "wasm32", allow(dead_code))]
fn worker_loop(shared: &Shared, on_panic: &PanicReport) {
    // The window comes first: jobs run at background priority (see `priority`).
    super::priority::lower_this_thread();
    loop {
        let job = {
            let mut queue = shared.queue.lock().unwrap_or_else(PoisonError::into_inner);
            loop {
                if queue.shutdown {
                    return;
                }
                // The first job that is not idle, else the first idle one.
                let next = queue.jobs.iter().position(|queued| !queued.idle);
                if let Some(queued) = queue.jobs.remove(next.unwrap_or(0)) {
                    queue.running += 1;
                    break queued;
                }
                queue = shared
                    .wake
                    .wait(queue)
                    .unwrap_or_else(PoisonError::into_inner);
            }
        };
        // A panicking job must not take the worker down with it; its result is missing, and
        // the UI is told which job it was.
        let Queued { kind, job, .. } = job;
        let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            super::priority::run_in_background(job)
        }));
        if let Err(payload) = ran {
            on_panic(kind, panic_message(payload.as_ref()));
        }
        shared
            .queue
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .running -= 1;
    }
}

/// What a panic said (its payload, when it is text).
#[cfg_attr(target_arch = "wasm32", allow(dead_code))]
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(text) = payload.downcast_ref::<&str>() {
        (*text).to_owned()
    } else if let Some(text) = payload.downcast_ref::<String>() {
        text.clone()
    } else {
        "no message".to_owned()
    }
}

/// A fraction in 0..=1 written by a job and read by the UI.
#[derive(Clone, Default)]
pub struct SharedProgress(Arc<AtomicU32>);

impl SharedProgress {
    pub fn set(&self, fraction: f32) {
        self.0
            .store(fraction.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
    }
    pub fn get(&self) -> f32 {
        f32::from_bits(self.0.load(Ordering::Relaxed))
    }
}

/// Counts jobs started and finished, so tests and the UI can tell when everything settled.
#[derive(Clone, Default)]
pub struct JobCounter(Arc<AtomicUsize>);

impl JobCounter {
    pub fn start(&self) -> JobTicket {
        self.0.fetch_add(1, Ordering::SeqCst);
        JobTicket(self.0.clone())
    }
    pub fn in_flight(&self) -> usize {
        self.0.load(Ordering::SeqCst)
    }
}

/// Held by a submitted job; dropping it (when the job ends, however it ends) counts it finished.
pub struct JobTicket(Arc<AtomicUsize>);

impl Drop for JobTicket {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// What the fairing job computed for one slider position and set of options.
pub struct Faired {
    pub positions: Vec<[f32; 3]>,
    /// Relative change of the enclosed volume against the loaded mesh.
    pub volume_change: f64,
    /// Root mean square of the vertex displacements against the loaded mesh (model units).
    pub rms_displacement: f64,
    pub elapsed: Duration,
    /// The method that made it (a baseline ignores the start level).
    pub method: fairmesh::fairing::Method,
    /// Faces left turned over against level 0 ([`fairmesh::multires::MultiresWorkspace::folds_left`]).
    pub folds_left: usize,
}

impl Faired {
    /// `positions` of `original`'s vertices as a result, with their volume change and RMS
    /// displacement against `original` measured.
    pub(in crate::app) fn measured(
        original: &fairmesh::TriMesh,
        positions: Vec<[f32; 3]>,
        elapsed: Duration,
        method: fairmesh::fairing::Method,
        folds_left: usize,
    ) -> Self {
        let (volume_change, rms_displacement) =
            fairmesh::metrics::change_of_positions(original, &positions);
        Faired {
            positions,
            volume_change,
            rms_displacement,
            elapsed,
            method,
            folds_left,
        }
    }
}

/// A job's answer to the UI. Each carries the generation it was started under.
pub enum JobResult {
    Loaded {
        load_generation: GenerationId,
        path: PathBuf,
        result: Result<Box<LoadedMesh>, IoError>,
        elapsed: Duration,
    },
    Hierarchy {
        document: GenerationId,
        hierarchy: GenerationId,
        /// The hierarchy (built on the denoised mesh when there was a denoise), whether its M0
        /// has the loaded mesh's triangles, and the time the denoise and the build took.
        result: Result<KeptHierarchy, HierarchyError>,
    },
    Faired {
        document: GenerationId,
        view: GenerationId,
        level: usize,
        /// `None`: cancelled or failed.
        result: Option<Faired>,
    },
    /// A level faired ahead (see `kept_results.rs`), under `key`.
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    FairedAhead {
        key: crate::app::kept_results::ResultKey,
        level: usize,
        /// `None`: stopped (the slider moved, a setting changed).
        result: Option<Faired>,
    },
    LevelMesh {
        document: GenerationId,
        view: GenerationId,
        level: usize,
        mesh: Arc<TriMesh>,
    },
    /// The measures of the faired result with `serial`.
    Measured {
        document: GenerationId,
        serial: u64,
        against_document: Option<Measures>,
        against_clean: Option<Measures>,
        measure_time: Duration,
    },
    /// Measuring the faired result `serial` stopped half way: the view moved on meanwhile. The
    /// result is measured again once the slider rests, if it is still the one on screen.
    MeasureStopped {
        document: GenerationId,
        serial: u64,
        positions: Arc<Vec<[f32; 3]>>,
    },
    /// Noise was added to a copy of the document's mesh.
    Noised {
        document: GenerationId,
        label: String,
        noisy: Arc<TriMesh>,
        clean: Arc<TriMesh>,
        /// The noisy mesh against the clean one.
        against_clean: Box<Measures>,
    },
    /// The export was written; `Ok` holds what the output could not keep of the input.
    Exported {
        path: PathBuf,
        result: Result<Vec<String>, IoError>,
        elapsed: Duration,
    },
    /// The level chain was written, one GLB per level; `Ok` holds the files and what they could
    /// not keep of the input.
    LevelsExported {
        folder: PathBuf,
        result: Result<(Vec<PathBuf>, Vec<String>), LevelChainError>,
        elapsed: Duration,
    },
    /// A job panicked (a bug): `kind` says which, `message` what the panic said. Whatever the
    /// job held (a fairing in flight, a hierarchy being built, a file loading) is cleared.
    JobFailed { kind: JobKind, message: String },
    /// The window's pixels, asked for by "Save image": the view's part goes to a PNG.
    ViewCaptured {
        image: Arc<egui::ColorImage>,
        /// The 3D view, in points.
        rect: egui::Rect,
        pixels_per_point: f32,
        /// The document's file: the PNG goes beside it.
        beside: PathBuf,
    },
    /// The PNG of the view was written (its path) or not (why).
    ViewImageSaved { result: Result<PathBuf, IoError> },
    /// A file dialog closed; `None` when it was cancelled or no dialog could be shown.
    DialogPicked {
        purpose: DialogPurpose,
        path: Option<PathBuf>,
    },
}

/// Why the level chain was not written (the export task words it for the status bar).
#[derive(Debug)]
pub enum LevelChainError {
    /// The folder could not be made.
    CreateFolder {
        folder: PathBuf,
        source: std::io::Error,
    },
    /// A level's file could not be written (the files written before it stay).
    Save(IoError),
}

impl JobResult {
    /// What arrived, in a few words (for `--log-frames`).
    pub fn describe(&self) -> &'static str {
        match self {
            JobResult::Loaded { .. } => "a loaded file",
            JobResult::Hierarchy { .. } => "the hierarchy",
            JobResult::Faired { .. } => "a fairing result",
            JobResult::FairedAhead { .. } => "a level faired ahead",
            JobResult::LevelMesh { .. } => "a level mesh",
            JobResult::Measured { .. } => "measures",
            JobResult::MeasureStopped { .. } => "a stopped measure",
            JobResult::Noised { .. } => "the noisy mesh",
            JobResult::Exported { .. } => "an export",
            JobResult::LevelsExported { .. } => "the level files",
            JobResult::ViewCaptured { .. } => "the window's pixels",
            JobResult::ViewImageSaved { .. } => "a saved view image",
            JobResult::DialogPicked { .. } => "a file dialog's answer",
            JobResult::JobFailed { .. } => "a failed job",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DialogPurpose {
    Open,
    Export,
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;

    #[test]
    fn worker_runs_jobs_in_order_in_the_background_pool() {
        let worker = Worker::spawn("fairmesh-test-worker", Box::new(|_, _| {})).unwrap();
        let (tx, rx) = mpsc::channel();
        for i in 0..3 {
            let tx = tx.clone();
            worker.submit(JobKind::Load, move || {
                let name = std::thread::current().name().map(str::to_owned);
                tx.send((i, name)).unwrap();
            });
        }
        let got: Vec<_> = (0..3)
            .map(|_| rx.recv_timeout(Duration::from_secs(5)).unwrap())
            .collect();
        assert_eq!(got.iter().map(|g| g.0).collect::<Vec<_>>(), vec![0, 1, 2]);
        // The worker hands each job to the background pool (lower priority) and waits for it.
        for (_, name) in &got {
            let name = name.as_deref().unwrap_or("");
            assert!(name.starts_with("fairmesh-background-"), "{name}");
        }
    }

    /// A worker busy with a job that waits for the returned sender, so that the jobs submitted
    /// next wait in the queue until the test releases it.
    fn blocked_worker(name: &str) -> (Worker, mpsc::Sender<()>) {
        let worker = Worker::spawn(name, Box::new(|_, _| {})).unwrap();
        let (release, released) = mpsc::channel::<()>();
        worker.submit(JobKind::Load, move || {
            released.recv_timeout(Duration::from_secs(5)).ok();
        });
        (worker, release)
    }

    #[test]
    fn latest_slot_keeps_only_the_newest_waiting_job() {
        let (worker, release) = blocked_worker("fairmesh-test-coalesce");
        let (tx, rx) = mpsc::channel();
        for i in 0..5 {
            let tx = tx.clone();
            worker.submit_latest(JobKind::Fair, move || tx.send(i).unwrap());
        }
        release.send(()).unwrap();
        assert_eq!(rx.recv_timeout(Duration::from_secs(5)).unwrap(), 4);
        assert!(rx.recv_timeout(Duration::from_millis(200)).is_err());
    }

    #[test]
    fn idle_jobs_wait_for_every_other_job() {
        let (worker, release) = blocked_worker("fairmesh-test-idle");
        let (tx, rx) = mpsc::channel();
        for name in ["idle 1", "idle 2"] {
            let tx = tx.clone();
            worker.submit_idle(JobKind::LevelSetUp, move || tx.send(name).unwrap());
        }
        let tx2 = tx.clone();
        worker.submit(JobKind::Load, move || tx2.send("normal").unwrap());
        worker.submit_latest(JobKind::Fair, move || tx.send("latest").unwrap());
        release.send(()).unwrap();
        let order: Vec<_> = (0..4)
            .map(|_| rx.recv_timeout(Duration::from_secs(5)).unwrap())
            .collect();
        assert_eq!(order, ["normal", "latest", "idle 1", "idle 2"]);
    }

    #[test]
    fn a_job_that_panics_is_reported_by_its_kind_and_the_worker_goes_on() {
        let (report, reports) = mpsc::channel();
        let worker = Worker::spawn(
            "fairmesh-test-panic",
            Box::new(move |kind, message| report.send((kind, message)).unwrap()),
        )
        .unwrap();
        let (tx, rx) = mpsc::channel();
        worker.submit(JobKind::Fair, || {
            panic!("index out of bounds: the len is 3 but the index is 7")
        });
        worker.submit(JobKind::Export, move || tx.send("ran").unwrap());
        let (kind, message) = reports.recv_timeout(Duration::from_secs(5)).unwrap();
        assert_eq!(kind, JobKind::Fair);
        assert!(message.contains("the index is 7"), "{message}");
        assert_eq!(rx.recv_timeout(Duration::from_secs(5)).unwrap(), "ran");
        assert!(reports.recv_timeout(Duration::from_millis(200)).is_err());
    }
}
