//! Headless tests of what an artist expects of an editor (issue 13): a question before Export
//! replaces a file, a PNG of the 3D view, recent files, smooth shading.
#![cfg(feature = "gui")]

use std::path::{Path, PathBuf};

use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;

mod editor_common;
use editor_common::{bunny, harness_for, retype, settle};

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
    let mut harness = harness_for(input);
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
    retype(
        &mut harness,
        |v| v.ends_with("_faired.obj"),
        &fresh.display().to_string(),
    );
    harness.key_press(egui::Key::Escape);
    harness.step();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::E);
    settle(&mut harness);
    assert!(harness.query_by_label("Replace fresh.obj?").is_none());
    assert!(fresh.is_file());
}
