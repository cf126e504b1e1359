//! Headless tests of the editor: the real app driven through egui_kittest on a software wgpu
//! adapter (lavapipe or llvmpipe; no GPU and no display needed). They load the bundled bunny,
//! wait for the background hierarchy and fairing, move the level slider with the keyboard,
//! export and re-load, check that a broken file leaves the mesh in place, drive the camera, and
//! compare viewport images with reference snapshots (`UPDATE_SNAPSHOTS=1` rewrites them).

use std::path::Path;
use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::kittest::{NodeT, Queryable};
use egui_kittest::SnapshotOptions;

mod editor_common;
use editor_common::{
    bunny, drag, harness_for, harness_sized, harness_with, retype, settle, viewport_image,
};
use fairmesh_editor::app::AppOptions;

fn snapshot_options() -> SnapshotOptions {
    // Software rasterisers differ a little between versions: compare with a tolerance.
    SnapshotOptions::new()
        .threshold(2.0)
        .max_failed_pixels(2500)
}

#[test]
fn loads_the_bunny_builds_the_hierarchy_and_fairs() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let status = harness.state().status();
    assert_eq!(status.document.as_deref(), Some(bunny().as_path()));
    assert!(status.error.is_none(), "{:?}", status.error);
    assert!(status.hierarchy_ready);
    assert!(status.level_count >= 1);
    assert!(status.faired_serial.is_some(), "a first fairing ran");
    assert!(status.view.shown_vertices > 30_000 && status.view.shown_faces > 70_000);
    // Per-level counts and the numbers are on screen.
    harness.get_by_label("Level sizes");
    harness.get_by_label_contains(&format!("levels (M0 … M{})", status.level_count - 1));
    harness.get_by_label("Volume change");
    harness.get_by_label("RMS displacement");
    harness.get_by_label("Hierarchy build");
}

/// With no file the editor opens the bunny compiled into the binary, not a file on disk: the
/// document is named by the bare file name (no folder), so it cannot have come from `assets/`.
#[test]
fn no_file_opens_the_bundled_bunny() {
    let mut harness = harness_with(AppOptions::default());
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.error.is_none(), "{:?}", status.error);
    assert_eq!(status.document.as_deref(), Some(Path::new("bunny00.obj")));
    assert!(status.hierarchy_ready);
    assert!(status.faired_serial.is_some(), "a first fairing ran");
    assert!(status.view.shown_vertices > 30_000 && status.view.shown_faces > 70_000);
}

#[test]
fn level_slider_refairs_and_updates_the_numbers() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let before = harness.state().status();
    let top = before.level_count - 1;

    nudge_level_slider(&mut harness);
    settle(&mut harness);
    let after = harness.state().status();
    let expected = (before.level + 1).min(top);
    assert_eq!(after.level, expected);
    if top >= 1 {
        // Starting from a coarser level smooths more: a new result with other numbers.
        assert_ne!(after.faired_serial, before.faired_serial);
        assert_ne!(after.rms_displacement, before.rms_displacement);
        assert!(after.rms_displacement.is_some_and(|r| r > 0.0));
        harness.get_by_label(&format!("Result: Constrained fairing from M{expected}"));
        // The slider keeps working while results stream in: several steps, one settle.
        for _ in 0..3 {
            nudge_level_slider(&mut harness);
            harness.step();
        }
        settle(&mut harness);
        let last = harness.state().status();
        assert_eq!(last.level, (before.level + 4).min(top));
        assert!(last.faired_serial > after.faired_serial);
    }
    // Fair M0 too: another run, the same level.
    let level_before = harness.state().status().level;
    harness.get_by_label("Fair M0 too").click();
    settle(&mut harness);
    let refaired = harness.state().status();
    assert!(refaired.faired_serial > after.faired_serial);
    assert_eq!(refaired.level, level_before);

    // The level itself: the coarse mesh of the chosen level, fewer faces than M0.
    harness.get_by_label("Level mesh").click();
    settle(&mut harness);
    let level_view = harness.state().status();
    if level_before > 0 {
        assert!(level_view.view.shown_faces < refaired.view.shown_faces);
    } else {
        assert_eq!(level_view.view.shown_faces, refaired.view.shown_faces);
    }
}

/// Switching to the level view while a fairing runs: the fairing, whose result the level view
/// does not show, is abandoned (its spinner goes); back on the faired view, the result for the
/// level the slider rests on comes and is measured.
#[test]
fn level_view_during_a_fairing_abandons_it_and_the_faired_view_brings_it_back() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let before = harness.state().status();
    nudge_level_slider(&mut harness);
    harness.step();
    harness.get_by_label("Level mesh").click();
    settle(&mut harness);
    assert!(
        harness.query_by_label_contains("fairing …").is_none(),
        "the fairing spinner is gone"
    );
    assert!(harness.query_by_label("running…").is_none());
    let level = harness.state().status().level;
    assert_eq!(level, before.level + 1);
    harness.get_by_label("Faired").click();
    settle(&mut harness);
    let after = harness.state().status();
    assert!(after.faired_serial > before.faired_serial);
    assert_eq!(after.faired_level, Some(level));
    let (against_document, _) = harness.state().faired_measures();
    assert!(against_document.is_some());
}

