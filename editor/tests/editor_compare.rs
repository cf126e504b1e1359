//! Headless tests of the editor's compare-and-experiment tools, driving the real app
//! through egui_kittest on a software wgpu adapter: noise injection with a clean reference, the
//! live numbers, the heat map and its legend, undo and redo of document changes, the baseline
//! methods, the before/after views (snapshot images compared with a tolerance;
//! `UPDATE_SNAPSHOTS=1` rewrites them) and the export of the level chain.

use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use fairmesh_editor::app::{App, Command};

mod editor_common;
use editor_common::{
    bunny, drag, export_by_shortcut, harness_for, harness_sized, settle, viewport_image,
};

/// Loads the bunny, adds the default noise (sigma 0.3 of the mean edge, seed 1, along the
/// normal) through the panel's button, and fairs from a middle level: M4 of the bunny's 19
/// (a quarter of the way up; the levels above it smooth away more than this noise, see
/// `explore_levels`).
fn noisy_bunny_faired_from_the_middle() -> Harness<'static, App> {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    assert_eq!(harness.state().settings().noise.seed, 1);
    harness
        .get_by_role_and_label(Role::Button, "Add noise")
        .click();
    settle(&mut harness);
    let middle = harness.state().status().level_count / 4;
    harness.state_mut().push_command(Command::SetLevel(middle));
    settle(&mut harness);
    assert_eq!(harness.state().status().level, middle);
    harness
}

#[test]
fn noise_keeps_the_clean_mesh_and_fairing_gets_closer_to_it() {
    let mut harness = noisy_bunny_faired_from_the_middle();
    let app = harness.state();
    let clean = app.clean_mesh().expect("the mesh before the noise is kept");
    let noisy = app.document_mesh().unwrap();
    let loaded = fairmesh::io::load(bunny()).unwrap().mesh;
    assert_eq!(
        clean.positions, loaded.positions,
        "the clean mesh is the loaded one"
    );
    assert_eq!(noisy.triangles, clean.triangles);
    let moved = noisy
        .positions
        .iter()
        .zip(&clean.positions)
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        moved > noisy.positions.len() * 9 / 10,
        "noise moved {moved} vertices"
    );

    // The same seed gives the same noise.
    let mut again = loaded.clone();
    fairmesh::noise::add_noise(
        &mut again,
        &fairmesh::noise::NoiseOptions::default()
            .with_sigma(0.3)
            .with_seed(1)
            .with_mode(fairmesh::noise::NoiseMode::Normal),
    );
    assert_eq!(again.positions, noisy.positions);

    let noise = app.noise_measures().expect("noisy vs clean numbers");
    let (against_noisy, against_clean) = app.faired_measures();
    let against_noisy = against_noisy.expect("numbers against the noisy mesh");
    let against_clean = against_clean.expect("numbers against the clean mesh");
    println!(
        "noisy vs clean: mean {:.3e} max {:.3e}; faired vs clean: mean {:.3e} max {:.3e} \
         volume {:?} %; faired vs noisy: volume {:?} % rms {:?} drift {:?}",
        noise.mean_distance,
        noise.max_distance,
        against_clean.mean_distance,
        against_clean.max_distance,
        against_clean.volume_change_percent,
        against_noisy.volume_change_percent,
        against_noisy.vertex_rms,
        against_noisy.barycenter_drift,
    );
    assert!(
        against_clean.mean_distance < 0.8 * noise.mean_distance,
        "fairing brings the surface closer to the clean one: {} -> {}",
        noise.mean_distance,
        against_clean.mean_distance
    );
    let volume = against_noisy.volume_change_percent.unwrap();
    assert!(volume.abs() < 0.1, "volume change {volume} %");
    assert!(against_noisy.vertex_rms.is_some_and(|r| r > 0.0));
    assert!(against_noisy.barycenter_drift.is_some_and(|d| d > 0.0));
    assert!(against_noisy.max_distance >= against_noisy.mean_distance);

    // Both columns are on screen.
    harness.get_by_label("input");
    harness.get_by_label("clean");
    harness.get_by_label("Mean distance");
    harness.get_by_label("Max distance");
    harness.get_by_label("RMS displacement");
    harness.get_by_label("Barycenter drift");
    harness.get_by_label(&format!("{:.3e}", against_clean.mean_distance));
    harness.step();
}

