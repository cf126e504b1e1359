//! The side panel's Fairing section and the sharp-edge controls under Hierarchy: start level,
//! method and its options, Apply; "Keep sharp edges" and its angle, and the kept edges drawn
//! over the mesh while those are pointed at. Every control says in its tooltip ([`tips`]) what
//! it does and when to change it; the ones the chosen method does not use are disabled and say
//! why.

use super::camera::OrbitCamera;
use super::command::PanelChange;
use super::panel_view::{Commands, PanelView, ViewportView};
use super::state::{
    CompareView, HierarchyState, MethodChoice, Settings, ViewMode, MAX_DENOISE_ROUNDS,
    MAX_SHARP_EDGE_ANGLE, MIN_SHARP_EDGE_ANGLE,
};
use super::tips;
use super::Command;
use fairmesh::fairing::{BoundaryMode, Method};
use fairmesh::multires::{Denoise, MultiresVariant};

/// The fairing section: start level, method and its options, Apply. Every control says in its
/// tooltip what it does and when to change it; the ones the chosen method does not use are
/// disabled and say why.
pub(super) fn fairing_controls(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
    top_level: usize,
) {
    let Some(document) = view.document else {
        return;
    };
    let (ready, level, applied) = (
        document.level_count().is_some(),
        document.level,
        document.applied,
    );
    let method = settings.fairing.method;
    let not_for_baseline = (!method.uses_hierarchy()).then(|| {
        format!(
            "Not used by {}: it smooths the whole input mesh at once, without the hierarchy.",
            method.label()
        )
    });
    let not_for_baseline = not_for_baseline.as_deref();
    let denoising = view.progress.hierarchy_denoising;
    denoise_controls(ui, document, settings, not_for_baseline, denoising);
    start_level_slider(commands, ui, (level, top_level), ready, not_for_baseline);
    folds_left_note(ui, document);
    let before = settings.clone();
    method_controls(settings, ui, method);
    boundary_and_variant(settings, ui, not_for_baseline);
    if settings.fairing.key() != before.fairing.key() {
        commands.push(Command::Refair);
    }
    progress_and_apply(ui, view, commands, applied);
}

/// "Remove noise first": Automatic, a number of rounds, or Off, and what the denoise found
/// (a change builds the hierarchy again: [`sharp_edge_controls`] sees the hierarchy's settings
/// change).
fn denoise_controls(
    ui: &mut egui::Ui,
    document: &super::state::Document,
    settings: &mut Settings,
    not_for_baseline: Option<&str>,
    denoising: bool,
) {
    let enabled = not_for_baseline.is_none();
    let label = |denoise: Denoise| match denoise {
        Denoise::Automatic => "Automatic",
        Denoise::Rounds(_) => "Rounds",
        Denoise::Off => "Off",
    };
    ui.horizontal(|ui| {
        let combo = ui.add_enabled_ui(enabled, |ui| {
            egui::ComboBox::from_label("Remove noise first")
                .selected_text(label(settings.hierarchy.denoise))
                .show_ui(ui, |ui| {
                    let rounds = match settings.hierarchy.denoise {
                        Denoise::Rounds(rounds) => rounds,
                        _ => denoised_rounds(document).unwrap_or(10),
                    };
                    for (choice, tip) in [
                        (Denoise::Automatic, tips::DENOISE_AUTOMATIC),
                        (Denoise::Rounds(rounds), tips::DENOISE_ROUNDS),
                        (Denoise::Off, tips::DENOISE_OFF),
                    ] {
                        let chosen = std::mem::discriminant(&settings.hierarchy.denoise)
                            == std::mem::discriminant(&choice);
                        if ui
                            .selectable_label(chosen, label(choice))
                            .on_hover_text(tip)
                            .clicked()
                            && !chosen
                        {
                            settings.hierarchy.denoise = choice;
                        }
                    }
                })
                .response
        });
        explain(combo.inner, tips::REMOVE_NOISE, not_for_baseline);
        if let Denoise::Rounds(count) = &mut settings.hierarchy.denoise {
            let value = ui.add_enabled(
                enabled,
                egui::DragValue::new(count).range(1..=MAX_DENOISE_ROUNDS),
            );
            explain(value, tips::DENOISE_ROUNDS, not_for_baseline);
        }
    });
    if !enabled {
        return;
    }
    match &document.hierarchy {
        HierarchyState::Ready {
            denoise: Some(found),
            ..
        } => {
            ui.small(found.describe())
                .on_hover_text(format!("Took {:.2} s", found.time.as_secs_f64()));
        }
        HierarchyState::Ready { denoise: None, .. } => {
            ui.small("The levels are built on the mesh as it is");
        }
        HierarchyState::Building if settings.hierarchy.denoise != Denoise::Off => {
            // Once the noise is removed, the view shows the result (start level 0) while the
            // levels are built on it.
            ui.small(if denoising {
                "Measuring the noise…"
            } else {
                "Noise removed; building the levels on the result…"
            });
        }
        _ => {}
    }
}

