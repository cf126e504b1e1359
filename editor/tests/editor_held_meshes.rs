//! Headless tests of the meshes a viewport keeps on the GPU: switching between the faired
//! result and the input mesh shows buffers already there (nothing is uploaded, the picture is
//! the one before), a held mesh's last image comes back in the frame of the switch while the
//! view is unchanged (nothing drawn), and a new result replaces the held one instead of adding
//! to it.

use egui_kittest::kittest::Queryable;

mod editor_common;
use editor_common::{bunny, drag, harness_for, settle, viewport_image};
use fairmesh_editor::app::{App, Command, Slot};
use fairmesh_editor::render::normals::{shading_normals, SHARP_EDGE_ANGLE};
use fairmesh_editor::render::ImageCounts;
use fairmesh_editor::render::MAX_HELD_MESHES;

type Harness = egui_kittest::Harness<'static, App>;

fn show(harness: &mut Harness, label: &str) {
    harness.get_by_label(label).click();
    settle(harness);
}

fn differing_pixels(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count()
}

fn uploads(harness: &Harness) -> fairmesh_editor::render::UploadCounts {
    harness.state().gpu_uploads(Slot::Main).expect("a renderer")
}

/// The band at the top of the view that holds its caption (points).
const CAPTION_HEIGHT: f32 = 30.0;

fn images(harness: &Harness) -> ImageCounts {
    harness
        .state()
        .image_counts(Slot::Main)
        .expect("a renderer")
}

/// Clicks the toolbar's `label` and runs the one frame that takes the click (and shows the
/// mesh); the view's pixels after that frame alone, and what the renderer did in it and the
/// next. The caption over the view is the next frame's: the first one's was drawn before the
/// click was applied.
fn switch_in_one_frame(harness: &mut Harness, label: &str) -> (image::RgbaImage, ImageCounts) {
    let before = images(harness);
    harness.get_by_label(label).click();
    harness.step();
    let full = harness.render().expect("the wgpu test renderer renders");
    let rect = harness
        .state()
        .viewport_rect()
        .expect("the viewport was drawn");
    let scale = full.width() as f32 / 1200.0;
    let crop = |v: f32| (v * scale).round() as u32;
    let mut image = image::imageops::crop_imm(
        &full,
        crop(rect.min.x),
        crop(rect.min.y),
        crop(rect.width()),
        crop(rect.height()),
    )
    .to_image();
    // The caption over the view: the one of the next frame.
    harness.step();
    let next = viewport_image(harness);
    for y in 0..crop(CAPTION_HEIGHT).min(image.height()) {
        for x in 0..image.width() {
            image.put_pixel(x, y, *next.get_pixel(x, y));
        }
    }
    let after = images(harness);
    let done = ImageCounts {
        drawn: after.drawn - before.drawn,
        parts: after.parts - before.parts,
        restored: after.restored - before.restored,
    };
    (image, done)
}

/// The normals on the GPU are those of the faired result the document holds now (smooth
/// shading's, split where the result has sharp edges: one per draw vertex).
fn gpu_shows_the_newest_result(harness: &Harness) {
    let app = harness.state();
    let positions = app.faired_positions().expect("a result");
    let triangles = app.document_mesh().expect("a document").triangles.clone();
    let (_, expected) = shading_normals(&positions, &triangles, None, SHARP_EDGE_ANGLE);
    let uploaded = app
        .uploaded_normals(Slot::Main)
        .expect("normals on the GPU");
    assert_eq!(uploaded.len(), expected.len());
    let off = uploaded
        .iter()
        .zip(&expected)
        .filter(|(a, b)| (0..3).any(|i| (a[i] - b[i]).abs() > 1e-4))
        .count();
    assert_eq!(off, 0, "normals of another result on the GPU");
}

