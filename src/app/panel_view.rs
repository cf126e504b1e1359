//! [`PanelView`]: what the side panel, the toolbar and the status bar show, borrowed read-only
//! from the app for one section. A section takes it with `&mut Settings` (the choices it edits
//! in place) and the frame's command list (everything else it asks for, applied by
//! [`App::apply`] after the widgets are drawn); [`App::panel`] hands the three out.

use std::path::{Path, PathBuf};

use super::history::History;
use super::state::{Document, DocumentSnapshot, Settings};
use super::{App, Command, FrameStats};
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
    pub hierarchy_progress: f32,
    pub fair_in_flight: bool,
    pub fair_progress: f32,
    /// The sharp-edge settings the current hierarchy was built with.
    pub hierarchy_built_with: (bool, u64),
    /// The single view shows "before" instead of "after".
    pub show_before: bool,
    /// The left button paints the mask instead of orbiting.
    pub paint_mode: bool,
    /// Vertices and faces on screen.
    pub shown_counts: (usize, usize),
    pub frame_stats: &'a FrameStats,
    pub viewport: Option<&'a Viewport3d>,
    /// Where "Export levels" writes (the typed folder, or one beside the document).
    pub levels_folder: Option<PathBuf>,
    /// An export waits for the user to say whether this existing file may be replaced.
    pub confirm_replace: Option<&'a Path>,
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
            loading: self.loading.as_deref(),
            error: self.error.as_deref(),
            message: self.message.as_deref(),
            open_path: &self.open_path,
            history: &self.history,
            hierarchy_progress: self.hierarchy_progress.get(),
            fair_in_flight: self.fair_in_flight,
            fair_progress: self.fair_progress.get(),
            hierarchy_built_with: self.hierarchy_built_with,
            show_before: self.show_before,
            paint_mode: self.paint_mode,
            shown_counts: self.shown_counts,
            frame_stats: &self.frame_stats,
            viewport: self.viewport.as_ref(),
            levels_folder: self.levels_folder(),
            confirm_replace: self.confirm_replace.as_deref(),
        };
        section(&view, &mut self.settings, &mut self.commands)
    }
}
