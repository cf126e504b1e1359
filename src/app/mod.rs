//! The editor (feature `gui`): an eframe app that loads a mesh, builds its decimation hierarchy in
//! the background, fairs it from the level picked with a slider, shows the result in a wgpu
//! viewport and exports it.
//!
//! Layout:
//! - [`state`]: persisted [`state::Settings`] and the [`state::Document`] (mesh and results);
//! - [`jobs`]: worker threads, generation numbers, job results;
//! - [`panels`]: the widgets; they only read state and emit [`Command`]s;
//! - [`camera`]: the orbit camera;
//! - this file: [`App`], which applies commands after the frame, dispatches jobs, applies their
//!   results, and keeps the viewport's GPU buffers in step with what should be shown.
//!
//! Named worker threads: `fairmesh-io` (load, export), `fairmesh-compute` (hierarchy, fairing,
//! level meshes; the levels' set-up as idle jobs that any fairing overtakes) and
//! `fairmesh-measure` (surface distances of a result, once the slider rests, on a one-thread
//! pool of its own), so an export or the next file's loading never waits for a long hierarchy
//! build and measuring never slows the next slider value. Each viewport's renderer has its own
//! `fairmesh-upload` thread for big meshes. Loading another file cancels the hierarchy build and
//! fairing of the previous one through their generation numbers.

pub mod camera;
pub mod history;
pub mod jobs;
pub mod panels;
pub mod state;

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use crate::hierarchy::{self, HierarchyError, HierarchyOptions};
use crate::multires::{self, MultiresWorkspace};
use crate::{metrics, TriMesh};

use camera::OrbitCamera;
use history::History;
use jobs::{
    DialogPurpose, Faired, Generation, JobCounter, JobResult, JobTicket, LoadedMesh,
    SharedProgress, Worker,
};
use state::{
    CompareView, Document, DocumentSnapshot, FairedResult, HeatReference, HierarchyState, Measures,
    Settings, ViewMode,
};

use crate::render::{DrawParams, MeshSource, Viewport3d};

/// Opens the editor window on `options.file`, or on the bundled bunny.
pub fn run(options: AppOptions) -> anyhow::Result<()> {
    let app_options = AppOptions {
        persistence: true,
        ..options
    };
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("fairmesh")
            .with_inner_size([1280.0, 800.0])
            .with_min_inner_size([640.0, 400.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: wgpu_configuration(),
        ..Default::default()
    };
    eframe::run_native(
        "fairmesh",
        options,
        Box::new(move |cc| Ok(Box::new(App::with_options(cc, app_options)))),
    )
    .map_err(|error| anyhow::anyhow!("the editor window failed: {error}"))
}

/// eframe's wgpu set-up, asking for the largest buffers the adapter allows: wgpu's default
/// limit (256 MiB per buffer) caps the wireframe at about 11M faces and the mesh at 22M, below
/// what big scans have; real GPUs allow far more.
fn wgpu_configuration() -> egui_wgpu::WgpuConfiguration {
    let mut configuration = egui_wgpu::WgpuConfiguration::default();
    if let egui_wgpu::WgpuSetup::CreateNew(setup) = &mut configuration.wgpu_setup {
        let base = setup.device_descriptor.clone();
        setup.device_descriptor = Arc::new(move |adapter| {
            let mut descriptor = base(adapter);
            let limits = &mut descriptor.required_limits;
            limits.max_buffer_size = limits.max_buffer_size.max(adapter.limits().max_buffer_size);
            descriptor
        });
    }
    configuration
}

/// How to start the app.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// The file to open; `None` opens the bunny compiled into the binary ([`crate::bundled`]).
    pub file: Option<PathBuf>,
    /// Read and write settings through eframe's storage (off in tests).
    pub persistence: bool,
    /// Print every UI frame whose CPU time is over this to standard error, split into its parts
    /// (`fairmesh edit --log-frames MS`: measures responsiveness in the real window).
    pub log_frames_over: Option<Duration>,
    /// Once the first mesh is loaded (or failed to) and every job is done, print one line about
    /// it (stdout, or the error to stderr) and close the window. CI uses it to check that a
    /// copied binary opens its bundled mesh in a real window (`fairmesh edit --exit-when-settled`).
    pub exit_when_settled: bool,
    /// Meshes of at least this many bytes (positions + triangles) upload to the GPU on the
    /// viewports' upload threads; `None` keeps the renderer's default (4 MB). Tests set 0.
    pub async_upload_bytes: Option<usize>,
    /// Caps the size of one GPU buffer below the device's limit (tests: what a small GPU does
    /// with a mesh or wireframe too big for it).
    pub max_buffer_bytes: Option<u64>,
}

/// Something the user asked for; applied after the frame's widgets are drawn.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    Open(PathBuf),
    OpenDialog,
    Export(PathBuf),
    ExportDialog,
    FitView,
    /// The start level changed.
    SetLevel(usize),
    /// A fairing option changed: run again.
    Refair,
    /// The view mode changed.
    SetViewMode(ViewMode),
    CancelHierarchy,
    RebuildHierarchy,
    DismissError,
    /// Add noise (the settings' sigma, seed and mode) to the document's mesh.
    AddNoise,
    /// Make the faired result the document's mesh.
    ApplyResult,
    Undo,
    Redo,
    /// Write the levels of the hierarchy (the settings' range) as GLB files into a folder.
    ExportLevels,
}

/// What the viewport has uploaded, to know when to upload again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Shown {
    document: u64,
    what: ShownMesh,
    /// The heat map's reference, when the heat map is on.
    heat: Option<HeatReference>,
}

/// The two viewports: the main one (the view mode's mesh: the result, a level, the original)
/// and the "before" one (the document's mesh) for the toggle, split and side-by-side views.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    Main = 0,
    Before = 1,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ShownMesh {
    Original,
    Faired { serial: u64 },
    Level { level: usize },
}

impl ShownMesh {
    /// Meshes with the same key share connectivity, so only positions need uploading.
    fn connectivity(self, base_matches_original: bool) -> (u8, usize) {
        match self {
            ShownMesh::Original => (0, 0),
            ShownMesh::Faired { .. } if base_matches_original => (0, 0),
            ShownMesh::Faired { .. } => (1, 0),
            ShownMesh::Level { level } => (2, level),
        }
    }
}

/// CPU time the UI thread spent per frame, for the performance readout.
#[derive(Default)]
pub struct FrameStats {
    recent: VecDeque<Duration>,
    /// Longest frame while a background job was running.
    pub max_while_busy: Duration,
    /// That frame split into applying results, uploading to the GPU, and drawing widgets.
    pub max_while_busy_parts: [Duration; 3],
    pub frames: u64,
    /// Frames over this are printed to standard error (`AppOptions::log_frames_over`).
    log_over: Option<Duration>,
    /// The main viewport's image count at the last frame (to tell whether it drew since).
    images_seen: u64,
}

impl FrameStats {
    const WINDOW: usize = 240;

    /// Records one frame: its CPU time in `App::ui`, that split into applying results, uploading
    /// and widgets, and the CPU time of the viewport's last offscreen draw (recorded in the
    /// previous frame's paint callback, which runs after `App::ui` returns).
    fn record(&mut self, elapsed: Duration, parts: [Duration; 3], render: Duration, busy: bool) {
        if let Some(limit) = self.log_over {
            if elapsed > limit || render > limit {
                let ms = |d: Duration| d.as_secs_f64() * 1e3;
                eprintln!(
                    "frame {}: {:.1} ms UI CPU (results {:.1}, upload {:.1}, widgets {:.1}), \
                     previous viewport draw {:.1} ms{}",
                    self.frames,
                    ms(elapsed),
                    ms(parts[0]),
                    ms(parts[1]),
                    ms(parts[2]),
                    ms(render),
                    if busy { ", working" } else { "" }
                );
            }
        }
        if self.recent.len() == Self::WINDOW {
            self.recent.pop_front();
        }
        self.recent.push_back(elapsed);
        if busy && elapsed > self.max_while_busy {
            self.max_while_busy = elapsed;
            self.max_while_busy_parts = parts;
        }
        self.frames += 1;
    }

