//! The editor window's layout: the toolbar (`toolbar.rs`) at the top, the status bar
//! (`status_bar.rs`) at the bottom, the side panel's sections on the right, and the 3D viewport
//! (`viewport_panel.rs`) in the middle. This file only places them; each lives in its own file:
//! View in `view_panel.rs`, Mesh and Noise in `mesh_panel.rs`, Hierarchy in `hierarchy_panel.rs`,
//! the sharp-edge controls and Fairing in `fairing_panel.rs`, Export in `export_panel.rs`, the
//! Numbers in `numbers_panel.rs`, Paint in `paint_panel.rs`, Performance in
//! `performance_panel.rs`. Their tooltips are in [`tips`]; the small widgets they share in
//! `widgets.rs`.
//! Each section takes the app's state read-only (`PanelView`), the `Settings` it edits in
//! place (display toggles, option values) and the frame's commands: whatever else it asks for
//! is a [`Command`](super::Command), applied by the app after the frame's widgets are drawn.

pub use super::tips;
use super::App;

/// Draws the whole window for this frame.
pub fn show(app: &mut App, ui: &mut egui::Ui) {
    egui::Panel::top("fairmesh-toolbar").show(ui, |ui| {
        app.panel(|view, settings, commands| super::toolbar::toolbar(ui, view, settings, commands))
    });
    egui::Panel::bottom("fairmesh-status").show(ui, |ui| {
        app.panel(|view, _, commands| super::status_bar::status_bar(ui, view, commands))
    });
    egui::Panel::right("fairmesh-controls")
        .resizable(true)
        .default_size(310.0)
        .show(ui, |ui| {
            // The bar stays visible: it says there is more below (Numbers, Paint) on a
            // window too short for every section.
            ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
            egui::ScrollArea::vertical()
                .scroll_bar_visibility(egui::scroll_area::ScrollBarVisibility::AlwaysVisible)
                .show(ui, |ui| controls(app, ui));
        });
    egui::CentralPanel::no_frame().show(ui, |ui| {
        app.viewport_section(|view, state, settings, commands| {
            super::viewport_panel::show(ui, view, state, settings, commands)
        })
    });
}

/// The side panel's sections, in the order shown; each gets the app's state read-only, the
/// settings and the frame's commands. Each sits under a heading that folds it away (a click on
/// the heading), so that on a short window the sections in use fit above the fold.
fn controls(app: &mut App, ui: &mut egui::Ui) {
    app.panel(|view, settings, commands| {
        let Some(document) = view.document else {
            ui.heading("No mesh");
            ui.label("Open a file, type a path above, or drop a mesh file on the window.");
            super::performance_panel::show(ui, view, settings, commands);
            return;
        };
        section(ui, "View", |ui| {
            super::view_panel::show(ui, view, settings, commands)
        });
        section(ui, "Mesh", |ui| super::mesh_panel::mesh_section(ui, view));
        section(ui, "Noise", |ui| {
            super::mesh_panel::noise_section(ui, settings, commands)
        });
        let top_level = section(ui, "Hierarchy", |ui| {
            let top_level = super::hierarchy_panel::hierarchy_section(ui, view, commands);
            super::fairing_panel::sharp_edge_controls(ui, view, settings, commands);
            top_level
        })
        .unwrap_or_else(|| document.level_count().unwrap_or(1).saturating_sub(1));
        section(ui, "Fairing", |ui| {
            super::fairing_panel::fairing_controls(ui, view, settings, commands, top_level)
        });
        section(ui, "Export", |ui| {
            super::export_panel::show(ui, view, settings, commands)
        });
        section(ui, "Numbers", |ui| super::numbers_panel::show(ui, view));
        // Below Export and the numbers: a painting session is an occasional step, and the
        // controls used on every file stay where they were.
        section(ui, PAINT_SECTION, |ui| {
            super::paint_panel::section(ui, view, settings, commands)
        });
        super::performance_panel::show(ui, view, settings, commands);
    })
}

/// The Paint section's heading.
pub const PAINT_SECTION: &str = "Paint where to fair";

/// One section of the side panel under its heading (open at first; a click folds it): what
/// `body` returned, `None` while folded.
fn section<R>(ui: &mut egui::Ui, title: &str, body: impl FnOnce(&mut egui::Ui) -> R) -> Option<R> {
    // The headings stand out enough between sections without a line, and the lines' room
    // keeps Export on an 800-point-high screen.
    egui::CollapsingHeader::new(egui::RichText::new(title).heading())
        .id_salt(("fairmesh-section", title))
        .default_open(true)
        .show_unindented(ui, body)
        .body_returned
}
