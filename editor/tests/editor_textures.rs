//! Headless tests of the viewport's texture orientation: a plane whose image is red in its top
//! half and blue in its bottom half, written as an OBJ (`vt` counts v from the image's bottom
//! row) and converted to GLB (`TEXCOORD_0` counts it from the top row), is drawn red above blue
//! in both; exported from the editor as GLB and loaded again, it still is.

mod editor_common;
use editor_common::{export_by_shortcut, harness_for, settle, viewport_image};
use std::path::{Path, PathBuf};

/// Quads per side of the plane (it lies in x, y at z = 0, facing the default camera).
const QUADS: usize = 4;

/// `plane.obj` with `plane.mtl` and `plane.png` in `dir`: the plane's top row (y = 1) has
/// `vt` v = 1, the image's top row.
fn write_plane(dir: &Path) -> PathBuf {
    let n = QUADS + 1;
    let mut text = String::from("mtllib plane.mtl\n");
    let mut uvs = String::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f32 / QUADS as f32, j as f32 / QUADS as f32);
            text += &format!("v {} {} 0\n", x - 0.5, y - 0.5);
            uvs += &format!("vt {x} {y}\n");
        }
    }
    text += &uvs;
    text += "usemtl paint\n";
    for j in 0..QUADS {
        for i in 0..QUADS {
            let a = j * n + i + 1;
            let (b, c, d) = (a + 1, a + 1 + n, a + n);
            text += &format!("f {a}/{a} {b}/{b} {c}/{c}\nf {a}/{a} {c}/{c} {d}/{d}\n");
        }
    }
    std::fs::write(dir.join("plane.obj"), text).unwrap();
    std::fs::write(
        dir.join("plane.mtl"),
        "newmtl paint\nKd 1 1 1\nmap_Kd plane.png\n",
    )
    .unwrap();
    let image = image::RgbImage::from_fn(16, 16, |_, y| {
        image::Rgb(if y < 8 { [255, 0, 0] } else { [0, 0, 255] })
    });
    image.save(dir.join("plane.png")).unwrap();
    dir.join("plane.obj")
}

/// The mean row of the pixels where red clearly leads, and of those where blue does, with how
/// many there are of each.
fn red_and_blue_rows(image: &image::RgbaImage) -> ((f64, usize), (f64, usize)) {
    let mean_row = |pick: &dyn Fn(&image::Rgba<u8>) -> bool| {
        let rows: Vec<u32> = image
            .enumerate_pixels()
            .filter(|(_, _, p)| pick(p))
            .map(|(_, y, _)| y)
            .collect();
        let mean = rows.iter().map(|&y| f64::from(y)).sum::<f64>() / rows.len().max(1) as f64;
        (mean, rows.len())
    };
    let leads = |a: u8, b: u8, c: u8| a as i32 > b as i32 + 60 && a as i32 > c as i32 + 60;
    (
        mean_row(&|p| leads(p[0], p[1], p[2])),
        mean_row(&|p| leads(p[2], p[0], p[1])),
    )
}

/// The viewport shows `path`'s plane red above blue.
fn assert_red_above_blue(image: &image::RgbaImage, what: &str) {
    let ((red_row, reds), (blue_row, blues)) = red_and_blue_rows(image);
    assert!(
        reds > 2000 && blues > 2000,
        "{what}: {reds} red and {blues} blue pixels"
    );
    assert!(
        red_row < blue_row,
        "{what}: red is drawn below blue (mean rows {red_row:.0} and {blue_row:.0})"
    );
}

fn snapshot(image: &image::RgbaImage, name: &str) {
    egui_kittest::image_snapshot_options(
        image,
        name,
        &egui_kittest::SnapshotOptions::new()
            .threshold(2.0)
            .max_failed_pixels(2500),
    );
}

#[test]
fn an_obj_plane_is_drawn_red_above_blue_and_so_is_its_glb() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_plane(dir.path());
    let mut harness = harness_for(obj.clone());
    settle(&mut harness);
    let image = viewport_image(&mut harness);
    assert_red_above_blue(&image, "plane.obj");
    snapshot(&image, "viewport_plane_obj_red_above_blue");

    // The same plane as GLB, its TEXCOORD_0 counted from the image's top row.
    let loaded = fairmesh::io::load(&obj).unwrap();
    let glb = dir.path().join("plane.glb");
    fairmesh::io::save_with_source(&glb, &loaded.mesh, &loaded.source).unwrap();
    let mut harness = harness_for(glb);
    settle(&mut harness);
    assert_red_above_blue(&viewport_image(&mut harness), "plane.glb");
}

#[test]
fn the_editors_export_to_glb_keeps_the_plane_red_above_blue() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_plane(dir.path());
    let mut harness = harness_for(obj);
    settle(&mut harness);
    let target = dir.path().join("exported.glb");
    export_by_shortcut(&mut harness, &target);
    let status = harness.state().status();
    assert!(status.error.is_none(), "{:?}", status.error);
    assert!(target.is_file(), "{:?}", status.message);

    let mut harness = harness_for(target);
    settle(&mut harness);
    assert_red_above_blue(&viewport_image(&mut harness), "exported.glb");
}
