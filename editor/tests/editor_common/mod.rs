//! What the editor's headless test files share: the bundled mesh, a harness running the real app
//! on egui_kittest's wgpu renderer, stepping frames until the background work is done, and the
//! viewport's pixels.
#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use fairmesh_editor::app::{App, AppOptions};

pub fn bunny() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the repository holds the crate")
        .join("assets/bunny00.obj")
}

pub fn harness_for(path: PathBuf) -> Harness<'static, App> {
    harness_sized(path, egui::vec2(1200.0, 800.0))
}

/// Like [`harness_for`], in a window of `size` points (tall ones show the whole side panel).
pub fn harness_sized(path: PathBuf, size: egui::Vec2) -> Harness<'static, App> {
    Harness::builder()
        .with_size(size)
        .wgpu()
        .build_eframe(move |cc| App::new_for_test(cc, path))
}

/// Like [`harness_for`], with the app's options (no persistence either way).
pub fn harness_with(options: AppOptions) -> Harness<'static, App> {
    Harness::builder()
        .with_size(egui::vec2(1200.0, 800.0))
        .wgpu()
        .build_eframe(move |cc| {
            App::with_options(
                cc,
                AppOptions {
                    persistence: false,
                    ..options
                },
            )
        })
}

/// Steps frames until every background job finished and its result was applied. The bound is
/// generous (the real hierarchy of a 75k-face mesh in a debug build on a busy machine).
pub fn settle(harness: &mut Harness<'_, App>) {
    let deadline = Instant::now() + Duration::from_secs(300);
    for _ in 0..200_000 {
        harness.step();
        if harness.state().status().view.drawing {
            // A big image drawn over several frames (software renderers) advances when frames
            // are rendered, which `step` alone does not do.
            harness.render().expect("the wgpu test renderer renders");
        }
        if harness.state().is_settled() {
            // One more frame: the results applied in the last one reach the viewport and labels.
            harness.step();
            return;
        }
        if Instant::now() > deadline {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    panic!("the editor did not settle: {:?}", harness.state().status());
}

/// Sets the start level to the hierarchy's middle one and waits for its result. A file opens at
/// level 0, `fair`'s result, which leaves a clean mesh (the bundled bunny) as it is; the tests
/// that need a smoothed result to look at start from here.
pub fn at_middle_level(harness: &mut Harness<'_, App>) -> usize {
    settle(harness);
    let middle = (harness.state().status().level_count - 1) / 2;
    assert!(middle > 0, "a hierarchy of more than two levels");
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::SetLevel(middle));
    settle(harness);
    assert_eq!(harness.state().status().faired_level, Some(middle));
    middle
}

/// The viewport's pixels out of a full-window render (the harness is 1200 points wide).
/// An image drawn over several frames (a big mesh on the software test renderer) is rendered
/// to its end first: the pixels are those of the complete image.
pub fn viewport_image(harness: &mut Harness<'_, App>) -> image::RgbaImage {
    let mut full = harness.render().expect("the wgpu test renderer renders");
    if harness.state().status().view.drawing {
        for _ in 0..10_000 {
            harness.step();
            harness.render().expect("the wgpu test renderer renders");
            if !harness.state().status().view.drawing {
                break;
            }
        }
        assert!(
            !harness.state().status().view.drawing,
            "the image was never completed"
        );
        // One more frame, whose panels know the image is complete (no "Drawing" caption).
        harness.step();
        full = harness.render().expect("the wgpu test renderer renders");
    }
    let rect = harness
        .state()
        .viewport_rect()
        .expect("the viewport was drawn");
    let scale = full.width() as f32 / 1200.0;
    let (x, y) = (
        (rect.min.x * scale).round() as u32,
        (rect.min.y * scale).round() as u32,
    );
    let (w, h) = (
        (rect.width() * scale).round() as u32,
        (rect.height() * scale).round() as u32,
    );
    image::imageops::crop_imm(
        &full,
        x,
        y,
        w.min(full.width() - x),
        h.min(full.height() - y),
    )
    .to_image()
}

/// A left-button drag from `from` to `to`: `steps` even moves, one frame each, then the release
/// at `to` (orbits, strokes, the split view's divider).
pub fn drag(harness: &mut Harness<'_, App>, from: egui::Pos2, to: egui::Pos2, steps: usize) {
    harness.hover_at(from);
    harness.step();
    harness.drag_at(from);
    harness.step();
    for i in 1..=steps {
        harness.hover_at(from.lerp(to, i as f32 / steps as f32));
        harness.step();
    }
    harness.drop_at(to);
    harness.step();
}

/// Exports the document to `target` with the shortcut, as a user would: types `target` into the
/// export path (which holds the default `…_faired.obj`), leaves the field, presses Ctrl+E and
/// waits until everything has settled.
pub fn export_by_shortcut(harness: &mut Harness<'_, App>, target: &Path) {
    retype(
        harness,
        |v| v.ends_with("_faired.obj"),
        &target.display().to_string(),
    );
    harness.key_press(egui::Key::Escape);
    harness.step();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::E);
    settle(harness);
}

/// Replaces the text of the text field whose current value satisfies `which`.
pub fn retype(harness: &mut Harness<'_, App>, which: impl Fn(&str) -> bool, text: &str) {
    let field = harness
        .get_all_by_role(Role::TextInput)
        .find(|node| node.value().is_some_and(|v| which(&v)))
        .expect("text field");
    field.focus();
    harness.step();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.step();
    harness
        .get_all_by_role(Role::TextInput)
        .find(|node| node.is_focused())
        .expect("focused text field")
        .type_text(text);
    harness.step();
}
