//! The editor (feature `gui`): an eframe app that loads a mesh, builds its decimation hierarchy in
//! the background, fairs it from the level picked with a slider, shows the result in a wgpu
//! viewport and exports it.
//!
//! Layout:
//! - this file: [`App`] and the frame: poll results, input, panels, apply commands, sync the view;
//! - [`state`]: persisted [`state::Settings`] and the [`state::Document`] (mesh and results);
//! - `tasks/`: one file per kind of background task (load, document changes, hierarchy,
//!   fairing, measure, export), each holding its launch and the handling of its result;
//! - [`jobs`]: worker threads, generation numbers, job results;
//! - `view_sync.rs`: keeps the viewports' GPU buffers in step with what should be shown;
//! - [`panels`]: the widgets; they emit [`Command`]s, applied after the frame. Beside it:
//!   `fairing_panel.rs` (the Fairing section, the sharp-edge controls, every tooltip),
//!   [`view_panel`] (the View section: compare, heat map, Shading, Studio lighting) and
//!   `viewport_panel.rs` (the 3D view's area: camera input, the compare views, overlays),
//!   `numbers_panel.rs` (the Numbers section);
//! - `input.rs`: shortcuts and dropped files; `frame_stats.rs`: the UI thread's frame times;
//! - [`camera`]: the orbit camera; [`history`]: undo and redo;
//! - [`paint`]: the brush that paints where to fair (`tasks/mask.rs` applies its strokes,
//!   `paint_panel.rs` holds its controls and its handling in the viewport).
//!
//! Named worker threads: `fairmesh-io` (load, export), `fairmesh-compute` (hierarchy, fairing,
//! level meshes; the levels' set-up as idle jobs that any fairing overtakes) and
//! `fairmesh-measure` (surface distances of a result, once the slider rests, on a one-thread
//! pool of its own), so an export or the next file's loading never waits for a long hierarchy
//! build and measuring never slows the next slider value. Each viewport's renderer has its own
//! `fairmesh-upload` thread for big meshes. Loading another file cancels the hierarchy build and
//! fairing of the previous one through their generation numbers.

pub mod camera;
mod confirm_replace;
mod fairing_panel;
mod frame_stats;
pub mod history;
mod input;
pub mod jobs;
mod numbers_panel;
pub mod paint;
mod paint_panel;
pub mod panels;
mod recent;
mod sharp_edges;
pub mod state;
mod tasks;
pub mod view_panel;
mod view_sync;
mod viewport_panel;

pub use frame_stats::FrameStats;
use tasks::measure::MeasureRequest;
use view_sync::Shown;
pub use view_sync::Slot;

use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::multires::MultiresWorkspace;
use crate::TriMesh;

use camera::OrbitCamera;
use history::History;
use jobs::{DialogPurpose, Generation, JobCounter, JobResult, JobTicket, SharedProgress, Worker};
use state::{
    CompareView, Document, DocumentSnapshot, HierarchyState, Measures, Settings, ViewMode,
};

