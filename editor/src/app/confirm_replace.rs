//! The question asked before an export replaces an existing file: "Replace FILE?" with Replace
//! and Cancel. The system's save dialog ("Export as…") asks on its own, so only typed paths and
//! Ctrl+E come here.

use crate::app::panel_view::{Commands, PanelView};
use crate::app::Command;

/// Shows the question while an export waits for an answer.
pub(super) fn show(ctx: &egui::Context, view: &PanelView, commands: &mut Commands) {
    let Some(path) = view.confirm_replace.map(|path| path.to_path_buf()) else {
        return;
    };
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let modal = egui::Modal::new(egui::Id::unique("fairmesh-confirm-replace")).show(ctx, |ui| {
        ui.set_max_width(420.0);
        ui.heading(format!("Replace {name}?"));
        ui.label(format!(
            "{} exists. Exporting replaces its content with the result.",
            path.display()
        ));
        ui.add_space(6.0);
        ui.horizontal(|ui| {
            let replace = ui
                .button("Replace")
                .on_hover_text("Write the result over the existing file");
            let cancel = ui
                .button("Cancel")
                .on_hover_text("Keep the existing file; nothing is written (Esc)");
            (replace.clicked(), cancel.clicked())
        })
        .inner
    });
    let (replace, cancel) = modal.inner;
    if replace {
        commands.push(Command::ReplaceExport(path));
    } else if cancel || modal.should_close() {
        commands.push(Command::CancelExport);
    }
}
