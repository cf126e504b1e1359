//! The side panel's Export section: the export path with Export and Export as…, and the level
//! chain (one GLB per level of the hierarchy, for LOD) with its folder and range (in a page,
//! without a folder: the levels download as one `.zip`).

use std::path::PathBuf;

use super::command::PanelChange;
use super::panel_view::{Commands, PanelView};
use super::state::Settings;
use super::Command;

/// The export path and buttons, and the level chain's export.
pub(super) fn show(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
) {
    let Some(document) = view.document else {
        return;
    };
    let mut export_path = document.export_path.clone();
    let label = ui.label("Export path:");
    ui.add(egui::TextEdit::singleline(&mut export_path).desired_width(f32::INFINITY))
        .labelled_by(label.id);
    ui.small(super::tips::EXPORT_FORMATS);
    if cfg!(target_arch = "wasm32") {
        ui.small(super::tips::WEB_EXPORT);
    }
    ui.horizontal(|ui| {
        if ui
            .button("Export")
            .on_hover_text("Write the result to the export path (Ctrl+E)")
            .clicked()
        {
            commands.push(Command::Export(PathBuf::from(export_path.trim())));
        }
        // A page has no save dialog: the browser asks where a download goes.
        if !cfg!(target_arch = "wasm32") && ui.button("Export as…").clicked() {
            commands.push(Command::ExportDialog);
        }
    });
    if export_path != document.export_path {
        commands.push(Command::Panel(PanelChange::ExportPath(export_path)));
    }

    ui.add_space(4.0);
    ui.strong("Level chain (LOD)");
    // A page has no folders: the levels download together, as one `.zip`.
    if !cfg!(target_arch = "wasm32") {
        let placeholder = view
            .levels_folder
            .as_ref()
            .map_or_else(String::new, |p| p.display().to_string());
        let label = ui.label("Levels folder:");
        ui.add(
            egui::TextEdit::singleline(&mut settings.level_chain.folder)
                .hint_text(placeholder)
                .desired_width(f32::INFINITY),
        )
        .labelled_by(label.id);
    }
    let top = document.level_count().unwrap_or(1).saturating_sub(1);
    // Edit copies: the stored range may reach past this mesh's levels (its end "to the top").
    let mut to = settings.level_chain.to.min(top);
    let mut from = settings.level_chain.from.min(to);
    ui.horizontal(|ui| {
        ui.label("Levels");
        let a = ui
            .add(egui::DragValue::new(&mut from).range(0..=top).prefix("M"))
            .on_hover_text("The first level written (M0: the full mesh)");
        ui.label("to");
        let b = ui
            .add(egui::DragValue::new(&mut to).range(0..=top).prefix("M"))
            .on_hover_text("The last level written (the coarsest is the top)");
        if a.changed() {
            settings.level_chain.from = from;
        }
        if b.changed() {
            settings.level_chain.to = if to == top { usize::MAX } else { to };
        }
    });
    if ui
        .add_enabled(
            document.level_count().is_some(),
            egui::Button::new("Export levels"),
        )
        .on_hover_text(if cfg!(target_arch = "wasm32") {
            "One GLB per level of the hierarchy, for LOD, downloaded together as one .zip"
        } else {
            "One GLB per level of the hierarchy, for LOD"
        })
        .clicked()
    {
        commands.push(Command::ExportLevels);
    }
}