use crate::render::Viewport3d;

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
    /// Open a file from the Recent menu (a missing one is named and dropped from the menu).
    OpenRecent(PathBuf),
    OpenDialog,
    /// Export to a typed path (asks first if the file exists).
    Export(PathBuf),
    /// Export to a path, replacing the file there (the user said so).
    ReplaceExport(PathBuf),
    /// The user said not to replace the file: nothing is written.
    CancelExport,
    ExportDialog,
    FitView,
    /// Save the 3D view as a PNG beside the document (taken in the next frame, without hints).
    SaveViewImage,
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
    /// One dab of the brush (the first of a stroke records an undo step); `erase` lowers the
    /// mask instead of raising it.
    Paint {
        view: paint::BrushView,
        erase: bool,
    },
    /// The stroke ended: remember the mask and fair with it.
    EndStroke,
    /// Forget the mask: fair the whole mesh.
    ClearMask,
    /// Paint what was unpainted and the other way round.
    InvertMask,
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
    /// Sharp edges the current hierarchy keeps (0 without "Keep sharp edges").
    pub sharp_edges_kept: usize,
    /// Sharp edges drawn over the mesh in the last frame (while their controls are pointed at).
    pub sharp_edges_drawn: usize,
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
    /// The camera as the last fit left it: while the user has not moved it since, switching to
    /// or from the side-by-side view fits it again (the halves are narrower than tall).
    fitted_camera: Option<OrbitCamera>,
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
    /// Earlier and later document states (noise, applied results, loading, mask changes).
    history: History<DocumentSnapshot>,
    /// The left button paints the mask instead of orbiting.
    paint_mode: bool,
    /// The mask's weights while a stroke is being painted.
    stroke: Option<Vec<f32>>,
    /// Where the brush's last dab of the stroke was (screen points).
    last_dab: Option<egui::Pos2>,
    /// Bumped with every change of the document's mask, so that its tint is uploaded again.
    mask_revision: u64,
    /// The sharp-edge settings the current hierarchy was asked for (see
    /// [`Settings::hierarchy_key`]): a change builds it again.
    hierarchy_built_with: (bool, u64),
    /// Draw the kept sharp edges over the mesh until then (their controls are hovered or were
    /// just changed).
    sharp_edges_shown_until: Option<std::time::Instant>,
    sharp_edges_drawn: usize,
    /// An export waits for the user to say whether this existing file may be replaced.
    confirm_replace: Option<PathBuf>,
    /// "Save image" was asked for: the next frame is drawn without the mouse hints and captured.
    capture_next_frame: bool,
    /// This frame is the one captured for "Save image".
    capturing_view: bool,
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
            fitted_camera: None,
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
            frame_stats: FrameStats::logging_over(options.log_frames_over),
            exit_when_settled: options.exit_when_settled,
            viewport_rect: None,
            history: History::new(HISTORY_BUDGET_BYTES),
            paint_mode: false,
            stroke: None,
            last_dab: None,
            mask_revision: 0,
            hierarchy_built_with: (false, 0),
            sharp_edges_shown_until: None,
            sharp_edges_drawn: 0,
            confirm_replace: None,
            capture_next_frame: false,
            capturing_view: false,
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
            && !self.capture_next_frame
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
            sharp_edges_kept: document.map_or(0, |d| match &d.hierarchy {
                HierarchyState::Ready { hierarchy, .. } => hierarchy.crease_edge_count(),
                _ => 0,
            }),
            sharp_edges_drawn: self.sharp_edges_drawn,
        }
    }

    fn busy(&self) -> bool {
        self.jobs.in_flight() > 0 || self.measure_wanted.is_some()
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
            Command::OpenRecent(path) => self.open_recent(path),
            Command::OpenDialog => self.open_dialog(DialogPurpose::Open),
            Command::Export(path) => self.export(path),
            Command::ReplaceExport(path) => {
                self.confirm_replace = None;
                self.write_export(path);
            }
            Command::CancelExport => {
                if let Some(path) = self.confirm_replace.take() {
                    self.message =
                        Some(format!("Export cancelled: {} is unchanged", path.display()));
                }
            }
            Command::ExportDialog => self.open_dialog(DialogPurpose::Export),
            Command::FitView => self.fit_view(),
            Command::SaveViewImage => self.save_view_image(),
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
            Command::Paint { view, erase } => self.paint_dab(&view, erase),
            Command::EndStroke => self.end_stroke(),
            Command::ClearMask => self.change_mask("Clear mask", |_| None),
            Command::InvertMask => {
                self.change_mask("Invert mask", |mask| mask.map(|m| m.inverted()))
            }
        }
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
            } => self.on_loaded(load_generation, path, result, elapsed),
            JobResult::Hierarchy {
                document,
                hierarchy,
                result,
                elapsed,
            } => self.on_hierarchy(document, hierarchy, result, elapsed),
            JobResult::Faired {
                document,
                view,
                level,
                result,
            } => self.on_faired(document, view, level, result),
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
        }
    }

    // ---- viewport -------------------------------------------------------------------------
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
        let compare = self.settings.compare;
        self.capturing_view = std::mem::take(&mut self.capture_next_frame);
        panels::show(self, ui);
        if self.capturing_view {
            self.capture_view(&ctx);
        }
        confirm_replace::show(self, &ctx);
        for command in std::mem::take(&mut self.commands) {
            self.apply(command);
        }
        let side_by_side = |view| view == CompareView::SideBySide;
        if side_by_side(self.settings.compare) != side_by_side(compare)
            && self.fitted_camera == Some(self.camera)
        {
            self.fit_view();
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