/// Once the editor has settled, shows the faired mesh, then the input mesh, each drawn whole:
/// both are then held. Their images, in that order.
fn faired_then_input(harness: &mut Harness) -> (image::RgbaImage, image::RgbaImage) {
    editor_common::at_middle_level(harness);
    show(harness, "Faired");
    let faired = viewport_image(harness);
    show(harness, "Input mesh");
    (faired, viewport_image(harness))
}

#[test]
fn switching_back_to_a_held_mesh_uploads_nothing_and_shows_the_same_picture() {
    let mut harness = harness_for(bunny());
    let (faired, input) = faired_then_input(&mut harness);
    assert!(
        differing_pixels(&faired, &input) > 1_000,
        "the input mesh looks different from the faired one"
    );
    let before = uploads(&harness);
    show(&mut harness, "Faired");
    assert_eq!(
        uploads(&harness),
        before,
        "switching back uploaded something"
    );
    let again = viewport_image(&mut harness);
    assert_eq!(
        differing_pixels(&faired, &again),
        0,
        "the faired picture after the switch is the one before it"
    );
    show(&mut harness, "Input mesh");
    assert_eq!(
        uploads(&harness),
        before,
        "switching to the input uploaded something"
    );
    assert_eq!(differing_pixels(&input, &viewport_image(&mut harness)), 0);
    let (held, bytes) = harness.state().held_meshes(Slot::Main).unwrap();
    assert_eq!(held, 2, "the input mesh and the result");
    assert!(bytes > 0);
}

#[test]
fn a_new_result_replaces_the_held_one() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    show(&mut harness, "Faired");
    let first = viewport_image(&mut harness);
    let (held, bytes) = harness.state().held_meshes(Slot::Main).unwrap();
    assert_eq!(held, 2, "the input mesh and the result");
    let before = uploads(&harness);

    // A coarser start level: a new result, written over the old one's buffers.
    let level = harness.state().status().level_count / 2;
    harness.state_mut().push_command(Command::SetLevel(level));
    settle(&mut harness);
    let after = uploads(&harness);
    assert_eq!(
        after.meshes, before.meshes,
        "no new buffers for the new result"
    );
    assert!(
        after.moves > before.moves,
        "the new result's positions written"
    );
    // The bytes may differ by the draw vertices where each result's own sharp edges split its
    // shading (56 bytes each; the two results here differ by one).
    let (held_now, bytes_now) = harness.state().held_meshes(Slot::Main).unwrap();
    assert_eq!(held_now, held, "the new result replaced the old one");
    assert!(
        bytes_now.abs_diff(bytes) < bytes / 100,
        "{bytes_now} bytes held, {bytes} before"
    );
    gpu_shows_the_newest_result(&harness);
    let second = viewport_image(&mut harness);
    assert!(
        differing_pixels(&first, &second) > 100,
        "the new result is drawn"
    );

    // Held while the input is shown, it is the new result that comes back.
    show(&mut harness, "Input mesh");
    let moved = uploads(&harness);
    show(&mut harness, "Faired");
    assert_eq!(uploads(&harness), moved);
    gpu_shows_the_newest_result(&harness);
    assert_eq!(differing_pixels(&second, &viewport_image(&mut harness)), 0);

    // The level view adds its mesh; a level change replaces it.
    show(&mut harness, "Level mesh");
    let (held, bytes) = harness.state().held_meshes(Slot::Main).unwrap();
    assert_eq!(held, MAX_HELD_MESHES);
    harness
        .state_mut()
        .push_command(Command::SetLevel(level + 1));
    settle(&mut harness);
    let (held_now, bytes_now) = harness.state().held_meshes(Slot::Main).unwrap();
    assert_eq!(held_now, held, "the new level replaced the old one");
    assert!(bytes_now < bytes, "a coarser level takes fewer bytes");
}