#[test]
fn undo_restores_the_noisy_mesh_exactly_and_redo_brings_the_result_back() {
    let mut harness = noisy_bunny_faired_from_the_middle();
    let noisy = harness.state().document_mesh().unwrap();
    let clean = harness.state().clean_mesh().unwrap();
    let result = harness.state().faired_positions().unwrap();
    assert_ne!(result.as_ref(), &noisy.positions);

    harness
        .get_by_role_and_label(Role::Button, "Apply result")
        .click();
    settle(&mut harness);
    assert_eq!(
        &harness.state().document_mesh().unwrap().positions,
        result.as_ref()
    );
    let (undo, redo) = harness.state().undo_redo_labels();
    assert!(undo.is_some_and(|l| l.starts_with("Apply result")));
    assert!(redo.is_none());

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    let undone = harness.state().document_mesh().unwrap();
    assert_eq!(
        undone.positions, noisy.positions,
        "undo restores the noisy mesh exactly"
    );
    assert_eq!(undone.triangles, noisy.triangles);
    assert_eq!(
        harness.state().clean_mesh().unwrap().positions,
        clean.positions
    );
    assert!(harness
        .state()
        .undo_redo_labels()
        .1
        .is_some_and(|l| l.starts_with("Apply result")));

    harness.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    settle(&mut harness);
    assert_eq!(
        &harness.state().document_mesh().unwrap().positions,
        result.as_ref()
    );

    // Ctrl+Y redoes too; two undos go back past the noise to the loaded bunny.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut harness);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Y);
    settle(&mut harness);
    assert_eq!(
        &harness.state().document_mesh().unwrap().positions,
        result.as_ref()
    );
    harness.get_by_role_and_label(Role::Button, "Undo").click();
    settle(&mut harness);
    harness.get_by_role_and_label(Role::Button, "Undo").click();
    settle(&mut harness);
    assert_eq!(
        harness.state().document_mesh().unwrap().positions,
        clean.positions
    );
    assert!(harness.state().clean_mesh().is_none());
    assert!(harness.state().undo_redo_labels().0.is_none());
    // The hierarchy is ready again and a result is on record.
    let status = harness.state().status();
    assert!(status.hierarchy_ready && status.faired_serial.is_some());
}

/// "Apply result" makes the result the document, and the view keeps showing exactly that mesh
/// until a setting changes: the applied mesh is not faired again with the same settings, so
/// Export writes the mesh the user applied (it once wrote a mesh faired twice).
#[test]
fn an_applied_result_stays_on_screen_and_is_what_export_writes() {
    let dir = tempfile::tempdir().unwrap();
    let mut harness = noisy_bunny_faired_from_the_middle();
    let result = harness.state().faired_positions().unwrap();
    harness
        .get_by_role_and_label(Role::Button, "Apply result")
        .click();
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.hierarchy_ready, "the applied mesh has its hierarchy");
    assert_eq!(
        status.faired_serial, None,
        "the applied mesh is not faired again"
    );
    assert_eq!(
        &harness.state().document_mesh().unwrap().positions,
        result.as_ref()
    );

    let target = dir.path().join("applied.glb");
    export_by_shortcut(&mut harness, &target);
    let written = fairmesh::io::load(&target).unwrap().mesh;
    assert_eq!(written.positions.len(), result.len());
    let largest_move = written
        .positions
        .iter()
        .zip(result.iter())
        .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0f32, f32::max);
    assert!(
        largest_move == 0.0,
        "the export is the applied mesh (a coordinate differs by {largest_move})"
    );

    // A changed setting fairs the new document again.
    let level = harness.state().status().level;
    harness
        .state_mut()
        .push_command(Command::SetLevel(level + 1));
    settle(&mut harness);
    assert!(harness.state().status().faired_serial.is_some());
}

