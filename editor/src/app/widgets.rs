//! Small widgets and formats the editor's panels share: the activity spinner beside work in
//! progress, durations in seconds and a slider that takes taps and keyboard focus. Imports no panel, so that every panel can use it.

/// A turning arc beside work in progress, like egui's spinner but without asking for a frame
/// of its own: it moves when the app repaints for the work's progress (every 50 ms, or 250 ms on
/// a software renderer), not at the display's full rate. egui's spinner repaints continuously,
/// which on a software renderer takes most of the CPU from the fairing it shows.
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

/// A duration as the Numbers and the panels show it: seconds, three decimals.
pub(super) fn seconds(duration: std::time::Duration) -> String {
    format!("{:.3} s", duration.as_secs_f64())
}

/// A slider over `value` in `range` that also takes a quick tap: a press and release within one
/// frame (a touchpad tap) sets the value under the pointer, which egui's slider alone ignores
/// (it moves only while the button is seen down). A press on it gives it keyboard focus, so the
/// arrow keys step it next.
pub(super) fn slider<N: egui::emath::Numeric>(
    ui: &mut egui::Ui,
    enabled: bool,
    value: &mut N,
    range: std::ops::RangeInclusive<N>,
    text: &str,
) -> egui::Response {
    let (low, high) = (range.start().to_f64(), range.end().to_f64());
    let mut response = ui.add_enabled(enabled, egui::Slider::new(value, range).text(text));
    if !enabled {
        return response;
    }
    // The rail is the left part of the response (the number field follows it), as tall as a
    // row; the handle's centre stays a handle's radius inside its ends.
    let thickness = ui
        .text_style_height(&egui::TextStyle::Body)
        .max(ui.spacing().interact_size.y);
    let rail = egui::Rect::from_min_size(
        response.rect.min,
        egui::vec2(ui.spacing().slider_width, thickness),
    );
    let tap = ui.input(|i| {
        i.pointer.primary_clicked()
            && i.pointer
                .interact_pos()
                .filter(|p| rail.contains(*p))
                .is_some()
    });
    if tap && response.hovered() {
        if let Some(pointer) = ui.input(|i| i.pointer.interact_pos()) {
            let ends = rail.x_range().shrink(thickness / 2.5);
            let fraction = ((pointer.x - ends.min) / ends.span().max(1.0)).clamp(0.0, 1.0);
            let mut picked = low + f64::from(fraction) * (high - low);
            if N::INTEGRAL {
                picked = picked.round();
            }
            let picked = N::from_f64(picked);
            if picked != *value {
                *value = picked;
                response.mark_changed();
            }
        }
    }
    if tap && response.hovered() || response.drag_started() {
        response.request_focus();
    }
    response
}