#[test]
fn a_held_mesh_comes_back_in_one_frame_while_the_view_is_unchanged() {
    let mut harness = harness_for(bunny());
    let (faired, input) = faired_then_input(&mut harness);
    let uploaded = uploads(&harness);

    // Back to the result: its last image, in the frame of the click, nothing drawn.
    let (image, done) = switch_in_one_frame(&mut harness, "Faired");
    let one_copy = ImageCounts {
        drawn: 0,
        parts: 0,
        restored: 1,
    };
    assert_eq!(done, one_copy, "the kept image shown, nothing drawn");
    assert!(!harness.state().status().view.drawing);
    assert_eq!(differing_pixels(&faired, &image), 0, "the result's picture");
    assert!(!harness.state().status().view.view_behind);
    let (image, done) = switch_in_one_frame(&mut harness, "Input mesh");
    assert_eq!(done, one_copy);
    assert_eq!(differing_pixels(&input, &image), 0, "the input's picture");
    assert_eq!(uploads(&harness), uploaded, "no upload either way");

    // One image per held mesh, the view's size in RGBA.
    let rect = harness.state().viewport_rect().unwrap();
    let (width, height) = (rect.width().round() as u64, rect.height().round() as u64);
    let kept = harness.state().kept_image_bytes(Slot::Main).unwrap();
    assert_eq!(
        kept,
        2 * width * height * 4,
        "two kept images of {width}×{height}"
    );

    // The camera turns: the result's kept image shows the old view, so it is drawn again.
    let centre = rect.center();
    drag(&mut harness, centre, centre + egui::vec2(80.0, 10.0), 4);
    settle(&mut harness);
    let turned_input = viewport_image(&mut harness);
    assert!(
        differing_pixels(&input, &turned_input) > 1_000,
        "the view turned"
    );
    let (_, done) = switch_in_one_frame(&mut harness, "Faired");
    assert_eq!(done.restored, 0, "an image of the old view is never shown");
    settle(&mut harness);
    let turned_faired = viewport_image(&mut harness);
    assert!(differing_pixels(&faired, &turned_faired) > 1_000);
    assert_eq!(images(&harness).restored, 2, "the result was drawn again");

    // The input's kept image is the one drawn after the turn: it comes back.
    let (image, done) = switch_in_one_frame(&mut harness, "Input mesh");
    assert_eq!(done, one_copy);
    assert_eq!(differing_pixels(&turned_input, &image), 0);

    // Another setting that changes the picture (smooth shading to flat): drawn again.
    harness.get_by_label("Flat").click();
    settle(&mut harness);
    let (_, done) = switch_in_one_frame(&mut harness, "Faired");
    assert_eq!(done.restored, 0, "the kept image was smooth-shaded");
    settle(&mut harness);
    assert_ne!(
        differing_pixels(&turned_faired, &viewport_image(&mut harness)),
        0
    );
}

/// The Performance section lists the meshes held on the GPU, which one is shown, their bytes
/// and their kept images' bytes, each explained in its tooltip.
#[test]
fn the_performance_section_lists_the_held_meshes() {
    use fairmesh_editor::app::panels::tips;
    let mut harness = editor_common::harness_sized(bunny(), egui::vec2(1200.0, 1800.0));
    faired_then_input(&mut harness);
    harness.get_by_label("Performance").click();
    settle(&mut harness);
    harness.get_by_label("Input mesh (shown)");
    // The toolbar's button, and the held result.
    assert_eq!(harness.get_all_by_label("Faired").count(), 2);
    let (held, bytes) = harness.state().held_meshes(Slot::Main).unwrap();
    assert_eq!(held, 2);
    let kept = harness.state().kept_image_bytes(Slot::Main).unwrap();
    assert!(kept > 0, "the result's kept image");
    let megabytes = |b: u64| format!("{:.1} MB", b as f64 / 1e6);
    for total in [bytes, kept] {
        let shown = harness.get_all_by_label(&megabytes(total)).count();
        assert!(shown >= 1, "the total {}", megabytes(total));
    }
    for tip in [tips::HELD_MESHES, tips::KEPT_IMAGE] {
        let described = harness
            .query_all_by(move |node| node.description().as_deref() == Some(tip))
            .count();
        assert!(described >= 2, "{tip}");
    }
}