fn snapshot_options() -> egui_kittest::SnapshotOptions {
    // Software rasterisers differ a little between versions: compare with a tolerance.
    egui_kittest::SnapshotOptions::new()
        .threshold(2.0)
        .max_failed_pixels(2500)
}

fn differing_pixels(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count()
}

/// Mean colour of the pixels in columns `x0..x1` that are not the background.
fn mesh_colour(image: &image::RgbaImage, x0: u32, x1: u32) -> [f64; 3] {
    let background = *image.get_pixel(3, image.height() / 2);
    let (mut sum, mut n) = ([0.0f64; 3], 0.0f64);
    for y in 0..image.height() {
        for x in x0..x1.min(image.width()) {
            let p = image.get_pixel(x, y);
            if p.0[..3] != background.0[..3] {
                for (total, value) in sum.iter_mut().zip(p.0) {
                    *total += value as f64;
                }
                n += 1.0;
            }
        }
    }
    sum.map(|s| s / n.max(1.0))
}

#[test]
fn heat_map_colours_by_distance_and_shows_a_legend() {
    let mut harness = noisy_bunny_faired_from_the_middle();
    let plain = viewport_image(&mut harness);
    assert!(harness.state().heat_map_top().is_none());

    harness.get_by_label("Heat map (H)").click();
    harness.step();
    harness.get_by_label("clean mesh").click();
    settle(&mut harness);
    assert!(harness.state().settings().view.heat_map);
    let top = harness
        .state()
        .heat_map_top()
        .expect("the heat map has a range");
    let (_, against_clean) = harness.state().faired_measures();
    let mut distances = against_clean.unwrap().vertex_distances.as_ref().clone();
    distances.sort_by(f32::total_cmp);
    let percentile = distances[((distances.len() - 1) as f64 * 0.99).round() as usize];
    assert_eq!(
        top, percentile,
        "the colour map spans 0 to the 99th percentile"
    );
    assert!(
        top < *distances.last().unwrap(),
        "outliers lie above the top"
    );
    harness.get_by_label("Distance to the clean mesh (model units)");
    harness.get_by_label("0");
    // The ticks are round numbers below the top, labelled in model units.
    let ticks = fairmesh_editor::render::colormap::legend_ticks(top as f64, 4);
    assert!(ticks.len() >= 2);
    let heat = viewport_image(&mut harness);
    assert!(
        differing_pixels(&plain, &heat) > 20_000,
        "the heat map recolours the mesh"
    );
    // Viridis: dark purple to yellow; the mean of a mostly-near mesh leans blue-green, unlike
    // the plain clay colour (red above blue).
    let [r, _, b] = mesh_colour(&heat, 0, heat.width());
    let [pr, _, pb] = mesh_colour(&plain, 0, plain.width());
    assert!(pr > pb && b > r, "plain {pr}/{pb}, heat {r}/{b}");

    // The input mesh against itself: every distance is 0, and the legend says so instead of
    // drawing a scale up to the least positive float.
    harness.get_by_label("Input mesh").click();
    harness.step();
    harness.get_by_label("input mesh").click();
    settle(&mut harness);
    assert_eq!(harness.state().heat_map_top(), Some(f32::MIN_POSITIVE));
    harness.get_by_label("Distance to the input mesh (model units)");
    harness.get_by_label("0 everywhere: the two meshes are the same");
    assert!(harness.query_by_label("0").is_none(), "no ticks");
    harness.get_by_label("Faired").click();
    harness.step();
    harness.get_by_label("clean mesh").click();
    settle(&mut harness);

    // H switches it off again.
    harness.key_press(egui::Key::H);
    harness.step();
    harness.step();
    assert!(harness.state().heat_map_top().is_none());
    assert!(harness
        .query_by_label("Distance to the clean mesh (model units)")
        .is_none());
}

