//! Headless tests of what the viewport shows while the heat map and a painted mask are both on:
//! the shape, the heat map's colours and the mask's tint always come from one result (after a
//! stroke, Clear mask, another stroke and undo), the view's caption says "computing…" while the
//! picture is the previous one, and the words around the view say what is on screen (the
//! Numbers rows' tooltips, the export formats, the status bar after another file loads).

use egui_kittest::kittest::{NodeT, Queryable};

mod editor_common;
use editor_common::{bunny, harness_sized, settle, viewport_image};
use fairmesh_editor::app::panels::tips;
use fairmesh_editor::app::App;

type Harness = egui_kittest::Harness<'static, App>;

/// Tall enough that the whole side panel (Clear mask, the Numbers) is on screen.
fn tall_bunny() -> Harness {
    let mut harness = harness_sized(bunny(), egui::vec2(1200.0, 1600.0));
    editor_common::at_middle_level(&mut harness);
    harness
}

fn stroke(harness: &mut Harness, dx: f32) {
    let centre = harness.state().viewport_rect().unwrap().center();
    editor_common::drag(
        harness,
        centre + egui::vec2(dx, 0.0),
        centre + egui::vec2(dx + 32.0, 0.0),
        4,
    );
    settle(harness);
}

/// The heat map's top as the view computes it: the 99th percentile of the distances above 0.
fn percentile_99(distances: &[f32]) -> f32 {
    let mut sorted: Vec<f32> = distances.iter().copied().filter(|d| *d > 0.0).collect();
    sorted.sort_by(f32::total_cmp);
    let rank = ((sorted.len() - 1) as f64 * 0.99).round() as usize;
    sorted[rank].max(0.0)
}

/// Pixels of the heat map's colours (viridis: blue, teal, green; the bunny's clay is warm,
/// red above green above blue).
fn heat_pixels(harness: &mut Harness) -> usize {
    viewport_image(harness)
        .pixels()
        .filter(|p| p[2] as i32 > p[0] as i32 + 25 || p[1] as i32 > p[0] as i32 + 25)
        .count()
}

/// The main view shows the newest result with that result's own heat map (its legend's top is
/// the 99th percentile of that result's distances from the input mesh), and says it is up to
/// date. Returns the legend's top.
fn heat_map_of_the_result_on_screen(harness: &mut Harness, step: &str) -> f32 {
    let status = harness.state().status();
    assert!(
        status.view.heat_shown,
        "{step}: heat map ticked but not shown"
    );
    assert!(status.faired_serial.is_some(), "{step}: no result");
    assert_eq!(
        status.view.shown_serial, status.faired_serial,
        "{step}: the view shows another result than the newest"
    );
    assert!(!status.view.view_behind, "{step}: the view says computing");
    let distances = harness
        .state()
        .faired_measures()
        .0
        .expect("the result was measured")
        .vertex_distances;
    let top = harness.state().heat_map_top().expect("a legend");
    assert_eq!(
        top,
        percentile_99(&distances).max(f32::MIN_POSITIVE),
        "{step}: the colours are not this result's"
    );
    assert!(
        heat_pixels(harness) > 2000,
        "{step}: heat-map colours on screen"
    );
    assert_eq!(status.view.caption, "After (faired)", "{step}");
    top
}

fn snapshot(harness: &mut Harness, name: &str) {
    let image = viewport_image(harness);
    egui_kittest::image_snapshot_options(
        &image,
        name,
        &egui_kittest::SnapshotOptions::new()
            .threshold(2.0)
            .max_failed_pixels(2500),
    );
}

#[test]
fn heat_map_mask_and_shape_come_from_one_result_through_the_mask_steps() {
    let mut harness = tall_bunny();
    harness.key_press(egui::Key::H);
    settle(&mut harness);
    let whole = heat_map_of_the_result_on_screen(&mut harness, "heat map on");

    // A stroke: the heat map stays (the mask's edge is outlined over it), of the masked result.
    harness.key_press(egui::Key::P);
    harness.step();
    stroke(&mut harness, 0.0);
    assert!(harness.state().mask().is_some());
    assert!(
        harness.state().status().view.mask_shown,
        "the mask is shown"
    );
    assert!(harness.state().settings().view.heat_map);
    let masked = heat_map_of_the_result_on_screen(&mut harness, "after a stroke");
    assert!(masked != whole, "the masked result's map is its own");
    snapshot(&mut harness, "heat_mask_1_stroke");

    // Clear mask: the whole mesh's result, with its colours.
    harness.get_by_label("Clear mask").click();
    settle(&mut harness);
    assert!(harness.state().mask().is_none());
    let cleared = heat_map_of_the_result_on_screen(&mut harness, "after Clear mask");
    assert!(cleared != masked, "the colours follow the cleared result");
    snapshot(&mut harness, "heat_mask_2_cleared");

    // A new stroke: the masked result's colours, not the whole mesh's.
    stroke(&mut harness, -20.0);
    let restroked = heat_map_of_the_result_on_screen(&mut harness, "after a new stroke");
    assert!(
        restroked != cleared,
        "the colours follow the new stroke's result"
    );
    snapshot(&mut harness, "heat_mask_3_new_stroke");

    // Undo the stroke: the heat map stays, of the result without it.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert!(harness.state().mask().is_none());
    heat_map_of_the_result_on_screen(&mut harness, "after undo");
    snapshot(&mut harness, "heat_mask_4_undone");
}

#[test]
fn the_caption_says_computing_while_the_picture_is_the_previous_one() {
    let mut harness = tall_bunny();
    harness.key_press(egui::Key::H);
    settle(&mut harness);
    let before = harness.state().status();
    // Another start level: until its result is faired and measured, the view keeps the
    // previous picture and says so.
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::SetLevel(
            (before.level + 1).min(before.level_count - 1),
        ));
    harness.step();
    harness.step();
    let status = harness.state().status();
    assert!(status.view.view_behind, "{status:?}");
    assert_eq!(
        status.view.shown_serial, before.view.shown_serial,
        "the previous picture"
    );
    assert_eq!(
        status.view.caption,
        format!("After (faired): {}", fairmesh_editor::app::COMPUTING)
    );
    settle(&mut harness);
    heat_map_of_the_result_on_screen(&mut harness, "the new level");
}

#[test]
fn the_words_say_what_is_on_screen() {
    let mut harness = tall_bunny();
    // Every row of the Numbers has a tooltip.
    for (name, tip) in tips::ROW_TIPS {
        let node = harness.get_by_label(name);
        assert_eq!(node.accesskit_node().description().as_deref(), Some(tip));
    }
    // The export hint names the six formats the editor guide lists.
    harness.get_by_label(tips::EXPORT_FORMATS);
    let guide = include_str!("../../docs/editor.md");
    assert!(guide.contains("GLB, glTF, OBJ, PLY, STL or OFF by extension"));

    // A message about this file's history is gone once another file is loaded.
    harness.key_press(egui::Key::P);
    harness.step();
    stroke(&mut harness, 0.0);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(
        harness.state().status().message.as_deref(),
        Some("Undone: Paint mask")
    );
    let other = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the repository holds the crate")
        .join("tests/data/elephant.obj");
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::Open(other));
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.document.unwrap().ends_with("elephant.obj"));
    assert_eq!(
        status.message, None,
        "the status bar still speaks of the bunny"
    );
}
