//! The editor: an eframe app that loads a mesh, builds its decimation hierarchy in
//! the background, fairs it from the level picked with a slider, shows the result in a wgpu
//! viewport and exports it.
//!
//! Layout:
//! - this file: [`App`] and the frame: poll results, input, panels, apply commands, sync the view;
//! - `launch.rs`: [`run`], [`AppOptions`] and the app's construction; [`Command`] and its
//!   application in `command.rs`; job results coming back in `results.rs`; [`AppStatus`] and
//!   the read-only views tests use in `status.rs`;
//! - [`state`]: persisted [`state::Settings`] and the [`state::Document`] (mesh and results);
//! - `tasks/`: one file per kind of background task (load, document changes, hierarchy,
//!   fairing, measure, export), each holding its launch and the handling of its result;
//! - [`App`] holds its state in owned parts: `workers.rs` (the threads and the results'
//!   channel), `in_flight.rs` (generations, progress, what is on screen), `view_state.rs` (the
//!   viewports, camera and what they hold), [`paint`]'s `Painting`, and the document with its
//!   [`history`];
//! - [`jobs`]: worker threads, generation numbers, job results (a job that panics is reported);
//! - `view_sync.rs`: keeps the viewports' GPU buffers in step with what should be shown;
//!   `appearance.rs`: the loaded file's materials, textures and colours as the viewport draws
//!   them;
//! - [`panels`]: the window's layout, placing the sections; each section reads the app's state
//!   through a `PanelView` (`panel_view.rs`), edits the [`state::Settings`] in place and emits
//!   [`Command`]s, applied after the frame. The sections: `toolbar.rs`, `status_bar.rs`,
//!   [`view_panel`] (the View section: compare, heat map, Shading, Studio lighting),
//!   `mesh_panel.rs` (Mesh and Noise), `hierarchy_panel.rs` (Hierarchy), `fairing_panel.rs`
//!   (the Fairing section and the sharp-edge controls), `export_panel.rs` (Export),
//!   `numbers_panel.rs` (Numbers), `paint_panel.rs`, `performance_panel.rs` (Performance) and
//!   `viewport_panel.rs` (the 3D view's area: camera input, the brush, the compare views,
//!   overlays; it reads a `ViewportView` and moves only what it owns, the camera, the brush's
//!   last dab and the renderers it draws with, through a `ViewportState`); [`tips`], every
//!   control's tooltip; `widgets.rs`, the small widgets the sections share;
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

mod appearance;
pub mod camera;
mod command;
mod compute;
mod confirm_replace;
mod export_panel;
mod fairing_panel;
mod frame_stats;
mod generation;
mod held_views;
mod hierarchy_panel;
pub mod history;
mod in_flight;
mod input;
pub mod jobs;
mod kept_results;
mod launch;
mod mesh_panel;
mod numbers_panel;
pub mod paint;
mod paint_panel;
mod panel_view;
pub mod panels;
mod performance_panel;
mod priority;
mod recent;
mod results;
mod sharp_edges;
mod shown;
pub mod state;
mod status;
mod status_bar;
mod tasks;
pub mod tips;
mod toolbar;
pub mod view_panel;
mod view_state;
mod view_sync;
mod viewport_panel;
#[cfg(target_arch = "wasm32")]
pub mod web;
mod widgets;
mod workers;

pub use command::{Command, PanelChange};
pub use frame_stats::FrameStats;
#[cfg(not(target_arch = "wasm32"))]
pub use launch::run;
pub use launch::{wgpu_configuration, AppOptions};
pub use shown::Slot;
pub use status::{AppStatus, ViewStatus};
pub use viewport_panel::COMPUTING;

use std::path::PathBuf;
use std::time::Duration;
use web_time::Instant;

use crate::render::Viewport3d;

use history::History;
use in_flight::InFlight;
use paint::Painting;
use state::{CompareView, Document, DocumentSnapshot, Settings};
use view_state::ViewState;
use workers::Workers;

/// The editor: its settings, the document, the workers and what the viewports show. The frame
/// (`ui` below) runs in this order: poll results, input, panels, apply commands, sync the view.
pub struct App {
    settings: Settings,
    persistence: bool,
    document: Option<Document>,
    /// Earlier and later document states (noise, applied results, loading, mask changes).
    history: History<DocumentSnapshot>,
    /// The background threads and the results coming back from them.
    workers: Workers,
    /// What runs for the document and which of its results are on screen.
    work: InFlight,
    /// What the 3D views show.
    view: ViewState,
    /// The brush and the stroke being painted.
    painting: Painting,
    dialog_open: bool,
    ctx: egui::Context,
    error: Option<String>,
    message: Option<String>,
    /// The typed path field for opening files.
    open_path: String,
    commands: Vec<Command>,
    frame_stats: FrameStats,
    /// [`AppOptions::exit_when_settled`], until it has fired.
    exit_when_settled: bool,
    /// An export waits for the user to say whether this existing file may be replaced.
    confirm_replace: Option<PathBuf>,
}

impl App {
    /// Queues a command as if a widget had emitted it (applied at the end of the next frame).
    pub fn push_command(&mut self, command: Command) {
        self.commands.push(command);
    }

