//! Headless tests of the viewport's colours: a glTF scene's textured ball (base colour texture
//! through its texture coordinates) and painted box (base colour factor), a PLY's vertex
//! colours and an OBJ's material library are drawn in their own colours; "Clay" (C) draws them
//! all in the clay colour again, and back. A JPEG texture is drawn, a cut-off one warns; a
//! texture transform places the texture; a texture seen small reads its mipmaps.

use egui_kittest::kittest::{NodeT, Queryable};

mod editor_common;
use editor_common::{harness_for, settle, viewport_image};
use fairmesh_editor::app::view_panel::{tips, CLAY};
use fairmesh_editor::app::App;

type Harness = egui_kittest::Harness<'static, App>;

fn asset(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the repository holds the crate")
        .join("tests/data/roundtrip")
        .join(name)
}

/// Pixels where blue clearly leads (the checker's blue squares; clay and its lights never).
fn blue_pixels(image: &image::RgbaImage) -> usize {
    image
        .pixels()
        .filter(|p| p[2] as i32 > p[0] as i32 + 40 && p[2] as i32 > p[1] as i32 + 20)
        .count()
}

/// Pixels where red clearly leads (the painted box: base colour factor ≈ 0.9, 0.31, 0.2).
fn red_pixels(image: &image::RgbaImage) -> usize {
    image
        .pixels()
        .filter(|p| p[0] as i32 > p[1] as i32 + 60 && p[0] as i32 > p[2] as i32 + 60)
        .count()
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

/// `name` opened, faired from a middle level (the pictures are of a smoothed result).
fn loaded(name: &str) -> Harness {
    let mut harness = harness_for(asset(name));
    editor_common::at_middle_level(&mut harness);
    harness
}

#[test]
fn a_scene_shows_its_texture_and_base_colours_and_clay_hides_them() {
    let mut harness = loaded("scene.glb");
    let node = harness.get_by_label(CLAY);
    assert_eq!(
        node.accesskit_node().description().as_deref(),
        Some(tips::CLAY)
    );
    assert!(!harness.state().settings().view.clay);
    let coloured = viewport_image(&mut harness);
    let (blue, red) = (blue_pixels(&coloured), red_pixels(&coloured));
    assert!(blue > 1500, "the checker texture on the ball: {blue} px");
    assert!(red > 1500, "the painted box: {red} px");
    snapshot(&coloured, "viewport_scene_textured");

    harness.key_press(egui::Key::C);
    harness.step();
    settle(&mut harness);
    assert!(harness.state().settings().view.clay);
    assert!(harness.state().main_draw_params().unwrap().clay);
    let clay = viewport_image(&mut harness);
    assert_eq!(blue_pixels(&clay), 0, "clay: no texture");
    assert_eq!(red_pixels(&clay), 0, "clay: no base colours");
    snapshot(&clay, "viewport_scene_clay");

    harness.get_by_label(CLAY).click();
    settle(&mut harness);
    assert!(!harness.state().settings().view.clay);
    let again = viewport_image(&mut harness);
    assert!(blue_pixels(&again) > 1500);
}

#[test]
fn a_plys_vertex_colours_are_drawn() {
    let mut harness = loaded("colored.ply");
    let coloured = viewport_image(&mut harness);
    harness.key_press(egui::Key::C);
    harness.step();
    settle(&mut harness);
    let clay = viewport_image(&mut harness);
    // The clay is one warm hue; the vertex colours add others: count the distinct coarse hues.
    let hues = |image: &image::RgbaImage| {
        let mut seen = std::collections::BTreeSet::new();
        for p in image.pixels().filter(|p| p[0].max(p[1]).max(p[2]) > 40) {
            let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
            seen.insert(((r - g).signum(), (g - b).signum(), (r - b).signum()));
        }
        seen.len()
    };
    assert!(
        hues(&coloured) > hues(&clay),
        "the vertex colours add hues: {} against clay's {}",
        hues(&coloured),
        hues(&clay)
    );
    snapshot(&coloured, "viewport_colored_ply");
}

#[test]
fn an_obj_with_a_textured_material_shows_its_texture() {
    let mut harness = loaded("textured.obj");
    let coloured = viewport_image(&mut harness);
    harness.key_press(egui::Key::C);
    harness.step();
    settle(&mut harness);
    let clay = viewport_image(&mut harness);
    let differing = coloured
        .pixels()
        .zip(clay.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        differing > 5000,
        "the texture changes the picture: {differing} px"
    );
    snapshot(&coloured, "viewport_textured_obj");
}

/// scene.gltf (with scene.bin and checker.png) in `folder`, its JSON changed by `edit`.
fn scene_edited(folder: &std::path::Path, edit: impl FnOnce(&mut serde_json::Value)) {
    for file in ["scene.bin", "checker.png"] {
        std::fs::copy(asset(file), folder.join(file)).unwrap();
    }
    let gltf = std::fs::read_to_string(asset("scene.gltf")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&gltf).unwrap();
    edit(&mut json);
    std::fs::write(folder.join("scene.gltf"), json.to_string()).unwrap();
}

/// scene.gltf with its checker texture as a JPEG (written here from checker.png) in a folder of
/// its own; `bytes` turns the JPEG's bytes into those the file gets (a cut-off copy).
fn scene_with_jpeg(folder: &std::path::Path, bytes: impl Fn(Vec<u8>) -> Vec<u8>) {
    let checker = image::open(asset("checker.png"))
        .expect("checker.png")
        .to_rgb8();
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 95)
        .encode_image(&checker)
        .expect("encoded");
    std::fs::write(folder.join("checker.jpg"), bytes(jpeg)).unwrap();
    scene_edited(folder, |json| {
        json["images"][0] = serde_json::json!({ "mimeType": "image/jpeg", "uri": "checker.jpg" });
    });
}

