//! The Recent menu beside Open: the last files opened (kept in the settings), newest first.

use std::path::PathBuf;

use crate::app::panel_view::Commands;
use crate::app::state::Settings;
use crate::app::{App, Command};

/// The toolbar's Recent menu.
pub(super) fn menu(ui: &mut egui::Ui, settings: &Settings, commands: &mut Commands) {
    let recent = settings.files.recent_files.clone();
    ui.add_enabled_ui(!recent.is_empty(), |ui| {
        let response = ui
            .menu_button("Recent", |ui| {
                for path in recent {
                    let label = path.display().to_string();
                    if ui
                        .button(&label)
                        .on_hover_text("Open this file again")
                        .clicked()
                    {
                        commands.push(Command::OpenRecent(path));
                        ui.close();
                    }
                }
            })
            .response;
        response
            .on_hover_text("Open one of the last files you opened")
            .on_disabled_hover_text("The files you open are listed here");
    });
}

impl App {
    /// Opens a file from the Recent menu; one that is gone is named and dropped from the menu.
    pub(super) fn open_recent(&mut self, path: PathBuf) {
        if !fairmesh::bundled::is_bunny_pseudo_path(&path) && !fairmesh::io::exists(&path) {
            self.settings.files.forget_recent(&path);
            self.error = Some(format!(
                "Cannot open {}: the file is no longer there (removed from Recent)",
                path.display()
            ));
            return;
        }
        self.open(path);
    }
}