#[test]
fn before_after_toggle_split_and_side_by_side_render() {
    let mut harness = noisy_bunny_faired_from_the_middle();
    let after = viewport_image(&mut harness);
    harness.key_press(egui::Key::B);
    harness.step();
    assert!(harness.state().showing_before());
    harness.step();
    let before = viewport_image(&mut harness);
    // The noisy mesh and the faired one share the camera: same outline, other facets.
    let changed = differing_pixels(&before, &after);
    assert!(
        changed > 5_000,
        "before and after differ ({changed} pixels)"
    );
    egui_kittest::image_snapshot_options(&before, "compare_before_noisy", &snapshot_options());
    harness.key_press(egui::Key::B);
    harness.step();
    assert!(!harness.state().showing_before());

    harness.get_by_label("Split").click();
    harness.step();
    harness.step();
    let split = viewport_image(&mut harness);
    let w = split.width();
    // Left of the divider is the before image, right of it the after image.
    let left_same = differing_pixels(
        &image::imageops::crop_imm(&split, 0, 0, w / 2 - 4, split.height()).to_image(),
        &image::imageops::crop_imm(&before, 0, 0, w / 2 - 4, split.height()).to_image(),
    );
    let right_same = differing_pixels(
        &image::imageops::crop_imm(&split, w / 2 + 4, 0, w / 2 - 4, split.height()).to_image(),
        &image::imageops::crop_imm(&after, w / 2 + 4, 0, w / 2 - 4, split.height()).to_image(),
    );
    assert!(
        left_same < 2_000 && right_same < 2_000,
        "{left_same} {right_same}"
    );
    egui_kittest::image_snapshot_options(&split, "compare_split", &snapshot_options());

    // Drag the divider to a third of the view.
    let rect = harness.state().viewport_rect().unwrap();
    let camera = *harness.state().camera();
    let start = rect.center();
    let target_x = rect.left() + rect.width() / 3.0;
    drag(&mut harness, start, egui::pos2(target_x, start.y), 4);
    let split_at = harness.state().settings().view.split;
    assert!((split_at - 1.0 / 3.0).abs() < 0.03, "divider at {split_at}");
    assert_eq!(
        harness.state().camera().yaw,
        camera.yaw,
        "dragging the divider does not orbit"
    );

    harness.get_by_label("Side by side").click();
    harness.step();
    harness.step();
    let side = viewport_image(&mut harness);
    let (lw, rw) = (side.width() / 2, side.width());
    let left = mesh_colour(&side, 0, lw);
    let right = mesh_colour(&side, lw, rw);
    assert!(
        left.iter().sum::<f64>() > 30.0 && right.iter().sum::<f64>() > 30.0,
        "both halves show a mesh"
    );
    egui_kittest::image_snapshot_options(&side, "compare_side_by_side", &snapshot_options());
}

/// Picks `method` in the fairing panel's combo box and waits for its result.
fn choose_method(harness: &mut Harness<'_, App>, method: &str) {
    harness.get_by_label("Method").click();
    for _ in 0..3 {
        harness.step();
    }
    harness.get_by_label(method).click();
    settle(harness);
}

#[test]
fn baselines_shrink_where_the_paper_method_does_not() {
    let mut harness = noisy_bunny_faired_from_the_middle();
    let (paper, _) = harness.state().faired_measures();
    let paper = paper.unwrap().volume_change_percent.unwrap();
    let mut shrinkage = Vec::new();
    for method in ["Laplacian", "Taubin λ|μ", "HC Laplacian"] {
        choose_method(&mut harness, method);
        settle(&mut harness);
        let (measures, _) = harness.state().faired_measures();
        let volume = measures.unwrap().volume_change_percent.unwrap();
        shrinkage.push((method, volume));
    }
    println!("volume change: paper {paper:+.4} %, baselines {shrinkage:?}");
    assert!(paper.abs() < 0.1);
    let laplacian = shrinkage[0].1;
    assert!(laplacian < -0.5, "Laplacian shrinks: {laplacian} %");
    assert!(
        laplacian.abs() > 10.0 * paper.abs(),
        "the paper's method keeps the volume far better"
    );
    // Taubin's inflating μ step and HC's correction step exist to undo Laplacian's shrinking: a
    // Taubin without μ or an HC without its correction is a Laplacian smoothing, and shrinks as
    // much.
    for &(method, volume) in &shrinkage[1..] {
        assert!(
            volume.abs() < 0.2 * laplacian.abs(),
            "{method} keeps the volume far better than Laplacian: {volume} % against {laplacian} %"
        );
    }
    // The Lambda slider is there for Laplacian and Taubin.
    choose_method(&mut harness, "Laplacian");
    harness.get_by_role_and_label(Role::Slider, "Lambda");
    harness.get_by_role_and_label(Role::Slider, "Iterations");
}