/// The viewport of scene.gltf with the checker's texture placed by `transform`
/// (KHR_texture_transform) and, if given, sampled with `sampler`.
fn scene_placed(
    transform: serde_json::Value,
    sampler: Option<serde_json::Value>,
) -> image::RgbaImage {
    let folder = tempfile::tempdir().unwrap();
    scene_edited(folder.path(), |json| {
        let info = &mut json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"];
        info["extensions"] = serde_json::json!({ "KHR_texture_transform": transform.clone() });
        json["extensionsUsed"] = serde_json::json!(["KHR_texture_transform"]);
        if let Some(sampler) = sampler {
            json["samplers"] = serde_json::json!([sampler]);
            json["textures"][0]["sampler"] = serde_json::json!(0);
        }
    });
    let mut harness = harness_for(folder.path().join("scene.gltf"));
    settle(&mut harness);
    let warnings = harness.state().appearance_warnings().to_vec();
    assert!(
        warnings.is_empty() || transform.get("texCoord").is_some(),
        "{warnings:?}"
    );
    viewport_image(&mut harness)
}

/// Pixels of the ball (blue leads) that differ from the next one to the right by more than 60
/// in all (red, green and blue): the speckle of a texture read finer than the screen's pixels.
fn speckled_pixels(image: &image::RgbaImage) -> usize {
    let blue = |p: &image::Rgba<u8>| p[2] as i32 > p[0] as i32 + 20;
    let mut count = 0;
    for y in 0..image.height() {
        for x in 0..image.width() - 1 {
            let (p, q) = (image.get_pixel(x, y), image.get_pixel(x + 1, y));
            let step: i32 = (0..3)
                .map(|c| (i32::from(p[c]) - i32::from(q[c])).abs())
                .sum();
            if blue(p) && blue(q) && step > 60 {
                count += 1;
            }
        }
    }
    count
}