    pub fn last(&self) -> Duration {
        self.recent.back().copied().unwrap_or_default()
    }
    pub fn mean(&self) -> Duration {
        if self.recent.is_empty() {
            return Duration::ZERO;
        }
        self.recent.iter().sum::<Duration>() / self.recent.len() as u32
    }
    pub fn max(&self) -> Duration {
        self.recent.iter().max().copied().unwrap_or_default()
    }
    pub fn reset_busy_max(&mut self) {
        self.max_while_busy = Duration::ZERO;
        self.max_while_busy_parts = [Duration::ZERO; 3];
    }
}

/// A summary of the app's state, for tests and the status line.
#[derive(Clone, Debug, Default)]
pub struct AppStatus {
    pub document: Option<PathBuf>,
    pub loading: bool,
    pub hierarchy_ready: bool,
    pub level_count: usize,
    pub level: usize,
    pub shown_vertices: usize,
    pub shown_faces: usize,
    /// Serial number of the faired result on record (changes with every new result).
    pub faired_serial: Option<u64>,
    /// The start level of that result.
    pub faired_level: Option<usize>,
    /// That result's measures are being computed on the measuring worker (not waiting).
    pub measuring: bool,
    /// Measurings given up because the view moved on (each is redone when the slider rests).
    pub measures_stopped: u64,
    pub volume_change: Option<f64>,
    pub rms_displacement: Option<f64>,
    pub error: Option<String>,
    pub message: Option<String>,
    pub images_drawn: u64,
}

pub struct App {
    settings: Settings,
    persistence: bool,
    document: Option<Document>,
    /// The file being loaded, while it loads.
    loading: Option<PathBuf>,
    load_generation: Generation,
    document_generation: Generation,
    hierarchy_generation: Generation,
    view_generation: Generation,
    /// View generation of the faired result on screen (newer results replace it, older don't).
    applied_view: u64,
    applied_level_view: u64,
    hierarchy_progress: SharedProgress,
    fair_progress: SharedProgress,
    fair_in_flight: bool,
    /// View generation of the newest fairing asked for.
    fair_view: u64,
    workspace: Arc<Mutex<MultiresWorkspace>>,
    io: Worker,
    compute: Worker,
    /// Measures faired results (surface distances need two BVHs per reference: 0.1-0.3 s on the
    /// bunny), so that the compute worker hands each result to the view at once and is free for
    /// the next slider value.
    measure: Worker,
    /// The measuring worker's own one-thread rayon pool (`None` if it could not be started: it
    /// then shares the global pool), so that the next slider value's fairing keeps the global
    /// pool (sharing it doubled the time to the next result on the bunny).
    measure_pool: Option<Arc<rayon::ThreadPool>>,
    /// The faired result to measure next; see [`MEASURE_DELAY`].
    measure_wanted: Option<MeasureRequest>,
    measures_stopped: u64,
    jobs: JobCounter,
    results_tx: Sender<(JobResult, JobTicket)>,
    results_rx: Receiver<(JobResult, JobTicket)>,
    dialog_open: bool,
    ctx: egui::Context,
    viewport: Option<Viewport3d>,
    viewport_before: Option<Viewport3d>,
    camera: OrbitCamera,
    shown: Option<Shown>,
    shown_before: Option<Shown>,
    /// Largest heat-map scalar uploaded per slot (the legend's and the colour map's top).
    heat_max: [Option<f32>; 2],
    /// The single view shows "before" instead of "after" (toggled with B).
    show_before: bool,
    shown_counts: (usize, usize),
    error: Option<String>,
    message: Option<String>,
    /// The typed path field for opening files.
    open_path: String,
    commands: Vec<Command>,
    next_serial: u64,
    frame_stats: FrameStats,
    /// [`AppOptions::exit_when_settled`], until it has fired.
    exit_when_settled: bool,
    /// Where the viewport was drawn in the last frame (points).
    viewport_rect: Option<egui::Rect>,
    /// Earlier and later document states (noise, applied results, loading).
    history: History<DocumentSnapshot>,
}

/// A faired result is measured once it has been on screen this long with no fairing in flight:
/// measuring takes a core for 0.1-0.3 s on the bunny (seconds on a 1M-face mesh), and while the
/// slider is dragged it would compete with the next value's fairing (on a 2-core machine one
/// slider step in ten then took 8 frames instead of 2-3). The numbers follow when the user
/// pauses.
const MEASURE_DELAY: Duration = Duration::from_millis(100);

/// A faired result waiting to be measured.
struct MeasureRequest {
    document: u64,
    serial: u64,
    positions: Arc<Vec<[f32; 3]>>,
    /// When the result arrived.
    arrived: Instant,
}

/// Memory the undo history may keep alive.
const HISTORY_BUDGET_BYTES: usize = 1 << 30;

impl App {
    /// The app as the window runs it: settings from eframe's storage when `persistence` is on.
    pub fn with_options(cc: &eframe::CreationContext<'_>, options: AppOptions) -> Self {
        let settings = if options.persistence {
            cc.storage
                .and_then(|storage| eframe::get_value::<Settings>(storage, Settings::STORAGE_KEY))
                .unwrap_or_default()
        } else {
            Settings::default()
        };
        let (results_tx, results_rx) = mpsc::channel();
        // Without threads the editor cannot work at all; failing to start one is fatal.
        let io = Worker::spawn("fairmesh-io").expect("cannot start the fairmesh-io thread");
        let compute =
            Worker::spawn("fairmesh-compute").expect("cannot start the fairmesh-compute thread");
        let measure =
            Worker::spawn("fairmesh-measure").expect("cannot start the fairmesh-measure thread");
        let measure_pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .thread_name(|_| "fairmesh-measure-pool".into())
            .build()
            .ok()
            .map(Arc::new);
        let file = options
            .file
            .unwrap_or_else(|| PathBuf::from(crate::bundled::BUNNY_PSEUDO_PATH));
        let mut app = Self {
            settings,
            persistence: options.persistence,
            document: None,
            loading: None,
            load_generation: Generation::default(),
            document_generation: Generation::default(),
            hierarchy_generation: Generation::default(),
            view_generation: Generation::default(),
            applied_view: 0,
            applied_level_view: 0,
            hierarchy_progress: SharedProgress::default(),
            fair_progress: SharedProgress::default(),
            fair_in_flight: false,
            fair_view: 0,
            workspace: Arc::new(Mutex::new(MultiresWorkspace::default())),
            io,
            compute,
            measure,
            measure_pool,
            measure_wanted: None,
            measures_stopped: 0,
            jobs: JobCounter::default(),
            results_tx,
            results_rx,
            dialog_open: false,
            ctx: cc.egui_ctx.clone(),
            viewport: (cc.wgpu_render_state.as_ref()).map(|s| Viewport3d::new(s, &cc.egui_ctx)),
            viewport_before: (cc.wgpu_render_state.as_ref())
                .map(|s| Viewport3d::new(s, &cc.egui_ctx)),
            camera: OrbitCamera::default(),
            shown: None,
            shown_before: None,
            heat_max: [None; 2],
            show_before: false,
            shown_counts: (0, 0),
            error: None,
            message: None,
            open_path: file.display().to_string(),
            commands: Vec::new(),
            next_serial: 0,
            frame_stats: FrameStats {
                log_over: options.log_frames_over,
                ..FrameStats::default()
            },
            exit_when_settled: options.exit_when_settled,
            viewport_rect: None,
            history: History::new(HISTORY_BUDGET_BYTES),
        };
        for viewport in app.viewports() {
            if let Some(bytes) = options.async_upload_bytes {
                viewport.set_async_upload_bytes(bytes);
            }
            if let Some(bytes) = options.max_buffer_bytes {
                viewport.cap_buffer_size(bytes);
            }
        }
        app.open(file);
        app
    }