#[test]
fn exports_the_level_chain_into_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("lod");
    // Tall enough that the whole side panel is on screen.
    let mut harness = harness_sized(bunny(), egui::vec2(1200.0, 1800.0));
    settle(&mut harness);
    let levels = harness.state().status().level_count;
    assert!(levels >= 3);
    harness
        .get_by_role_and_label(Role::TextInput, "Levels folder:")
        .focus();
    harness.step();
    harness
        .get_by_role_and_label(Role::TextInput, "Levels folder:")
        .type_text(&folder.display().to_string());
    harness.step();
    harness.key_press(egui::Key::Escape);
    harness.step();
    assert_eq!(harness.state().levels_folder(), Some(folder.clone()));
    harness
        .get_by_role_and_label(Role::Button, "Export levels")
        .click();
    settle(&mut harness);
    let status = harness.state().status();
    assert!(status.error.is_none(), "{:?}", status.error);
    let message = status.message.unwrap();
    assert!(
        message.contains(&format!("Exported {levels} levels")) && message.contains("lod"),
        "{message}"
    );
    let mut previous_faces = usize::MAX;
    for level in 0..levels {
        let path = folder.join(format!("bunny00_L{level:02}.glb"));
        let mesh = fairmesh::io::load(&path).unwrap().mesh;
        assert!(
            mesh.face_count() < previous_faces,
            "level {level} is coarser"
        );
        previous_faces = mesh.face_count();
    }
}

#[test]
fn shortcuts_export_and_persisted_settings_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    let target = dir.path().join("shortcut.glb");
    export_by_shortcut(&mut harness, &target);
    assert!(
        target.is_file(),
        "Ctrl+E exported: {:?}",
        harness.state().status()
    );

    // F and W work again once no text field has the keyboard; tooltips name the keys.
    harness.key_press(egui::Key::W);
    harness.step();
    assert!(harness.state().settings().view.wireframe);
    harness.get_by_label("Fit view (F)").hover();
    for _ in 0..60 {
        harness.step();
    }
    harness.get_by_label("Fit the mesh into the view (F)");

    // What persists: the settings, including the last folder, survive a JSON round trip.
    let settings = harness.state().settings().clone();
    assert_eq!(settings.files.last_dir.as_deref(), Some(dir.path()));
    let json = serde_json::to_string(&settings).unwrap();
    let back: fairmesh_editor::app::state::Settings = serde_json::from_str(&json).unwrap();
    assert_eq!(back, settings);
}

/// Prints the numbers for every start level (not a pass/fail test):
/// `cargo test --test editor_compare -- --ignored explore_levels --nocapture`.
#[test]
#[ignore]
fn explore_levels() {
    let mut harness = noisy_bunny_faired_from_the_middle();
    let top = harness.state().status().level_count;
    let noise = harness.state().noise_measures().unwrap();
    println!("levels {top}, noise mean {:.3e}", noise.mean_distance);
    for level in 0..top {
        harness.state_mut().push_command(Command::SetLevel(level));
        settle(&mut harness);
        let (d, c) = harness.state().faired_measures();
        let (d, c) = (d.unwrap(), c.unwrap());
        println!(
            "M{level}: clean mean {:.3e} vol {:?}; doc vol {:?}",
            c.mean_distance, c.volume_change_percent, d.volume_change_percent
        );
    }
}
