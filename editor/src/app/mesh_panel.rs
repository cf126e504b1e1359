//! The side panel's Mesh section (the file's name and size, what loading repaired, whether noise
//! was added) and its Noise section (sigma, seed and direction, Add noise).

use super::panel_view::{Commands, PanelView};
use super::state::Settings;
use super::tips;
use super::Command;
use fairmesh::noise::NoiseMode;

/// The file's name and size, what loading repaired, and whether noise was added.
pub(super) fn mesh_section(ui: &mut egui::Ui, view: &PanelView) {
    let Some(document) = view.document else {
        return;
    };
    let name = document
        .path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| document.path.display().to_string());
    ui.label(name)
        .on_hover_text(document.path.display().to_string());
    let (vertices, faces) = (
        document.original.vertex_count(),
        document.original.face_count(),
    );
    ui.label(format!(
        "Input mesh: {vertices} {}, {faces} {}",
        if vertices == 1 { "vertex" } else { "vertices" },
        if faces == 1 { "face" } else { "faces" }
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
    for warning in report.warnings.iter().chain(view.appearance_warnings) {
        ui.small(format!("Warning: {warning}"));
    }

    if let Some(clean) = &document.clean {
        ui.small(format!(
            "Noise added: the mesh before it is kept as the clean mesh ({} vertices)",
            clean.vertex_count()
        ));
    }
}

/// Sigma, seed and direction of the noise, and the button that adds it.
pub(super) fn noise_section(ui: &mut egui::Ui, settings: &mut Settings, commands: &mut Commands) {
    let sigma = &mut settings.noise.sigma;
    super::widgets::slider(ui, true, sigma, 0.0..=2.0, "Sigma (× mean edge)")
        .on_hover_text(tips::NOISE_SIGMA);
    ui.horizontal(|ui| {
        let label = ui.label("Seed").on_hover_text(tips::NOISE_SEED);
        ui.add(egui::DragValue::new(&mut settings.noise.seed))
            .labelled_by(label.id)
            .on_hover_text(tips::NOISE_SEED);
    });
    egui::ComboBox::from_label("Noise direction")
        .selected_text(noise_mode_name(settings.noise.mode))
        .show_ui(ui, |ui| {
            for mode in [
                NoiseMode::Normal,
                NoiseMode::Direction,
                NoiseMode::Isotropic,
            ] {
                ui.selectable_value(&mut settings.noise.mode, mode, noise_mode_name(mode));
            }
        })
        .response
        .on_hover_text(tips::NOISE_DIRECTION);
    if ui
        .button("Add noise")
        .on_hover_text(
            "Adds noise to the input mesh; the mesh before it is kept as the clean mesh, to \
             measure how close the result gets to it",
        )
        .clicked()
    {
        commands.push(Command::AddNoise);
    }
}

/// What the Noise direction menu calls each mode.
fn noise_mode_name(mode: NoiseMode) -> &'static str {
    match mode {
        NoiseMode::Normal => "Along the normal",
        NoiseMode::Direction => "Random direction",
        NoiseMode::Isotropic => "Isotropic",
    }
}
