//! The 3D viewport's area: the camera's mouse handling (orbit, pan, zoom; the split view's
//! divider first, the paint brush when painting), the views the compare mode asks for (one,
//! split at the divider, side by side) with their captions, and what is drawn over them: the
//! mouse hints, the heat map's legend, the brush outline, the kept sharp edges, and why a mesh
//! is not drawn.

use super::state::{CompareView, HeatReference, ViewMode};
use super::{App, Slot};
use crate::render::colormap::{legend_ticks, viridis_strip};

pub fn show(app: &mut App, ui: &mut egui::Ui) {
    let rect = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
    app.viewport_rect = Some(rect);
    let divider_x = rect.left() + rect.width() * app.settings.split.clamp(0.0, 1.0);
    let divider_dragged = split_divider(app, ui, rect, divider_x);
    let painting = !divider_dragged && super::paint_panel::viewport_brush(app, ui, &response, rect);
    if !divider_dragged {
        camera_input(app, ui, &response, painting);
    }
    let painter = ui.painter_at(rect);
    if app.viewport.is_none() {
        painter.text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "No wgpu renderer: the 3D view needs eframe's wgpu backend",
            egui::FontId::proportional(16.0),
            ui.visuals().text_color(),
        );
    }
    draw_views(app, &painter, rect, divider_x);
    overlays(app, ui, &painter, rect, painting);
}

/// The split view's divider sits on top of the camera's area and takes its drags first; returns
/// whether it is being dragged.
fn split_divider(app: &mut App, ui: &mut egui::Ui, rect: egui::Rect, divider_x: f32) -> bool {
    if app.settings.compare != CompareView::Split {
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
    app.settings.split = ((x - rect.left()) / rect.width().max(1.0)).clamp(0.02, 0.98);
    true
}

/// Orbit, pan and zoom (while painting, the middle button turns the view instead of the left).
fn camera_input(app: &mut App, ui: &egui::Ui, response: &egui::Response, painting: bool) {
    let orbit_button = match painting {
        true => egui::PointerButton::Middle,
        false => egui::PointerButton::Primary,
    };
    if response.dragged_by(orbit_button) {
        app.camera.orbit(response.drag_delta());
    }
    if response.dragged_by(egui::PointerButton::Secondary)
        || (!painting && response.dragged_by(egui::PointerButton::Middle))
    {
        app.camera
            .pan(response.drag_delta(), response.rect.height());
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta().y);
        if scroll != 0.0 {
            app.camera.zoom(scroll);
        }
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
fn draw_views(app: &mut App, painter: &egui::Painter, rect: egui::Rect, divider_x: f32) {
    let after_name = match app.settings.view_mode {
        ViewMode::Faired => "After (faired)",
        ViewMode::Level => "Level mesh",
        ViewMode::Original => "Input mesh",
    };
    let top_left = |r: egui::Rect| r.left_top() + egui::vec2(10.0, 8.0);
    match app.settings.compare {
        CompareView::Single => {
            let slot = match app.show_before {
                true => Slot::Before,
                false => Slot::Main,
            };
            let params = app.draw_params(rect, slot);
            if let Some(viewport) = app.viewport_mut(slot) {
                viewport.paint(painter, rect, params);
            }
            let name = if app.show_before {
                "Before (B)"
            } else {
                after_name
            };
            caption(painter, top_left(rect), egui::Align2::LEFT_TOP, name);
        }
        CompareView::Split => {
            let (left, right) = rect.split_left_right_at_x(divider_x);
            let before_params = app.draw_params(rect, Slot::Before);
            let after_params = app.draw_params(rect, Slot::Main);
            if let Some(viewport) = app.viewport_mut(Slot::Before) {
                viewport.paint_part(painter, rect, left, before_params);
            }
            if let Some(viewport) = app.viewport_mut(Slot::Main) {
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
            let before_params = app.draw_params(left, Slot::Before);
            let after_params = app.draw_params(right, Slot::Main);
            if let Some(viewport) = app.viewport_mut(Slot::Before) {
                viewport.paint(painter, left, before_params);
            }
            if let Some(viewport) = app.viewport_mut(Slot::Main) {
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
/// not drawn, over the views.
fn overlays(
    app: &mut App,
    ui: &mut egui::Ui,
    painter: &egui::Painter,
    rect: egui::Rect,
    painting: bool,
) {
    // A saved image of the view leaves out the mouse hints.
    let hint = if app.capturing_view {
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
    if let (Some(top), Some(reference)) = (app.heat_top(), app.heat_reference()) {
        heat_legend(ui, rect, top, reference);
    }
    super::paint_panel::brush_outline(app, ui, rect);
    super::fairing_panel::sharp_edge_overlay(app, ui, rect);
    let wireframe = app.settings.wireframe;
    let problem = app
        .viewports()
        .find_map(|viewport| viewport.problem(wireframe));
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