/// The results of the levels next to the one the slider rests on are made ahead of time, and
/// a level shown once is kept: moving the slider to one shows its result, measured, in the frame
/// that takes the move (a fairing's result comes back in a later frame at the earliest). A
/// changed setting drops what was kept: the same level then shows a result of its own.
#[test]
fn levels_next_to_the_slider_show_at_once_and_a_changed_setting_fairs_them_again() {
    let mut harness = harness_for(bunny());
    let middle = editor_common::at_middle_level(&mut harness);
    let kept_around = |harness: &mut egui_kittest::Harness<'_, fairmesh_editor::app::App>| {
        let deadline = Instant::now() + Duration::from_secs(300);
        loop {
            harness.step();
            let status = harness.state().status();
            // The level on screen and two either side (and the ones shown before).
            if status.kept_results >= 5 && !status.fairing_ahead {
                return;
            }
            assert!(Instant::now() < deadline, "not faired ahead: {status:?}");
            std::thread::sleep(Duration::from_millis(10));
        }
    };
    let set_level = |harness: &mut egui_kittest::Harness<'_, fairmesh_editor::app::App>,
                     level: usize| {
        harness
            .state_mut()
            .push_command(fairmesh_editor::app::Command::SetLevel(level));
        harness.step();
        harness.state().status()
    };
    kept_around(&mut harness);
    let at_middle = harness.state().status();
    let mut coarser = Vec::new();
    for level in [middle + 1, middle + 2, middle, middle - 1] {
        let status = set_level(&mut harness, level);
        assert_eq!(status.faired_level, Some(level), "shown in the same frame");
        assert!(status.faired_serial > at_middle.faired_serial);
        assert!(!status.measuring);
        assert!(harness.state().faired_measures().0.is_some(), "measured");
        coarser.push(status.rms_displacement);
    }
    // Back at the middle level: the very result shown first.
    assert_eq!(coarser[2], at_middle.rms_displacement);
    assert_ne!(coarser[0], at_middle.rms_displacement);

    // Another setting: nothing kept is shown for it.
    settle(&mut harness);
    harness.get_by_label("Fair M0 too").click();
    harness.step();
    assert_eq!(
        harness.state().status().faired_level,
        Some(middle - 1),
        "the old result stays until the new one comes"
    );
    settle(&mut harness);
    let refaired = harness.state().status();
    assert_eq!(refaired.faired_level, Some(middle - 1));
    assert_ne!(refaired.rms_displacement, coarser[3]);
    kept_around(&mut harness);
    let status = set_level(&mut harness, middle);
    assert_eq!(status.faired_level, Some(middle));
    assert_ne!(status.rms_displacement, at_middle.rms_displacement);
}

/// A result's measuring stops when the view moves on (here to the level mesh, which brings no
/// new result) and is done again once things rest: the numbers end up being that result's.
#[test]
fn measuring_stops_when_the_view_moves_on_and_is_redone() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    nudge_level_slider(&mut harness);
    let deadline = Instant::now() + Duration::from_secs(60);
    while !harness.state().status().measuring {
        harness.step();
        std::thread::sleep(Duration::from_millis(2));
        assert!(
            Instant::now() < deadline,
            "the new result is never measured"
        );
    }
    let measured = harness.state().status().faired_serial;
    harness.get_by_label("Level mesh").click();
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.measures_stopped >= 1, "the measuring was stopped");
    assert_eq!(status.faired_serial, measured, "no newer result came");
    assert!(!status.measuring);
    let (against_document, _) = harness.state().faired_measures();
    assert!(against_document.is_some_and(|m| m.mean_distance > 0.0));
    // The numbers panel shows them (back in the faired view).
    harness.get_by_label("Faired").click();
    settle(&mut harness);
    assert!(harness.query_by_label("running…").is_none());
}

#[test]
fn exports_and_reloads_the_result() {
    let dir = tempfile::tempdir().unwrap();
    // Tall enough that the Export section sits in the side panel's view.
    let mut harness = harness_sized(bunny(), egui::vec2(1200.0, 1400.0));
    settle(&mut harness);
    // The clean bunny at level 0 is left as it is; a coarser start level smooths it.
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::SetLevel(3));
    settle(&mut harness);
    let loaded = harness.state().status();
    assert_eq!(loaded.faired_level, Some(3));
    let faired = harness.state().faired_positions().expect("a faired result");
    let input = harness.state().document_mesh().expect("a document");
    assert_ne!(*faired, input.positions, "fairing moved the bunny");

    // The default export name sits next to the input, in its format.
    let default_export = bunny().with_file_name("bunny00_faired.obj");
    assert!(harness
        .get_all_by_role(Role::TextInput)
        .any(|node| node.value() == Some(default_export.display().to_string())));

    let target = dir.path().join("bunny_faired.glb");
    retype(
        &mut harness,
        |v| v.ends_with("_faired.obj"),
        &target.display().to_string(),
    );
    harness
        .get_by_role_and_label(Role::Button, "Export")
        .click();
    settle(&mut harness);
    let exported = harness.state().status();
    assert!(exported.error.is_none(), "{:?}", exported.error);
    assert!(
        exported
            .message
            .as_deref()
            .is_some_and(|m| m.starts_with("Exported to") && m.contains("bunny_faired.glb")),
        "{:?}",
        exported.message
    );
    assert!(target.is_file());

    retype(
        &mut harness,
        |v| v.ends_with("bunny00.obj"),
        &target.display().to_string(),
    );
    harness.get_by_role_and_label(Role::Button, "Load").click();
    settle(&mut harness);
    let reloaded = harness.state().status();
    assert_eq!(reloaded.document.as_deref(), Some(target.as_path()));
    assert!(reloaded.error.is_none(), "{:?}", reloaded.error);
    assert_eq!(reloaded.view.shown_faces, loaded.view.shown_faces);
    assert_eq!(reloaded.view.shown_vertices, loaded.view.shown_vertices);
    // What was exported, and is now the document, is the faired result, vertex for vertex, on
    // the input's triangles: not the input, not another level's result.
    let document = harness
        .state()
        .document_mesh()
        .expect("the reloaded document");
    assert_eq!(document.positions, *faired);
    assert_eq!(document.triangles, input.triangles);
}

