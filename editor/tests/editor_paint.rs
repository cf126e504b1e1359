//! Headless tests of "Paint where to fair": a brush stroke on the bunny paints a mask, the
//! result moves only the painted vertices, the mask is tinted in the view, remembered for the
//! file, inverted and cleared, and undo takes it away again.

use egui_kittest::kittest::Queryable;

mod editor_common;
use editor_common::{bunny, harness_for, harness_sized, settle, viewport_image};
use fairmesh_editor::app::App;

type Harness = egui_kittest::Harness<'static, App>;

/// A short stroke with the left button across the middle of the view.
fn stroke_across_the_middle(harness: &mut Harness) {
    let centre = harness.state().viewport_rect().unwrap().center();
    editor_common::drag(harness, centre, centre + egui::vec2(32.0, 0.0), 4);
}

/// Pixels of the view tinted orange (the mask's tint; the bunny itself is beige).
fn orange_pixels(harness: &mut Harness) -> usize {
    viewport_image(harness)
        .pixels()
        .filter(|p| p[0] as i32 - p[1] as i32 > 80 && p[1] as i32 - p[2] as i32 > 20)
        .count()
}

/// The faired result's vertices against the document's: (unpainted vertices that moved,
/// fully painted vertices that moved, fully painted vertices).
fn moved_by_mask(harness: &Harness) -> (usize, usize, usize) {
    let state = harness.state();
    let mask = state.mask().expect("a mask");
    let document = state.document_mesh().unwrap();
    let faired = state.faired_positions().unwrap();
    let (mut outside, mut inside, mut painted) = (0, 0, 0);
    for (v, (p, q)) in faired.iter().zip(&document.positions).enumerate() {
        match mask.weight(v) {
            0.0 => outside += usize::from(p != q),
            1.0 => {
                painted += 1;
                inside += usize::from(p != q);
            }
            _ => {}
        }
    }
    (outside, inside, painted)
}

#[test]
fn painting_a_disc_fairs_only_inside_it_and_undo_removes_the_mask() {
    let mut harness = harness_for(bunny());
    editor_common::at_middle_level(&mut harness);
    assert!(harness.state().mask().is_none());
    assert_eq!(
        orange_pixels(&mut harness),
        0,
        "nothing painted, nothing tinted"
    );
    let camera = *harness.state().camera();

    harness.key_press(egui::Key::P);
    harness.step();
    assert!(harness.state().paint_mode());
    stroke_across_the_middle(&mut harness);
    settle(&mut harness);

    // The left button painted instead of turning the view.
    assert_eq!(*harness.state().camera(), camera);
    let mask = harness.state().mask().expect("the stroke painted a mask");
    let total = mask.len();
    assert!(
        mask.painted_count() > 20 && mask.painted_count() < total / 4,
        "a disc: {} of {total}",
        mask.painted_count()
    );
    let (outside, inside, painted) = moved_by_mask(&harness);
    assert_eq!(outside, 0, "vertices outside the painted disc moved");
    assert!(
        inside > painted / 2,
        "{inside} of {painted} painted vertices moved"
    );
    harness.get_by_label_contains(&format!("Painted: {} of {total}", mask.painted_count()));
    assert!(
        orange_pixels(&mut harness) > 200,
        "the painted disc is tinted"
    );
    // Remembered for the file.
    let remembered = harness.state().settings().paint.mask_for(&bunny(), total);
    assert_eq!(
        remembered.map(|m| m.painted_count()),
        Some(mask.painted_count())
    );

    // Undo takes the mask away: the whole mesh is faired again.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert!(harness.state().mask().is_none(), "undo removes the mask");
    harness.get_by_label("Nothing painted: the whole mesh is smoothed");
    let state = harness.state();
    let (faired, document) = (
        state.faired_positions().unwrap(),
        state.document_mesh().unwrap(),
    );
    let moved = faired
        .iter()
        .zip(&document.positions)
        .filter(|(p, q)| p != q)
        .count();
    assert!(
        moved > total / 2,
        "unmasked, most of the mesh moves: {moved}"
    );
    assert!(state.settings().paint.mask_for(&bunny(), total).is_none());
    assert_eq!(orange_pixels(&mut harness), 0);

    // Redo brings it back.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Y);
    settle(&mut harness);
    assert_eq!(harness.state().mask(), Some(mask));
}

#[test]
fn invert_and_clear_change_the_mask_and_explain_themselves() {
    // Tall enough that the whole side panel is on screen.
    let mut harness = harness_sized(bunny(), egui::vec2(1200.0, 1600.0));
    settle(&mut harness);
    harness.get_by_label("Paint (P)").click();
    harness.step();
    assert!(harness.state().paint_mode());
    stroke_across_the_middle(&mut harness);
    settle(&mut harness);
    let painted = harness.state().mask().unwrap();

    harness.get_by_label("Invert mask").click();
    settle(&mut harness);
    let inverted = harness.state().mask().unwrap();
    for (w, u) in painted.weights().iter().zip(inverted.weights()) {
        assert_eq!(*u, 1.0 - w);
    }
    let (outside, _, _) = moved_by_mask(&harness);
    assert_eq!(outside, 0, "the painted disc keeps its shape once inverted");

    harness.get_by_label("Clear mask").click();
    settle(&mut harness);
    assert!(harness.state().mask().is_none());
    // Every paint control has a tooltip in plain words.
    use fairmesh_editor::app::panels::tips;
    for (label, tip) in [
        ("Paint (P)", tips::PAINT),
        ("Add", tips::BRUSH_ADD),
        ("Erase", tips::BRUSH_ERASE),
        ("Brush radius (pt)", tips::BRUSH_RADIUS),
        ("Soft edge", tips::BRUSH_SOFTNESS),
        ("Show mask", tips::SHOW_MASK),
        ("Clear mask", tips::CLEAR_MASK),
        ("Invert mask", tips::INVERT_MASK),
    ] {
        let described = harness
            .query_all_by(move |node| {
                node.description()
                    .as_deref()
                    .is_some_and(|d| d.starts_with(tip))
            })
            .count();
        assert!(described >= 1, "{label} has no tooltip");
    }
}
