//! The editor's widgets: toolbar (open, view toggles), error banner, controls side panel
//! (hierarchy, fairing options, numbers, export, performance) and the 3D viewport.
//! Widgets read the app's state and emit [`Command`]s; the app applies them after the frame.
//! Plain display toggles (wireframe, option values) are edited in place.

use std::path::PathBuf;

use super::state::{BoundarySetting, HierarchyState, VariantSetting, ViewMode};
use super::{App, Command};

pub fn show(app: &mut App, ui: &mut egui::Ui) {
    egui::Panel::top("fairmesh-toolbar").show(ui, |ui| toolbar(app, ui));
    egui::Panel::right("fairmesh-controls")
        .resizable(true)
        .default_size(310.0)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| controls(app, ui));
        });
    egui::CentralPanel::no_frame().show(ui, |ui| viewport(app, ui));
}

fn toolbar(app: &mut App, ui: &mut egui::Ui) {
    ui.add_space(4.0);
    ui.horizontal(|ui| {
        if ui
            .button("Open…")
            .on_hover_text("Pick a mesh file")
            .clicked()
        {
            app.commands.push(Command::OpenDialog);
        }
        let label = ui.label("Path:");
        let edit = ui
            .add(
                egui::TextEdit::singleline(&mut app.open_path)
                    .hint_text("type a mesh path, or drop a file on the window")
                    .desired_width(340.0),
            )
            .labelled_by(label.id);
        let entered = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        if ui.button("Load").clicked() || entered {
            let typed = app.open_path.trim();
            if typed.is_empty() {
                app.error = Some("Type the path of a mesh file to load".into());
            } else {
                app.commands.push(Command::Open(PathBuf::from(typed)));
            }
        }
        ui.separator();
        if ui.button("Fit view (F)").clicked() {
            app.commands.push(Command::FitView);
        }
        ui.checkbox(&mut app.settings.wireframe, "Wireframe (W)");
        ui.separator();
        let mut mode = app.settings.view_mode;
        ui.selectable_value(&mut mode, ViewMode::Faired, "Faired");
        ui.selectable_value(&mut mode, ViewMode::Level, "Level mesh");
        ui.selectable_value(&mut mode, ViewMode::Original, "Original");
        if mode != app.settings.view_mode {
            app.commands.push(Command::SetViewMode(mode));
        }
    });
    if let Some(path) = &app.loading {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(format!("Loading {} …", path.display()));
        });
    }
    if let Some(error) = app.error.clone() {
        egui::Frame::new()
            .fill(egui::Color32::from_rgb(110, 24, 24))
            .inner_margin(6.0)
            .corner_radius(4.0)
            .show(ui, |ui| {
                ui.horizontal(|ui| {
                    ui.colored_label(egui::Color32::WHITE, format!("Error: {error}"));
                    if ui.button("Dismiss").clicked() {
                        app.commands.push(Command::DismissError);
                    }
                });
            });
    }
    if let Some(message) = &app.message {
        ui.colored_label(egui::Color32::from_rgb(140, 200, 140), message);
    }
    ui.add_space(2.0);
}