#[test]
fn export_writes_an_artists_file_back_with_its_materials_groups_and_uvs() {
    let dir = tempfile::tempdir().unwrap();
    let data = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the repository holds the crate")
        .join("tests/data/roundtrip");
    let input = dir.path().join("textured.obj");
    std::fs::copy(data.join("textured.obj"), &input).unwrap();
    let mut harness = harness_for(input.clone());
    settle(&mut harness);
    // The clean file at level 0 is left as it is; a coarser start level smooths it.
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::SetLevel(1));
    settle(&mut harness);
    assert_eq!(harness.state().status().faired_level, Some(1));
    // The default export (Ctrl+E) keeps the input's format; nothing is lost, so no note.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::E);
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.error.is_none(), "{:?}", status.error);
    let message = status.message.unwrap_or_default();
    assert!(message.starts_with("Exported to"), "{message}");
    assert!(!message.contains("Note"), "{message}");
    let before = std::fs::read_to_string(&input).unwrap();
    let after = std::fs::read_to_string(dir.path().join("textured_faired.obj")).unwrap();
    // Every line but the positions, the normals (turned with their faces) and the texture
    // coordinates (which follow their vertex's slide along the surface) comes back.
    let kept = |text: &str| -> Vec<String> {
        text.lines()
            .filter(|l| !l.starts_with("v ") && !l.starts_with("vn ") && !l.starts_with("vt "))
            .map(str::to_owned)
            .collect()
    };
    assert_eq!(kept(&before), kept(&after));
    let count = |text: &str, start: &str| text.lines().filter(|l| l.starts_with(start)).count();
    for start in ["v ", "vn ", "vt "] {
        assert_eq!(count(&before, start), count(&after, start), "{start}lines");
    }
    assert_ne!(before, after, "the faired shape was written");

    // Exported as GLB, the editor says what it carried over (the UVs) and what it could not: only
    // the OBJ was copied, so its material library is missing and the materials come out white.
    retype(
        &mut harness,
        |v| v.ends_with("_faired.obj"),
        &dir.path().join("as.glb").display().to_string(),
    );
    harness.key_press(egui::Key::Escape);
    harness.step();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::E);
    settle(&mut harness);
    assert!(dir.path().join("as.glb").is_file());
    let message = harness.state().status().message.unwrap_or_default();
    assert!(
        message.contains("Note") && message.contains("UVs"),
        "{message}"
    );
    assert!(
        message.contains("textured.mtl (not found beside textured.obj)")
            && message.contains("are written white")
            && message.contains("'checker'")
            && message.contains("'paint'"),
        "{message}"
    );
}

#[test]
fn a_broken_file_shows_an_error_and_keeps_the_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.obj");
    std::fs::write(&broken, "v 0 0 0\nv one two three\nf 1 2 3\n").unwrap();
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let before = harness.state().status();

    for path in [broken.clone(), dir.path().join("missing.obj")] {
        harness
            .state_mut()
            .push_command(fairmesh_editor::app::Command::Open(path.clone()));
        settle(&mut harness);
        let after = harness.state().status();
        let error = after.error.clone().expect("an error is shown");
        assert!(
            error.contains(path.file_name().unwrap().to_str().unwrap()),
            "{error}"
        );
        harness.get_by_label_contains("Could not open the file");
        assert_eq!(after.document, before.document, "the old mesh stays");
        assert_eq!(after.view.shown_faces, before.view.shown_faces);
        harness
            .get_by_role_and_label(Role::Button, "Dismiss")
            .click();
        harness.step();
        harness.step();
        assert!(harness.state().status().error.is_none());
    }
}

/// A long error (a deep path, what is wrong, what to do) wraps inside the window: its end and
/// the Dismiss button stay on screen.
#[test]
fn a_long_error_wraps_inside_the_window() {
    let dir = tempfile::tempdir().unwrap();
    let deep = dir
        .path()
        .join("a folder with a long name/and another one inside it/and a third");
    std::fs::create_dir_all(&deep).unwrap();
    let draco = deep.join("compressed.gltf");
    std::fs::write(
        &draco,
        r#"{"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_draco_mesh_compression"],
            "extensionsRequired": ["KHR_draco_mesh_compression"]}"#,
    )
    .unwrap();
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::Open(draco));
    settle(&mut harness);
    let error = harness.state().status().error.expect("an error is shown");
    assert!(
        error.ends_with("save the file again without mesh compression"),
        "{error}"
    );
    let width = 1200.0;
    let message = harness.get_by_label_contains("Could not open the file");
    assert!(message.rect().right() <= width, "{:?}", message.rect());
    assert!(
        message.rect().height() > 20.0,
        "one line: {:?}",
        message.rect()
    );
    let dismiss = harness.get_by_role_and_label(Role::Button, "Dismiss");
    assert!(dismiss.rect().right() <= width, "{:?}", dismiss.rect());
    dismiss.click();
    harness.step();
    harness.step();
    assert!(harness.state().status().error.is_none());
}

/// A path pasted into the Path field opens with Load. In the window Ctrl+V becomes this paste
/// event from the system clipboard (eframe's `clipboard` feature); without that feature egui
/// only pastes what was copied inside the editor.
#[test]
fn a_pasted_path_opens_with_load() {
    let mushroom = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the repository holds the crate")
        .join("tests/data/mushroom_open.obj");
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    harness
        .get_by_role_and_label(Role::TextInput, "Path:")
        .focus();
    harness.step();
    // The field holds the open file's path: select it, so the paste replaces it.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.step();
    harness.event(egui::Event::Paste(mushroom.display().to_string()));
    harness.step();
    harness.get_by_role_and_label(Role::Button, "Load").click();
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.error.is_none(), "{:?}", status.error);
    assert_eq!(status.document.as_deref(), Some(mushroom.as_path()));
}

#[test]
fn camera_orbits_pans_zooms_and_fits() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let rect = harness.state().viewport_rect().unwrap();
    let fitted = *harness.state().camera();

    let centre = rect.center();
    drag(&mut harness, centre, centre + egui::vec2(100.0, 25.0), 5);
    let orbited = *harness.state().camera();
    assert!(orbited.yaw != fitted.yaw && orbited.pitch != fitted.pitch);
    assert_eq!(orbited.target, fitted.target);

    harness.hover_at(centre);
    harness.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, 120.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Unknown,
        modifiers: egui::Modifiers::NONE,
    });
    for _ in 0..30 {
        harness.step();
    }
    assert!(harness.state().camera().distance < orbited.distance);

    harness.key_press(egui::Key::F);
    harness.step();
    let refitted = *harness.state().camera();
    assert!((refitted.distance - fitted.distance).abs() < 1e-4 * fitted.distance);
    assert_eq!(refitted.target, fitted.target);

    assert!(!harness.state().settings().view.wireframe);
    harness.key_press(egui::Key::W);
    harness.step();
    assert!(harness.state().settings().view.wireframe);
}