/// The rounds the last automatic denoise kept, to start the manual setting from.
fn denoised_rounds(document: &super::state::Document) -> Option<usize> {
    match &document.hierarchy {
        HierarchyState::Ready {
            denoise: Some(found),
            ..
        } => Some(found.report.rounds_run.max(1)),
        _ => None,
    }
}

/// The start level slider (`level` of `0..=top`), off for a baseline and until the hierarchy
/// is `ready`.
fn start_level_slider(
    commands: &mut Vec<Command>,
    ui: &mut egui::Ui,
    (mut level, top_level): (usize, usize),
    ready: bool,
    not_for_baseline: Option<&str>,
) {
    let level_off = match (not_for_baseline, ready) {
        (Some(why), _) => Some(why.to_owned()),
        (None, false) => Some("Waiting for the hierarchy to be built.".to_owned()),
        (None, true) => None,
    };
    // Until the hierarchy is built the range reaches the level, which is shown, not 0.
    let top = top_level.max(level);
    let slider =
        super::widgets::slider(ui, level_off.is_none(), &mut level, 0..=top, "Start level");
    if explain(slider, tips::START_LEVEL, level_off.as_deref()).changed() {
        commands.push(Command::SetLevel(level));
    }
    ui.add_enabled(
        level_off.is_none(),
        egui::Label::new(egui::RichText::new(START_LEVEL_WORDS).small()),
    )
    .on_hover_text(tips::START_LEVEL)
    .on_disabled_hover_text(tips::START_LEVEL);
}

/// Under the slider, when the result of the level it rests on left faces turned over (from the
/// coarsest levels of a large mesh only).
fn folds_left_note(ui: &mut egui::Ui, document: &super::state::Document) {
    let Some(faired) = document
        .faired
        .as_ref()
        .filter(|f| f.folds_left > 0 && f.level == document.level)
    else {
        return;
    };
    ui.label(
        egui::RichText::new(format!(
            "{} faces left turned over at this level (point here for why)",
            faired.folds_left
        ))
        .small()
        .color(ui.visuals().warn_fg_color),
    )
    .on_hover_text(tips::FOLDS_LEFT);
}

/// What moving the start level does, under the slider.
const START_LEVEL_WORDS: &str =
    "0 keeps all the detail; each step right takes more away     (coarser start, smoother result).";

/// The method and the options of `method` (the one chosen when the frame began): iterations and
/// rounds over the hierarchy, or a baseline's iterations and step.
fn method_controls(settings: &mut Settings, ui: &mut egui::Ui, method: Method) {
    let combo = egui::ComboBox::from_label("Method")
        .selected_text(settings.fairing.method.label())
        .show_ui(ui, |ui| {
            for method in Method::ALL {
                ui.selectable_value(&mut settings.fairing.method, method, method.label());
            }
        });
    explain(combo.response, tips::METHOD, None);
    if method.uses_hierarchy() {
        let iterations = ui.add(
            egui::Slider::new(&mut settings.fairing.iterations, 1..=50)
                .text("Iterations per level"),
        );
        explain(iterations, tips::ITERATIONS_PER_LEVEL, None);
        let rounds = ui.add(egui::Slider::new(&mut settings.fairing.rounds, 1..=10).text("Rounds"));
        explain(rounds, tips::ROUNDS, None);
    } else {
        ui.small("A baseline smooths the mesh itself (no hierarchy): watch the volume change.");
        let iterations = ui.add(
            egui::Slider::new(&mut settings.fairing.baseline_iterations, 1..=200)
                .text("Iterations"),
        );
        explain(iterations, tips::BASELINE_ITERATIONS, None);
        if matches!(method, Method::Laplacian | Method::Taubin) {
            let lambda = ui.add(
                egui::Slider::new(&mut settings.fairing.baseline_lambda, 0.05..=1.0).text("Lambda"),
            );
            explain(lambda, tips::LAMBDA, None);
        }
    }
}

/// Boundary handling (every method), "Fair M0 too" and the variant (the hierarchy's only: off,
/// saying why, for a baseline).
fn boundary_and_variant(
    settings: &mut Settings,
    ui: &mut egui::Ui,
    not_for_baseline: Option<&str>,
) {
    let boundary = egui::ComboBox::from_label("Boundary")
        .selected_text(match settings.fairing.boundary {
            BoundaryMode::Curve => "Smooth as curve",
            BoundaryMode::Fixed => "Fixed",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(
                &mut settings.fairing.boundary,
                BoundaryMode::Curve,
                "Smooth as curve",
            );
            ui.selectable_value(&mut settings.fairing.boundary, BoundaryMode::Fixed, "Fixed");
        });
    explain(boundary.response, tips::BOUNDARY, None);
    let hierarchy_only = not_for_baseline.is_none();
    let fair_finest = ui.add_enabled(
        hierarchy_only,
        egui::Checkbox::new(&mut settings.fairing.fair_finest, "Fair M0 too"),
    );
    explain(fair_finest, tips::FAIR_FINEST, not_for_baseline);
    let variant = ui.add_enabled_ui(hierarchy_only, |ui| {
        egui::ComboBox::from_label("Variant")
            .selected_text(match settings.fairing.variant {
                MultiresVariant::Paper => "Paper",
                MultiresVariant::Improved => "Improved",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(
                    &mut settings.fairing.variant,
                    MultiresVariant::Paper,
                    "Paper",
                );
                ui.selectable_value(
                    &mut settings.fairing.variant,
                    MultiresVariant::Improved,
                    "Improved",
                );
            })
            .response
    });
    explain(variant.inner, tips::VARIANT, not_for_baseline);
}

