//! The side panel's View section: how before and after are compared (single, split, side by
//! side, the before toggle), the heat map and its reference, and how the surface is lit
//! (Shading: Flat / Smooth, and Studio lighting on or off). Display settings only: they are edited
//! in place, and the next frame's view sync and draw parameters pick them up.

use super::command::PanelChange;
use super::panel_view::{Commands, PanelView};
use super::state::Settings;
use super::state::{CompareView, HeatReference};
use super::Command;
use crate::render::{Lighting, Shading};

/// What each choice does, in the words the tooltips use (tests look them up).
pub mod tips {
    pub const FLAT: &str = "Light each triangle with its own normal: every facet shows, as \
        it is. Use it to judge the triangles themselves. S switches between Flat and Smooth";
    pub const SMOOTH: &str = "Blend the light across triangles from normals at the corners: \
        the surface looks as a render would show it. Bumps that remain show as wobbly \
        highlights. Sharp edges stay crisp: where two faces meet at more than 80° (the rim \
        of a machined part, the edge of a box) each side keeps its own light. S switches \
        between Flat and Smooth";
    pub const STUDIO: &str = "On: a warm key light, a cool fill light and a rim light along \
        the outline, with a soft highlight: uneven spots show as kinks in the highlight. Off: \
        one plain light from above left of you";
    pub const CLAY: &str = "On: every surface in one plain clay colour, to judge the shape \
        alone. Off: the file's own colours (its materials' colours and textures, its vertex \
        colours), so you see what the smoothing does to them: a texture moves with the \
        surface. C switches it";
    pub const HEAT_INPUT: &str = "Colour by distance from the input mesh: how far the result \
        moved";
    pub const HEAT_CLEAN: &str = "Colour by distance from the clean mesh (before noise was \
        added): how close the result came back to it";
}

/// The section's rows, top of the side panel so they never take the viewport's room.
pub(super) fn show(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
) {
    compare_row(ui, settings);
    heat_rows(ui, view, settings, commands);
    look_rows(ui, settings);
}

fn compare_row(ui: &mut egui::Ui, settings: &mut Settings) {
    ui.horizontal(|ui| {
        ui.label("Compare:");
        let mut compare = settings.view.compare;
        ui.selectable_value(&mut compare, CompareView::Single, "Single")
            .on_hover_text("One view; B toggles before and after");
        ui.selectable_value(&mut compare, CompareView::Split, "Split")
            .on_hover_text("Before left of the divider, after right of it (drag the divider)");
        ui.selectable_value(&mut compare, CompareView::SideBySide, "Side by side")
            .on_hover_text("Before and after next to each other, one camera");
        settings.view.compare = compare;
    });
}

fn heat_rows(
    ui: &mut egui::Ui,
    view: &PanelView,
    settings: &mut Settings,
    commands: &mut Commands,
) {
    ui.horizontal(|ui| {
        ui.add_enabled(
            settings.view.compare == CompareView::Single,
            egui::Button::selectable(view.show_before, "Before (B)"),
        )
        .on_hover_text("Show the input mesh instead of the result (B)")
        .on_disabled_hover_text("Split and Side by side show before and after already")
        .clicked()
        .then(|| commands.push(Command::Panel(PanelChange::ToggleBefore)));
        ui.checkbox(&mut settings.view.heat_map, "Heat map (H)")
            .on_hover_text("Colour each vertex by its distance from the reference mesh (H)");
        // On the heat map's row (it colours the surface too), so the panel keeps its width.
        ui.checkbox(&mut settings.view.clay, CLAY)
            .on_hover_text(tips::CLAY);
    });
    // The reference only while the heat map is on: the panel below stays a row higher, so
    // Export fits an 800-point-high window.
    if !settings.view.heat_map {
        return;
    }
    ui.horizontal(|ui| {
        let has_clean = view.document.is_some_and(|d| d.clean.is_some());
        ui.label("against");
        ui.selectable_value(
            &mut settings.view.heat_reference,
            HeatReference::Document,
            "input mesh",
        )
        .on_hover_text(tips::HEAT_INPUT);
        ui.add_enabled(
            has_clean,
            egui::Button::selectable(
                settings.view.heat_reference == HeatReference::Clean,
                "clean mesh",
            ),
        )
        .on_hover_text(tips::HEAT_CLEAN)
        .on_disabled_hover_text("Add noise first: the mesh before it becomes the clean one")
        .clicked()
        .then(|| settings.view.heat_reference = HeatReference::Clean);
    });
}

/// Shading and lighting: how the surface is lit in every view (before, after, heat map, mask).
/// One row, so that the panel's lower sections stay on a 800-point-high screen.
fn look_rows(ui: &mut egui::Ui, settings: &mut Settings) {
    ui.horizontal(|ui| {
        ui.label("Shading:");
        for shading in Shading::ALL {
            let tip = match shading {
                Shading::Flat => tips::FLAT,
                Shading::Smooth => tips::SMOOTH,
            };
            ui.selectable_value(&mut settings.view.shading, shading, shading.label())
                .on_hover_text(tip);
        }
        let mut studio = settings.view.lighting == Lighting::Studio;
        if ui
            .checkbox(&mut studio, STUDIO_LIGHTING)
            .on_hover_text(tips::STUDIO)
            .changed()
        {
            settings.view.lighting = match studio {
                true => Lighting::Studio,
                false => Lighting::Simple,
            };
        }
    });
}

/// The control that leaves the file's colours out.
pub const CLAY: &str = "Clay (C)";

/// The lighting control's label.
pub const STUDIO_LIGHTING: &str = "Studio lighting";