#[test]
fn viewport_snapshots() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    // The loaded mesh, so the image does not depend on the fairing algorithm's details.
    harness.get_by_label("Input mesh").click();
    // Flat shading under the simple light (tests/editor_shading.rs covers the others).
    harness.get_by_label("Flat").click();
    harness
        .get_by_label(fairmesh_editor::app::view_panel::STUDIO_LIGHTING)
        .click();
    settle(&mut harness);

    let shaded = viewport_image(&mut harness);
    assert!(harness.state().status().view.images_drawn >= 1);
    // The mesh covers the middle of the view, in many shades (one per facet orientation).
    let (w, h) = shaded.dimensions();
    let background = *shaded.get_pixel(3, 3);
    let middle = *shaded.get_pixel(w / 2, h / 2);
    assert_ne!(
        middle, background,
        "the mesh is drawn in the middle of the view"
    );
    let mut shades = std::collections::HashSet::new();
    for y in (0..h).step_by(3) {
        for x in (0..w).step_by(3) {
            shades.insert(shaded.get_pixel(x, y).0);
        }
    }
    assert!(
        shades.len() > 100,
        "flat shading gives many shades: {}",
        shades.len()
    );
    egui_kittest::image_snapshot_options(&shaded, "viewport_bunny", &snapshot_options());

    harness.key_press(egui::Key::W);
    harness.step();
    let wire = viewport_image(&mut harness);
    let differing = shaded
        .pixels()
        .zip(wire.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        differing > 5_000,
        "the wireframe changes the image ({differing} pixels)"
    );
    egui_kittest::image_snapshot_options(&wire, "viewport_bunny_wireframe", &snapshot_options());
}

/// The background upload path (used for big meshes) draws exactly what the in-frame path draws:
/// the bunny with every mesh sent to the upload threads gives the same viewport images, shaded
/// and with the wireframe (whose edges are then built on the upload thread too).
#[test]
fn background_uploads_draw_the_same_images() {
    let mut images = Vec::new();
    for async_upload_bytes in [None, Some(0)] {
        let mut harness = harness_with(AppOptions {
            file: Some(bunny()),
            async_upload_bytes,
            ..AppOptions::default()
        });
        settle(&mut harness);
        harness.get_by_label("Input mesh").click();
        settle(&mut harness);
        let shaded = viewport_image(&mut harness);
        harness.key_press(egui::Key::W);
        harness.step();
        // The first image with the wireframe asks for the edges; in the background they land a
        // moment later, and `settle` waits for them.
        let first_wire = viewport_image(&mut harness);
        settle(&mut harness);
        let wire = viewport_image(&mut harness);
        if async_upload_bytes.is_none() {
            assert_eq!(first_wire, wire, "in-frame edges are there at once");
        }
        assert_ne!(shaded, wire, "the wireframe is drawn");
        images.push((shaded, wire));
    }
    assert!(
        images[0].0 == images[1].0,
        "shaded images differ between the in-frame and background uploads"
    );
    assert!(
        images[0].1 == images[1].1,
        "wireframe images differ between the in-frame and background uploads"
    );
}

/// A mesh or wireframe too big for the GPU's buffers is not drawn, and the viewport says why
/// (instead of wgpu's validation error ending the app). The bunny's triangles take 0.9 MB and
/// its wireframe edges 1.8 MB: a 1 MB cap keeps the mesh and refuses the wireframe, 0.5 MB
/// refuses both.
#[test]
fn meshes_too_big_for_the_gpu_buffers_are_refused_with_a_reason() {
    let mut harness = harness_with(AppOptions {
        file: Some(bunny()),
        max_buffer_bytes: Some(1_000_000),
        ..AppOptions::default()
    });
    settle(&mut harness);
    let shaded = viewport_image(&mut harness);
    assert!(harness.query_by_label_contains("Not drawn").is_none());
    harness.key_press(egui::Key::W);
    harness.step();
    settle(&mut harness);
    let wire = viewport_image(&mut harness);
    // Below the notice at the top, the image is the shaded one: no wireframe.
    let differing = (100..shaded.height())
        .flat_map(|y| (0..shaded.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| shaded.get_pixel(x, y) != wire.get_pixel(x, y))
        .count();
    assert_eq!(
        differing, 0,
        "the wireframe was refused, the shaded mesh stays"
    );
    harness.get_by_label_contains(
        "Not drawn: the wireframe of 75408 faces needs a 1.8 MB buffer; this GPU allows 1.0 MB",
    );

    let mut harness = harness_with(AppOptions {
        file: Some(bunny()),
        max_buffer_bytes: Some(500_000),
        ..AppOptions::default()
    });
    settle(&mut harness);
    harness.get_by_label_contains(
        "Not drawn: the mesh of 75408 faces needs a 0.9 MB buffer; this GPU allows 0.5 MB",
    );
    let image = viewport_image(&mut harness);
    let background = *image.get_pixel(3, 3);
    let (w, h) = image.dimensions();
    assert_eq!(
        *image.get_pixel(w / 2, h / 2),
        background,
        "no mesh is drawn"
    );
}

/// Undo and redo across an Open bring back the camera of the document they bring back: the
/// view shows that mesh, not the place where the other one was.
#[test]
fn undo_and_redo_across_open_bring_the_documents_camera_back() {
    let dir = tempfile::tempdir().unwrap();
    let far = dir.path().join("far.obj");
    let mut mesh = fairmesh::io::load(bunny()).unwrap().mesh;
    for p in &mut mesh.positions {
        *p = [p[0] * 10.0 + 5.0, p[1] * 10.0, p[2] * 10.0 - 3.0];
    }
    write_obj(&mesh, &far);

    let mut harness = harness_for(bunny());
    settle(&mut harness);
    // The user's own view of the bunny (zoomed in) is part of what comes back.
    harness.hover_at(harness.state().viewport_rect().unwrap().center());
    harness.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, 120.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Unknown,
        modifiers: egui::Modifiers::NONE,
    });
    for _ in 0..30 {
        harness.step();
    }
    let bunny_camera = *harness.state().camera();
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::Open(far.clone()));
    settle(&mut harness);
    let far_camera = *harness.state().camera();
    assert_ne!(far_camera.target, bunny_camera.target);

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    assert_eq!(
        harness.state().status().document.as_deref(),
        Some(bunny().as_path())
    );
    assert_eq!(*harness.state().camera(), bunny_camera, "the bunny's view");

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Y);
    settle(&mut harness);
    assert_eq!(
        harness.state().status().document.as_deref(),
        Some(far.as_path())
    );
    assert_eq!(*harness.state().camera(), far_camera, "the far mesh's view");
}

