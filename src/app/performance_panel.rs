//! The side panel's Performance section (collapsed unless the user opened it): the UI thread's
//! frame times ([`super::FrameStats`]), the viewport's images and the GPU adapter.

use super::command::PanelChange;
use super::panel_view::{Commands, PanelView};
use super::state::Settings;
use super::Command;

/// The frame times, images drawn and adapter; "Reset max" forgets the largest frame time while
/// working.
pub(super) fn show(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
) {
    ui.separator();
    let response = egui::CollapsingHeader::new("Performance")
        .default_open(settings.show_performance)
        .show(ui, |ui| {
            let stats = view.frame_stats;
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
                    if let Some(viewport) = view.viewport {
                        ui.label("viewport images");
                        ui.label(viewport.images_drawn().to_string());
                        ui.end_row();
                    }
                });
            // Long adapter names wrap at the panel's width instead of widening it.
            if let Some(viewport) = view.viewport {
                ui.add(
                    egui::Label::new(
                        egui::RichText::new(format!("Adapter: {}", viewport.adapter_description()))
                            .small(),
                    )
                    .wrap(),
                );
            }
            if ui.button("Reset max").clicked() {
                commands.push(Command::Panel(PanelChange::ResetBusyMax));
            }
        });
    settings.show_performance = response.fully_open();
}

fn milliseconds(duration: std::time::Duration) -> String {
    format!("{:.2} ms", duration.as_secs_f64() * 1000.0)
}
