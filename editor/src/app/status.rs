//! What the app shows to tests and the status line: [`AppStatus`], a summary, and the read-only
//! views of the settings, the document, the faired result and its numbers.

use std::path::PathBuf;
use std::sync::Arc;

use crate::render::Viewport3d;
use fairmesh::TriMesh;

use super::camera::OrbitCamera;
use super::state::{Document, HierarchyState, Measures, Settings};
use super::{App, FrameStats};

/// A summary of the app's state, for tests and the status line.
#[derive(Clone, Debug, Default)]
pub struct AppStatus {
    pub document: Option<PathBuf>,
    pub loading: bool,
    pub hierarchy_ready: bool,
    pub level_count: usize,
    pub level: usize,
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
    /// Sharp edges the current hierarchy keeps (0 without "Keep sharp edges").
    pub sharp_edges_kept: usize,
    /// Faired results kept by start level, to be shown again at once.
    pub kept_results: usize,
    /// A level next to the one on screen is being faired ahead.
    pub fairing_ahead: bool,
    /// What the main view shows.
    pub view: ViewStatus,
}

/// What the 3D view shows, as [`AppStatus::view`].
#[derive(Clone, Debug, Default)]
pub struct ViewStatus {
    pub shown_vertices: usize,
    pub shown_faces: usize,
    pub images_drawn: u64,
    /// A viewport is drawing a new image over several frames (a big mesh on a software
    /// renderer); the view shows the one before it.
    pub drawing: bool,
    /// The faired result whose shape the main view shows (its serial), if it shows one.
    pub shown_serial: Option<u64>,
    /// The main view colours its mesh with a heat map: that mesh's own distances.
    pub heat_shown: bool,
    /// The main view tints the painted mask over its mesh.
    pub mask_shown: bool,
    /// The main view's picture is older than the one being computed ("computing…").
    pub view_behind: bool,
    /// The main view's caption (in the single view, unless it shows "Before").
    pub caption: String,
    /// Sharp edges drawn over the mesh in the last frame (while their controls are pointed at).
    pub sharp_edges_drawn: usize,
}

impl App {
    pub fn frame_stats(&self) -> &FrameStats {
        &self.frame_stats
    }

    pub fn frame_stats_mut(&mut self) -> &mut FrameStats {
        &mut self.frame_stats
    }

    /// What could not be shown of the loaded file's colours (a base colour texture that did
    /// not decode), as the Mesh section says it; empty until the viewport drew the file.
    pub fn appearance_warnings(&self) -> &[String] {
        let current = match (&self.view.appearance, &self.document) {
            (Some((source, _)), Some(document)) => Arc::ptr_eq(source, &document.source),
            _ => false,
        };
        match current {
            true => &self.view.appearance_warnings,
            false => &[],
        }
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Whether the single view shows "before" (the document's mesh) instead of the result.
    pub fn showing_before(&self) -> bool {
        self.view.show_before
    }

    /// The heat map's top value (the legend's range is 0 to this), while the heat map is shown.
    pub fn heat_map_top(&self) -> Option<f32> {
        self.heat_top()
    }

    /// Where the 3D view was drawn in the last frame, in points.
    pub fn viewport_rect(&self) -> Option<egui::Rect> {
        self.view.viewport_rect
    }

    pub fn camera(&self) -> &OrbitCamera {
        &self.view.camera
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
            loading: self.work.loading.is_some(),
            hierarchy_ready: document.and_then(Document::level_count).is_some(),
            level_count: document.and_then(Document::level_count).unwrap_or(0),
            level: document.map(|d| d.level).unwrap_or(0),
            faired_serial: faired.map(|f| f.serial),
            faired_level: faired.map(|f| f.level),
            measuring: faired.is_some_and(|f| f.measures_pending)
                && self.work.measure_wanted.is_none(),
            measures_stopped: self.work.measures_stopped,
            volume_change: faired.map(|f| f.volume_change),
            rms_displacement: faired.map(|f| f.rms_displacement),
            error: self.error.clone(),
            message: self.message.clone(),
            sharp_edges_kept: document.map_or(0, |d| match &d.hierarchy {
                HierarchyState::Ready { hierarchy, .. } => hierarchy.crease_edge_count(),
                _ => 0,
            }),
            kept_results: self.work.kept.len(),
            fairing_ahead: self.work.ahead_in_flight,
            view: ViewStatus {
                shown_vertices: self.view.shown_counts.0,
                shown_faces: self.view.shown_counts.1,
                images_drawn: self
                    .view
                    .viewport
                    .as_ref()
                    .map_or(0, Viewport3d::images_drawn),
                drawing: self.drawing(),
                shown_serial: self.view.shown.and_then(|s| match s.what {
                    super::shown::ShownMesh::Faired { serial } => Some(serial),
                    _ => None,
                }),
                heat_shown: self.view.shown.is_some_and(|s| s.heat.is_some())
                    && self.slot_look(super::Slot::Main).scalar_range.is_some(),
                mask_shown: self.view.shown.is_some_and(|s| s.mask.is_some()),
                view_behind: self.main_view_behind(),
                caption: super::viewport_panel::main_caption(
                    self.settings.view.view_mode,
                    self.main_view_behind(),
                ),
                sharp_edges_drawn: self.view.sharp_edges_drawn,
            },
        }
    }
}