/// After a slider step the new result is on screen at once while its distances are measured a
/// moment later: until then the rows that still hold the previous result's numbers are greyed
/// and say so (rather than beside the fresh ones, unmarked).
#[test]
fn numbers_of_the_previous_result_are_greyed_until_the_new_ones_arrive() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let before = harness.state().status();
    let (measures, _) = harness.state().faired_measures();
    let old_mean = format!("{:.3e}", measures.unwrap().mean_distance);
    assert!(!harness
        .get_by_label(&old_mean)
        .accesskit_node()
        .is_disabled());

    nudge_level_slider(&mut harness);
    let deadline = Instant::now() + Duration::from_secs(120);
    while harness.state().status().faired_serial == before.faired_serial {
        harness.step();
        std::thread::sleep(Duration::from_millis(2));
        assert!(Instant::now() < deadline, "no new result came");
    }
    // The frame that took the new result drew the panel: its distances are not measured yet
    // (measuring starts a moment after a result arrives).
    let stale = harness.get_by_label(&old_mean).accesskit_node();
    assert!(
        stale.is_disabled(),
        "the previous result's number is greyed"
    );
    assert!(
        stale
            .description()
            .is_some_and(|d| d.contains("previous result")),
        "{:?}",
        stale.description()
    );

    settle(&mut harness);
    let (measures, _) = harness.state().faired_measures();
    let new_mean = format!("{:.3e}", measures.unwrap().mean_distance);
    assert_ne!(new_mean, old_mean);
    assert!(!harness
        .get_by_label(&new_mean)
        .accesskit_node()
        .is_disabled());
}

/// At 800×600 every toolbar control is inside the window (the toolbar wraps), and a status
/// message or an error does not move the controls under the pointer.
#[test]
fn small_window_keeps_the_toolbar_and_messages_do_not_move_the_controls() {
    let mut harness = harness_sized(bunny(), egui::vec2(800.0, 600.0));
    settle(&mut harness);
    for label in ["Level mesh", "Input mesh", "Undo", "Redo"] {
        let rect = harness.get_by_label(label).rect();
        assert!(
            rect.right() <= 800.0 && rect.bottom() <= 600.0,
            "{label} at {rect:?}"
        );
    }
    let fit = harness.get_by_label("Fit view (F)").rect();
    let apply = harness
        .get_by_role_and_label(Role::Button, "Apply result")
        .rect();
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::Open("missing.obj".into()));
    settle(&mut harness);
    assert!(harness.state().status().error.is_some());
    harness.get_by_label_contains("Could not open the file");
    assert_eq!(harness.get_by_label("Fit view (F)").rect(), fit);
    assert_eq!(
        harness
            .get_by_role_and_label(Role::Button, "Apply result")
            .rect(),
        apply
    );
}

/// The side-by-side halves are narrower than tall: switching to them fits the mesh into each
/// half (while the user has not moved the camera), and so does F (once both meshes were
/// cropped and F did not fit them).
#[test]
fn side_by_side_halves_show_the_whole_mesh() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let fits_the_halves = |harness: &egui_kittest::Harness<'_, fairmesh_editor::app::App>| {
        let camera = *harness.state().camera();
        let rect = harness.state().viewport_rect().unwrap();
        let aspect = rect.width() / 2.0 / rect.height();
        assert!(aspect < 1.0);
        let half_height = camera.distance * (camera.fov_y * 0.5).tan();
        let half_width = half_height * aspect;
        assert!(
            half_width >= camera.scene_radius && half_height >= camera.scene_radius,
            "the bounding sphere (radius {}) fits in {half_width} × {half_height}",
            camera.scene_radius
        );
    };
    harness.get_by_label("Side by side").click();
    harness.step();
    harness.step();
    fits_the_halves(&harness);

    // After an orbit, switching views keeps the user's camera; F fits again.
    harness.get_by_label("Single").click();
    harness.step();
    let fitted = *harness.state().camera();
    let centre = harness.state().viewport_rect().unwrap().center();
    drag(&mut harness, centre, centre + egui::vec2(60.0, 0.0), 4);
    let orbited = *harness.state().camera();
    assert_ne!(orbited.yaw, fitted.yaw, "the drag orbited");
    harness.get_by_label("Side by side").click();
    harness.step();
    assert_eq!(*harness.state().camera(), orbited);
    harness.key_press(egui::Key::F);
    harness.step();
    harness.step();
    fits_the_halves(&harness);
}

