//! The side panel's Hierarchy section: the decimation hierarchy's build progress (with Cancel),
//! why it failed (with Build hierarchy), or its levels and their sizes.

use super::panel_view::{Commands, PanelView};
use super::state::HierarchyState;
use super::Command;

/// The hierarchy's progress, failure or levels; returns the top level (0 until it is built).
pub(super) fn hierarchy_section(
    ui: &mut egui::Ui,
    view: &PanelView,
    commands: &mut Commands,
) -> usize {
    let Some(document) = view.document else {
        return 0;
    };
    let mut top_level = 0;
    match &document.hierarchy {
        HierarchyState::Building => {
            ui.label(if view.progress.hierarchy_denoising {
                "Removing noise first…"
            } else {
                "Building the levels…"
            })
            .on_hover_text(super::tips::HIERARCHY_BUILDING);
            ui.horizontal(|ui| {
                ui.add(
                    egui::ProgressBar::new(view.progress.hierarchy)
                        .show_percentage()
                        // Narrow enough that the toolbar stays one row at 1200 points.
                        .desired_width(180.0),
                );
                if ui
                    .button("Cancel")
                    .on_hover_text(super::tips::CANCEL_HIERARCHY)
                    .clicked()
                {
                    commands.push(Command::CancelHierarchy);
                }
            });
        }
        HierarchyState::Failed(reason) => {
            ui.label(format!("Not built: {reason}"));
            if ui.button("Build hierarchy").clicked() {
                commands.push(Command::RebuildHierarchy);
            }
        }
        HierarchyState::Ready {
            levels, hierarchy, ..
        } => {
            top_level = levels.len().saturating_sub(1);
            if top_level == 0 {
                ui.label("1 level (M0 only)").on_hover_text(
                    "The mesh is too small to decimate: the hierarchy holds only the input mesh",
                );
            } else {
                ui.label(format!("{} levels (M0 … M{top_level})", levels.len()));
            }
            let loose = hierarchy.loose_triangles().len();
            if loose > 0 {
                ui.label(format!("{loose} loose triangles left out of the levels"))
                    .on_hover_text(
                        "These triangles lie over other triangles or hang from an edge as fins \
                         (a scan's reconstruction leaves them). The levels are built without \
                         them, so M0 here has fewer faces than the mesh; the smoothed result \
                         keeps them, following their corners.",
                    );
            }
            egui::CollapsingHeader::new("Level sizes")
                .default_open(levels.len() <= 12)
                .show(ui, |ui| {
                    egui::Grid::new("fairmesh-levels")
                        .striped(true)
                        .show(ui, |ui| {
                            ui.strong("Level");
                            ui.strong("Vertices");
                            ui.strong("Faces");
                            ui.end_row();
                            for (index, info) in levels.iter().enumerate() {
                                ui.label(format!("M{index}"));
                                ui.label(info.vertices.to_string());
                                ui.label(info.faces.to_string());
                                ui.end_row();
                            }
                        });
                });
        }
    }
    top_level
}
