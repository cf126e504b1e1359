//! The 3D viewport's area: the camera's mouse handling (orbit, pan, zoom; the split view's
//! divider first, the paint brush when painting), the views the compare mode asks for (one,
//! split at the divider, side by side) with their captions, and what is drawn over them: the
//! mouse hints, the heat map's legend, the brush outline, the kept sharp edges, and why a mesh
//! is not drawn.

use super::panel_view::{Commands, ViewportDrawn, ViewportState, ViewportView};
use super::state::{CompareView, HeatReference, Settings, ViewMode};
use super::Slot;
use crate::render::colormap::{legend_ticks, viridis_strip};

/// The 3D view's area. Like the panels it reads the app's state ([`ViewportView`]), edits the
/// settings in place (the split's divider) and emits commands (the brush's dabs and strokes);
/// it also moves the camera and draws with the renderers it owns ([`ViewportState`]).
pub fn show(
    ui: &mut egui::Ui,
    view: &ViewportView,
    state: &mut ViewportState,
    settings: &mut Settings,
    commands: &mut Commands,
) -> ViewportDrawn {
    let rect = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
    let divider_x = rect.left() + rect.width() * settings.view.split.clamp(0.0, 1.0);
    let divider_dragged = split_divider(ui, settings, rect, divider_x);
    let painting = !divider_dragged
        && super::paint_panel::viewport_brush(ui, &response, rect, view, state, settings, commands);
    if !divider_dragged {
        camera_input(state, ui, &response, painting);
    }
    let painter = ui.painter_at(rect);
    if state.viewports[Slot::Main as usize].is_none() {
        painter.text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "No wgpu renderer: the 3D view needs eframe's wgpu backend",
            egui::FontId::proportional(16.0),
            ui.visuals().text_color(),
        );
    }
    draw_views(view, state, settings, &painter, rect, divider_x);
    let sharp_edges_drawn = overlays(ui, view, state, settings, &painter, rect, painting);
    ViewportDrawn {
        rect,
        sharp_edges_drawn,
    }
}

/// The split view's divider sits on top of the camera's area and takes its drags first; returns
/// whether it is being dragged.
fn split_divider(
    ui: &mut egui::Ui,
    settings: &mut Settings,
    rect: egui::Rect,
    divider_x: f32,
) -> bool {
    if settings.view.compare != CompareView::Split {
        return false;
    }
    let handle = egui::Rect::from_x_y_ranges(divider_x - 6.0..=divider_x + 6.0, rect.y_range());
    let divider = ui
        .interact(
            handle,
            ui.scope_id().with("fairmesh-split-divider"),
            egui::Sense::drag(),
        )
        .on_hover_cursor(egui::CursorIcon::ResizeHorizontal)
        .on_hover_text("Drag to move the divider: before on the left, after on the right");
    if !divider.dragged() {
        return false;
    }
    let x = divider
        .interact_pointer_pos()
        .map_or(divider_x + divider.drag_delta().x, |p| p.x);
    settings.view.split = ((x - rect.left()) / rect.width().max(1.0)).clamp(0.02, 0.98);
    true
}

/// Orbit, pan and zoom (while painting, the middle button turns the view instead of the left).
fn camera_input(
    state: &mut ViewportState,
    ui: &egui::Ui,
    response: &egui::Response,
    painting: bool,
) {
    let orbit_button = match painting {
        true => egui::PointerButton::Middle,
        false => egui::PointerButton::Primary,
    };
    if response.dragged_by(orbit_button) {
        state.camera.orbit(response.drag_delta());
    }
    if response.dragged_by(egui::PointerButton::Secondary)
        || (!painting && response.dragged_by(egui::PointerButton::Middle))
    {
        state
            .camera
            .pan(response.drag_delta(), response.rect.height());
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta().y);
        if scroll != 0.0 {
            state.camera.zoom(scroll);
        }
    }
}

/// What a view's caption adds while its picture is the previous one.
pub const COMPUTING: &str = "computing…";

/// The main view's caption in `mode`; `behind`: its picture is the previous one until the new
/// one is computed (and measured, for the heat map), and the caption says so.
pub fn main_caption(mode: ViewMode, behind: bool) -> String {
    let name = match mode {
        ViewMode::Faired => "After (faired)",
        ViewMode::Level => "Level mesh",
        ViewMode::Original => "Input mesh",
    };
    match behind {
        true => format!("{name}: {COMPUTING}"),
        false => name.to_owned(),
    }
}