/// Every fairing control explains itself in its tooltip (read here as its accessible
/// description); the ones a baseline method does not use are disabled and say why, and the
/// numbers name the method instead of a start level it did not use.
#[test]
fn fairing_controls_explain_themselves_and_say_why_they_are_off() {
    // Tall enough that the whole side panel is on screen.
    let mut harness = harness_sized(bunny(), egui::vec2(1200.0, 1600.0));
    settle(&mut harness);
    let description = |harness: &egui_kittest::Harness<'_, fairmesh_editor::app::App>,
                       role: Role,
                       label: &str| {
        let node = harness.get_by_role_and_label(role, label);
        let node = node.accesskit_node();
        (node.description().unwrap_or_default(), node.is_disabled())
    };
    use fairmesh_editor::app::panels::tips;
    let controls = [
        (Role::Slider, "Start level", tips::START_LEVEL),
        (
            Role::Slider,
            "Iterations per level",
            tips::ITERATIONS_PER_LEVEL,
        ),
        (Role::Slider, "Rounds", tips::ROUNDS),
        (Role::CheckBox, "Fair M0 too", tips::FAIR_FINEST),
        (Role::Button, "Apply result", tips::APPLY),
    ];
    for (role, label, tip) in controls {
        let (text, disabled) = description(&harness, role, label);
        assert_eq!(text, tip, "{label}");
        assert!(!disabled, "{label}");
    }
    for (label, tip) in [
        ("Method", tips::METHOD),
        ("Boundary", tips::BOUNDARY),
        ("Variant", tips::VARIANT),
    ] {
        let described = harness
            .query_all_by(move |node| node.description().as_deref() == Some(tip))
            .count();
        assert_eq!(described, 1, "{label} has its tooltip");
    }
    let level = harness.state().status().level;
    harness.get_by_label_contains(&format!("Result: Constrained fairing from M{level}"));

    harness.get_by_label("Method").click();
    for _ in 0..3 {
        harness.step();
    }
    harness.get_by_label("Laplacian").click();
    settle(&mut harness);
    for (role, label) in [
        (Role::Slider, "Start level"),
        (Role::CheckBox, "Fair M0 too"),
    ] {
        let (text, disabled) = description(&harness, role, label);
        assert!(disabled, "{label} is off for Laplacian");
        assert!(
            text.contains("Not used by Laplacian"),
            "{label} says why: {text}"
        );
    }
    harness.get_by_label_contains("Result: Laplacian, whole mesh");
    assert!(harness.query_by_label_contains("from M").is_none());
    // Its result is the same at every level: kept once, nothing faired ahead.
    let status = harness.state().status();
    assert!(!status.fairing_ahead);
    assert_eq!(status.kept_results, 1);
}

/// A file opens at start level 0 (`fair`'s result: all the detail kept), and at the level last
/// chosen for it when it is opened again.
#[test]
fn a_file_opens_at_level_0_then_at_the_last_one_chosen() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.level_count >= 3);
    assert_eq!(status.level, 0);
    assert_eq!(status.faired_level, Some(0));

    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::SetLevel(2));
    settle(&mut harness);
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::Open(bunny()));
    settle(&mut harness);
    let reopened = harness.state().status();
    assert_eq!(reopened.level, 2);
    assert_eq!(reopened.faired_level, Some(2));
}

/// Opening the Performance section does not widen the side panel (it once widened it for
/// good, taking the viewport's room).
#[test]
fn performance_section_keeps_the_side_panel_width() {
    let mut harness = harness_sized(bunny(), egui::vec2(1200.0, 1600.0));
    settle(&mut harness);
    let width = harness.state().viewport_rect().unwrap().width();
    harness.get_by_label("Performance").click();
    for _ in 0..10 {
        harness.step();
    }
    assert!(
        harness.query_by_label("UI frame (CPU)").is_some(),
        "it opened"
    );
    assert_eq!(harness.state().viewport_rect().unwrap().width(), width);
    harness.get_by_label("Performance").click();
    for _ in 0..10 {
        harness.step();
    }
    assert_eq!(harness.state().viewport_rect().unwrap().width(), width);
}

