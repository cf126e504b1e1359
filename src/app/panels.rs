//! The editor's widgets: toolbar (open, view toggles), status bar, controls side panel
//! (mesh, noise, hierarchy, one function each, in the order shown); the View section is in
//! `view_panel.rs`, the Fairing section and sharp-edge controls (and [`tips`], every
//! control's tooltip) in `fairing_panel.rs`, Export in `export_panel.rs`, the Numbers in
//! `numbers_panel.rs`, Paint in `paint_panel.rs`, Performance in `performance_panel.rs`, the
//! 3D viewport's area in `viewport_panel.rs`.
//! Each section takes the app's state read-only ([`PanelView`]), the [`Settings`] it edits in
//! place (display toggles, option values) and the frame's commands: whatever else it asks for
//! is a [`Command`], applied by the app after the frame's widgets are drawn.

use std::path::PathBuf;

use super::command::PanelChange;
pub use super::fairing_panel::tips;
use super::panel_view::{Commands, PanelView};
use super::state::{HierarchyState, Settings, ViewMode};
use super::{App, Command};
use crate::noise::NoiseMode;

pub fn show(app: &mut App, ui: &mut egui::Ui) {
    egui::Panel::top("fairmesh-toolbar").show(ui, |ui| {
        app.panel(|view, settings, commands| toolbar(ui, view, settings, commands))
    });
    egui::Panel::bottom("fairmesh-status").show(ui, |ui| {
        app.panel(|view, _, commands| status_bar(ui, view, commands))
    });
    egui::Panel::right("fairmesh-controls")
        .resizable(true)
        .default_size(310.0)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| controls(app, ui));
        });
    egui::CentralPanel::no_frame().show(ui, |ui| {
        app.viewport_section(|view, state, settings, commands| {
            super::viewport_panel::show(ui, view, state, settings, commands)
        })
    });
}

