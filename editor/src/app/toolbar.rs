//! The toolbar at the top of the window: Open…, Recent and the typed path with Load; Fit view,
//! Save image, Wireframe and which mesh the view shows; Undo and Redo. It wraps in a narrow
//! window, so that no control ends up off screen.

use std::path::PathBuf;

use super::command::PanelChange;
use super::panel_view::{Commands, PanelView};
use super::state::{Settings, ViewMode};
use super::Command;

/// The toolbar's three groups, separated.
pub(super) fn toolbar(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
) {
    ui.add_space(4.0);
    // Wraps in a narrow window, so that no control ends up off screen.
    ui.horizontal_wrapped(|ui| {
        file_controls(ui, view, settings, commands);
        ui.separator();
        view_controls(ui, view, settings, commands);
        ui.separator();
        undo_redo_buttons(ui, view, commands);
    });
    ui.add_space(2.0);
}

/// Open…, the Recent menu, and the typed path with Load.
fn file_controls(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
) {
    if ui
        .button("Open…")
        .on_hover_text("Pick a mesh file (Ctrl+O)")
        .clicked()
    {
        commands.push(Command::OpenDialog);
    }
    super::recent::menu(ui, settings, commands);
    let label = ui.label("Path:");
    let mut open_path = view.open_path.to_owned();
    let edit = ui
        .add(
            egui::TextEdit::singleline(&mut open_path)
                .hint_text("type a mesh path, or drop a file on the window")
                // Narrow enough that the toolbar stays one row at 1200 points.
                .desired_width(180.0),
        )
        .labelled_by(label.id);
    if open_path != view.open_path {
        commands.push(Command::Panel(PanelChange::OpenPath(open_path.clone())));
    }
    let entered = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
    if ui.button("Load").clicked() || entered {
        let typed = open_path.trim();
        if typed.is_empty() {
            commands.push(Command::Panel(PanelChange::Error(
                "Type the path of a mesh file to load".into(),
            )));
        } else {
            commands.push(Command::Open(PathBuf::from(typed)));
        }
    }
}

/// Fit view, Save image, Wireframe, and which mesh the view shows (result, level, input).
fn view_controls(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
) {
    if ui
        .button("Fit view (F)")
        .on_hover_text("Fit the mesh into the view (F)")
        .clicked()
    {
        commands.push(Command::FitView);
    }
    super::tasks::view_image::button(ui, view, commands);
    ui.checkbox(&mut settings.view.wireframe, "Wireframe (W)")
        .on_hover_text("Draw the edges over the faces (W)");
    ui.separator();
    let mut mode = settings.view.view_mode;
    ui.selectable_value(&mut mode, ViewMode::Faired, "Faired")
        .on_hover_text("Show the result of the fairing");
    ui.selectable_value(&mut mode, ViewMode::Level, "Level mesh")
        .on_hover_text("Show the coarse mesh of the start level, where the fairing begins");
    ui.selectable_value(&mut mode, ViewMode::Original, "Input mesh")
        .on_hover_text("Show the input mesh: as loaded, or as Add noise or Apply result left it");
    if mode != settings.view.view_mode {
        commands.push(Command::SetViewMode(mode));
    }
}

/// Undo and Redo, saying what they would undo or redo, and the next undo step's name.
fn undo_redo_buttons(ui: &mut egui::Ui, view: &PanelView, commands: &mut Commands) {
    let undo_label = view.history.undo_label().map(str::to_owned);
    let redo_label = view.history.redo_label().map(str::to_owned);
    let undo = ui
        .add_enabled(undo_label.is_some(), egui::Button::new("Undo"))
        .on_hover_text(match &undo_label {
            Some(label) => format!("Undo {label} (Ctrl+Z)"),
            None => "Nothing to undo (Ctrl+Z)".into(),
        })
        .on_disabled_hover_text("Nothing to undo (Ctrl+Z)");
    if undo.clicked() {
        commands.push(Command::Undo);
    }
    let redo = ui
        .add_enabled(redo_label.is_some(), egui::Button::new("Redo"))
        .on_hover_text(match &redo_label {
            Some(label) => format!("Redo {label} (Ctrl+Shift+Z, Ctrl+Y)"),
            None => "Nothing to redo (Ctrl+Shift+Z, Ctrl+Y)".into(),
        })
        .on_disabled_hover_text("Nothing to redo (Ctrl+Shift+Z, Ctrl+Y)");
    if redo.clicked() {
        commands.push(Command::Redo);
    }
    if let Some(label) = &undo_label {
        ui.small(format!("undo: {label}"));
    }
}