fn caption(painter: &egui::Painter, at: egui::Pos2, align: egui::Align2, text: &str) {
    painter.text(
        at,
        align,
        text,
        egui::FontId::proportional(15.0),
        egui::Color32::from_gray(220),
    );
}

/// The views the compare mode shows, each with its caption.
fn draw_views(
    view: &ViewportView,
    state: &mut ViewportState,
    settings: &Settings,
    painter: &egui::Painter,
    rect: egui::Rect,
    divider_x: f32,
) {
    let after_name = &main_caption(settings.view.view_mode, view.main_behind);
    let top_left = |r: egui::Rect| r.left_top() + egui::vec2(10.0, 8.0);
    let params = |state: &ViewportState, rect: egui::Rect, slot: Slot| {
        view.looks[slot as usize].draw_params(state.camera, settings, rect)
    };
    match settings.view.compare {
        CompareView::Single => {
            let slot = match view.show_before {
                true => Slot::Before,
                false => Slot::Main,
            };
            let params = params(state, rect, slot);
            if let Some(viewport) = state.viewport(slot) {
                viewport.paint(painter, rect, params);
            }
            let name = if view.show_before {
                "Before (B)"
            } else {
                after_name
            };
            caption(painter, top_left(rect), egui::Align2::LEFT_TOP, name);
        }
        CompareView::Split => {
            let (left, right) = rect.split_left_right_at_x(divider_x);
            let before_params = params(state, rect, Slot::Before);
            let after_params = params(state, rect, Slot::Main);
            if let Some(viewport) = state.viewport(Slot::Before) {
                viewport.paint_part(painter, rect, left, before_params);
            }
            if let Some(viewport) = state.viewport(Slot::Main) {
                viewport.paint_part(painter, rect, right, after_params);
            }
            painter.line_segment(
                [
                    egui::pos2(divider_x, rect.top()),
                    egui::pos2(divider_x, rect.bottom()),
                ],
                egui::Stroke::new(2.0, egui::Color32::from_gray(230)),
            );
            caption(painter, top_left(rect), egui::Align2::LEFT_TOP, "Before");
            let top_right = rect.right_top() + egui::vec2(-10.0, 8.0);
            caption(painter, top_right, egui::Align2::RIGHT_TOP, after_name);
        }
        CompareView::SideBySide => {
            let (left, right) = rect.split_left_right_at_fraction(0.5);
            let before_params = params(state, left, Slot::Before);
            let after_params = params(state, right, Slot::Main);
            if let Some(viewport) = state.viewport(Slot::Before) {
                viewport.paint(painter, left, before_params);
            }
            if let Some(viewport) = state.viewport(Slot::Main) {
                viewport.paint(painter, right, after_params);
            }
            painter.line_segment(
                [
                    egui::pos2(right.left(), rect.top()),
                    egui::pos2(right.left(), rect.bottom()),
                ],
                egui::Stroke::new(1.0, egui::Color32::from_gray(90)),
            );
            caption(painter, top_left(left), egui::Align2::LEFT_TOP, "Before");
            caption(painter, top_left(right), egui::Align2::LEFT_TOP, after_name);
        }
    }
}

/// The mouse hints, the heat map's legend, the brush, the kept sharp edges and why a mesh is
/// not drawn, over the views; returns how many sharp edges were drawn.
fn overlays(
    ui: &mut egui::Ui,
    view: &ViewportView,
    state: &ViewportState,
    settings: &Settings,
    painter: &egui::Painter,
    rect: egui::Rect,
    painting: bool,
) -> usize {
    // A saved image of the view leaves out the mouse hints.
    let hint = if view.capturing_view {
        ""
    } else if painting {
        "Painting: left drag paints (Shift: erase) · middle drag: orbit · right drag: pan · P: stop painting"
    } else {
        "Left drag: orbit · right/middle drag: pan · scroll: zoom · F: fit · W: wireframe · B: before/after · P: paint"
    };
    painter.text(
        rect.left_bottom() + egui::vec2(8.0, -8.0),
        egui::Align2::LEFT_BOTTOM,
        hint,
        egui::FontId::proportional(12.0),
        egui::Color32::from_gray(150),
    );
    if !view.capturing_view && state.viewports.iter().flatten().any(|v| v.drawing()) {
        // A big mesh's new image on a software renderer takes several frames; the view shows
        // the previous image until then.
        painter.text(
            rect.right_bottom() + egui::vec2(-8.0, -8.0),
            egui::Align2::RIGHT_BOTTOM,
            "Drawing the new image…",
            egui::FontId::proportional(12.0),
            egui::Color32::from_gray(190),
        );
    }
    if let Some((top, reference)) = view.heat_legend {
        heat_legend(ui, rect, top, reference);
    }
    super::paint_panel::brush_outline(ui, view, settings, rect);
    let sharp_edges_drawn =
        super::fairing_panel::sharp_edge_overlay(ui, view, state.camera, settings, rect);
    let problem = state
        .viewports
        .iter()
        .flatten()
        .find_map(|viewport| viewport.problem(settings.view.wireframe));
    if let Some(problem) = problem {
        let text = egui::RichText::new(format!("Not drawn: {problem}"))
            .size(14.0)
            .color(egui::Color32::from_rgb(240, 150, 90));
        let area = egui::Rect::from_min_size(
            rect.left_top() + egui::vec2(8.0, 32.0),
            egui::vec2(rect.width() - 16.0, 20.0),
        );
        ui.put(area, egui::Label::new(text).selectable(false));
    }
    sharp_edges_drawn
}