#[test]
fn a_jpeg_texture_is_drawn_and_a_cut_off_one_leaves_a_warning_and_the_base_colour() {
    let folder = tempfile::tempdir().unwrap();
    scene_with_jpeg(folder.path(), |jpeg| jpeg);
    let mut harness = harness_for(folder.path().join("scene.gltf"));
    settle(&mut harness);
    let coloured = viewport_image(&mut harness);
    assert!(
        blue_pixels(&coloured) > 1500,
        "the JPEG checker on the ball: {} px",
        blue_pixels(&coloured)
    );
    assert!(red_pixels(&coloured) > 1500, "the painted box");
    assert!(harness.state().appearance_warnings().is_empty());

    let cut = tempfile::tempdir().unwrap();
    scene_with_jpeg(cut.path(), |jpeg| jpeg[..jpeg.len() * 2 / 3].to_vec());
    let mut harness = harness_for(cut.path().join("scene.gltf"));
    settle(&mut harness);
    let plain = viewport_image(&mut harness);
    assert_eq!(
        blue_pixels(&plain),
        0,
        "no texture: the base colour (white)"
    );
    assert!(
        red_pixels(&plain) > 1500,
        "the painted box keeps its colour"
    );
    let warnings = harness.state().appearance_warnings().to_vec();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    for named in [
        "scene.gltf",
        "checker.jpg",
        "'checker'",
        "base colour alone",
    ] {
        assert!(warnings[0].contains(named), "{named} in {}", warnings[0]);
    }
    // The Mesh section says it.
    harness.get_by_label(&format!("Warning: {}", warnings[0]));
}

/// KHR_texture_transform places the texture: scaled to nothing and offset into one of the
/// checker's squares, the whole ball takes that square's colour.
#[test]
fn a_texture_transform_places_the_texture() {
    let checker = viewport_image(&mut loaded("scene.gltf"));
    let ball = blue_pixels(&checker);
    // Texel (4, 4) is in a blue square, (12, 4) in a white one (8-texel squares).
    let blue = scene_placed(
        serde_json::json!({"offset": [0.0703125, 0.0703125], "scale": [0.0, 0.0]}),
        None,
    );
    assert!(
        blue_pixels(&blue) > ball * 3 / 2,
        "the ball all blue: {} px against {ball} with the checker",
        blue_pixels(&blue)
    );
    let white = scene_placed(
        serde_json::json!({"offset": [0.1953125, 0.0703125], "scale": [0.0, 0.0]}),
        None,
    );
    assert_eq!(blue_pixels(&white), 0, "the ball all white");
    assert!(red_pixels(&white) > 1500, "the painted box as it was");
    // Over a second set of texture coordinates, which the viewport does not have: the base
    // colour alone (white), and a warning (checked in `scene_placed`).
    let other_set = scene_placed(serde_json::json!({"texCoord": 1}), None);
    assert_eq!(blue_pixels(&other_set), 0, "no texture over TEXCOORD_0");
}

/// A texture seen small reads its mipmaps: the checker repeated 256 times over the ball blends
/// into one light blue, where the full-size texture alone (the sampler's minification filter
/// LINEAR, no mipmaps) speckles with its squares.
#[test]
fn a_minified_texture_reads_its_mipmaps_unless_its_sampler_says_not() {
    let repeated = serde_json::json!({"scale": [256.0, 256.0]});
    let mipmapped = scene_placed(repeated.clone(), None);
    let nearest_level = scene_placed(
        repeated.clone(),
        Some(serde_json::json!({"magFilter": 9729, "minFilter": 9985})),
    );
    let full_size = scene_placed(
        repeated,
        Some(serde_json::json!({"magFilter": 9729, "minFilter": 9729})),
    );
    let (blended, nearest, aliased) = (
        speckled_pixels(&mipmapped),
        speckled_pixels(&nearest_level),
        speckled_pixels(&full_size),
    );
    assert!(
        aliased > 500 && aliased > 10 * blended.max(1) && aliased > 10 * nearest.max(1),
        "speckle: {aliased} px without mipmaps, {blended} with, {nearest} nearest level"
    );
    assert!(blue_pixels(&mipmapped) > 1500, "the ball is light blue");
}
