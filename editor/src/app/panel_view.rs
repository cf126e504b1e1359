//! [`PanelView`]: what the side panel, the toolbar and the status bar show, borrowed read-only
//! from the app for one section. A section takes it with `&mut Settings` (the choices it edits
//! in place) and the frame's command list (everything else it asks for, applied by
//! [`App::apply`] after the widgets are drawn); [`App::panel`] hands the three out.
//!
//! The 3D view's area gets the same, with its own read-only [`ViewportView`], plus
//! [`ViewportState`]: what it owns and changes as the mouse moves (the camera, the brush's last
//! dab, the renderers it draws into); [`App::viewport_section`] hands them out and keeps what
//! the area reports back ([`ViewportDrawn`]).

use std::path::{Path, PathBuf};
use web_time::Instant;

use super::camera::OrbitCamera;
use super::history::History;
use super::state::{Document, DocumentSnapshot, HeatReference, Settings};
use super::view_sync::SlotLook;
use super::{App, Command, FrameStats, Slot};
use crate::render::Viewport3d;

/// The app's state as the panels see it: read-only.
pub struct PanelView<'a> {
    pub document: Option<&'a Document>,
    /// The file being loaded, while it loads.
    pub loading: Option<&'a Path>,
    pub error: Option<&'a str>,
    pub message: Option<&'a str>,
    /// The typed path field for opening files.
    pub open_path: &'a str,
    pub history: &'a History<DocumentSnapshot>,
    /// How far the hierarchy and the fairing have come.
    pub progress: WorkProgress,
    /// The sharp-edge settings the current hierarchy was built with.
    pub hierarchy_built_with: Option<super::state::HierarchyKey>,
    /// The single view shows "before" instead of "after".
    pub show_before: bool,
    /// The left button paints the mask instead of orbiting.
    pub paint_mode: bool,
    /// Vertices and faces on screen.
    pub shown_counts: (usize, usize),
    pub frame_stats: &'a FrameStats,
    pub viewport: Option<&'a Viewport3d>,
    /// The Before view's renderer (the split and side-by-side views, B).
    pub viewport_before: Option<&'a Viewport3d>,
    /// What each viewport's held meshes show (indexed by [`Slot`]).
    pub(super) held_views: &'a [Vec<super::held_views::HeldView>; 2],
    /// What could not be shown of the file's colours (a texture that did not decode).
    pub appearance_warnings: &'a [String],
    /// Where "Export levels" writes (the typed folder, or one beside the document).
    pub levels_folder: Option<PathBuf>,
    /// An export waits for the user to say whether this existing file may be replaced.
    pub confirm_replace: Option<&'a Path>,
}

/// How far the background work has come, as the panels show it.
#[derive(Clone, Copy, Debug, Default)]
pub struct WorkProgress {
    /// The hierarchy's build (or the denoise before it), 0 to 1.
    pub hierarchy: f32,
    /// The hierarchy's job is denoising the mesh before building on it.
    pub hierarchy_denoising: bool,
    /// A fairing runs for the slider's value.
    pub fair_in_flight: bool,
    /// That fairing, 0 to 1.
    pub fair: f32,
}

/// A section's commands go here; the app applies them after the frame's widgets.
pub type Commands = Vec<Command>;