/// The fairing's progress while it runs, a note when the mesh is an `applied` result, and
/// "Apply result".
fn progress_and_apply(ui: &mut egui::Ui, view: &PanelView, commands: &mut Commands, applied: bool) {
    if view.progress.fair_in_flight {
        ui.horizontal(|ui| {
            super::widgets::activity_spinner(ui);
            ui.label(format!("fairing … {:.0} %", view.progress.fair * 100.0));
        });
    }
    if applied {
        ui.small(
            "Showing the applied result as it is. Change the start level or an option to fair \
             it again.",
        );
    }
    let has_result = view.document.is_some_and(|d| d.faired.is_some());
    let apply = ui.add_enabled(has_result, egui::Button::new("Apply result"));
    if explain(
        apply,
        tips::APPLY,
        (!has_result).then_some("There is no result to apply yet."),
    )
    .clicked()
    {
        commands.push(Command::ApplyResult);
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
pub(super) fn sharp_edge_controls(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
) {
    let Some(document) = view.document else {
        return;
    };
    let not_for_baseline = (!settings.fairing.method.uses_hierarchy()).then(|| {
        format!(
            "Not used by {}: it smooths the whole mesh at once, across sharp edges too.",
            settings.fairing.method.label()
        )
    });
    let kept = match &document.hierarchy {
        HierarchyState::Ready { hierarchy, .. } => Some(hierarchy.crease_edge_count()),
        _ => None,
    };
    let enabled = not_for_baseline.is_none();
    let keep = ui.add_enabled(
        enabled,
        egui::Checkbox::new(&mut settings.hierarchy.keep_sharp_edges, "Keep sharp edges"),
    );
    let keep = explain(keep, tips::KEEP_SHARP_EDGES, not_for_baseline.as_deref());
    let angle = ui.add_enabled(
        enabled && settings.hierarchy.keep_sharp_edges,
        egui::Slider::new(
            &mut settings.hierarchy.sharp_edge_angle,
            MIN_SHARP_EDGE_ANGLE..=MAX_SHARP_EDGE_ANGLE,
        )
        .suffix("°")
        .fixed_decimals(0)
        .text("Sharp edge angle"),
    );
    let angle = explain(angle, tips::SHARP_EDGE_ANGLE, not_for_baseline.as_deref());
    let now = web_time::Instant::now();
    let pointed_at = keep.hovered() || angle.hovered() || angle.dragged();
    // The hierarchy is built again when the angle is let go (not at every step of a drag).
    let settled = !angle.dragged();
    // (`start_hierarchy` records the settings it builds with, before the next frame.)
    let rebuild = settled && Some(settings.hierarchy_key()) != view.hierarchy_built_with;
    // The edges are shown when their own settings change (not the denoise's).
    let edges_changed = view
        .hierarchy_built_with
        .is_some_and(|built| !built.same_sharp_edges(&settings.hierarchy_key()));
    if pointed_at || (rebuild && edges_changed) {
        commands.push(Command::Panel(PanelChange::ShowSharpEdgesUntil(
            now + SHARP_EDGES_LINGER,
        )));
    }
    if rebuild {
        commands.push(Command::RebuildHierarchy);
    }
    if settings.hierarchy.keep_sharp_edges && enabled {
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
pub(super) fn sharp_edge_overlay(
    ui: &egui::Ui,
    view: &ViewportView,
    camera: &OrbitCamera,
    settings: &Settings,
    rect: egui::Rect,
) -> usize {
    let Some(until) = view.sharp_edges_shown_until else {
        return 0;
    };
    let now = web_time::Instant::now();
    if now > until || settings.view.view_mode == ViewMode::Level {
        return 0;
    }
    ui.ctx().request_repaint_after(until - now);
    let Some(document) = view.document else {
        return 0;
    };
    let HierarchyState::Ready { sharp_edges, .. } = &document.hierarchy else {
        return 0;
    };
    let shows_before = view.show_before && settings.view.compare == CompareView::Single;
    let positions: &[[f32; 3]] = match (&document.faired, shows_before) {
        (Some(faired), false) => &faired.positions,
        _ => &document.original.positions,
    };
    let image = super::paint_panel::painted_image(settings, rect);
    let aspect = image.width() / image.height().max(1.0);
    let segments = sharp_edges.segments(positions, camera.view_proj(aspect), camera.eye(), image);
    let drawn = segments.len();
    let painter = ui.painter_at(image);
    let stroke = egui::Stroke::new(2.0, egui::Color32::from_rgb(60, 230, 255));
    for segment in segments {
        painter.line_segment(segment, stroke);
    }
    drawn
}