fn controls(app: &mut App, ui: &mut egui::Ui) {
    let Some(document) = &app.document else {
        ui.heading("No mesh");
        ui.label("Open a file, type a path above, or drop a mesh file on the window.");
        performance(app, ui);
        return;
    };

    ui.heading("Mesh");
    let name = document
        .path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| document.path.display().to_string());
    ui.label(name)
        .on_hover_text(document.path.display().to_string());
    ui.label(format!(
        "Loaded: {} vertices, {} faces",
        document.original.vertex_count(),
        document.original.face_count()
    ));
    let report = &document.report;
    if report.welded_vertices
        + report.removed_degenerate_faces
        + report.removed_unreferenced_vertices
        > 0
    {
        ui.small(format!(
            "welded {}, removed {} degenerate faces, {} unused vertices",
            report.welded_vertices,
            report.removed_degenerate_faces,
            report.removed_unreferenced_vertices
        ));
    }
    for warning in &report.warnings {
        ui.small(format!("Warning: {warning}"));
    }

    ui.separator();
    ui.heading("Hierarchy");
    let mut top_level = 0;
    match &document.hierarchy {
        HierarchyState::Building => {
            ui.horizontal(|ui| {
                ui.add(
                    egui::ProgressBar::new(app.hierarchy_progress.get())
                        .show_percentage()
                        .desired_width(180.0),
                );
                if ui.button("Cancel").clicked() {
                    app.commands.push(Command::CancelHierarchy);
                }
            });
        }
        HierarchyState::Failed(reason) => {
            ui.label(format!("Not built: {reason}"));
            if ui.button("Build hierarchy").clicked() {
                app.commands.push(Command::RebuildHierarchy);
            }
        }
        HierarchyState::Ready { levels, .. } => {
            top_level = levels.len().saturating_sub(1);
            ui.label(format!("{} levels (M0 … M{top_level})", levels.len()));
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

    ui.separator();
    ui.heading("Fairing");
    let ready = document.level_count().is_some();
    let mut level = document.level;
    let slider = ui.add_enabled(
        ready,
        egui::Slider::new(&mut level, 0..=top_level).text("Start level"),
    );
    if slider.changed() {
        app.commands.push(Command::SetLevel(level));
    }
    let before = app.settings.clone();
    ui.add(egui::Slider::new(&mut app.settings.iterations, 1..=50).text("Iterations per level"));
    ui.add(egui::Slider::new(&mut app.settings.rounds, 1..=10).text("Rounds"));
    egui::ComboBox::from_label("Boundary")
        .selected_text(match app.settings.boundary {
            BoundarySetting::Curve => "Smooth as curve",
            BoundarySetting::Fixed => "Fixed",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(
                &mut app.settings.boundary,
                BoundarySetting::Curve,
                "Smooth as curve",
            );
            ui.selectable_value(&mut app.settings.boundary, BoundarySetting::Fixed, "Fixed");
        });
    ui.checkbox(&mut app.settings.fair_finest, "Fair M0 too");
    egui::ComboBox::from_label("Variant")
        .selected_text(match app.settings.variant {
            VariantSetting::Paper => "Paper",
            VariantSetting::Improved => "Improved",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut app.settings.variant, VariantSetting::Paper, "Paper");
            ui.selectable_value(
                &mut app.settings.variant,
                VariantSetting::Improved,
                "Improved",
            );
        });
    if app.settings.fairing_key() != before.fairing_key() {
        app.commands.push(Command::Refair);
    }
    if app.fair_in_flight {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(format!(
                "fairing … {:.0} %",
                app.fair_progress.get() * 100.0
            ));
        });
    }

    ui.separator();
    ui.heading("Numbers");
    egui::Grid::new("fairmesh-numbers")
        .num_columns(2)
        .show(ui, |ui| {
            ui.label("Shown vertices");
            ui.label(app.shown_counts.0.to_string());
            ui.end_row();
            ui.label("Shown faces");
            ui.label(app.shown_counts.1.to_string());
            ui.end_row();
            let faired = document.faired.as_ref();
            ui.label("Volume change");
            ui.label(faired.map_or("–".into(), |f| {
                format!("{:+.4} %", f.volume_change * 100.0)
            }));
            ui.end_row();
            ui.label("RMS displacement");
            let (lo, hi) = document.bounds;
            let diagonal = ((0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f32>()).sqrt();
            ui.label(faired.map_or("–".into(), |f| {
                format!(
                    "{:.3e} ({:.3} % of diagonal)",
                    f.rms_displacement,
                    f.rms_displacement / diagonal.max(f32::MIN_POSITIVE) as f64 * 100.0
                )
            }));
            ui.end_row();
            ui.label("Faired from");
            ui.label(faired.map_or("–".into(), |f| format!("M{}", f.level)));
            ui.end_row();
            ui.label("Load time");
            ui.label(seconds(document.load_time));
            ui.end_row();
            ui.label("Hierarchy build");
            ui.label(match &document.hierarchy {
                HierarchyState::Ready { build_time, .. } => seconds(*build_time),
                HierarchyState::Building => "building …".into(),
                HierarchyState::Failed(_) => "–".into(),
            });
            ui.end_row();
            ui.label("Last fairing");
            ui.label(faired.map_or("–".into(), |f| seconds(f.elapsed)));
            ui.end_row();
        });

    ui.separator();
    ui.heading("Export");
    let mut export_path = document.export_path.clone();
    let label = ui.label("Export path:");
    ui.add(egui::TextEdit::singleline(&mut export_path).desired_width(f32::INFINITY))
        .labelled_by(label.id);
    ui.small("GLB, glTF, OBJ or PLY, by extension");
    ui.horizontal(|ui| {
        if ui.button("Export").clicked() {
            app.commands
                .push(Command::Export(PathBuf::from(export_path.trim())));
        }
        if ui.button("Export as…").clicked() {
            app.commands.push(Command::ExportDialog);
        }
    });
    if let Some(document) = &mut app.document {
        document.export_path = export_path;
    }

    performance(app, ui);
}