impl App {
    /// Runs one section of the panels with what it shows, the settings it edits and the
    /// frame's command list.
    pub(super) fn panel<R>(
        &mut self,
        section: impl FnOnce(&PanelView<'_>, &mut Settings, &mut Commands) -> R,
    ) -> R {
        let view = PanelView {
            document: self.document.as_ref(),
            loading: self.work.loading.as_deref(),
            error: self.error.as_deref(),
            message: self.message.as_deref(),
            open_path: &self.open_path,
            history: &self.history,
            progress: WorkProgress {
                hierarchy: self.work.hierarchy_progress.get(),
                hierarchy_denoising: (self.work.hierarchy_denoising)
                    .load(std::sync::atomic::Ordering::Relaxed),
                fair_in_flight: self.work.fair_in_flight,
                fair: self.work.fair_progress.get(),
            },
            hierarchy_built_with: self.work.hierarchy_built_with,
            show_before: self.view.show_before,
            paint_mode: self.painting.paint_mode,
            shown_counts: self.view.shown_counts,
            frame_stats: &self.frame_stats,
            viewport: self.view.viewport.as_ref(),
            viewport_before: self.view.viewport_before.as_ref(),
            held_views: &self.view.held_views,
            appearance_warnings: match (&self.view.appearance, &self.document) {
                (Some((source, _)), Some(d)) if std::sync::Arc::ptr_eq(source, &d.source) => {
                    &self.view.appearance_warnings
                }
                _ => &[],
            },
            levels_folder: self.levels_folder(),
            confirm_replace: self.confirm_replace.as_deref(),
        };
        section(&view, &mut self.settings, &mut self.commands)
    }
}

/// The app's state as the 3D view's area sees it: read-only.
pub struct ViewportView<'a> {
    pub document: Option<&'a Document>,
    /// The single view shows "before" instead of "after".
    pub show_before: bool,
    /// The left button paints the mask instead of orbiting.
    pub paint_mode: bool,
    /// A brush stroke is under way (its dabs were applied, its end not yet).
    pub stroking: bool,
    /// This frame is the one captured for "Save image": no mouse hints.
    pub capturing_view: bool,
    /// The heat map's top value and reference, when the legend is shown.
    pub heat_legend: Option<(f32, HeatReference)>,
    /// How each slot's image is coloured (indexed by [`Slot`]).
    pub looks: [SlotLook; 2],
    /// The main view shows an older picture than the one being computed.
    pub main_behind: bool,
    /// Draw the kept sharp edges over the mesh until then.
    pub sharp_edges_shown_until: Option<Instant>,
}

/// What the 3D view's area owns and changes itself, frame by frame: not the document, the mask
/// or the settings (those change through commands and `&mut Settings`).
pub struct ViewportState<'a> {
    /// Orbited, panned and zoomed by the mouse.
    pub camera: &'a mut OrbitCamera,
    /// Where the brush's last dab of the stroke was (screen points).
    pub last_dab: &'a mut Option<egui::Pos2>,
    /// The renderers the views are drawn with (`None` without a wgpu render state), indexed
    /// by [`Slot`].
    pub viewports: [Option<&'a mut Viewport3d>; 2],
}

impl ViewportState<'_> {
    /// A slot's renderer, when there is a wgpu renderer.
    pub fn viewport(&mut self, slot: Slot) -> Option<&mut Viewport3d> {
        self.viewports[slot as usize].as_deref_mut()
    }
}

/// What the 3D view's area reports after drawing.
#[derive(Clone, Copy, Debug)]
pub struct ViewportDrawn {
    /// Where the view was drawn (points).
    pub rect: egui::Rect,
    /// Sharp edges drawn over the mesh.
    pub sharp_edges_drawn: usize,
}

impl App {
    /// Runs the 3D view's area with what it shows, what it owns, the settings and the frame's
    /// command list, and keeps what it reports.
    pub(super) fn viewport_section(
        &mut self,
        section: impl FnOnce(
            &ViewportView<'_>,
            &mut ViewportState<'_>,
            &mut Settings,
            &mut Commands,
        ) -> ViewportDrawn,
    ) {
        let heat_legend = self.heat_top().zip(self.heat_reference());
        let looks = [self.slot_look(Slot::Main), self.slot_look(Slot::Before)];
        let view = ViewportView {
            document: self.document.as_ref(),
            show_before: self.view.show_before,
            paint_mode: self.painting.paint_mode,
            stroking: self.painting.stroke.is_some(),
            capturing_view: self.view.capturing_view,
            heat_legend,
            looks,
            main_behind: self.main_view_behind(),
            sharp_edges_shown_until: self.view.sharp_edges_shown_until,
        };
        let mut state = ViewportState {
            camera: &mut self.view.camera,
            last_dab: &mut self.painting.last_dab,
            viewports: [
                self.view.viewport.as_mut(),
                self.view.viewport_before.as_mut(),
            ],
        };
        let drawn = section(&view, &mut state, &mut self.settings, &mut self.commands);
        self.view.viewport_rect = Some(drawn.rect);
        self.view.sharp_edges_drawn = drawn.sharp_edges_drawn;
    }
}