    /// The app for tests: opens `file`, no persistence.
    pub fn new_for_test(cc: &eframe::CreationContext<'_>, file: impl Into<PathBuf>) -> Self {
        Self::with_options(
            cc,
            AppOptions {
                file: Some(file.into()),
                ..AppOptions::default()
            },
        )
    }

    /// Queues a command as if a widget had emitted it (applied at the end of the next frame).
    pub fn push_command(&mut self, command: Command) {
        self.commands.push(command);
    }

    /// No job running or waiting and every result applied.
    pub fn is_settled(&self) -> bool {
        self.jobs.in_flight() == 0
            && self.commands.is_empty()
            && self.measure_wanted.is_none()
            && !self.upload_pending()
    }

    /// Whether a viewport's background upload of a big mesh has not landed yet.
    fn upload_pending(&self) -> bool {
        self.viewports().any(Viewport3d::upload_pending)
    }

    /// The viewports there are (none without a wgpu render state).
    fn viewports(&self) -> impl Iterator<Item = &Viewport3d> {
        [&self.viewport, &self.viewport_before]
            .into_iter()
            .flatten()
    }

    pub fn frame_stats(&self) -> &FrameStats {
        &self.frame_stats
    }

    pub fn frame_stats_mut(&mut self) -> &mut FrameStats {
        &mut self.frame_stats
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Whether the single view shows "before" (the document's mesh) instead of the result.
    pub fn showing_before(&self) -> bool {
        self.show_before
    }

    /// The heat map's top value (the legend's range is 0 to this), while the heat map is shown.
    pub fn heat_map_top(&self) -> Option<f32> {
        self.heat_top()
    }

    /// Where the 3D view was drawn in the last frame, in points.
    pub fn viewport_rect(&self) -> Option<egui::Rect> {
        self.viewport_rect
    }

    pub fn camera(&self) -> &OrbitCamera {
        &self.camera
    }

    /// The document's mesh (as loaded, noisy, or an applied result).
    pub fn document_mesh(&self) -> Option<Arc<TriMesh>> {
        self.document.as_ref().map(|d| d.original.clone())
    }

    /// The mesh kept from before noise was injected.
    pub fn clean_mesh(&self) -> Option<Arc<TriMesh>> {
        self.document.as_ref().and_then(|d| d.clean.clone())
    }

    /// Positions of the faired result on record.
    pub fn faired_positions(&self) -> Option<Arc<Vec<[f32; 3]>>> {
        self.document
            .as_ref()
            .and_then(|d| d.faired.as_ref())
            .map(|f| f.positions.clone())
    }

    /// The faired result's numbers against the document mesh and against the clean mesh.
    pub fn faired_measures(&self) -> (Option<Measures>, Option<Measures>) {
        let faired = self.document.as_ref().and_then(|d| d.faired.as_ref());
        (
            faired.and_then(|f| f.against_document.clone()),
            faired.and_then(|f| f.against_clean.clone()),
        )
    }

    /// The document's mesh measured against the clean mesh (after noise).
    pub fn noise_measures(&self) -> Option<Measures> {
        self.document.as_ref().and_then(|d| d.against_clean.clone())
    }

    /// Labels of what undo and redo would do now.
    pub fn undo_redo_labels(&self) -> (Option<String>, Option<String>) {
        (
            self.history.undo_label().map(str::to_owned),
            self.history.redo_label().map(str::to_owned),
        )
    }

    pub fn status(&self) -> AppStatus {
        let document = self.document.as_ref();
        let faired = document.and_then(|d| d.faired.as_ref());
        AppStatus {
            document: document.map(|d| d.path.clone()),
            loading: self.loading.is_some(),
            hierarchy_ready: document.and_then(Document::level_count).is_some(),
            level_count: document.and_then(Document::level_count).unwrap_or(0),
            level: document.map(|d| d.level).unwrap_or(0),
            shown_vertices: self.shown_counts.0,
            shown_faces: self.shown_counts.1,
            faired_serial: faired.map(|f| f.serial),
            faired_level: faired.map(|f| f.level),
            measuring: faired.is_some_and(|f| f.measures_pending) && self.measure_wanted.is_none(),
            measures_stopped: self.measures_stopped,
            volume_change: faired.map(|f| f.volume_change),
            rms_displacement: faired.map(|f| f.rms_displacement),
            error: self.error.clone(),
            message: self.message.clone(),
            images_drawn: self.viewport.as_ref().map_or(0, Viewport3d::images_drawn),
        }
    }

    fn busy(&self) -> bool {
        self.jobs.in_flight() > 0 || self.measure_wanted.is_some()
    }

    /// Hands the waiting result to the measuring worker once no fairing is in flight and it has
    /// waited [`MEASURE_DELAY`]; until then asks for a frame when the delay is up.
    fn start_waiting_measure(&mut self) {
        let Some(request) = &self.measure_wanted else {
            return;
        };
        let waited = request.arrived.elapsed();
        if self.fair_in_flight {
            return;
        }
        if waited < MEASURE_DELAY {
            self.ctx.request_repaint_after(MEASURE_DELAY - waited);
            return;
        }
        if let Some(request) = self.measure_wanted.take() {
            self.request_measures(request.document, request.serial, request.positions);
        }
    }

    fn send_result(
        tx: &Sender<(JobResult, JobTicket)>,
        ctx: &egui::Context,
        result: JobResult,
        ticket: JobTicket,
    ) {
        // The receiver is gone only when the app closed; nothing left to tell.
        let _ = tx.send((result, ticket));
        ctx.request_repaint();
    }

    // ---- commands -------------------------------------------------------------------------

    fn apply(&mut self, command: Command) {
        match command {
            Command::Open(path) => self.open(path),
            Command::OpenDialog => self.open_dialog(DialogPurpose::Open),
            Command::Export(path) => self.export(path),
            Command::ExportDialog => self.open_dialog(DialogPurpose::Export),
            Command::FitView => self.fit_view(),
            Command::SetLevel(level) => {
                if let Some(document) = &mut self.document {
                    let top = document.level_count().unwrap_or(1).saturating_sub(1);
                    document.level = level.min(top);
                    document.applied = false;
                    self.settings
                        .remember_start_level(&document.path, document.level);
                }
                self.refresh_view();
            }
            Command::Refair => {
                if let Some(document) = &mut self.document {
                    document.applied = false;
                }
                self.refresh_view();
            }
            Command::SetViewMode(mode) => {
                self.settings.view_mode = mode;
                self.refresh_view();
            }
            Command::CancelHierarchy => {
                self.hierarchy_generation.bump();
                if let Some(document) = &mut self.document {
                    if matches!(document.hierarchy, HierarchyState::Building) {
                        document.hierarchy = HierarchyState::Failed("cancelled".into());
                    }
                }
            }
            Command::RebuildHierarchy => self.start_hierarchy(),
            Command::DismissError => self.error = None,
            Command::AddNoise => self.add_noise(),
            Command::ApplyResult => self.apply_faired_result(),
            Command::Undo => self.undo(),
            Command::Redo => self.redo(),
            Command::ExportLevels => self.export_levels(),
        }
    }

    /// Makes `snapshot` the document. With `record`, the current document goes on the undo
    /// stack under that label first. Jobs of the replaced document become stale; the hierarchy
    /// is rebuilt unless the snapshot kept one.
    fn install(&mut self, snapshot: DocumentSnapshot, record: Option<String>) {
        if let (Some(label), Some(current)) = (record, &self.document) {
            let mut previous = current.snapshot();
            previous.camera = Some(self.camera);
            self.history.record(label, previous);
        }
        // The camera follows the document: another file's comes back with it (undo and redo
        // across an Open), or the view is fitted to it; the same file's keeps the user's view.
        let other_file = self
            .document
            .as_ref()
            .is_none_or(|current| current.path != snapshot.path);
        let camera = snapshot.camera;
        let previous = self.document.take();
        // Freeing a big mesh and its hierarchy takes tens of milliseconds: not on the UI thread
        // (what the history keeps is shared, so this frees only what nobody else holds).
        if previous.is_some() {
            self.io.submit(move || drop(previous));
        }
        let generation = self.document_generation.bump();
        let document = Document::from_snapshot(snapshot, generation);
        let needs_build = matches!(document.hierarchy, HierarchyState::Building);
        self.document = Some(document);
        self.applied_view = 0;
        self.applied_level_view = 0;
        self.fair_in_flight = false;
        if other_file {
            match camera {
                Some(camera) => self.camera = camera,
                None => self.fit_view(),
            }
        }
        if needs_build {
            self.start_hierarchy();
        } else {
            // Whatever was building belonged to the document just replaced.
            self.hierarchy_generation.bump();
            self.refresh_view();
        }
    }

    /// Adds noise to a copy of the document's mesh on the io worker (see `JobResult::Noised`).
    fn add_noise(&mut self) {
        let Some(document) = &self.document else {
            self.error = Some("Nothing to add noise to: no mesh is loaded".into());
            return;
        };
        let options = self.settings.noise_options();
        if options.sigma <= 0.0 {
            self.error = Some("Noise: sigma must be above 0".into());
            return;
        }
        let mesh = document.original.clone();
        let clean = document.clean.clone().unwrap_or_else(|| mesh.clone());
        let document = document.generation;
        let document_generation = self.document_generation.clone();
        let label = format!(
            "Noise σ {} × edge, seed {}, {:?}",
            options.sigma, options.seed, options.mode
        );
        self.message = Some(format!("Adding noise ({label}) …"));
        let (tx, ctx, ticket) = (self.results_tx.clone(), self.ctx.clone(), self.jobs.start());
        self.io.submit(move || {
            if !document_generation.is_current(document) {
                return;
            }
            let mut noisy = mesh.as_ref().clone();
            crate::noise::add_noise(&mut noisy, &options);
            let against_clean = Box::new(Measures::of(&clean, &noisy));
            let message = JobResult::Noised {
                document,
                label,
                noisy: Arc::new(noisy),
                clean,
                against_clean,
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// "Apply": the faired result becomes the document's mesh (undoable).
    fn apply_faired_result(&mut self) {
        let Some(document) = &self.document else {
            return;
        };
        let Some(faired) = &document.faired else {
            self.error = Some("Nothing to apply: no faired result yet".into());
            return;
        };
        let triangles = match &document.hierarchy {
            HierarchyState::Ready { hierarchy, .. } => hierarchy.base_mesh().triangles.clone(),
            _ => document.original.triangles.clone(),
        };
        if triangles
            .iter()
            .flatten()
            .any(|&c| c as usize >= faired.positions.len())
        {
            self.error = Some("The faired result does not fit the mesh".into());
            return;
        }
        let label = format!("Apply result ({})", faired.method.describe(faired.level));
        let mut snapshot = document.snapshot();
        snapshot.mesh = Arc::new(TriMesh {
            positions: faired.positions.as_ref().clone(),
            triangles,
        });
        snapshot.against_clean = faired.against_clean.clone();
        snapshot.hierarchy = None;
        snapshot.applied = true;
        self.install(snapshot, Some(label.clone()));
        self.message = Some(format!("{label}: the result is now the input mesh"));
    }

    /// The current document as undo and redo keep it, with the view of it.
    fn current_snapshot(&self) -> Option<DocumentSnapshot> {
        let mut snapshot = self.document.as_ref()?.snapshot();
        snapshot.camera = Some(self.camera);
        Some(snapshot)
    }

    fn undo(&mut self) {
        let Some(current) = self.current_snapshot() else {
            return;
        };
        let label = self.history.undo_label().map(str::to_owned);
        if let (Ok(previous), Some(label)) = (self.history.undo(current), label) {
            self.install(previous, None);
            self.message = Some(format!("Undone: {label}"));
        }
    }

    fn redo(&mut self) {
        let Some(current) = self.current_snapshot() else {
            return;
        };
        let label = self.history.redo_label().map(str::to_owned);
        if let (Ok(next), Some(label)) = (self.history.redo(current), label) {
            self.install(next, None);
            self.message = Some(format!("Redone: {label}"));
        }
    }

    /// Starts loading `path` on the io worker; the current mesh stays until it arrives.
    fn open(&mut self, path: PathBuf) {
        let generation = self.load_generation.bump();
        self.loading = Some(path.clone());
        self.open_path = path.display().to_string();
        let (tx, ctx, ticket) = (self.results_tx.clone(), self.ctx.clone(), self.jobs.start());
        self.io.submit(move || {
            let started = Instant::now();
            // The bundled bunny comes from the binary itself; it is named by its file name, so
            // its default export is `bunny00_faired.glb` in the working directory.
            let (path, loaded) = if crate::bundled::is_bunny_pseudo_path(&path) {
                let loaded = crate::bundled::load_bunny(&crate::io::LoadOptions::default());
                (PathBuf::from(crate::bundled::BUNNY_FILE_NAME), loaded)
            } else {
                let loaded = crate::io::load(&path);
                (path, loaded)
            };
            let result = loaded
                .map_err(|error| error.to_string())
                .and_then(|loaded| {
                    if loaded.mesh.triangles.is_empty() {
                        Err(format!("{}: the file holds no triangles", path.display()))
                    } else {
                        // The topology is dropped here, on the io worker.
                        Ok(Box::new(LoadedMesh {
                            mesh: loaded.mesh,
                            report: loaded.report,
                            source: loaded.source,
                        }))
                    }
                });
            let message = JobResult::Loaded {
                load_generation: generation,
                path,
                result,
                elapsed: started.elapsed(),
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    fn start_hierarchy(&mut self) {
        let Some(document) = &mut self.document else {
            return;
        };
        let generation = self.hierarchy_generation.bump();
        document.hierarchy = HierarchyState::Building;
        self.hierarchy_progress.set(0.0);
        let mesh = document.original.clone();
        let document_generation = document.generation;
        let hierarchy_generation = self.hierarchy_generation.clone();
        let progress_out = self.hierarchy_progress.clone();
        let (tx, ctx, ticket) = (self.results_tx.clone(), self.ctx.clone(), self.jobs.start());
        self.compute.submit(move || {
            if !hierarchy_generation.is_current(generation) {
                return;
            }
            let started = Instant::now();
            let mut progress = |fraction: f32| {
                progress_out.set(fraction);
                hierarchy_generation.is_current(generation)
            };
            let result =
                hierarchy::build_hierarchy(&mesh, &HierarchyOptions::default(), &mut progress).map(
                    |built| {
                        // Compared here, not on the UI thread (millions of triangles).
                        let matches = built.base_mesh().triangles == mesh.triangles;
                        (Arc::new(built), matches)
                    },
                );
            let message = JobResult::Hierarchy {
                document: document_generation,
                hierarchy: generation,
                result,
                elapsed: started.elapsed(),
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// Asks for what the current view mode needs at the current level and options.
    fn refresh_view(&mut self) {
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
        let view = self.view_generation.bump();
        match self.settings.view_mode {
            ViewMode::Level => self.request_level_mesh(hierarchy, document_generation, level, view),
            // An applied result is shown as it is until a setting changes.
            ViewMode::Faired | ViewMode::Original if applied => {}
            ViewMode::Faired | ViewMode::Original => {
                self.request_fairing(hierarchy, document_generation, level, view)
            }
        }
    }

    /// Sets up every level of a new hierarchy (connectivity and fairing operator) on the compute
    /// worker, after the view's first fairing (already queued), so that moving the level slider
    /// later never waits for a level's set-up (bunny00: about 0.2 s for all 20 levels; a
    /// 1.2M-face mesh: about 2 s). One idle job per level, finest first: a fairing the user asks
    /// for meanwhile runs before the next level's set-up, so it waits for one level at most.
    fn prepare_levels(&mut self, hierarchy: Arc<hierarchy::Hierarchy>, document: u64) {
        for level in 1..hierarchy.level_count() {
            let options = self.settings.multires_options(level);
            let document_generation = self.document_generation.clone();
            let workspace = self.workspace.clone();
            let hierarchy = hierarchy.clone();
            let ticket = self.jobs.start();
            self.compute.submit_idle(move || {
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

    fn request_fairing(
        &mut self,
        hierarchy: Arc<hierarchy::Hierarchy>,
        document: u64,
        level: usize,
        view: u64,
    ) {
        let options = self.settings.multires_options(level);
        let baseline = self.settings.baseline_options();
        let method = self.settings.method;
        let document_generation = self.document_generation.clone();
        let progress_out = self.fair_progress.clone();
        let workspace = self.workspace.clone();
        let (tx, ctx, ticket) = (self.results_tx.clone(), self.ctx.clone(), self.jobs.start());
        self.fair_in_flight = true;
        self.fair_view = view;
        self.fair_progress.set(0.0);
        self.compute.submit_latest("fair", move || {
            if !document_generation.is_current(document) {
                return;
            }
            let started = Instant::now();
            // A newer slider value does not cancel this run: while dragging, finished runs are
            // what keeps the view moving. Only a new document makes it pointless.
            let mut progress = |fraction: f32| {
                progress_out.set(fraction);
                document_generation.is_current(document)
            };
            let positions = match &baseline {
                // A baseline smooths the document's mesh itself; the level does not apply.
                Some(method) => {
                    let mut mesh = hierarchy.base_mesh().clone();
                    let topology = crate::Topology::build(&mesh);
                    crate::fairing::fair(&mut mesh, &topology, method);
                    progress(1.0);
                    Some(mesh.positions)
                }
                None => {
                    let mut workspace = workspace.lock().unwrap_or_else(PoisonError::into_inner);
                    multires::fair_multires(&hierarchy, &options, &mut workspace, &mut progress)
                }
            };
            let result = positions.map(|positions| {
                let (volume_change, rms_displacement) =
                    compare_to_base(hierarchy.base_mesh(), &positions);
                Faired {
                    positions,
                    volume_change,
                    rms_displacement,
                    elapsed: started.elapsed(),
                    method,
                }
            });
            let message = JobResult::Faired {
                document,
                view,
                level,
                result,
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// Measures the faired result `serial` against the document's mesh and the clean one on the
    /// measuring worker (a newer result replaces a waiting request).
    fn request_measures(&mut self, document: u64, serial: u64, positions: Arc<Vec<[f32; 3]>>) {
        let Some(current) = self.document.as_ref().filter(|d| d.generation == document) else {
            return;
        };
        let HierarchyState::Ready { hierarchy, .. } = &current.hierarchy else {
            return;
        };
        let hierarchy = hierarchy.clone();
        let clean = current.clean.clone();
        let pool = self.measure_pool.clone();
        let document_generation = self.document_generation.clone();
        // A slider move, an option or a view change bumps the view generation: the result
        // being measured is then about to be replaced, so measuring it stops and gives the
        // cores to the next fairing.
        let (view_generation, view) =
            (self.view_generation.clone(), self.view_generation.current());
        let (tx, ctx, ticket) = (self.results_tx.clone(), self.ctx.clone(), self.jobs.start());
        self.measure.submit_latest("measure", move || {
            if !document_generation.is_current(document) {
                return;
            }
            let started = Instant::now();
            let base = hierarchy.base_mesh();
            let faired = TriMesh {
                positions: positions.as_ref().clone(),
                triangles: base.triangles.clone(),
            };
            let stop =
                || !view_generation.is_current(view) || !document_generation.is_current(document);
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

    fn request_level_mesh(
        &mut self,
        hierarchy: Arc<hierarchy::Hierarchy>,
        document: u64,
        level: usize,
        view: u64,
    ) {
        let document_generation = self.document_generation.clone();
        let (tx, ctx, ticket) = (self.results_tx.clone(), self.ctx.clone(), self.jobs.start());
        self.compute.submit_latest("level", move || {
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

    fn export(&mut self, path: PathBuf) {
        let Some(document) = &self.document else {
            self.error = Some("Nothing to export: no mesh is loaded".into());
            return;
        };
        if path.as_os_str().is_empty() {
            self.error = Some("Export: type a file path first".into());
            return;
        }
        // The faired positions go with M0's triangles (the hierarchy's base mesh).
        let file_source = document.source.clone();
        let (positions, triangles_source) = match (&document.faired, &document.hierarchy) {
            (Some(faired), HierarchyState::Ready { hierarchy, .. }) => (
                Some(faired.positions.clone()),
                SharedMesh::Base(hierarchy.clone()),
            ),
            _ => (None, SharedMesh::Mesh(document.original.clone())),
        };
        let (tx, ctx, ticket) = (self.results_tx.clone(), self.ctx.clone(), self.jobs.start());
        self.message = Some(format!("Exporting to {} …", path.display()));
        self.io.submit(move || {
            let started = Instant::now();
            let source = triangles_source.mesh();
            let mesh = match positions {
                Some(positions) if positions.len() == source.positions.len() => TriMesh {
                    positions: positions.as_ref().clone(),
                    triangles: source.triangles.clone(),
                },
                _ => source.clone(),
            };
            let result = crate::io::save_with_source(&path, &mesh, &file_source)
                .map(|report| report.warnings)
                .map_err(|error| error.to_string());
            let message = JobResult::Exported {
                path,
                result,
                elapsed: started.elapsed(),
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    /// The folder the level chain goes to: the typed one, or `<stem>_levels` next to the file.
    pub fn levels_folder(&self) -> Option<PathBuf> {
        let typed = self.settings.levels_folder.trim();
        if !typed.is_empty() {
            return Some(PathBuf::from(typed));
        }
        let path = &self.document.as_ref()?.path;
        let stem = path.file_stem()?.to_string_lossy().into_owned();
        Some(path.with_file_name(format!("{stem}_levels")))
    }

    /// Writes levels `levels_from..=levels_to` as `<stem>_L<level>.glb` on the io worker.
    fn export_levels(&mut self) {
        let Some(document) = &self.document else {
            self.error = Some("Nothing to export: no mesh is loaded".into());
            return;
        };
        let HierarchyState::Ready { hierarchy, .. } = &document.hierarchy else {
            self.error = Some("Export levels: the hierarchy is not built yet".into());
            return;
        };
        let Some(folder) = self.levels_folder() else {
            self.error = Some("Export levels: type a folder first".into());
            return;
        };
        let hierarchy = hierarchy.clone();
        let file_source = document.source.clone();
        let top = hierarchy.level_count().saturating_sub(1);
        let to = self.settings.levels_to.min(top);
        let from = self.settings.levels_from.min(to);
        let stem = document
            .path
            .file_stem()
            .map_or_else(|| "mesh".to_owned(), |s| s.to_string_lossy().into_owned());
        self.message = Some(format!(
            "Exporting levels M{from} … M{to} to {} …",
            folder.display()
        ));
        let (tx, ctx, ticket) = (self.results_tx.clone(), self.ctx.clone(), self.jobs.start());
        self.io.submit(move || {
            let started = Instant::now();
            let result = std::fs::create_dir_all(&folder)
                .map_err(|error| format!("cannot create {}: {error}", folder.display()))
                .and_then(|()| {
                    (from..=to)
                        .map(|level| {
                            let path = folder.join(format!("{stem}_L{level:02}.glb"));
                            crate::io::save_with_source(
                                &path,
                                &hierarchy.level_mesh(level),
                                &file_source,
                            )
                            .map(|report| (path, report.warnings))
                            .map_err(|error| error.to_string())
                        })
                        .collect::<Result<Vec<_>, _>>()
                })
                .map(|written| {
                    let mut warnings: Vec<String> = written
                        .iter()
                        .flat_map(|(_, w)| w.iter().cloned())
                        .collect();
                    // Every coarse level loses the same things: say it once.
                    warnings.dedup();
                    (
                        written.into_iter().map(|(path, _)| path).collect(),
                        warnings,
                    )
                });
            let message = JobResult::LevelsExported {
                folder,
                result,
                elapsed: started.elapsed(),
            };
            Self::send_result(&tx, &ctx, message, ticket);
        });
    }

    fn open_dialog(&mut self, purpose: DialogPurpose) {
        if self.dialog_open {
            return;
        }
        let start_dir = self.settings.last_dir.clone().or_else(|| {
            self.document
                .as_ref()
                .and_then(|d| d.path.parent().map(Path::to_path_buf))
        });
        let default_name = self.document.as_ref().and_then(|d| {
            PathBuf::from(&d.export_path)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
        });
        let (tx, ctx) = (self.results_tx.clone(), self.ctx.clone());
        let ticket = self.jobs.start();
        let spawned = std::thread::Builder::new()
            .name("fairmesh-dialog".into())
            .spawn(move || {
                let mut dialog = rfd::FileDialog::new();
                if let Some(dir) = start_dir {
                    dialog = dialog.set_directory(dir);
                }
                let path = match purpose {
                    DialogPurpose::Open => dialog
                        .add_filter("Meshes", &["obj", "glb", "gltf", "ply", "stl", "off"])
                        .add_filter("All files", &["*"])
                        .pick_file(),
                    DialogPurpose::Export => {
                        if let Some(name) = default_name {
                            dialog = dialog.set_file_name(name);
                        }
                        dialog
                            .add_filter("glTF binary", &["glb"])
                            .add_filter("glTF", &["gltf"])
                            .add_filter("Wavefront OBJ", &["obj"])
                            .add_filter("PLY", &["ply"])
                            .add_filter("STL", &["stl"])
                            .add_filter("OFF", &["off"])
                            .save_file()
                    }
                };
                Self::send_result(&tx, &ctx, JobResult::DialogPicked { purpose, path }, ticket);
            });
        match spawned {
            Ok(_) => self.dialog_open = true,
            Err(error) => self.error = Some(format!("Cannot open a file dialog: {error}")),
        }
    }

    fn fit_view(&mut self) {
        let Some(document) = &self.document else {
            return;
        };
        let (lo, hi) = match (self.settings.view_mode, &document.level_mesh) {
            (ViewMode::Level, Some((_, mesh))) => state::bounds_of(&mesh.positions),
            _ => document.bounds,
        };
        // Each side-by-side half is half the view's width.
        let aspect = self.viewport_rect.map_or(1.0, |rect| {
            let width = match self.settings.compare {
                CompareView::SideBySide => rect.width() * 0.5,
                CompareView::Single | CompareView::Split => rect.width(),
            };
            width / rect.height().max(1.0)
        });
        self.camera.fit(
            glam::Vec3::from_array(lo),
            glam::Vec3::from_array(hi),
            aspect,
        );
    }

    // ---- results --------------------------------------------------------------------------

    fn poll_results(&mut self) {
        while let Ok((result, ticket)) = self.results_rx.try_recv() {
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
            } => {
                if !self.load_generation.is_current(load_generation) {
                    return;
                }
                self.loading = None;
                match result {
                    Ok(loaded) => {
                        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                            self.settings.last_dir = Some(dir.to_path_buf());
                        }
                        let loaded = *loaded;
                        let name = path
                            .file_name()
                            .map(|n| n.to_string_lossy().into_owned())
                            .unwrap_or_else(|| path.display().to_string());
                        let snapshot = DocumentSnapshot {
                            export_path: state::default_export_path(&path).display().to_string(),
                            path,
                            mesh: Arc::new(loaded.mesh),
                            source: loaded.source,
                            clean: None,
                            against_clean: None,
                            report: loaded.report,
                            load_time: elapsed,
                            level: 0,
                            hierarchy: None,
                            applied: false,
                            camera: None,
                        };
                        self.install(snapshot, Some(format!("Open {name}")));
                        if let Some(document) = &mut self.document {
                            document.pick_start_level = true;
                        }
                        self.error = None;
                        self.fit_view();
                    }
                    Err(error) => {
                        self.error = Some(format!("Could not open the file: {error}"));
                    }
                }
            }
            JobResult::Hierarchy {
                document,
                hierarchy,
                result,
                elapsed,
            } => {
                if !self.hierarchy_generation.is_current(hierarchy) {
                    return;
                }
                let Some(current) = self.document.as_mut().filter(|d| d.generation == document)
                else {
                    return;
                };
                match result {
                    Ok((hierarchy, base_matches_original)) => {
                        let levels = (0..hierarchy.level_count())
                            .map(|l| hierarchy.level_info(l))
                            .collect::<Vec<_>>();
                        current.level = if current.pick_start_level {
                            current.pick_start_level = false;
                            self.settings.start_level_for(&current.path, levels.len())
                        } else {
                            current.level.min(levels.len().saturating_sub(1))
                        };
                        let warm = hierarchy.clone();
                        current.hierarchy = HierarchyState::Ready {
                            base_matches_original,
                            hierarchy,
                            levels,
                            build_time: elapsed,
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
            JobResult::Faired {
                document,
                view,
                level,
                result,
            } => {
                // The newest fairing asked for has answered (a view change to the level mesh
                // since does not make it any less finished).
                if view >= self.fair_view {
                    self.fair_in_flight = false;
                }
                let Some(current) = self.document.as_mut().filter(|d| d.generation == document)
                else {
                    return;
                };
                // Older than what is on screen: stale.
                if view <= self.applied_view {
                    return;
                }
                if let Some(faired) = result {
                    self.applied_view = view;
                    self.next_serial += 1;
                    // The previous result's measures stay on screen until this one's arrive.
                    let previous = current.faired.take();
                    let positions = Arc::new(faired.positions);
                    current.faired = Some(FairedResult {
                        positions: positions.clone(),
                        level,
                        method: faired.method,
                        volume_change: faired.volume_change,
                        rms_displacement: faired.rms_displacement,
                        elapsed: faired.elapsed,
                        serial: self.next_serial,
                        against_document: previous
                            .as_ref()
                            .and_then(|p| p.against_document.clone()),
                        against_clean: previous.and_then(|p| p.against_clean),
                        measure_time: Duration::ZERO,
                        measures_pending: true,
                    });
                    self.measure_wanted = Some(MeasureRequest {
                        document,
                        serial: self.next_serial,
                        positions,
                        arrived: Instant::now(),
                    });
                }
            }
            JobResult::Measured {
                document,
                serial,
                against_document,
                against_clean,
                measure_time,
            } => {
                let Some(faired) = self
                    .document
                    .as_mut()
                    .filter(|d| d.generation == document)
                    .and_then(|d| d.faired.as_mut())
                    .filter(|f| f.serial == serial)
                else {
                    return;
                };
                faired.against_document = against_document;
                faired.against_clean = against_clean;
                faired.measure_time = measure_time;
                faired.measures_pending = false;
            }
            JobResult::MeasureStopped {
                document,
                serial,
                positions,
            } => {
                self.measures_stopped += 1;
                let still_shown = self
                    .document
                    .as_ref()
                    .filter(|d| d.generation == document)
                    .and_then(|d| d.faired.as_ref())
                    .is_some_and(|f| f.serial == serial);
                // A newer result has its own request already; this one is measured again.
                if still_shown && self.measure_wanted.is_none() {
                    self.measure_wanted = Some(MeasureRequest {
                        document,
                        serial,
                        positions,
                        arrived: Instant::now(),
                    });
                }
            }
            JobResult::LevelMesh {
                document,
                view,
                level,
                mesh,
            } => {
                let Some(current) = self.document.as_mut().filter(|d| d.generation == document)
                else {
                    return;
                };
                if view <= self.applied_level_view {
                    return;
                }
                self.applied_level_view = view;
                current.level_mesh = Some((level, mesh));
            }
            JobResult::Noised {
                document,
                label,
                noisy,
                clean,
                against_clean,
            } => {
                let Some(current) = self.document.as_ref().filter(|d| d.generation == document)
                else {
                    return;
                };
                let mut snapshot = current.snapshot();
                snapshot.mesh = noisy;
                snapshot.clean = Some(clean);
                snapshot.against_clean = Some(*against_clean);
                snapshot.hierarchy = None;
                snapshot.applied = false;
                self.install(snapshot, Some(label.clone()));
                self.message = Some(format!(
                    "{label}: the mesh before the noise is kept as the clean mesh"
                ));
            }
            JobResult::Exported {
                path,
                result,
                elapsed,
            } => match result {
                Ok(warnings) => {
                    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                        self.settings.last_dir = Some(dir.to_path_buf());
                    }
                    self.message = Some(format!(
                        "Exported to {} ({:.2} s){}",
                        path.display(),
                        elapsed.as_secs_f64(),
                        notes(&warnings)
                    ));
                }
                Err(error) => {
                    self.message = None;
                    self.error = Some(format!("Export failed: {error}"));
                }
            },
            JobResult::LevelsExported {
                folder,
                result,
                elapsed,
            } => match result {
                Ok((paths, warnings)) => {
                    self.message = Some(format!(
                        "Exported {} levels to {} ({:.2} s){}",
                        paths.len(),
                        folder.display(),
                        elapsed.as_secs_f64(),
                        notes(&warnings)
                    ));
                }
                Err(error) => {
                    self.message = None;
                    self.error = Some(format!("Level export failed: {error}"));
                }
            },
            JobResult::DialogPicked { purpose, path } => {
                self.dialog_open = false;
                match (purpose, path) {
                    (DialogPurpose::Open, Some(path)) => self.open(path),
                    (DialogPurpose::Export, Some(path)) => {
                        if let Some(document) = &mut self.document {
                            document.export_path = path.display().to_string();
                        }
                        self.export(path);
                    }
                    (_, None) => {
                        self.message = Some(
                            "No file chosen (if no dialog appeared, type a path instead)".into(),
                        );
                    }
                }
            }
        }
    }

    // ---- viewport -------------------------------------------------------------------------

    /// The heat map's reference now: `None` when it is off; the clean mesh only when there is one.
    fn heat_reference(&self) -> Option<HeatReference> {
        if !self.settings.heat_map {
            return None;
        }
        let has_clean = self.document.as_ref().is_some_and(|d| d.clean.is_some());
        Some(match self.settings.heat_reference {
            HeatReference::Clean if has_clean => HeatReference::Clean,
            _ => HeatReference::Document,
        })
    }

    /// Whether the before viewport is on screen.
    fn before_needed(&self) -> bool {
        self.settings.compare != CompareView::Single || self.show_before
    }

    /// What a viewport should show now: for the main one the view mode's mesh when it exists,
    /// otherwise the last good mesh of this document, otherwise the loaded mesh; for the before
    /// one the document's mesh.
    fn wanted_mesh(&self, slot: Slot) -> Option<Shown> {
        let document = self.document.as_ref()?;
        let heat = self.heat_reference();
        if slot == Slot::Before {
            return Some(Shown {
                document: document.generation,
                what: ShownMesh::Original,
                heat,
            });
        }
        let previous = self
            .shown
            .filter(|s| s.document == document.generation)
            .map(|s| s.what);
        let what = match self.settings.view_mode {
            ViewMode::Original => ShownMesh::Original,
            ViewMode::Faired => match &document.faired {
                Some(faired) => ShownMesh::Faired {
                    serial: faired.serial,
                },
                None => ShownMesh::Original,
            },
            ViewMode::Level => match &document.level_mesh {
                Some((level, _)) => ShownMesh::Level { level: *level },
                None => previous.unwrap_or(ShownMesh::Original),
            },
        };
        Some(Shown {
            document: document.generation,
            what,
            heat,
        })
    }

    /// Distance of each vertex of `what` from the heat map's reference (`None`: no heat map for
    /// that mesh, as for level meshes, or not computed yet).
    fn heat_scalars(&self, what: ShownMesh, reference: HeatReference) -> Option<Arc<Vec<f32>>> {
        let document = self.document.as_ref()?;
        match what {
            ShownMesh::Faired { .. } => {
                let faired = document.faired.as_ref()?;
                let measures = match reference {
                    HeatReference::Clean => faired.against_clean.as_ref(),
                    HeatReference::Document => faired.against_document.as_ref(),
                }?;
                Some(measures.vertex_distances.clone())
            }
            ShownMesh::Original => match reference {
                HeatReference::Clean => document
                    .against_clean
                    .as_ref()
                    .map(|m| m.vertex_distances.clone()),
                // The document's mesh is its own reference: zero everywhere.
                HeatReference::Document => {
                    Some(Arc::new(vec![0.0; document.original.vertex_count()]))
                }
            },
            ShownMesh::Level { .. } => None,
        }
    }

    fn sync_viewport(&mut self) {
        self.sync_slot(Slot::Main);
        if self.before_needed() {
            self.sync_slot(Slot::Before);
        }
    }

    /// Uploads the wanted mesh (and heat-map scalars) when they differ from what is on the GPU.
    fn sync_slot(&mut self, slot: Slot) {
        let Some(wanted) = self.wanted_mesh(slot) else {
            return;
        };
        let shown = match slot {
            Slot::Main => self.shown,
            Slot::Before => self.shown_before,
        };
        if shown == Some(wanted) {
            return;
        }
        let Some(document) = &self.document else {
            return;
        };
        let viewport = match slot {
            Slot::Main => self.viewport.as_ref(),
            Slot::Before => self.viewport_before.as_ref(),
        };
        let mesh_changed =
            shown.is_none_or(|s| (s.document, s.what) != (wanted.document, wanted.what));
        let mut counts = None;
        if mesh_changed {
            let base = match &document.hierarchy {
                HierarchyState::Ready {
                    hierarchy,
                    base_matches_original,
                    ..
                } => Some((hierarchy.clone(), *base_matches_original)),
                _ => None,
            };
            let matches = base.as_ref().is_none_or(|b| b.1);
            let same_connectivity = shown.is_some_and(|shown| {
                shown.document == wanted.document
                    && shown.what.connectivity(matches) == wanted.what.connectivity(matches)
            });
            let source = match wanted.what {
                ShownMesh::Original => ViewMesh {
                    connectivity: SharedMesh::Mesh(document.original.clone()),
                    positions: None,
                },
                ShownMesh::Faired { .. } => {
                    let Some(faired) = &document.faired else {
                        return;
                    };
                    let connectivity = match &base {
                        Some((hierarchy, false)) => SharedMesh::Base(hierarchy.clone()),
                        _ => SharedMesh::Mesh(document.original.clone()),
                    };
                    ViewMesh {
                        connectivity,
                        positions: Some(faired.positions.clone()),
                    }
                }
                ShownMesh::Level { .. } => {
                    let Some((_, mesh)) = &document.level_mesh else {
                        return;
                    };
                    ViewMesh {
                        connectivity: SharedMesh::Mesh(mesh.clone()),
                        positions: None,
                    }
                }
            };
            counts = Some((source.positions().len(), source.triangles().len()));
            if let Some(viewport) = viewport {
                if !(same_connectivity && viewport.set_positions(source.positions())) {
                    viewport.set_mesh(Arc::new(source));
                }
            }
        }
        let mut heat_max = None;
        if let Some(reference) = wanted.heat {
            if let Some(scalars) = self.heat_scalars(wanted.what, reference) {
                if viewport.is_none_or(|v| v.set_scalars(&scalars)) {
                    heat_max = Some(heat_map_top(&scalars));
                }
            }
        }
        self.heat_max[slot as usize] = heat_max;
        match slot {
            Slot::Main => {
                if let Some(counts) = counts {
                    self.shown_counts = counts;
                }
                self.shown = Some(wanted);
            }
            Slot::Before => self.shown_before = Some(wanted),
        }
    }

    /// The heat map's top value for the slots on screen (shared, so the colours compare).
    fn heat_top(&self) -> Option<f32> {
        self.heat_reference()?;
        let main = self.heat_max[Slot::Main as usize];
        let before = self
            .before_needed()
            .then(|| self.heat_max[Slot::Before as usize])
            .flatten();
        match (main, before) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        }
        .map(|top| top.max(f32::MIN_POSITIVE))
    }

    fn draw_params(&self, rect: egui::Rect, slot: Slot) -> DrawParams {
        let aspect = rect.width() / rect.height().max(1.0);
        let top = self.heat_top();
        let scalar_range = self.heat_max[slot as usize].and(top).map(|top| [0.0, top]);
        DrawParams {
            view_proj: self.camera.view_proj(aspect).to_cols_array_2d(),
            eye: self.camera.eye().to_array(),
            light_dir: self.camera.light_dir().to_array(),
            wireframe: self.settings.wireframe,
            scalar_range,
            size: [0, 0],
        }
    }

    fn handle_global_input(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        if let Some(path) = dropped.into_iter().next() {
            self.commands.push(Command::Open(path));
        }
        // Shortcuts work unless a text field has the keyboard (it has its own undo, and typing
        // an F or a W must not fit the view or toggle the wireframe).
        let text_focus = ctx.text_edit_focused();
        let (undo, redo) = ctx.input(|i| {
            let command = i.modifiers.command;
            (
                command && !i.modifiers.shift && i.key_pressed(egui::Key::Z),
                command
                    && ((i.modifiers.shift && i.key_pressed(egui::Key::Z))
                        || i.key_pressed(egui::Key::Y)),
            )
        });
        let (open, export) = ctx.input(|i| {
            let command_only = i.modifiers.command && !i.modifiers.shift && !i.modifiers.alt;
            (
                command_only && i.key_pressed(egui::Key::O),
                command_only && i.key_pressed(egui::Key::E),
            )
        });
        if open {
            self.commands.push(Command::OpenDialog);
        }
        if export {
            if let Some(document) = &self.document {
                let path = PathBuf::from(document.export_path.trim());
                self.commands.push(Command::Export(path));
            }
        }
        if !text_focus && undo {
            self.commands.push(Command::Undo);
        }
        if !text_focus && redo {
            self.commands.push(Command::Redo);
        }
        if text_focus {
            return;
        }
        let plain = |i: &egui::InputState, key| i.key_pressed(key) && i.modifiers.is_none();
        let (fit, wire, before, heat) = ctx.input(|i| {
            (
                plain(i, egui::Key::F),
                plain(i, egui::Key::W),
                plain(i, egui::Key::B),
                plain(i, egui::Key::H),
            )
        });
        if fit {
            self.commands.push(Command::FitView);
        }
        if wire {
            self.settings.wireframe = !self.settings.wireframe;
        }
        if before {
            self.show_before = !self.show_before;
        }
        if heat {
            self.settings.heat_map = !self.settings.heat_map;
        }
    }
}

/// The heat map's top: the 99th percentile of the distances, so a few outliers do not turn the
/// rest of the mesh into the map's darkest colour (larger values take the top colour).
fn heat_map_top(distances: &[f32]) -> f32 {
    let mut finite: Vec<f32> = distances
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .collect();
    if finite.is_empty() {
        return 0.0;
    }
    let rank = ((finite.len() - 1) as f64 * 0.99).round() as usize;
    let (_, value, _) = finite.select_nth_unstable_by(rank, f32::total_cmp);
    value.max(0.0)
}

/// A mesh held by the document, shared with a worker or the renderer without copying it.
#[derive(Clone)]
enum SharedMesh {
    /// The hierarchy's base mesh M0 (the connectivity faired results have).
    Base(Arc<hierarchy::Hierarchy>),
    Mesh(Arc<TriMesh>),
}

impl SharedMesh {
    fn mesh(&self) -> &TriMesh {
        match self {
            Self::Base(hierarchy) => hierarchy.base_mesh(),
            Self::Mesh(mesh) => mesh,
        }
    }
}

/// What the viewport shows: a mesh's triangles with its own positions or other ones (a faired
/// result) over them.
struct ViewMesh {
    connectivity: SharedMesh,
    positions: Option<Arc<Vec<[f32; 3]>>>,
}

impl MeshSource for ViewMesh {
    fn positions(&self) -> &[[f32; 3]] {
        match &self.positions {
            Some(positions) => positions,
            None => &self.connectivity.mesh().positions,
        }
    }
    fn triangles(&self) -> &[[u32; 3]] {
        &self.connectivity.mesh().triangles
    }
}

/// Relative volume change and RMS vertex displacement of `positions` against `base`.
fn compare_to_base(base: &TriMesh, positions: &[[f32; 3]]) -> (f64, f64) {
    if positions.len() != base.positions.len() || positions.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let before = metrics::signed_volume(base);
    let after_mesh = TriMesh {
        positions: positions.to_vec(),
        triangles: base.triangles.clone(),
    };
    let after = metrics::signed_volume(&after_mesh);
    let volume_change = if before.abs() > 0.0 {
        (after - before) / before.abs()
    } else {
        f64::NAN
    };
    let sum_squared: f64 = positions
        .iter()
        .zip(&base.positions)
        .map(|(p, q)| {
            (0..3)
                .map(|k| (p[k] as f64 - q[k] as f64).powi(2))
                .sum::<f64>()
        })
        .sum();
    (volume_change, (sum_squared / positions.len() as f64).sqrt())
}

impl eframe::App for App {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let started = Instant::now();
        let ctx = ui.ctx().clone();
        // Busy at the start counts too: the frame that applies the last result is a working one.
        let busy_before = self.busy();
        self.poll_results();
        self.start_waiting_measure();
        self.handle_global_input(&ctx);
        let results_done = Instant::now();
        // Upload before drawing, so the viewport draws what the panels describe.
        self.sync_viewport();
        let upload_done = Instant::now();
        panels::show(self, ui);
        for command in std::mem::take(&mut self.commands) {
            self.apply(command);
        }
        let widgets_done = Instant::now();
        self.sync_viewport();
        let parts = [
            results_done - started,
            (upload_done - results_done) + widgets_done.elapsed(),
            widgets_done - upload_done,
        ];
        let busy = self.busy();
        if busy {
            // Progress bars move without input events.
            ctx.request_repaint_after(Duration::from_millis(50));
        }
        // The viewport's draw of the previous frame, if it drew a new image.
        let render = match &self.viewport {
            Some(viewport) => {
                let images = viewport.images_drawn();
                let drew = images != self.frame_stats.images_seen;
                self.frame_stats.images_seen = images;
                if drew {
                    viewport.last_draw_time()
                } else {
                    Duration::ZERO
                }
            }
            None => Duration::ZERO,
        };
        self.frame_stats
            .record(started.elapsed(), parts, render, busy || busy_before);
        if self.exit_when_settled && !busy && self.is_settled() && self.loading.is_none() {
            self.exit_when_settled = false;
            let status = self.status();
            match (&status.document, &status.error) {
                (Some(path), None) => println!(
                    "editor: {} loaded, {} levels, {} vertices and {} faces on screen",
                    path.display(),
                    status.level_count,
                    status.shown_vertices,
                    status.shown_faces
                ),
                (_, Some(error)) => eprintln!("editor: {error}"),
                (None, None) => eprintln!("editor: no mesh was loaded"),
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.persistence {
            eframe::set_value(storage, Settings::STORAGE_KEY, &self.settings);
        }
    }
}

impl Drop for App {
    fn drop(&mut self) {
        // Cancel whatever still runs for this app.
        self.document_generation.bump();
        self.hierarchy_generation.bump();
        self.load_generation.bump();
    }
}

/// What an export could not keep, as a note after its status message.
fn notes(warnings: &[String]) -> String {
    if warnings.is_empty() {
        String::new()
    } else {
        format!(". Note: {}", warnings.join(". "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displacement_and_volume_of_identical_meshes_are_zero() {
        let mesh = TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        );
        let (dv, rms) = compare_to_base(&mesh, &mesh.positions);
        assert_eq!(dv, 0.0);
        assert_eq!(rms, 0.0);
        let moved: Vec<_> = mesh
            .positions
            .iter()
            .map(|p| [p[0] + 0.5, p[1], p[2]])
            .collect();
        let (dv, rms) = compare_to_base(&mesh, &moved);
        assert!(dv.abs() < 1e-12, "translation keeps the volume");
        assert!((rms - 0.5).abs() < 1e-12);
    }
}