/// Writes `mesh` as a minimal OBJ (the test needs a big file before `io::save` can be relied on).
fn write_obj(mesh: &fairmesh::TriMesh, path: &Path) {
    use std::io::Write;
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for p in &mesh.positions {
        writeln!(out, "v {} {} {}", p[0], p[1], p[2]).unwrap();
    }
    for t in &mesh.triangles {
        writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
}

/// Responsiveness figures (not a pass/fail timing test): on the noisy 1.2M-face bunny (noise 0.3
/// mean edge lengths, seed 1, as `fairmesh noise` adds it), seconds from opening the file to
/// the input on record, to the faired result (level 0, `fair`'s result) and to the hierarchy;
/// UI-thread CPU time per frame meanwhile; then seconds from a slider release to the result of
/// the level it rests on, for a step and for jumps to coarse levels; then frames from a slider
/// step to the new result on the bunny. Run with `cargo test --release --test editor --
/// --ignored --nocapture responsiveness`.
#[test]
#[ignore]
fn responsiveness() {
    let dir = tempfile::tempdir().unwrap();
    let large = dir.path().join("bunny_x16_noisy.obj");
    let base = fairmesh::io::load(bunny()).unwrap().mesh;
    let mut big = fairmesh::mesh::subdivide_loop(&fairmesh::mesh::subdivide_loop(&base));
    fairmesh::noise::add_noise(
        &mut big,
        &fairmesh::noise::NoiseOptions::default().with_sigma(0.3),
    );
    write_obj(&big, &large);
    println!("large mesh: {} faces, noise 0.3", big.face_count());

    let opened = Instant::now();
    let mut harness = harness_for(large);
    // Until the document is in (that frame uploads the mesh) and the hierarchy build runs.
    while harness.state().status().document.is_none() {
        harness.step();
        std::thread::sleep(Duration::from_millis(5));
    }
    println!(
        "1.2M faces: input on record {:.1} s after opening; the frame that received and \
         uploaded it: {:.2} ms",
        opened.elapsed().as_secs_f64(),
        harness.state().frame_stats().last().as_secs_f64() * 1e3
    );
    harness.state_mut().frame_stats_mut().reset_busy_max();
    let mut frames = 0;
    let mut max_frame = Duration::ZERO;
    let mut faired_at = None;
    while !harness.state().status().hierarchy_ready || faired_at.is_none() {
        harness.step();
        frames += 1;
        max_frame = max_frame.max(harness.state().frame_stats().last());
        if faired_at.is_none() && harness.state().status().faired_serial.is_some() {
            faired_at = Some(opened.elapsed());
        }
        std::thread::sleep(Duration::from_millis(16));
        assert!(opened.elapsed() < Duration::from_secs(900));
    }
    println!(
        "1.2M faces: faired result (level {:?}) {:.1} s after opening, hierarchy ready {:.1} s; \
         {frames} frames, UI frame max {:.2} ms, mean {:.2} ms",
        harness.state().status().faired_level,
        faired_at.unwrap().as_secs_f64(),
        opened.elapsed().as_secs_f64(),
        max_frame.as_secs_f64() * 1e3,
        harness.state().frame_stats().mean().as_secs_f64() * 1e3
    );
    // The first slider step right after the hierarchy is ready (the levels' set-up job runs
    // then, and the step's fairing waits behind it on the compute worker), then jumps as a
    // drag released on a coarse level, each from where the last one rests.
    let start = harness.state().status().level;
    let (frames, elapsed) = slider_step_to_result(&mut harness, start + 1);
    println!(
        "1.2M faces, slider to level {} just after the hierarchy: new result after {frames} \
         frames ({:.0} ms)",
        start + 1,
        elapsed.as_secs_f64() * 1e3
    );
    let top = harness.state().status().level_count - 1;
    for level in [top / 2, top / 2 + 1, top * 2 / 3, top * 2 / 3 - 1] {
        let started = Instant::now();
        harness
            .state_mut()
            .push_command(fairmesh_editor::app::Command::SetLevel(level));
        while harness.state().status().faired_level != Some(level) {
            harness.step();
            std::thread::sleep(Duration::from_millis(16));
            assert!(started.elapsed() < Duration::from_secs(300));
        }
        println!(
            "1.2M faces, slider released on level {level} of {top}: its result after {:.0} ms",
            started.elapsed().as_secs_f64() * 1e3
        );
    }
    drop(harness);

    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let top = harness.state().status().level_count - 1;
    let start = harness.state().status().level;
    for level in start + 1..=top.min(start + 6) {
        let (frames, elapsed) = slider_step_to_result(&mut harness, level);
        println!(
            "slider to level {level}: new result after {frames} frames ({:.0} ms)",
            elapsed.as_secs_f64() * 1e3
        );
    }
}

/// Focuses the start-level slider (one frame) and presses the right arrow on it (taken in the
/// next frame).
fn nudge_level_slider(harness: &mut egui_kittest::Harness<'_, fairmesh_editor::app::App>) {
    harness
        .get_by_role_and_label(Role::Slider, "Start level")
        .focus();
    harness.step();
    harness.key_press(egui::Key::ArrowRight);
}

/// Moves the start-level slider one step right (to `level`) and steps 16 ms frames until the
/// result for `level` is on record (an earlier level's may arrive first); the frames counted
/// include the one that took the key press.
fn slider_step_to_result(
    harness: &mut egui_kittest::Harness<'_, fairmesh_editor::app::App>,
    level: usize,
) -> (usize, Duration) {
    let started = Instant::now();
    nudge_level_slider(harness);
    let mut frames = 0;
    loop {
        harness.step();
        frames += 1;
        if harness.state().status().faired_level == Some(level) {
            return (frames, started.elapsed());
        }
        assert!(started.elapsed() < Duration::from_secs(300));
        std::thread::sleep(Duration::from_millis(16));
    }
}

#[test]
fn keep_sharp_edges_keeps_a_boxs_edges_in_the_hierarchy_and_draws_them_while_pointed_at() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("box.obj");
    fairmesh::io::save(&path, &fairmesh::mesh::shapes::cuboid([2.0, 1.0, 0.5], 0.1)).unwrap();
    let mut harness = harness_for(path);
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.hierarchy_ready);
    // On by default (as in `fairmesh fair`): the box's two outlines (60 edges each) and four
    // upright edges (5 each).
    assert_eq!(status.sharp_edges_kept, 140, "on by default");
    let levels_with = status.level_count;

    // Pointing at the control draws the kept edges the camera sees (a box shows at most three
    // faces, so some edges are behind it).
    harness
        .get_by_role_and_label(Role::CheckBox, "Keep sharp edges")
        .hover();
    harness.step();
    harness.step();
    let drawn = harness.state().status().view.sharp_edges_drawn;
    assert!(drawn > 40 && drawn < 140, "{drawn} edges drawn");

    harness
        .get_by_role_and_label(Role::CheckBox, "Keep sharp edges")
        .click();
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.hierarchy_ready, "the hierarchy was built again");
    assert_eq!(status.sharp_edges_kept, 0);
    assert!(!harness.state().settings().hierarchy.keep_sharp_edges);
    assert!(status.faired_serial.is_some(), "and the view fairs with it");
    assert!(
        levels_with >= status.level_count,
        "kept edges never make the hierarchy shorter"
    );
}

/// The noise controls explain themselves too (sigma, seed, direction and the button).
#[test]
fn noise_controls_explain_themselves() {
    let mut harness = harness_sized(bunny(), egui::vec2(1200.0, 1600.0));
    settle(&mut harness);
    use fairmesh_editor::app::panels::tips;
    for (label, tip) in [
        ("Sigma (× mean edge)", tips::NOISE_SIGMA),
        ("Seed", tips::NOISE_SEED),
        ("Noise direction", tips::NOISE_DIRECTION),
    ] {
        let described = harness
            .query_all_by(move |node| node.description().as_deref() == Some(tip))
            .count();
        assert!(described >= 1, "{label} has no tooltip");
    }
    let slider = harness.get_by_role_and_label(Role::Slider, "Sigma (× mean edge)");
    assert_eq!(
        slider.accesskit_node().description().as_deref(),
        Some(tips::NOISE_SIGMA)
    );
}

/// The edges whose two faces fold by more than 90° (their normals point more than a right angle
/// apart), among the interior edges of `positions` on `triangles`.
fn edges_folded_beyond_90_degrees(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
) -> std::collections::BTreeSet<(u32, u32)> {
    let normal = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| glam::Vec3::from(positions[v as usize]));
        (b - a).cross(c - a)
    };
    let mut faces_of_edge = std::collections::HashMap::<(u32, u32), Vec<usize>>::new();
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            faces_of_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(f);
        }
    }
    faces_of_edge
        .into_iter()
        .filter(|(_, faces)| faces.len() == 2)
        .filter(|(_, faces)| normal(&triangles[faces[0]]).dot(normal(&triangles[faces[1]])) < 0.0)
        .map(|(edge, _)| edge)
        .collect()
}