fn toolbar(ui: &mut egui::Ui, view: &PanelView, settings: &mut Settings, commands: &mut Commands) {
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
    ui.checkbox(&mut settings.wireframe, "Wireframe (W)")
        .on_hover_text("Draw the edges over the faces (W)");
    ui.separator();
    let mut mode = settings.view_mode;
    ui.selectable_value(&mut mode, ViewMode::Faired, "Faired")
        .on_hover_text("Show the result of the fairing");
    ui.selectable_value(&mut mode, ViewMode::Level, "Level mesh")
        .on_hover_text("Show the coarse mesh of the start level, where the fairing begins");
    ui.selectable_value(&mut mode, ViewMode::Original, "Input mesh")
        .on_hover_text("Show the input mesh: as loaded, or as Add noise or Apply result left it");
    if mode != settings.view_mode {
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

/// Loading, errors and messages, at the bottom of the window: their coming and going does not
/// move the controls (a click meant for one button would hit another).
fn status_bar(ui: &mut egui::Ui, view: &PanelView, commands: &mut Commands) {
    ui.add_space(2.0);
    if let Some(path) = view.loading {
        ui.horizontal(|ui| {
            activity_spinner(ui);
            ui.label(format!("Loading {} …", path.display()));
        });
    }
    if let Some(error) = view.error {
        egui::Frame::new()
            .fill(egui::Color32::from_rgb(110, 24, 24))
            .inner_margin(6.0)
            .corner_radius(4.0)
            .show(ui, |ui| {
                // The button first and the message wrapped in the width left: a long message
                // (a path, then what is wrong and what to do) once ran past the window's
                // edge, taking its end and the button with it.
                ui.horizontal(|ui| {
                    if ui
                        .button("Dismiss")
                        .on_hover_text("Hide this message")
                        .clicked()
                    {
                        commands.push(Command::DismissError);
                    }
                    ui.add(
                        egui::Label::new(
                            egui::RichText::new(format!("Error: {error}"))
                                .color(egui::Color32::WHITE),
                        )
                        .wrap(),
                    );
                });
            });
    }
    if let Some(message) = view.message {
        ui.colored_label(egui::Color32::from_rgb(140, 200, 140), message);
    }
    if view.loading.is_none() && view.error.is_none() && view.message.is_none() {
        // The bar keeps its height when there is nothing to say.
        ui.weak("Ready");
    }
    ui.add_space(2.0);
}

/// The side panel's sections, in the order shown; each gets the app's state read-only, the
/// settings and the frame's commands.
fn controls(app: &mut App, ui: &mut egui::Ui) {
    app.panel(|view, settings, commands| {
        if view.document.is_none() {
            ui.heading("No mesh");
            ui.label("Open a file, type a path above, or drop a mesh file on the window.");
            super::performance_panel::show(ui, view, settings, commands);
            return;
        };
        ui.heading("View");
        super::view_panel::show(ui, view, settings, commands);
        mesh_section(ui, view);
        noise_section(ui, settings, commands);
        let top_level = hierarchy_section(ui, view, commands);
        super::fairing_panel::sharp_edge_controls(ui, view, settings, commands);
        ui.separator();
        ui.heading("Fairing");
        super::fairing_panel::fairing_controls(ui, view, settings, commands, top_level);
        super::export_panel::show(ui, view, settings, commands);
        ui.separator();
        ui.heading("Numbers");
        super::numbers_panel::show(ui, view);
        // Below Export and the numbers: a painting session is an occasional step, and the
        // controls used on every file stay where they were.
        super::paint_panel::section(ui, view, settings, commands);
        super::performance_panel::show(ui, view, settings, commands);
    })
}

/// The file's name and size, what loading repaired, and whether noise was added.
fn mesh_section(ui: &mut egui::Ui, view: &PanelView) {
    let Some(document) = view.document else {
        return;
    };
    ui.separator();
    ui.heading("Mesh");
    let name = document
        .path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| document.path.display().to_string());
    ui.label(name)
        .on_hover_text(document.path.display().to_string());
    let (vertices, faces) = (
        document.original.vertex_count(),
        document.original.face_count(),
    );
    ui.label(format!(
        "Input mesh: {vertices} {}, {faces} {}",
        if vertices == 1 { "vertex" } else { "vertices" },
        if faces == 1 { "face" } else { "faces" }
    ));
    let report = &document.report;
    if report.welded_vertices
        + report.removed_degenerate_faces
        + report.removed_repeated_faces
        + report.removed_unreferenced_vertices
        > 0
    {
        ui.small(format!(
            "welded {}, removed {} degenerate faces, {} repeated faces, {} unused vertices",
            report.welded_vertices,
            report.removed_degenerate_faces,
            report.removed_repeated_faces,
            report.removed_unreferenced_vertices
        ));
    }
    for warning in &report.warnings {
        ui.small(format!("Warning: {warning}"));
    }

    if let Some(clean) = &document.clean {
        ui.small(format!(
            "Noise added: the mesh before it is kept as the clean mesh ({} vertices)",
            clean.vertex_count()
        ));
    }
}

/// Sigma, seed and direction of the noise, and the button that adds it.
fn noise_section(ui: &mut egui::Ui, settings: &mut Settings, commands: &mut Commands) {
    ui.separator();
    ui.heading("Noise");
    ui.add(egui::Slider::new(&mut settings.noise_sigma, 0.0..=2.0).text("Sigma (× mean edge)"))
        .on_hover_text(tips::NOISE_SIGMA);
    ui.horizontal(|ui| {
        let label = ui.label("Seed").on_hover_text(tips::NOISE_SEED);
        ui.add(egui::DragValue::new(&mut settings.noise_seed))
            .labelled_by(label.id)
            .on_hover_text(tips::NOISE_SEED);
    });
    egui::ComboBox::from_label("Noise direction")
        .selected_text(noise_mode_name(settings.noise_mode))
        .show_ui(ui, |ui| {
            for mode in [
                NoiseMode::Normal,
                NoiseMode::Direction,
                NoiseMode::Isotropic,
            ] {
                ui.selectable_value(&mut settings.noise_mode, mode, noise_mode_name(mode));
            }
        })
        .response
        .on_hover_text(tips::NOISE_DIRECTION);
    if ui
        .button("Add noise")
        .on_hover_text(
            "Adds noise to the input mesh; the mesh before it is kept as the clean mesh, to \
             measure how close the result gets to it",
        )
        .clicked()
    {
        commands.push(Command::AddNoise);
    }
}

/// The hierarchy's progress, failure or levels; returns the top level (0 until it is built).
fn hierarchy_section(ui: &mut egui::Ui, view: &PanelView, commands: &mut Commands) -> usize {
    let Some(document) = view.document else {
        return 0;
    };
    ui.separator();
    ui.heading("Hierarchy");
    let mut top_level = 0;
    match &document.hierarchy {
        HierarchyState::Building => {
            ui.horizontal(|ui| {
                ui.add(
                    egui::ProgressBar::new(view.hierarchy_progress)
                        .show_percentage()
                        // Narrow enough that the toolbar stays one row at 1200 points.
                        .desired_width(180.0),
                );
                if ui.button("Cancel").clicked() {
                    commands.push(Command::CancelHierarchy);
                }
            });
        }
        HierarchyState::Failed(reason) => {
            ui.label(format!("Not built: {reason}"));
            if ui.button("Build hierarchy").clicked() {
                commands.push(Command::RebuildHierarchy);
            }
        }
        HierarchyState::Ready {
            levels, hierarchy, ..
        } => {
            top_level = levels.len().saturating_sub(1);
            if top_level == 0 {
                ui.label("1 level (M0 only)").on_hover_text(
                    "The mesh is too small to decimate: the hierarchy holds only the input mesh",
                );
            } else {
                ui.label(format!("{} levels (M0 … M{top_level})", levels.len()));
            }
            let loose = hierarchy.loose_triangles().len();
            if loose > 0 {
                ui.label(format!("{loose} loose triangles left out of the levels"))
                    .on_hover_text(
                        "These triangles lie over other triangles or hang from an edge as fins \
                         (a scan's reconstruction leaves them). The levels are built without \
                         them, so M0 here has fewer faces than the mesh; the smoothed result \
                         keeps them, following their corners.",
                    );
            }
            egui::CollapsingHeader::new("Level sizes")
                .default_open(levels.len() <= 12)
                .show(ui, |ui| {
                    egui::Grid::new("fairmesh-levels")
                        .striped(true)
                        .show(ui, |ui| {
                            ui.strong("Level");
                            ui.strong("Vertices");
                            ui.strong("Faces");
                            ui.end_row();
                            for (index, info) in levels.iter().enumerate() {
                                ui.label(format!("M{index}"));
                                ui.label(info.vertices.to_string());
                                ui.label(info.faces.to_string());
                                ui.end_row();
                            }
                        });
                });
        }
    }
    top_level
}

/// A turning arc beside work in progress, like egui's spinner but without asking for a frame
/// of its own: it moves when the app repaints for the work's progress (every 50 ms, or 250 ms on
/// a software renderer), not at the display's full rate. egui's spinner repaints continuously,
/// which on a software renderer took most of the CPU from the fairing it was showing.
pub(super) fn activity_spinner(ui: &mut egui::Ui) {
    let size = ui.text_style_height(&egui::TextStyle::Body);
    let (rect, _) = ui.allocate_exact_size(egui::vec2(size, size), egui::Sense::hover());
    if !ui.is_rect_visible(rect) {
        return;
    }
    let time = ui.input(|i| i.time);
    let start = time * 5.0;
    let points: Vec<egui::Pos2> = (0..=24)
        .map(|i| {
            let angle = start + i as f64 / 24.0 * std::f64::consts::PI * 1.5;
            let (sin, cos) = angle.sin_cos();
            rect.center() + rect.width() * 0.4 * egui::vec2(cos as f32, sin as f32)
        })
        .collect();
    ui.painter().add(egui::Shape::line(
        points,
        egui::Stroke::new(2.0, ui.visuals().strong_text_color()),
    ));
}

fn noise_mode_name(mode: NoiseMode) -> &'static str {
    match mode {
        NoiseMode::Normal => "Along the normal",
        NoiseMode::Direction => "Random direction",
        NoiseMode::Isotropic => "Isotropic",
    }
}

pub(super) fn seconds(duration: std::time::Duration) -> String {
    format!("{:.3} s", duration.as_secs_f64())
}
