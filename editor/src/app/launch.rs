//! Starting the editor: [`run`] opens the window, [`AppOptions`] says how, and
//! [`App::with_options`] builds the app (settings, worker threads, viewports) and opens the
//! first file.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use super::history::History;
use super::in_flight::InFlight;
use super::paint::Painting;
use super::state::Settings;
use super::view_state::ViewState;
use super::workers::Workers;
use super::{App, FrameStats};

/// Opens the editor window on `options.file`, or on the bundled bunny.
#[cfg(not(target_arch = "wasm32"))]
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
pub fn wgpu_configuration() -> egui_wgpu::WgpuConfiguration {
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
    /// The file to open; `None` opens the bunny compiled into the binary ([`fairmesh::bundled`]).
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

/// Memory the undo history may keep alive.
const HISTORY_BUDGET_BYTES: usize = 1 << 30;

impl App {
    /// The app as the window runs it: settings from eframe's storage when `persistence` is on.
    pub fn with_options(cc: &eframe::CreationContext<'_>, options: AppOptions) -> Self {
        let settings = if options.persistence {
            cc.storage
                .and_then(|storage| eframe::get_value::<Settings>(storage, Settings::STORAGE_KEY))
                .map(Settings::upgraded)
                .unwrap_or_default()
        } else {
            Settings::default()
        };
        let file = options
            .file
            .clone()
            .unwrap_or_else(|| PathBuf::from(fairmesh::bundled::BUNNY_PSEUDO_PATH));
        let mut app = Self::fresh(cc, settings, &options, &file);
        app.configure_viewports(&options);
        app.open(file);
        app
    }

    /// The app with nothing loaded yet, its threads started and `file` in the path field.
    fn fresh(
        cc: &eframe::CreationContext<'_>,
        settings: Settings,
        options: &AppOptions,
        file: &std::path::Path,
    ) -> Self {
        Self {
            settings,
            persistence: options.persistence,
            document: None,
            history: History::new(HISTORY_BUDGET_BYTES),
            workers: Workers::spawn(&cc.egui_ctx),
            work: InFlight::default(),
            view: ViewState::new(cc),
            painting: Painting::default(),
            dialog_open: false,
            ctx: cc.egui_ctx.clone(),
            error: None,
            message: None,
            open_path: file.display().to_string(),
            commands: Vec::new(),
            frame_stats: FrameStats::logging_over(options.log_frames_over),
            exit_when_settled: options.exit_when_settled,
            confirm_replace: None,
        }
    }

    /// Applies the options' upload threshold and buffer cap to the viewports.
    fn configure_viewports(&self, options: &AppOptions) {
        for viewport in self.viewports() {
            if let Some(bytes) = options.async_upload_bytes {
                viewport.set_async_upload_bytes(bytes);
            }
            if let Some(bytes) = options.max_buffer_bytes {
                viewport.cap_buffer_size(bytes);
            }
        }
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
}