    /// No job running or waiting and every result applied.
    pub fn is_settled(&self) -> bool {
        self.workers.jobs.in_flight() == 0
            && self.commands.is_empty()
            && self.work.measure_wanted.is_none()
            && !self.view.capture_next_frame
            && !self.upload_pending()
            && !self.drawing()
    }

    /// Whether a viewport is drawing a new image over several frames.
    fn drawing(&self) -> bool {
        self.viewports().any(Viewport3d::drawing)
    }

    /// Whether a viewport's background upload of a big mesh has not landed yet.
    fn upload_pending(&self) -> bool {
        self.viewports().any(Viewport3d::upload_pending)
    }

    /// The viewports there are (none without a wgpu render state).
    fn viewports(&self) -> impl Iterator<Item = &Viewport3d> {
        self.view.viewports()
    }

    /// A job is running or waiting.
    fn busy(&self) -> bool {
        self.workers.jobs.in_flight() > 0 || self.work.measure_wanted.is_some()
    }
}

impl App {
    /// Applies the commands the frame's widgets and shortcuts emitted; fits the view again when
    /// the compare view went to or from side by side (`compare`: before the widgets) and the
    /// camera was not moved since the last fit.
    fn apply_commands(&mut self, compare: CompareView) {
        for command in std::mem::take(&mut self.commands) {
            self.apply(command);
        }
        let side_by_side = |view| view == CompareView::SideBySide;
        if side_by_side(self.settings.view.compare) != side_by_side(compare)
            && self.view.fitted_camera == Some(self.view.camera)
        {
            self.fit_view();
        }
    }

    /// The viewport's draw of the previous frame, if it drew a new image. A held mesh's kept
    /// image shown again is logged too (the frame log times view switches by both).
    fn new_image_draw_time(&mut self) -> Duration {
        match &self.view.viewport {
            Some(viewport) => {
                let images = viewport.image_counts();
                let seen = std::mem::replace(&mut self.frame_stats.images_seen, images);
                if images.restored != seen.restored {
                    self.frame_stats.log_arrival("a kept image of the 3D view");
                }
                if images.drawn != seen.drawn {
                    self.frame_stats.log_arrival("a new image of the 3D view");
                    viewport.last_draw_time()
                } else {
                    Duration::ZERO
                }
            }
            None => Duration::ZERO,
        }
    }

    /// [`AppOptions::exit_when_settled`]: once the first mesh is in and nothing runs, says so
    /// and closes the window.
    fn exit_if_settled(&mut self, ctx: &egui::Context, busy: bool) {
        if self.exit_when_settled && !busy && self.is_settled() && self.work.loading.is_none() {
            self.exit_when_settled = false;
            let status = self.status();
            match (&status.document, &status.error) {
                (Some(path), None) => println!(
                    "editor: {} loaded, {} levels, {} vertices and {} faces on screen",
                    path.display(),
                    status.level_count,
                    status.view.shown_vertices,
                    status.view.shown_faces
                ),
                (_, Some(error)) => eprintln!("editor: {error}"),
                (None, None) => eprintln!("editor: no mesh was loaded"),
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }
}

impl eframe::App for App {
    /// One frame: poll results, input, panels, apply commands, sync the view.
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let started = Instant::now();
        let ctx = ui.ctx().clone();
        let had_input = ctx.input(|i| !i.events.is_empty());
        self.frame_stats.record_start(started, had_input);
        // Busy at the start counts too: the frame that applies the last result is a working one.
        let busy_before = self.busy();
        // A page has no threads: one waiting job runs here, between two frames.
        #[cfg(target_arch = "wasm32")]
        {
            self.mark_first_picture();
            self.poll_web();
            self.run_one_job();
        }
        self.poll_results();
        self.start_waiting_measure();
        self.handle_global_input(&ctx);
        let results_done = Instant::now();
        // Upload before drawing, so the viewport draws what the panels describe.
        self.sync_viewport();
        let upload_done = Instant::now();
        let compare = self.settings.view.compare;
        // A saved view waits for an image being drawn over several frames to be complete.
        self.view.capturing_view = self.view.capture_next_frame && !self.drawing();
        self.view.capture_next_frame &= !self.view.capturing_view;
        panels::show(self, ui);
        if self.view.capturing_view {
            self.capture_view(&ctx);
        }
        self.panel(|view, _, commands| confirm_replace::show(&ctx, view, commands));
        self.apply_commands(compare);
        let widgets_done = Instant::now();
        self.sync_viewport();
        let parts = [
            results_done - started,
            (upload_done - results_done) + widgets_done.elapsed(),
            widgets_done - upload_done,
        ];
        let busy = self.busy();
        if busy {
            // Progress bars and spinners move without input events. A software renderer draws
            // each frame on the cores the work runs on (~50 ms of both cores for a 1280×800
            // window under lavapipe): there they move four times a second.
            let software = self.viewports().any(Viewport3d::software);
            ctx.request_repaint_after(Duration::from_millis(if software { 250 } else { 50 }));
        }
        let render = self.new_image_draw_time();
        self.frame_stats
            .record(started.elapsed(), parts, render, busy || busy_before);
        self.exit_if_settled(&ctx, busy);
        #[cfg(target_arch = "wasm32")]
        self.publish_status();
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
        self.work.cancel_all();
    }
}
