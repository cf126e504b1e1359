//! The editor's widgets: toolbar (open, view toggles), status bar, controls side panel
//! (hierarchy, fairing options, numbers, export, performance); the View section is in
//! `view_panel.rs`, the 3D viewport's area in `viewport_panel.rs`.
//! Widgets read the app's state and emit [`Command`]s; the app applies them after the frame.
//! Plain display toggles (wireframe, option values) are edited in place.

use std::path::PathBuf;

use super::state::{
    BoundarySetting, CompareView, HierarchyState, Measures, MethodSetting, VariantSetting,
    ViewMode, MAX_SHARP_EDGE_ANGLE, MIN_SHARP_EDGE_ANGLE,
};
use super::{App, Command};
use crate::noise::NoiseMode;

pub fn show(app: &mut App, ui: &mut egui::Ui) {
    egui::Panel::top("fairmesh-toolbar").show(ui, |ui| toolbar(app, ui));
    egui::Panel::bottom("fairmesh-status").show(ui, |ui| status_bar(app, ui));
    egui::Panel::right("fairmesh-controls")
        .resizable(true)
        .default_size(310.0)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| controls(app, ui));
        });
    egui::CentralPanel::no_frame().show(ui, |ui| super::viewport_panel::show(app, ui));
}

fn toolbar(app: &mut App, ui: &mut egui::Ui) {
    ui.add_space(4.0);
    // Wraps in a narrow window, so that no control ends up off screen.
    ui.horizontal_wrapped(|ui| {
        if ui
            .button("Open…")
            .on_hover_text("Pick a mesh file (Ctrl+O)")
            .clicked()
        {
            app.commands.push(Command::OpenDialog);
        }
        super::recent::menu(app, ui);
        let label = ui.label("Path:");
        let edit = ui
            .add(
                egui::TextEdit::singleline(&mut app.open_path)
                    .hint_text("type a mesh path, or drop a file on the window")
                    // Narrow enough that the toolbar stays one row at 1200 points.
                    .desired_width(180.0),
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
        if ui
            .button("Fit view (F)")
            .on_hover_text("Fit the mesh into the view (F)")
            .clicked()
        {
            app.commands.push(Command::FitView);
        }
        super::tasks::view_image::button(app, ui);
        ui.checkbox(&mut app.settings.wireframe, "Wireframe (W)")
            .on_hover_text("Draw the edges over the faces (W)");
        ui.separator();
        let mut mode = app.settings.view_mode;
        ui.selectable_value(&mut mode, ViewMode::Faired, "Faired")
            .on_hover_text("Show the result of the fairing");
        ui.selectable_value(&mut mode, ViewMode::Level, "Level mesh")
            .on_hover_text("Show the coarse mesh of the start level, where the fairing begins");
        ui.selectable_value(&mut mode, ViewMode::Original, "Input mesh")
            .on_hover_text(
                "Show the input mesh: as loaded, or as Add noise or Apply result left it",
            );
        if mode != app.settings.view_mode {
            app.commands.push(Command::SetViewMode(mode));
        }
        ui.separator();
        let undo_label = app.history.undo_label().map(str::to_owned);
        let redo_label = app.history.redo_label().map(str::to_owned);
        let undo = ui
            .add_enabled(undo_label.is_some(), egui::Button::new("Undo"))
            .on_hover_text(match &undo_label {
                Some(label) => format!("Undo {label} (Ctrl+Z)"),
                None => "Nothing to undo (Ctrl+Z)".into(),
            })
            .on_disabled_hover_text("Nothing to undo (Ctrl+Z)");
        if undo.clicked() {
            app.commands.push(Command::Undo);
        }
        let redo = ui
            .add_enabled(redo_label.is_some(), egui::Button::new("Redo"))
            .on_hover_text(match &redo_label {
                Some(label) => format!("Redo {label} (Ctrl+Shift+Z, Ctrl+Y)"),
                None => "Nothing to redo (Ctrl+Shift+Z, Ctrl+Y)".into(),
            })
            .on_disabled_hover_text("Nothing to redo (Ctrl+Shift+Z, Ctrl+Y)");
        if redo.clicked() {
            app.commands.push(Command::Redo);
        }
        if let Some(label) = &undo_label {
            ui.small(format!("undo: {label}"));
        }
    });
    ui.add_space(2.0);
}

/// Loading, errors and messages, at the bottom of the window: their coming and going does not
/// move the controls (a click meant for one button would hit another).
fn status_bar(app: &mut App, ui: &mut egui::Ui) {
    ui.add_space(2.0);
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
    if app.loading.is_none() && app.error.is_none() && app.message.is_none() {
        // The bar keeps its height when there is nothing to say.
        ui.weak("Ready");
    }
    ui.add_space(2.0);
}

fn controls(app: &mut App, ui: &mut egui::Ui) {
    if app.document.is_none() {
        ui.heading("No mesh");
        ui.label("Open a file, type a path above, or drop a mesh file on the window.");
        performance(app, ui);
        return;
    };

    ui.heading("View");
    super::view_panel::show(app, ui);
    let Some(document) = &app.document else {
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
    ui.label(format!(
        "Input mesh: {} vertices, {} faces",
        document.original.vertex_count(),
        document.original.face_count()
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

    ui.separator();
    ui.heading("Noise");
    ui.add(egui::Slider::new(&mut app.settings.noise_sigma, 0.0..=2.0).text("Sigma (× mean edge)"));
    ui.horizontal(|ui| {
        let label = ui.label("Seed");
        ui.add(egui::DragValue::new(&mut app.settings.noise_seed))
            .labelled_by(label.id);
    });
    egui::ComboBox::from_label("Noise direction")
        .selected_text(noise_mode_name(app.settings.noise_mode))
        .show_ui(ui, |ui| {
            for mode in [
                NoiseMode::Normal,
                NoiseMode::Direction,
                NoiseMode::Isotropic,
            ] {
                ui.selectable_value(&mut app.settings.noise_mode, mode, noise_mode_name(mode));
            }
        });
    if ui
        .button("Add noise")
        .on_hover_text(
            "Adds noise to the input mesh; the mesh before it is kept as the clean mesh, to \
             measure how close the result gets to it",
        )
        .clicked()
    {
        app.commands.push(Command::AddNoise);
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
                        // Narrow enough that the toolbar stays one row at 1200 points.
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
    sharp_edge_controls(app, ui);

    ui.separator();
    ui.heading("Fairing");
    fairing_controls(app, ui, top_level);
    let Some(document) = &app.document else {
        return;
    };

    ui.separator();
    ui.heading("Export");
    let mut export_path = document.export_path.clone();
    let label = ui.label("Export path:");
    ui.add(egui::TextEdit::singleline(&mut export_path).desired_width(f32::INFINITY))
        .labelled_by(label.id);
    ui.small("GLB, glTF, OBJ or PLY, by extension");
    ui.horizontal(|ui| {
        if ui
            .button("Export")
            .on_hover_text("Write the result to the export path (Ctrl+E)")
            .clicked()
        {
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

    ui.add_space(4.0);
    ui.strong("Level chain (LOD)");
    let placeholder = app
        .levels_folder()
        .map_or_else(String::new, |p| p.display().to_string());
    let label = ui.label("Levels folder:");
    ui.add(
        egui::TextEdit::singleline(&mut app.settings.levels_folder)
            .hint_text(placeholder)
            .desired_width(f32::INFINITY),
    )
    .labelled_by(label.id);
    let top = app
        .document
        .as_ref()
        .and_then(|d| d.level_count())
        .unwrap_or(1)
        .saturating_sub(1);
    // Edit copies: the stored range may reach past this mesh's levels (its end "to the top").
    let mut to = app.settings.levels_to.min(top);
    let mut from = app.settings.levels_from.min(to);
    ui.horizontal(|ui| {
        ui.label("Levels");
        let a = ui.add(egui::DragValue::new(&mut from).range(0..=top).prefix("M"));
        ui.label("to");
        let b = ui.add(egui::DragValue::new(&mut to).range(0..=top).prefix("M"));
        if a.changed() {
            app.settings.levels_from = from;
        }
        if b.changed() {
            app.settings.levels_to = if to == top { usize::MAX } else { to };
        }
    });
    if ui
        .add_enabled(
            app.document
                .as_ref()
                .is_some_and(|d| d.level_count().is_some()),
            egui::Button::new("Export levels"),
        )
        .on_hover_text("One GLB per level of the hierarchy, for LOD")
        .clicked()
    {
        app.commands.push(Command::ExportLevels);
    }

    let Some(document) = &app.document else {
        return;
    };
    ui.separator();
    ui.heading("Numbers");
    let faired = document.faired.as_ref();
    let against_document = faired.and_then(|f| f.against_document.as_ref());
    let against_clean = faired.and_then(|f| f.against_clean.as_ref());
    let has_clean = document.clean.is_some();
    let (lo, hi) = document.bounds;
    let diagonal = ((0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f32>()).sqrt() as f64;
    ui.label(match faired {
        Some(f) => format!("Result: {}", f.method.describe(f.level)),
        None => "Result: none yet".to_owned(),
    });
    egui::Grid::new("fairmesh-measures")
        .num_columns(if has_clean { 3 } else { 2 })
        .striped(true)
        .show(ui, |ui| {
            ui.strong("Result vs.");
            ui.strong("input")
                .on_hover_text("The input mesh: the mesh the result was smoothed from");
            if has_clean {
                ui.strong("clean")
                    .on_hover_text("The clean mesh: the input mesh before noise was added");
            }
            ui.end_row();
            type Row = fn(&Measures) -> String;
            let percent = |v: f64| format!("{v:+.4} %");
            let rows: [(&str, Row); 5] = [
                ("Volume change", |m| {
                    m.volume_change_percent
                        .map_or("–".into(), |v| format!("{v:+.4} %"))
                }),
                ("Mean distance", |m| format!("{:.3e}", m.mean_distance)),
                ("Max distance", |m| format!("{:.3e}", m.max_distance)),
                ("RMS displacement", |m| {
                    m.vertex_rms.map_or("–".into(), |v| format!("{v:.3e}"))
                }),
                ("Barycenter drift", |m| {
                    m.barycenter_drift
                        .map_or("–".into(), |v| format!("{v:.3e}"))
                }),
            ];
            // Volume change and RMS displacement against the input come with the result
            // itself; the other numbers are measured a moment later. Until then they are the
            // previous result's: greyed, and saying so.
            let fresh = |name: &str| -> Option<(String, String)> {
                let f = faired?;
                match name {
                    "Volume change" => Some((percent(f.volume_change * 100.0), String::new())),
                    "RMS displacement" => Some((
                        format!("{:.3e}", f.rms_displacement),
                        format!(
                            "{:.3} % of the bounding box diagonal",
                            f.rms_displacement / diagonal.max(f64::MIN_POSITIVE) * 100.0
                        ),
                    )),
                    _ => None,
                }
            };
            let pending = faired.is_some_and(|f| f.measures_pending);
            let value = |ui: &mut egui::Ui, text: String| {
                let label = ui.add_enabled(!pending, egui::Label::new(text));
                if pending {
                    label.on_hover_text(PENDING_TIP);
                }
            };
            for (name, row) in rows {
                ui.label(name);
                match fresh(name) {
                    Some((text, tip)) if tip.is_empty() => {
                        ui.label(text);
                    }
                    Some((text, tip)) => {
                        ui.label(text).on_hover_text(tip);
                    }
                    None => value(ui, against_document.map_or("–".into(), row)),
                }
                if has_clean {
                    value(ui, against_clean.map_or("–".into(), row));
                }
                ui.end_row();
            }
            if let Some(noise) = &document.against_clean {
                ui.label("Noise");
                ui.label(format!("{:.3e}", noise.mean_distance))
                    .on_hover_text("Mean distance of the input mesh from the clean mesh");
                ui.end_row();
            }
        });
    ui.small("Distances in model units.");

    egui::Grid::new("fairmesh-numbers")
        .num_columns(2)
        .show(ui, |ui| {
            ui.label("Shown vertices");
            ui.label(app.shown_counts.0.to_string());
            ui.end_row();
            ui.label("Shown faces");
            ui.label(app.shown_counts.1.to_string());
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
            ui.label("Measuring");
            ui.label(faired.map_or("–".into(), |f| {
                if f.measures_pending {
                    "running…".into()
                } else {
                    seconds(f.measure_time)
                }
            }));
            ui.end_row();
        });

    // Below Export and the numbers: a painting session is an occasional step, and the controls
    // used on every file stay where they were.
    super::paint_panel::section(app, ui);
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
                    let [results, upload, widgets] = stats.max_while_busy_parts;
                    ui.label(milliseconds(stats.max_while_busy))
                        .on_hover_text(format!(
                            "Results {}, upload {}, widgets {}",
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
                    }
                });
            // Long adapter names wrap at the panel's width instead of widening it.
            if let Some(viewport) = &app.viewport {
                ui.add(
                    egui::Label::new(
                        egui::RichText::new(format!("Adapter: {}", viewport.adapter_description()))
                            .small(),
                    )
                    .wrap(),
                );
            }
            if ui.button("Reset max").clicked() {
                app.frame_stats.reset_busy_max();
            }
        });
    app.settings.show_performance = response.fully_open();
}

/// The fairing section: start level, method and its options, Apply. Every control says in its
/// tooltip what it does and when to change it; the ones the chosen method does not use are
/// disabled and say why.
fn fairing_controls(app: &mut App, ui: &mut egui::Ui, top_level: usize) {
    let Some(document) = &app.document else {
        return;
    };
    let ready = document.level_count().is_some();
    let method = app.settings.method;
    let not_for_baseline = (!method.uses_hierarchy()).then(|| {
        format!(
            "Not used by {}: it smooths the whole input mesh at once, without the hierarchy.",
            method.label()
        )
    });
    let level_off = match (&not_for_baseline, ready) {
        (Some(why), _) => Some(why.clone()),
        (None, false) => Some("Waiting for the hierarchy to be built.".to_owned()),
        (None, true) => None,
    };
    let mut level = document.level;
    let slider = ui.add_enabled(
        level_off.is_none(),
        egui::Slider::new(&mut level, 0..=top_level).text("Start level"),
    );
    if explain(slider, tips::START_LEVEL, level_off.as_deref()).changed() {
        app.commands.push(Command::SetLevel(level));
    }
    let applied = document.applied;
    let before = app.settings.clone();
    let settings = &mut app.settings;
    let combo = egui::ComboBox::from_label("Method")
        .selected_text(settings.method.label())
        .show_ui(ui, |ui| {
            for method in MethodSetting::ALL {
                ui.selectable_value(&mut settings.method, method, method.label());
            }
        });
    explain(combo.response, tips::METHOD, None);
    if method.uses_hierarchy() {
        let iterations = ui
            .add(egui::Slider::new(&mut settings.iterations, 1..=50).text("Iterations per level"));
        explain(iterations, tips::ITERATIONS_PER_LEVEL, None);
        let rounds = ui.add(egui::Slider::new(&mut settings.rounds, 1..=10).text("Rounds"));
        explain(rounds, tips::ROUNDS, None);
    } else {
        ui.small("A baseline smooths the mesh itself (no hierarchy): watch the volume change.");
        let iterations = ui
            .add(egui::Slider::new(&mut settings.baseline_iterations, 1..=200).text("Iterations"));
        explain(iterations, tips::BASELINE_ITERATIONS, None);
        if matches!(method, MethodSetting::Laplacian | MethodSetting::Taubin) {
            let lambda =
                ui.add(egui::Slider::new(&mut settings.baseline_lambda, 0.05..=1.0).text("Lambda"));
            explain(lambda, tips::LAMBDA, None);
        }
    }
    let boundary = egui::ComboBox::from_label("Boundary")
        .selected_text(match settings.boundary {
            BoundarySetting::Curve => "Smooth as curve",
            BoundarySetting::Fixed => "Fixed",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(
                &mut settings.boundary,
                BoundarySetting::Curve,
                "Smooth as curve",
            );
            ui.selectable_value(&mut settings.boundary, BoundarySetting::Fixed, "Fixed");
        });
    explain(boundary.response, tips::BOUNDARY, None);
    let hierarchy_only = not_for_baseline.is_none();
    let fair_finest = ui.add_enabled(
        hierarchy_only,
        egui::Checkbox::new(&mut settings.fair_finest, "Fair M0 too"),
    );
    explain(fair_finest, tips::FAIR_FINEST, not_for_baseline.as_deref());
    let variant = ui.add_enabled_ui(hierarchy_only, |ui| {
        egui::ComboBox::from_label("Variant")
            .selected_text(match settings.variant {
                VariantSetting::Paper => "Paper",
                VariantSetting::Improved => "Improved",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut settings.variant, VariantSetting::Paper, "Paper");
                ui.selectable_value(&mut settings.variant, VariantSetting::Improved, "Improved");
            })
            .response
    });
    explain(variant.inner, tips::VARIANT, not_for_baseline.as_deref());
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
    if applied {
        ui.small(
            "Showing the applied result as it is. Change the start level or an option to fair \
             it again.",
        );
    }
    let has_result = app.document.as_ref().is_some_and(|d| d.faired.is_some());
    let apply = ui.add_enabled(has_result, egui::Button::new("Apply result"));
    if explain(
        apply,
        tips::APPLY,
        (!has_result).then_some("There is no result to apply yet."),
    )
    .clicked()
    {
        app.commands.push(Command::ApplyResult);
    }
}

/// Shows `tip` on hover; when the control is disabled, shows `tip` and why it is off. The text
/// is the control's accessible description either way (screen readers, tests).
fn explain(response: egui::Response, tip: &str, off_because: Option<&str>) -> egui::Response {
    match off_because {
        Some(why) if !response.enabled() => {
            let text = format!("{tip}\n\n{why}");
            response
                .on_hover_text(text.clone())
                .on_disabled_hover_text(text)
        }
        _ => response.on_hover_text(tip),
    }
}

/// "Keep sharp edges" and its angle (the hierarchy is built again when either changes; while
/// they are hovered or just changed, the kept edges are drawn over the mesh).
fn sharp_edge_controls(app: &mut App, ui: &mut egui::Ui) {
    let Some(document) = &app.document else {
        return;
    };
    let not_for_baseline = (!app.settings.method.uses_hierarchy()).then(|| {
        format!(
            "Not used by {}: it smooths the whole mesh at once, across sharp edges too.",
            app.settings.method.label()
        )
    });
    let kept = match &document.hierarchy {
        HierarchyState::Ready { hierarchy, .. } => Some(hierarchy.crease_edge_count()),
        _ => None,
    };
    let enabled = not_for_baseline.is_none();
    let keep = ui.add_enabled(
        enabled,
        egui::Checkbox::new(&mut app.settings.keep_sharp_edges, "Keep sharp edges"),
    );
    let keep = explain(keep, tips::KEEP_SHARP_EDGES, not_for_baseline.as_deref());
    let angle = ui.add_enabled(
        enabled && app.settings.keep_sharp_edges,
        egui::Slider::new(
            &mut app.settings.sharp_edge_angle,
            MIN_SHARP_EDGE_ANGLE..=MAX_SHARP_EDGE_ANGLE,
        )
        .suffix("°")
        .fixed_decimals(0)
        .text("Sharp edge angle"),
    );
    let angle = explain(angle, tips::SHARP_EDGE_ANGLE, not_for_baseline.as_deref());
    let now = std::time::Instant::now();
    if keep.hovered() || angle.hovered() || angle.dragged() {
        app.sharp_edges_shown_until = Some(now + SHARP_EDGES_LINGER);
    }
    // The hierarchy is built again when the angle is let go (not at every step of a drag).
    let settled = !angle.dragged();
    // (`start_hierarchy` records the settings it builds with, before the next frame.)
    if settled && app.settings.hierarchy_key() != app.hierarchy_built_with {
        app.sharp_edges_shown_until = Some(now + SHARP_EDGES_LINGER);
        app.commands.push(Command::RebuildHierarchy);
    }
    if app.settings.keep_sharp_edges && enabled {
        match kept {
            Some(0) => ui.small("No sharp edges found at this angle"),
            Some(edges) => ui.small(format!(
                "{edges} sharp edges kept (drawn in cyan while you point here)"
            )),
            None => ui.small("Finding sharp edges…"),
        };
    }
}

/// How long the kept sharp edges stay drawn after the pointer leaves their controls.
const SHARP_EDGES_LINGER: std::time::Duration = std::time::Duration::from_millis(1500);

/// Draws the kept sharp edges over the result's image while [`sharp_edge_controls`] asks for it.
pub(super) fn sharp_edge_overlay(app: &mut App, ui: &egui::Ui, rect: egui::Rect) {
    app.sharp_edges_drawn = 0;
    let Some(until) = app.sharp_edges_shown_until else {
        return;
    };
    let now = std::time::Instant::now();
    if now > until || app.settings.view_mode == ViewMode::Level {
        return;
    }
    ui.ctx().request_repaint_after(until - now);
    let Some(document) = &app.document else {
        return;
    };
    let HierarchyState::Ready { sharp_edges, .. } = &document.hierarchy else {
        return;
    };
    let faired = document.faired.as_ref().map(|f| f.positions.clone());
    let shows_before = app.show_before && app.settings.compare == CompareView::Single;
    let positions: &[[f32; 3]] = match (&faired, shows_before) {
        (Some(faired), false) => faired,
        _ => &document.original.positions,
    };
    let image = super::paint_panel::painted_image(app, rect);
    let aspect = image.width() / image.height().max(1.0);
    let segments = sharp_edges.segments(
        positions,
        app.camera.view_proj(aspect),
        app.camera.eye(),
        image,
    );
    app.sharp_edges_drawn = segments.len();
    let painter = ui.painter_at(image);
    let stroke = egui::Stroke::new(2.0, egui::Color32::from_rgb(60, 230, 255));
    for segment in segments {
        painter.line_segment(segment, stroke);
    }
}

/// The fairing controls' tooltips: what each does and when to change it, in plain words.
pub mod tips {
    pub const KEEP_SHARP_EDGES: &str = "Keep the mesh's sharp edges (the edges of a machined \
        part, a fold, a rim) sharp: the coarse levels keep them and the smoothing runs along them, \
        not across them. Turn it off for organic shapes if smoothing leaves ridges where there \
        should be none.";
    pub const SHARP_EDGE_ANGLE: &str = "How sharply the surface must fold at an edge for the edge \
        to be kept sharp. Lower: more edges are kept (gentle folds too). Higher: only the sharpest. \
        The kept edges are drawn over the mesh while you point here.";
    pub const START_LEVEL: &str = "How coarse a version of the mesh the smoothing starts from \
        (M0 is the mesh itself). Higher: smoother, bigger bumps go. Lower: more of the detail \
        stays. Raise it until the noise is gone; lower it if wanted features melt away.";
    pub const METHOD: &str = "Constrained fairing (the paper's method) smooths without \
        shrinking the mesh. The others are classic smoothers to compare with: watch the volume \
        change under Numbers.";
    pub const ITERATIONS_PER_LEVEL: &str = "Smoothing passes on each level on the way back to \
        full detail. More: a little smoother and slower. The start level matters far more: \
        change this last.";
    pub const ROUNDS: &str = "How often each level's smoothing starts over from where it got \
        to. More: a little smoother and slower; 1 is usually enough.";
    pub const BASELINE_ITERATIONS: &str = "Smoothing passes over the whole mesh. More: \
        smoother, and (for Laplacian) more shrinkage.";
    pub const LAMBDA: &str = "How far each pass moves a vertex towards its neighbours (0 to \
        1). Higher: faster smoothing, more shrinkage.";
    pub const BOUNDARY: &str = "What happens to open borders (holes, cut edges). Smooth as \
        curve: the border line is smoothed too. Fixed: border vertices stay where they are; use \
        it when the mesh must still meet another part.";
    pub const FAIR_FINEST: &str = "Also smooth the full-detail mesh (M0) at the end. On: the \
        finest noise goes too. Off: the finest detail stays as it was.";
    pub const VARIANT: &str = "Paper: the method as published. Improved: two corrections that \
        keep the shape from drifting and shrinking over the levels. Keep Improved unless you \
        compare with the paper.";
    pub const PAINT: &str = "Paint where to fair (P). On: the left button paints on the mesh \
        instead of turning the view (middle drag turns it, right drag pans). Only the painted \
        part is smoothed; the rest keeps its exact shape.";
    pub const BRUSH_ADD: &str = "The brush marks the part to smooth.";
    pub const BRUSH_ERASE: &str = "The brush unmarks what it touches, so it keeps its shape \
        (on a mesh with no mask yet: protects it while the rest is smoothed). Hold Shift to \
        erase for a moment.";
    pub const BRUSH_RADIUS: &str = "Size of the brush on screen, in points. Zoom in to paint \
        finer detail.";
    pub const BRUSH_SOFTNESS: &str = "How much of the brush's edge fades out. Higher: the \
        smoothing blends gently into the untouched part; 0: a hard edge.";
    pub const SHOW_MASK: &str = "Tint the painted part orange on the mesh (it replaces the \
        heat map while shown).";
    pub const CLEAR_MASK: &str = "Remove the paint: the whole mesh is smoothed again (undo \
        with Ctrl+Z).";
    pub const INVERT_MASK: &str = "Smooth what was left alone and keep what was painted \
        (undo with Ctrl+Z).";
    pub const APPLY: &str = "Make the result the input mesh, to add noise to it, fair it \
        again or export it as it is (undo with Ctrl+Z).";
}

/// What a greyed number in the Numbers panel means.
const PENDING_TIP: &str =
    "From the previous result: the result on screen is being measured, its numbers follow";

fn noise_mode_name(mode: NoiseMode) -> &'static str {
    match mode {
        NoiseMode::Normal => "Along the normal",
        NoiseMode::Direction => "Random direction",
        NoiseMode::Isotropic => "Isotropic",
    }
}

fn seconds(duration: std::time::Duration) -> String {
    format!("{:.3} s", duration.as_secs_f64())
}

fn milliseconds(duration: std::time::Duration) -> String {
    format!("{:.2} ms", duration.as_secs_f64() * 1000.0)
}