/// The heat map's legend: the viridis strip with round tick values in model units.
fn heat_legend(ui: &mut egui::Ui, viewport: egui::Rect, top: f32, reference: HeatReference) {
    const WIDTH: f32 = 240.0;
    let area = egui::Rect::from_min_size(
        viewport.right_bottom() + egui::vec2(-WIDTH - 28.0, -92.0),
        egui::vec2(WIDTH + 20.0, 84.0),
    );
    ui.scope_builder(egui::UiBuilder::new().max_rect(area), |ui| {
        egui::Frame::new()
            .fill(egui::Color32::from_black_alpha(180))
            .inner_margin(8.0)
            .corner_radius(4.0)
            .show(ui, |ui| {
                let title = match reference {
                    HeatReference::Clean => "Distance to the clean mesh (model units)",
                    HeatReference::Document => "Distance to the input mesh (model units)",
                };
                ui.label(
                    egui::RichText::new(title)
                        .small()
                        .color(egui::Color32::WHITE),
                );
                // Every distance is zero (the top is clamped to the least positive float): a
                // scale of 1e-38 would read as a measurement.
                if top <= f32::MIN_POSITIVE {
                    ui.label(
                        egui::RichText::new("0 everywhere: the two meshes are the same")
                            .small()
                            .color(egui::Color32::WHITE),
                    );
                    return;
                }
                let (strip, _) =
                    ui.allocate_exact_size(egui::vec2(WIDTH, 14.0), egui::Sense::hover());
                let colours = viridis_strip(64);
                let step = strip.width() / colours.len() as f32;
                for (i, [r, g, b, _]) in colours.into_iter().enumerate() {
                    let x = strip.left() + i as f32 * step;
                    ui.painter().rect_filled(
                        egui::Rect::from_x_y_ranges(x..=x + step + 0.5, strip.y_range()),
                        0.0,
                        egui::Color32::from_rgb(r, g, b),
                    );
                }
                let (labels, _) =
                    ui.allocate_exact_size(egui::vec2(WIDTH, 16.0), egui::Sense::hover());
                let ticks = legend_ticks(top as f64, 4);
                let spacing = ticks.get(1).copied().unwrap_or(top as f64);
                for value in ticks {
                    let x = strip.left() + strip.width() * (value / top as f64) as f32;
                    ui.painter().line_segment(
                        [
                            egui::pos2(x, strip.bottom()),
                            egui::pos2(x, strip.bottom() + 3.0),
                        ],
                        egui::Stroke::new(1.0, egui::Color32::WHITE),
                    );
                    let text = tick_text(value, spacing);
                    let at = egui::Rect::from_center_size(
                        egui::pos2(
                            x.clamp(labels.left() + 18.0, labels.right() - 18.0),
                            labels.center().y,
                        ),
                        egui::vec2(44.0, 16.0),
                    );
                    ui.put(
                        at,
                        egui::Label::new(
                            egui::RichText::new(text)
                                .small()
                                .color(egui::Color32::WHITE),
                        ),
                    );
                }
            });
    });
}

/// A tick value with as many decimals as the tick spacing needs.
fn tick_text(value: f64, spacing: f64) -> String {
    if value == 0.0 {
        return "0".into();
    }
    // NaN, zero and negative spacings fall outside the range too.
    if !(1e-3..1e5).contains(&spacing) {
        return format!("{value:.0e}");
    }
    let decimals = (-spacing.log10().floor()).max(0.0) as usize;
    format!("{value:.decimals$}")
}
