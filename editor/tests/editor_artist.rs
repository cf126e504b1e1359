//! Headless tests of what an artist expects of an editor: a question before Export
//! replaces a file, a PNG of the 3D view, recent files, smooth shading.

use std::path::{Path, PathBuf};

use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;

mod editor_common;
use editor_common::{
    bunny, export_by_shortcut, harness_for, harness_sized, retype, settle, viewport_image,
};

/// The bundled bunny copied into `dir` (what the editor writes beside it stays there).
fn bunny_in(dir: &Path) -> PathBuf {
    let path = dir.join("bunny00.obj");
    std::fs::copy(bunny(), &path).unwrap();
    path
}

#[test]
fn export_asks_before_replacing_a_file_and_cancel_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = bunny_in(dir.path());
    let target = dir.path().join("bunny00_faired.obj");
    std::fs::write(&target, "precious").unwrap();
    // Tall enough that the Export section sits in the side panel's view.
    let mut harness = harness_sized(input, egui::vec2(1200.0, 1400.0));
    settle(&mut harness);

    // Ctrl+E to the existing default path asks first, and Cancel leaves the file alone.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::E);
    settle(&mut harness);
    harness.get_by_label("Replace bunny00_faired.obj?");
    harness
        .get_by_role_and_label(Role::Button, "Cancel")
        .click();
    settle(&mut harness);
    assert!(harness
        .query_by_label("Replace bunny00_faired.obj?")
        .is_none());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious");
    let status = harness.state().status();
    assert!(
        status
            .message
            .as_deref()
            .is_some_and(|m| m.contains("cancelled")),
        "{:?}",
        status.message
    );

    // The Export button asks too; Replace writes the result.
    harness
        .get_by_role_and_label(Role::Button, "Export")
        .click();
    settle(&mut harness);
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious");
    harness
        .get_by_role_and_label(Role::Button, "Replace")
        .click();
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.error.is_none(), "{:?}", status.error);
    assert!(
        status
            .message
            .as_deref()
            .is_some_and(|m| m.starts_with("Exported to")),
        "{:?}",
        status.message
    );
    assert!(std::fs::read_to_string(&target).unwrap().contains("\nf "));

    // A new file is written at once, without a question.
    let fresh = dir.path().join("fresh.obj");
    export_by_shortcut(&mut harness, &fresh);
    assert!(harness.query_by_label("Replace fresh.obj?").is_none());
    assert!(fresh.is_file());
}

/// Mean absolute difference of two images' RGB values, over their common part.
fn mean_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let (w, h) = (a.width().min(b.width()), a.height().min(b.height()));
    let mut sum = 0u64;
    for y in 0..h {
        for x in 0..w {
            let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
            sum += (0..3).map(|c| p[c].abs_diff(q[c]) as u64).sum::<u64>();
        }
    }
    sum as f64 / (3 * w * h) as f64
}

#[test]
fn save_image_writes_the_views_pixels_beside_the_file_without_replacing_one() {
    let dir = tempfile::tempdir().unwrap();
    let input = bunny_in(dir.path());
    let mut harness = harness_for(input);
    settle(&mut harness);

    harness.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::S,
    );
    settle(&mut harness);
    let first = dir.path().join("bunny00_view.png");
    let status = harness.state().status();
    assert!(status.error.is_none(), "{:?}", status.error);
    assert_eq!(
        status.message,
        Some(format!("Saved the view to {}", first.display()))
    );
    let saved = image::open(&first).unwrap().to_rgba8();
    // The view's pixels: its size, not the window's, and the same picture (the saved one has
    // no mouse hints at the bottom).
    let view = viewport_image(&mut harness);
    let full = harness.render().unwrap();
    assert!(saved.width() < full.width(), "the side panel is left out");
    assert!(
        saved.width().abs_diff(view.width()) <= 1,
        "{} vs {}",
        saved.width(),
        view.width()
    );
    assert!(saved.height().abs_diff(view.height()) <= 1);
    let difference = mean_difference(&saved, &view);
    assert!(difference < 2.0, "mean difference {difference}");
    // Not an empty picture: the bunny is on it.
    let background = *saved.get_pixel(2, 2);
    let drawn = saved.pixels().filter(|p| **p != background).count();
    assert!(
        drawn > (saved.width() * saved.height() / 20) as usize,
        "{drawn} pixels drawn"
    );

    // The button saves another one beside it; the first stays.
    let before = std::fs::read(&first).unwrap();
    harness
        .get_by_role_and_label(Role::Button, "Save image")
        .click();
    settle(&mut harness);
    let second = dir.path().join("bunny00_view_2.png");
    assert!(second.is_file());
    assert_eq!(std::fs::read(&first).unwrap(), before);
    assert!(harness
        .state()
        .status()
        .message
        .is_some_and(|m| m.contains("bunny00_view_2.png")));
}

#[test]
fn recent_files_reopen_and_a_missing_one_is_named_and_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let input = bunny_in(dir.path());
    let other = dir.path().join("other.obj");
    std::fs::copy(bunny(), &other).unwrap();
    let mut harness = harness_for(input.clone());
    settle(&mut harness);
    retype(
        &mut harness,
        |v| v.ends_with("bunny00.obj"),
        &other.display().to_string(),
    );
    harness.get_by_role_and_label(Role::Button, "Load").click();
    settle(&mut harness);
    assert_eq!(
        harness.state().settings().files.recent_files,
        vec![other.clone(), input.clone()],
        "newest first"
    );

    // The first file again, from the menu.
    open_recent_menu(&mut harness);
    harness
        .get_by_role_and_label(Role::Button, &input.display().to_string())
        .click();
    settle(&mut harness);
    let status = harness.state().status();
    assert_eq!(status.document.as_deref(), Some(input.as_path()));
    assert!(status.error.is_none(), "{:?}", status.error);
    assert_eq!(
        harness.state().settings().files.recent_files,
        vec![input.clone(), other.clone()]
    );

    // A file that is gone: the error names it, the mesh stays, the menu forgets it.
    std::fs::remove_file(&other).unwrap();
    open_recent_menu(&mut harness);
    harness
        .get_by_role_and_label(Role::Button, &other.display().to_string())
        .click();
    settle(&mut harness);
    let status = harness.state().status();
    let error = status.error.unwrap_or_default();
    assert!(error.contains(&other.display().to_string()), "{error}");
    assert!(error.contains("no longer there"), "{error}");
    assert_eq!(status.document.as_deref(), Some(input.as_path()));
    assert_eq!(harness.state().settings().files.recent_files, vec![input]);
}

fn open_recent_menu(harness: &mut egui_kittest::Harness<'_, fairmesh_editor::app::App>) {
    harness
        .get_by_role_and_label(Role::Button, "Recent")
        .click();
    for _ in 0..3 {
        harness.step();
    }
}