#[test]
fn with_no_control_touched_the_editor_fairs_as_fair_does_and_coarser_levels_start_from_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let noisy = path("noisy.ply");
    let mut bunny = fairmesh::io::load(bunny()).unwrap().mesh;
    fairmesh::noise::add_noise(&mut bunny, &fairmesh::noise::NoiseOptions::default());
    fairmesh::io::save(&noisy, &bunny).unwrap();
    // What `fairmesh fair` does with no option (`cli/tests/cli.rs` checks that it is this).
    let loaded = fairmesh::io::load(&noisy).unwrap();
    let mut by_fair = loaded.mesh;
    fairmesh::fairing::fair_constrained(
        &mut by_fair,
        &loaded.topology,
        &fairmesh::fairing::FairOptions::default(),
    );

    let mut harness = harness_for(noisy.clone().into());
    // Level 0's result is `fair`'s, the denoise's own: it is shown as soon as the denoise ends,
    // while the levels are still being built on it (the hierarchy's result comes after it on
    // the same worker, and building it takes far longer than a frame here).
    let deadline = Instant::now() + Duration::from_secs(300);
    while harness.state().status().faired_serial.is_none() {
        harness.step();
        assert!(Instant::now() < deadline, "no faired result");
        std::thread::sleep(Duration::from_millis(2));
    }
    let first = harness.state().status();
    assert!(
        !first.hierarchy_ready,
        "the first faired picture waited for the levels"
    );
    assert_eq!(first.faired_level, Some(0));
    let before_levels = harness.state().faired_positions().unwrap();
    assert!(before_levels.as_slice() == by_fair.positions.as_slice());
    settle(&mut harness);
    assert_eq!(harness.state().status().level, 0, "a file opens at level 0");
    let mesh = harness.state().document_mesh().unwrap();
    let at_m0 = harness.state().faired_positions().unwrap();
    // The panel says what the denoise found.
    harness.get_by_label_contains("Noise about");
    // Byte for byte `fair`'s result.
    assert!(at_m0.as_slice() == by_fair.positions.as_slice());
    // A middle level removes detail on top of it, and leaves no edge folded that `fair`
    // unfolded (the paper's multires alone left a fifth of the noise's folds on this mesh).
    let middle = (harness.state().status().level_count - 1) / 2;
    assert!(middle > 0);
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::SetLevel(middle));
    settle(&mut harness);
    assert_eq!(harness.state().status().faired_level, Some(middle));
    let opening = harness.state().faired_positions().unwrap();
    assert!(opening.as_slice() != at_m0.as_slice());
    let folded =
        |positions: &[[f32; 3]]| edges_folded_beyond_90_degrees(positions, &mesh.triangles);
    let noisy_folds = folded(&mesh.positions).len();
    assert!(
        noisy_folds > 1000,
        "the noise folds many edges: {noisy_folds}"
    );
    let by_fair_folds = folded(&by_fair.positions);
    let opening_folds = folded(&opening);
    let new_folds: Vec<_> = opening_folds.difference(&by_fair_folds).collect();
    assert!(
        new_folds.is_empty(),
        "edges folded at the middle level that fair unfolded: {new_folds:?} ({} folded there, \
         {} after fair, {noisy_folds} in the noisy mesh)",
        opening_folds.len(),
        by_fair_folds.len()
    );
}

#[test]
fn a_box_keeps_its_corners_at_a_middle_level() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("box.obj");
    let cuboid = fairmesh::mesh::shapes::cuboid([2.0, 1.0, 0.5], 0.05);
    fairmesh::io::save(&path, &cuboid).unwrap();
    let mut harness = harness_for(path);
    settle(&mut harness);
    let middle = (harness.state().status().level_count - 1) / 2;
    assert!(middle > 0, "a middle level");
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::SetLevel(middle));
    settle(&mut harness);
    assert_eq!(harness.state().status().faired_level, Some(middle));
    let faired = harness.state().faired_positions().unwrap();
    let diagonal = (2.0f32 * 2.0 + 1.0 + 0.25).sqrt();
    let (low, high) = fairmesh_editor::app::state::bounds_of(&cuboid.positions);
    let at_side = |p: [f32; 3], k: usize| p[k] == low[k] || p[k] == high[k];
    let corners: Vec<usize> = (0..cuboid.positions.len())
        .filter(|&v| (0..3).all(|k| at_side(cuboid.positions[v], k)))
        .collect();
    assert_eq!(corners.len(), 8);
    for v in corners {
        let moved = glam::Vec3::from(faired[v]).distance(glam::Vec3::from(cuboid.positions[v]));
        assert!(moved <= 0.01 * diagonal, "corner {v} moved {moved}");
    }
}

/// A clean CAD part as exporters write it (every vertex on a rim, sides fanned from slivers),
/// which the denoise leaves alone, opens at level 0: its result is the part as it is, where a
/// middle level's smoothing tore its rims and slivers apart. Coarser levels stay the user's
/// choice.
#[test]
fn a_clean_cad_part_opens_as_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("box_with_holes.obj");
    let part = fairmesh::mesh::shapes::cad_box_with_holes([4.0, 3.0, 2.0], 0.2, 0.5, 16);
    fairmesh::io::save(&path, &part).unwrap();
    let mut harness = harness_for(path);
    settle(&mut harness);
    harness.get_by_label_contains("as in a CAD part");
    let status = harness.state().status();
    assert!(status.level_count > 1, "coarser levels to choose from");
    assert_eq!(status.level, 0);
    let faired = harness.state().faired_positions().unwrap();
    let input = harness.state().document_mesh().unwrap();
    assert!(faired.as_slice() == input.positions.as_slice());
}
