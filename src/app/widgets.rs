//! Small widgets and formats the editor's panels share: the activity spinner beside work in
//! progress and durations in seconds. Imports no panel, so that every panel can use it.

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
