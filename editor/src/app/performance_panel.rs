//! The side panel's Performance section (collapsed unless the user opened it): the UI thread's
//! frame times ([`super::FrameStats`]), the viewport's images, the meshes held on the GPU with
//! their kept images, and the GPU adapter.

use super::command::PanelChange;
use super::held_views::held_lines;
use super::panel_view::{Commands, PanelView};
use super::state::Settings;
use super::tips;
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
        .default_open(settings.view.show_performance)
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
                        let images = viewport.image_counts();
                        ui.label("viewport images")
                            .on_hover_text(tips::VIEWPORT_IMAGES);
                        ui.label(format!(
                            "{} drawn, {} kept shown",
                            images.drawn, images.restored
                        ))
                        .on_hover_text(tips::VIEWPORT_IMAGES);
                        ui.end_row();
                    }
                });
            held_meshes(ui, view);
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
            if ui
                .button("Reset max")
                .on_hover_text(tips::RESET_MAX)
                .clicked()
            {
                commands.push(Command::Panel(PanelChange::ResetBusyMax));
            }
        });
    settings.view.show_performance = response.fully_open();
}

/// The meshes held on the GPU, each with its bytes and its kept image's, and their sum.
fn held_meshes(ui: &mut egui::Ui, view: &PanelView) {
    let lines = held_lines(view.held_views, [view.viewport, view.viewport_before]);
    if lines.is_empty() {
        return;
    }
    ui.label("Held on the GPU").on_hover_text(tips::HELD_MESHES);
    egui::Grid::new("fairmesh-held-meshes")
        .num_columns(3)
        .show(ui, |ui| {
            ui.label(egui::RichText::new("mesh").small());
            ui.label(egui::RichText::new("buffers").small());
            ui.label(egui::RichText::new("kept image").small())
                .on_hover_text(tips::KEPT_IMAGE);
            ui.end_row();
            for line in &lines {
                let name = match line.on_screen {
                    true => format!("{} (shown)", line.name),
                    false => line.name.clone(),
                };
                ui.label(name).on_hover_text(tips::HELD_MESHES);
                ui.label(megabytes(line.bytes));
                ui.label(match line.image_bytes {
                    0 => "none".to_owned(),
                    bytes => megabytes(bytes),
                })
                .on_hover_text(tips::KEPT_IMAGE);
                ui.end_row();
            }
            let buffers: u64 = lines.iter().map(|l| l.bytes).sum();
            let images: u64 = lines.iter().map(|l| l.image_bytes).sum();
            ui.label("total");
            ui.label(megabytes(buffers));
            ui.label(megabytes(images));
            ui.end_row();
        });
}

fn megabytes(bytes: u64) -> String {
    format!("{:.1} MB", bytes as f64 / 1e6)
}

fn milliseconds(duration: std::time::Duration) -> String {
    format!("{:.2} ms", duration.as_secs_f64() * 1000.0)
}