fn performance(app: &mut App, ui: &mut egui::Ui) {
    ui.separator();
    let response = egui::CollapsingHeader::new("Performance")
        .default_open(app.settings.show_performance)
        .show(ui, |ui| {
            let stats = &app.frame_stats;
            egui::Grid::new("fairmesh-performance")
                .num_columns(2)
                .show(ui, |ui| {
                    ui.label("UI frame (CPU)");
                    ui.label(milliseconds(stats.last()));
                    ui.end_row();
                    ui.label("mean / max of 240");
                    ui.label(format!(
                        "{} / {}",
                        milliseconds(stats.mean()),
                        milliseconds(stats.max())
                    ));
                    ui.end_row();
                    ui.label("max while working");
                    ui.label(milliseconds(stats.max_while_busy));
                    ui.end_row();
                    ui.label("  results / upload / widgets");
                    let [results, upload, widgets] = stats.max_while_busy_parts;
                    ui.label(format!(
                        "{} / {} / {}",
                        milliseconds(results),
                        milliseconds(upload),
                        milliseconds(widgets)
                    ));
                    ui.end_row();
                    ui.label("frames");
                    ui.label(stats.frames.to_string());
                    ui.end_row();
                    if let Some(viewport) = &app.viewport {
                        ui.label("viewport images");
                        ui.label(viewport.images_drawn().to_string());
                        ui.end_row();
                        ui.label("adapter");
                        ui.label(viewport.adapter_description());
                        ui.end_row();
                    }
                });
            if ui.button("Reset max").clicked() {
                app.frame_stats.reset_busy_max();
            }
        });
    app.settings.show_performance = response.fully_open();
}

fn viewport(app: &mut App, ui: &mut egui::Ui) {
    let rect = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
    app.viewport_rect = Some(rect);
    if response.dragged_by(egui::PointerButton::Primary) {
        app.camera.orbit(response.drag_delta());
    }
    if response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
    {
        app.camera.pan(response.drag_delta(), rect.height());
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta().y);
        if scroll != 0.0 {
            app.camera.zoom(scroll);
        }
    }
    let params = app.draw_params(rect);
    let painter = ui.painter_at(rect);
    match &mut app.viewport {
        Some(viewport) => viewport.paint(&painter, rect, params),
        None => {
            painter.text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "No wgpu renderer: the 3D view needs eframe's wgpu backend",
                egui::FontId::proportional(16.0),
                ui.visuals().text_color(),
            );
        }
    }
    painter.text(
        rect.left_bottom() + egui::vec2(8.0, -8.0),
        egui::Align2::LEFT_BOTTOM,
        "Left drag: orbit · right/middle drag: pan · scroll: zoom · F: fit · W: wireframe",
        egui::FontId::proportional(12.0),
        egui::Color32::from_gray(150),
    );
}

fn seconds(duration: std::time::Duration) -> String {
    format!("{:.3} s", duration.as_secs_f64())
}

fn milliseconds(duration: std::time::Duration) -> String {
    format!("{:.2} ms", duration.as_secs_f64() * 1000.0)
}
