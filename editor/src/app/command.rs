//! [`Command`]: what the user asked for, emitted by the widgets and the shortcuts, and
//! [`App::apply`], which carries it out after the frame's widgets are drawn.

use std::path::PathBuf;

use super::jobs::DialogPurpose;
use super::state::{HierarchyState, ViewMode};
use super::{paint, App};

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
    /// What a panel shows changed, not the document.
    Panel(PanelChange),
}

/// A change of what the panels and the viewport show (not of the document), asked for by a
/// panel, which only reads the app's state.
#[derive(Clone, Debug, PartialEq)]
pub enum PanelChange {
    /// The typed path field for opening files changed.
    OpenPath(String),
    /// Say what went wrong in the status bar.
    Error(String),
    /// The document's export path field changed.
    ExportPath(String),
    /// Forget the largest frame time while working (the Performance section).
    ResetBusyMax,
    /// The single view toggles between before and after.
    ToggleBefore,
    /// The left button paints (`true`) or orbits.
    PaintMode(bool),
    /// Draw the kept sharp edges over the mesh until then (their controls are pointed at or
    /// were just changed).
    ShowSharpEdgesUntil(web_time::Instant),
}

impl App {
    /// Carries out one command (the frame applies them after its widgets are drawn).
    pub(super) fn apply(&mut self, command: Command) {
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
                        .files
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
                let previous = std::mem::replace(&mut self.settings.view.view_mode, mode);
                // The input mesh and the result are both shown from the fairing asked for
                // whenever a setting changed: switching between them asks for nothing new.
                let fairs = |mode| matches!(mode, ViewMode::Faired | ViewMode::Original);
                if !(fairs(previous) && fairs(mode)) {
                    self.refresh_view();
                }
            }
            Command::CancelHierarchy => {
                self.work.hierarchy_generation.bump();
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
            Command::Panel(change) => self.apply_panel_change(change),
        }
    }

    /// The changes of what the panels and the viewport show, not the document: the
    /// panels drew this frame before them, so the next frame shows them.
    fn apply_panel_change(&mut self, change: PanelChange) {
        let repaint = match change {
            PanelChange::OpenPath(path) => {
                self.open_path = path;
                false
            }
            PanelChange::Error(error) => {
                self.error = Some(error);
                true
            }
            PanelChange::ExportPath(path) => {
                if let Some(document) = &mut self.document {
                    document.export_path = path;
                }
                false
            }
            PanelChange::ResetBusyMax => {
                self.frame_stats.reset_busy_max();
                false
            }
            PanelChange::ToggleBefore => {
                self.view.show_before = !self.view.show_before;
                true
            }
            PanelChange::PaintMode(on) => {
                self.painting.paint_mode = on;
                true
            }
            PanelChange::ShowSharpEdgesUntil(until) => {
                let shown = self
                    .view
                    .sharp_edges_shown_until
                    .is_some_and(|shown| shown > web_time::Instant::now());
                self.view.sharp_edges_shown_until = Some(until);
                // Drawn from the next frame; one already drawing them repaints on its own.
                !shown
            }
        };
        if repaint {
            self.ctx.request_repaint();
        }
    }
}
