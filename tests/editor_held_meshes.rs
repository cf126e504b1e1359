//! Headless tests of the meshes a viewport keeps on the GPU: switching between the faired
//! result and the input mesh shows buffers already there (nothing is uploaded, the picture is
//! the one before), and a new result replaces the held one instead of adding to it.
#![cfg(feature = "gui")]

use egui_kittest::kittest::Queryable;

mod editor_common;
use editor_common::{bunny, harness_for, settle, viewport_image};
use fairmesh::app::{App, Command, Slot};
use fairmesh::render::normals::vertex_normals;
use fairmesh::render::MAX_HELD_MESHES;

type Harness = egui_kittest::Harness<'static, App>;

fn show(harness: &mut Harness, label: &str) {
    harness.get_by_label(label).click();
    settle(harness);
}

fn differing_pixels(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count()
}

fn uploads(harness: &Harness) -> fairmesh::render::UploadCounts {
    harness.state().gpu_uploads(Slot::Main).expect("a renderer")
}

/// The normals on the GPU are those of the faired result the document holds now.
fn gpu_shows_the_newest_result(harness: &Harness) {
    let app = harness.state();
    let positions = app.faired_positions().expect("a result");
    let triangles = app.document_mesh().expect("a document").triangles.clone();
    let expected = vertex_normals(&positions, &triangles);
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

#[test]
fn switching_back_to_a_held_mesh_uploads_nothing_and_shows_the_same_picture() {
    let mut harness = harness_for(bunny());
    settle(&mut harness);
    show(&mut harness, "Faired");
    let faired = viewport_image(&mut harness);
    show(&mut harness, "Input mesh");
    let input = viewport_image(&mut harness);
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
    assert_eq!(
        harness.state().held_meshes(Slot::Main).unwrap(),
        (held, bytes),
        "the new result replaced the old one"
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
