//! The "Paint where to fair" controls of the side panel, and the brush in the viewport: while
//! painting, the left button emits [`Command::Paint`] dabs (one stroke per press) and the brush's
//! outline follows the cursor.

use super::command::PanelChange;
use super::paint::BrushView;
use super::panel_view::{Commands, PanelView, ViewportState, ViewportView};
use super::state::{CompareView, Settings, ViewMode};
use super::tips;
use super::Command;

/// The side panel's section: paint mode, brush, mask tint, clear and invert.
pub(super) fn section(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
) {
    let level_view = settings.view.view_mode == ViewMode::Level;
    let mut paint_mode = view.paint_mode;
    let paint = ui
        .add_enabled(
            !level_view,
            egui::Checkbox::new(&mut paint_mode, "Paint (P)"),
        )
        .on_hover_text(tips::PAINT)
        .on_disabled_hover_text(format!(
            "{}\n\nThe level view shows a coarse mesh: switch to Faired to paint.",
            tips::PAINT
        ));
    if paint.changed() {
        commands.push(Command::Panel(PanelChange::PaintMode(paint_mode)));
        if !paint_mode {
            commands.push(Command::EndStroke);
        }
    }
    let brush = &mut settings.paint;
    ui.horizontal(|ui| {
        ui.selectable_value(&mut brush.erase, false, "Add")
            .on_hover_text(tips::BRUSH_ADD);
        ui.selectable_value(&mut brush.erase, true, "Erase")
            .on_hover_text(tips::BRUSH_ERASE);
    });
    super::widgets::slider(
        ui,
        true,
        &mut brush.radius,
        4.0..=200.0,
        "Brush radius (pt)",
    )
    .on_hover_text(tips::BRUSH_RADIUS);
    super::widgets::slider(ui, true, &mut brush.softness, 0.0..=1.0, "Soft edge")
        .on_hover_text(tips::BRUSH_SOFTNESS);
    ui.checkbox(&mut brush.show_mask, "Show mask")
        .on_hover_text(tips::SHOW_MASK);
    let mask = view.document.and_then(|d| d.mask.as_ref());
    ui.horizontal(|ui| {
        let has_mask = mask.is_some();
        let clear = ("Clear mask", tips::CLEAR_MASK, Command::ClearMask);
        mask_button(ui, has_mask, clear, commands);
        let invert = ("Invert mask", tips::INVERT_MASK, Command::InvertMask);
        mask_button(ui, has_mask, invert, commands);
    });
    match mask {
        Some(mask) => ui.small(format!(
            "Painted: {} of {} vertices are smoothed; the rest keeps its shape",
            mask.painted_count(),
            mask.len()
        )),
        None => ui.small("Nothing painted: the whole mesh is smoothed"),
    };
}

/// A button that changes the mask (`label`, `tip`, the `command` it emits): off, saying so, while
/// nothing is painted.
fn mask_button(
    ui: &mut egui::Ui,
    has_mask: bool,
    (label, tip, command): (&str, &str, Command),
    commands: &mut Commands,
) {
    let button = ui
        .add_enabled(has_mask, egui::Button::new(label))
        .on_hover_text(tip)
        .on_disabled_hover_text(format!("{tip}\n\nNothing is painted."));
    if button.clicked() {
        commands.push(command);
    }
}

/// The brush in the viewport: emits dabs while the left button is down on the view in paint
/// mode and ends the stroke on release. Returns whether the left button belongs to the brush
/// (so it does not orbit).
pub(super) fn viewport_brush(
    ui: &egui::Ui,
    response: &egui::Response,
    rect: egui::Rect,
    view: &ViewportView,
    state: &mut ViewportState,
    settings: &Settings,
    commands: &mut Commands,
) -> bool {
    if !view.paint_mode || settings.view.view_mode == ViewMode::Level {
        if view.stroking {
            commands.push(Command::EndStroke);
        }
        return false;
    }
    let image = painted_image(settings, rect);
    let (primary_down, shift, hover) = ui.input(|i| {
        (
            i.pointer.primary_down(),
            i.modifiers.shift,
            i.pointer.hover_pos(),
        )
    });
    let radius = settings.paint.radius;
    let pressed_here = response.is_pointer_button_down_on() && primary_down;
    match response.interact_pointer_pos().or(hover) {
        Some(cursor) if pressed_here && image.contains(cursor) => {
            // Dabs every quarter radius from the last one, so a fast stroke leaves no gaps
            // between the frames' cursor positions; at most 8 a frame (each dab tests every
            // triangle: on a big mesh a frame must not pay for dozens).
            let from = state.last_dab.unwrap_or(cursor);
            let spacing = (radius * 0.25).max(1.0);
            let steps = ((cursor - from).length() / spacing).ceil().clamp(1.0, 8.0) as usize;
            let aspect = image.width() / image.height().max(1.0);
            let erase = settings.paint.erase != shift;
            for step in 1..=steps {
                let view = BrushView {
                    view_proj: state.camera.view_proj(aspect),
                    eye: state.camera.eye(),
                    rect: image,
                    cursor: from.lerp(cursor, step as f32 / steps as f32),
                    radius,
                };
                commands.push(Command::Paint { view, erase });
            }
            *state.last_dab = Some(cursor);
        }
        _ if !primary_down && (view.stroking || state.last_dab.is_some()) => {
            *state.last_dab = None;
            commands.push(Command::EndStroke);
        }
        _ => {}
    }
    true
}

/// The image the brush paints on: the result's, the right half side by side, the whole view
/// otherwise.
pub(super) fn painted_image(settings: &Settings, rect: egui::Rect) -> egui::Rect {
    match settings.view.compare {
        CompareView::SideBySide => rect.split_left_right_at_fraction(0.5).1,
        CompareView::Single | CompareView::Split => rect,
    }
}

/// The brush's outline at the cursor (and its hard inner part), over the drawn mesh; orange
/// adds, blue erases.
pub(super) fn brush_outline(
    ui: &egui::Ui,
    view: &ViewportView,
    settings: &Settings,
    rect: egui::Rect,
) {
    if !view.paint_mode || settings.view.view_mode == ViewMode::Level {
        return;
    }
    let (shift, hover) = ui.input(|i| (i.modifiers.shift, i.pointer.hover_pos()));
    let Some(cursor) = hover.filter(|p| painted_image(settings, rect).contains(*p)) else {
        return;
    };
    let brush = &settings.paint;
    let colour = if brush.erase != shift {
        egui::Color32::from_rgb(120, 190, 255)
    } else {
        egui::Color32::from_rgb(255, 150, 60)
    };
    let painter = ui.painter_at(rect);
    painter.circle_stroke(cursor, brush.radius, egui::Stroke::new(1.5, colour));
    let inner = brush.radius * (1.0 - brush.softness.clamp(0.0, 1.0));
    if inner > 1.0 {
        painter.circle_stroke(cursor, inner, egui::Stroke::new(0.8, colour));
    }
}
