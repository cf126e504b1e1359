//! The status bar at the bottom of the window: loading, the error with Dismiss, messages, or
//! "Ready".

use super::panel_view::{Commands, PanelView};
use super::widgets::activity_spinner;
use super::Command;

/// Loading, errors and messages, at the bottom of the window: their coming and going does not
/// move the controls (a click meant for one button would hit another).
pub(super) fn status_bar(ui: &mut egui::Ui, view: &PanelView, commands: &mut Commands) {
    ui.add_space(2.0);
    if let Some(path) = view.loading {
        ui.horizontal(|ui| {
            activity_spinner(ui);
            ui.label(format!("Loading {} …", path.display()));
        });
    }
    if let Some(error) = view.error {
        egui::Frame::new()
            .fill(egui::Color32::from_rgb(110, 24, 24))
            .inner_margin(6.0)
            .corner_radius(4.0)
            .show(ui, |ui| {
                // The button first and the message wrapped in the width left, so that a long
                // message (a path, then what is wrong and what to do) never runs past the
                // window's edge, taking its end and the button with it.
                ui.horizontal(|ui| {
                    if ui
                        .button("Dismiss")
                        .on_hover_text("Hide this message")
                        .clicked()
                    {
                        commands.push(Command::DismissError);
                    }
                    ui.add(
                        egui::Label::new(
                            egui::RichText::new(format!("Error: {error}"))
                                .color(egui::Color32::WHITE),
                        )
                        .wrap(),
                    );
                });
            });
    }
    if let Some(message) = view.message {
        ui.colored_label(egui::Color32::from_rgb(140, 200, 140), message);
    }
    if view.loading.is_none() && view.error.is_none() && view.message.is_none() {
        // The bar keeps its height when there is nothing to say.
        ui.weak("Ready");
    }
    ui.add_space(2.0);
}
