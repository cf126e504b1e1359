//! Textures stay the right way up in every format: a plane whose image is red in its top half and
//! blue in its bottom half, written here in each format by hand (an OBJ with its `.mtl` and PNG,
//! a GLB with the PNG inside, a PLY with `s t`, `u v` or `texture_u texture_v`), is converted
//! between the formats, and faired, with `io::save_with_source`; every output is read back with
//! this file's own small readers (not the library's) and each texture coordinate looked up in the
//! image *in its file's own convention*: OBJ `vt` and PLY count v from the image's bottom row,
//! glTF `TEXCOORD_0` from its top row. The colour at every vertex must be the one the input's
//! texture shows there: red above the middle of the plane, blue below.
//!
//! What PLY's texture coordinates mean was read off a file trimesh wrote (its `s t` are the
//! numbers its OBJ export writes as `vt`; `python/tests/test_texture_orientation.py` checks the
//! library against trimesh's own reading of each output).

use fairmesh::fairing::{self, BoundaryMode, FairOptions, MethodOptions, Relaxation};
use fairmesh::io::{self, Format, TextureVOrigin};
use fairmesh::TriMesh;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Quads per side of the plane; no vertex row lies on its middle (y = 0.5).
const QUADS: usize = 5;
const RED: [u8; 3] = [255, 0, 0];
const BLUE: [u8; 3] = [0, 0, 255];

/// The plane's vertices (x right, y up, z 0) and triangles; with `jitter`, its inner vertices
/// are moved along the plane (by at most a third of a quad, never across y = 0.5), so that
/// fairing slides them back.
fn plane(jitter: bool) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let n = QUADS + 1;
    let mut positions = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let inner = i > 0 && j > 0 && i < QUADS && j < QUADS;
            let (dx, dy) = if jitter && inner {
                let k = (i * 7 + j * 3) % 5;
                (
                    0.012 * k as f32 - 0.024,
                    0.05 - 0.02 * ((i + 2 * j) % 6) as f32,
                )
            } else {
                (0.0, 0.0)
            };
            positions.push([
                i as f32 / QUADS as f32 + dx,
                j as f32 / QUADS as f32 + dy,
                0.0,
            ]);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..QUADS {
        for i in 0..QUADS {
            let a = (j * n + i) as u32;
            let (b, c, d) = (a + 1, a + 1 + n as u32, a + n as u32);
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    (positions, triangles)
}

/// The texture coordinate of a point of the plane, in OBJ's convention (v from the bottom row):
/// the plane's top row (y = 1) maps to the image's top row.
fn obj_uv(p: [f32; 3]) -> [f32; 2] {
    [p[0], p[1]]
}

/// The image: 16 × 16, its top 8 rows red, its bottom 8 blue.
fn image_png() -> Vec<u8> {
    let image = image::RgbImage::from_fn(16, 16, |_, y| image::Rgb(if y < 8 { RED } else { BLUE }));
    let mut png = Vec::new();
    image::DynamicImage::ImageRgb8(image)
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

/// The colour the image has at `uv`, read in the convention `origin` (the pixel it falls in,
/// clamped to the image).
fn colour_at(uv: [f32; 2], origin: TextureVOrigin) -> [u8; 3] {
    let image = image::load_from_memory(&image_png()).unwrap().to_rgb8();
    let (w, h) = (image.width() as f32, image.height() as f32);
    let from_top = match origin {
        TextureVOrigin::Top => uv[1],
        TextureVOrigin::Bottom => 1.0 - uv[1],
    };
    let x = (uv[0] * w).floor().clamp(0.0, w - 1.0) as u32;
    let y = (from_top * h).floor().clamp(0.0, h - 1.0) as u32;
    image.get_pixel(x, y).0
}

/// Where each format counts v from, as its specification and its writers have it (this file's
/// own table, so that the library's is checked, not used).
fn v_origin(format: Format) -> TextureVOrigin {
    match format {
        Format::Obj | Format::Ply => TextureVOrigin::Bottom,
        Format::Glb | Format::Gltf => TextureVOrigin::Top,
        other => panic!("{other} holds no texture coordinates"),
    }
}

/// What the input's texture shows at a point of the plane: red above its middle, blue below.
fn colour_of_point(p: [f32; 3]) -> [u8; 3] {
    if p[1] > 0.5 {
        RED
    } else {
        BLUE
    }
}

// ---------------------------------------------------------------------------------------------
// The inputs, written by hand.

/// `plane.obj` with `plane.mtl` and `plane.png` in `dir`.
fn write_obj(dir: &Path, jitter: bool) -> PathBuf {
    let (positions, triangles) = plane(jitter);
    let mut text = String::from("mtllib plane.mtl\no plane\n");
    for p in &positions {
        text += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for p in &positions {
        let [u, v] = obj_uv(*p);
        text += &format!("vt {u} {v}\n");
    }
    text += "usemtl paint\n";
    for t in &triangles {
        let [a, b, c] = t.map(|v| v + 1);
        text += &format!("f {a}/{a} {b}/{b} {c}/{c}\n");
    }
    std::fs::write(dir.join("plane.obj"), text).unwrap();
    std::fs::write(
        dir.join("plane.mtl"),
        "newmtl paint\nKd 1 1 1\nmap_Kd plane.png\n",
    )
    .unwrap();
    std::fs::write(dir.join("plane.png"), image_png()).unwrap();
    dir.join("plane.obj")
}

/// `plane.ply` (ASCII) in `dir`, its texture coordinates under the names `u_name`, `v_name`.
fn write_ply(dir: &Path, u_name: &str, v_name: &str) -> PathBuf {
    let (positions, triangles) = plane(false);
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nproperty float {u_name}\nproperty float {v_name}\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        positions.len(),
        triangles.len()
    );
    for p in &positions {
        let [u, v] = obj_uv(*p);
        text += &format!("{} {} {} {u} {v}\n", p[0], p[1], p[2]);
    }
    for [a, b, c] in &triangles {
        text += &format!("3 {a} {b} {c}\n");
    }
    let path = dir.join("plane.ply");
    std::fs::write(&path, text).unwrap();
    path
}

/// `plane.glb` in `dir`: one node, its mesh's TEXCOORD_0 in glTF's convention (v from the top
/// row), its material's base colour texture the PNG, stored in the buffer.
fn write_glb(dir: &Path) -> PathBuf {
    let (positions, triangles) = plane(false);
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut add = |bytes: Vec<u8>, bin: &mut Vec<u8>| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend(bytes);
        views.len() - 1
    };
    let floats =
        |values: Vec<f32>| -> Vec<u8> { values.iter().flat_map(|f| f.to_le_bytes()).collect() };
    let position_view = add(
        floats(positions.iter().flatten().copied().collect()),
        &mut bin,
    );
    let uv_view = add(
        floats(
            positions
                .iter()
                .flat_map(|p| {
                    let [u, v] = obj_uv(*p);
                    [u, 1.0 - v]
                })
                .collect(),
        ),
        &mut bin,
    );
    let index_view = add(
        triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect(),
        &mut bin,
    );
    let image_view = add(image_png(), &mut bin);
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let document = json!({
        "asset": {"version": "2.0", "generator": "texture_orientation test"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "plane"}],
        "meshes": [{"name": "plane", "primitives": [{
            "attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"name": "paint",
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}],
        "textures": [{"source": 0}],
        "images": [{"bufferView": image_view, "mimeType": "image/png"}],
        "accessors": [
            {"bufferView": position_view, "componentType": 5126, "count": positions.len(),
             "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": uv_view, "componentType": 5126, "count": positions.len(), "type": "VEC2"},
            {"bufferView": index_view, "componentType": 5125, "count": triangles.len() * 3,
             "type": "SCALAR"}
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}]
    });
    let mut text = serde_json::to_vec(&document).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + text.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((text.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(text);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(bin);
    let path = dir.join("plane.glb");
    std::fs::write(&path, glb).unwrap();
    path
}

// ---------------------------------------------------------------------------------------------
// The outputs, read back here: per face corner, its position and its texture coordinate as the
// file holds it.

type Corner = ([f32; 3], [f32; 2]);

fn read_corners(path: &Path) -> Vec<Corner> {
    match Format::from_path(path).unwrap() {
        Format::Obj => obj_corners(&std::fs::read_to_string(path).unwrap()),
        Format::Ply => ply_corners(&std::fs::read(path).unwrap()),
        Format::Glb | Format::Gltf => gltf_corners(path),
        other => panic!("{other} holds no texture coordinates"),
    }
}

fn numbers(words: std::str::SplitWhitespace<'_>) -> Vec<f32> {
    words.map(|w| w.parse().unwrap()).collect()
}

fn obj_corners(text: &str) -> Vec<Corner> {
    let (mut v, mut vt, mut corners) = (Vec::new(), Vec::new(), Vec::new());
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let n = numbers(words);
                v.push([n[0], n[1], n[2]]);
            }
            Some("vt") => {
                let n = numbers(words);
                vt.push([n[0], n[1]]);
            }
            Some("f") => {
                for corner in words {
                    let mut parts = corner.split('/');
                    let p: usize = parts.next().unwrap().parse().unwrap();
                    let t: usize = parts.next().expect("a corner without vt").parse().unwrap();
                    corners.push((v[p - 1], vt[t - 1]));
                }
            }
            _ => {}
        }
    }
    corners
}

/// A PLY (ASCII, or binary little endian as the library writes it): per vertex its x y z and its
/// texture coordinate (`s t`, `u v` or `texture_u texture_v`).
fn ply_corners(bytes: &[u8]) -> Vec<Corner> {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let binary = header.contains("binary_little_endian");
    let mut count = 0;
    let mut properties: Vec<(String, String)> = Vec::new();
    let mut in_vertex = false;
    for line in header.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["element", name, n] => {
                in_vertex = *name == "vertex";
                if in_vertex {
                    count = n.parse().unwrap();
                }
            }
            ["property", kind, name] if in_vertex => {
                properties.push((kind.to_string(), name.to_string()))
            }
            _ => {}
        }
    }
    let rows: Vec<HashMap<String, f32>> = if binary {
        let mut at = end;
        (0..count)
            .map(|_| {
                let mut row = HashMap::new();
                for (kind, name) in &properties {
                    let size = match kind.as_str() {
                        "float" => 4,
                        "double" => 8,
                        "uchar" => 1,
                        other => panic!("property type {other}"),
                    };
                    let raw = &bytes[at..at + size];
                    let value = match size {
                        4 => f32::from_le_bytes(raw.try_into().unwrap()),
                        8 => f64::from_le_bytes(raw.try_into().unwrap()) as f32,
                        _ => raw[0] as f32,
                    };
                    row.insert(name.clone(), value);
                    at += size;
                }
                row
            })
            .collect()
    } else {
        let body = std::str::from_utf8(&bytes[end..]).unwrap();
        body.lines()
            .take(count)
            .map(|line| {
                let values = numbers(line.split_whitespace());
                (properties.iter().map(|(_, name)| name.clone()))
                    .zip(values)
                    .collect()
            })
            .collect()
    };
    let uv_names = [("s", "t"), ("u", "v"), ("texture_u", "texture_v")];
    let (u, v) = uv_names
        .into_iter()
        .find(|(u, _)| properties.iter().any(|(_, name)| name == u))
        .expect("a PLY without texture coordinates");
    rows.iter()
        .map(|row| ([row["x"], row["y"], row["z"]], [row[u], row[v]]))
        .collect()
}

/// Every primitive's POSITION and TEXCOORD_0 elements (floats; the outputs written here have no
/// node transforms).
fn gltf_corners(path: &Path) -> Vec<Corner> {
    let bytes = std::fs::read(path).unwrap();
    let (json, bin): (Value, Vec<u8>) = if bytes.starts_with(b"glTF") {
        let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let json = serde_json::from_slice(&bytes[20..20 + length]).unwrap();
        (json, bytes[20 + length + 8..].to_vec())
    } else {
        let json: Value = serde_json::from_slice(&bytes).unwrap();
        let uri = json["buffers"][0]["uri"].as_str().unwrap().to_string();
        (json, std::fs::read(path.with_file_name(uri)).unwrap())
    };
    for node in json["nodes"].as_array().unwrap() {
        for key in ["matrix", "translation", "rotation", "scale"] {
            assert!(
                node.get(key).is_none(),
                "{}: a node transform",
                path.display()
            );
        }
    }
    let floats = |accessor: usize, components: usize| -> Vec<Vec<f32>> {
        let a = &json["accessors"][accessor];
        assert_eq!(a["componentType"], 5126);
        let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
            + a["byteOffset"].as_u64().unwrap_or(0) as usize;
        let stride = view["byteStride"]
            .as_u64()
            .map_or(4 * components, |s| s as usize);
        (0..a["count"].as_u64().unwrap() as usize)
            .map(|k| {
                (0..components)
                    .map(|c| {
                        let at = start + k * stride + 4 * c;
                        f32::from_le_bytes(bin[at..at + 4].try_into().unwrap())
                    })
                    .collect()
            })
            .collect()
    };
    let mut corners = Vec::new();
    for mesh in json["meshes"].as_array().unwrap() {
        for primitive in mesh["primitives"].as_array().unwrap() {
            let attributes = &primitive["attributes"];
            let positions = floats(attributes["POSITION"].as_u64().unwrap() as usize, 3);
            let uvs = floats(
                attributes["TEXCOORD_0"]
                    .as_u64()
                    .expect("a primitive without TEXCOORD_0") as usize,
                2,
            );
            for (p, t) in positions.iter().zip(&uvs) {
                corners.push(([p[0], p[1], p[2]], [t[0], t[1]]));
            }
        }
    }
    corners
}

/// Every corner of `path`, looked up in its format's own convention, shows what the input's
/// texture shows at that point, and its texture coordinate is the input's map at that point
/// (within `tolerance`): the texture did not move on the surface.
fn assert_right_way_up(path: &Path, tolerance: f32) {
    let format = Format::from_path(path).unwrap();
    let origin = v_origin(format);
    let corners = read_corners(path);
    assert!(!corners.is_empty(), "{}: no corners", path.display());
    for (p, uv) in corners {
        assert_eq!(
            colour_at(uv, origin),
            colour_of_point(p),
            "{}: the vertex at {p:?} (texture coordinate {uv:?} in {format}) shows the wrong colour",
            path.display()
        );
        let in_obj_terms = match origin {
            TextureVOrigin::Bottom => uv,
            TextureVOrigin::Top => [uv[0], 1.0 - uv[1]],
        };
        let expected = obj_uv(p);
        assert!(
            (in_obj_terms[0] - expected[0]).abs() <= tolerance
                && (in_obj_terms[1] - expected[1]).abs() <= tolerance,
            "{}: the vertex at {p:?} has texture coordinate {uv:?} ({in_obj_terms:?} counted from \
             the bottom row), where the input's texture has {expected:?}",
            path.display()
        );
    }
}

/// `input` loaded and saved as `output` with its mesh unchanged; the save report's warnings.
fn convert(input: &Path, output: &Path) -> Vec<String> {
    let loaded = io::load(input).unwrap();
    io::save_with_source(output, &loaded.mesh, &loaded.source)
        .unwrap()
        .warnings
}

/// The input files written by hand are right by this file's own reading (so that a wrong
/// reading here could not pass the library's outputs).
#[test]
fn the_hand_written_inputs_show_red_above_blue() {
    let dir = tempfile::tempdir().unwrap();
    for path in [
        write_obj(dir.path(), false),
        write_glb(dir.path()),
        write_ply(dir.path(), "s", "t"),
    ] {
        assert_right_way_up(&path, 1e-6);
    }
    // And a texture coordinate read the other way up would show the other colour.
    assert_eq!(colour_at([0.5, 0.9], TextureVOrigin::Bottom), RED);
    assert_eq!(colour_at([0.5, 0.9], TextureVOrigin::Top), BLUE);
}

/// The library says where each format counts v from as the formats do.
#[test]
fn the_library_knows_where_each_format_counts_v_from() {
    for format in [Format::Obj, Format::Ply, Format::Glb, Format::Gltf] {
        assert_eq!(format.texture_v_origin(), v_origin(format), "{format}");
    }
}

#[test]
fn obj_to_glb_to_obj_and_obj_to_gltf_keep_the_texture_the_right_way_up() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_obj(dir.path(), false);
    let glb = dir.path().join("from_obj.glb");
    let gltf = dir.path().join("from_obj.gltf");
    let back = dir.path().join("from_glb.obj");
    convert(&obj, &glb);
    convert(&obj, &gltf);
    convert(&glb, &back);
    // 1 − v rounds once to f32 for v below a half, and once more on the way back.
    for path in [&glb, &gltf, &back] {
        assert_right_way_up(path, 1e-6);
    }
    // The image went along: the GLB's own material, the OBJ's `.mtl`.
    let mtl = std::fs::read_to_string(back.with_extension("mtl")).unwrap();
    assert!(mtl.contains("map_Kd"), "{mtl}");
}

#[test]
fn a_glb_made_elsewhere_converts_to_obj_and_ply_the_right_way_up() {
    let dir = tempfile::tempdir().unwrap();
    let glb = write_glb(dir.path());
    for name in ["from_glb.obj", "from_glb.ply"] {
        let out = dir.path().join(name);
        convert(&glb, &out);
        assert_right_way_up(&out, 1e-6);
    }
}

#[test]
fn ply_converts_to_and_from_obj_and_glb_the_right_way_up() {
    let dir = tempfile::tempdir().unwrap();
    // Each of the names PLY writers use for texture coordinates means the same.
    for (u, v) in [("s", "t"), ("u", "v"), ("texture_u", "texture_v")] {
        let ply = write_ply(dir.path(), u, v);
        for name in ["from_ply.obj", "from_ply.glb", "from_ply.gltf"] {
            let out = dir.path().join(name);
            convert(&ply, &out);
            assert_right_way_up(&out, 1e-6);
        }
    }
    let obj = write_obj(dir.path(), false);
    let glb = write_glb(dir.path());
    for (input, name) in [(&obj, "from_obj.ply"), (&glb, "from_glb_too.ply")] {
        let out = dir.path().join(name);
        convert(input, &out);
        assert_right_way_up(&out, 1e-6);
    }
}

/// `mesh` faired once, every vertex relaxed along the surface, the plane's edges held (so that
/// every vertex stays on the plane, where the input's texture map is known exactly).
fn faired(loaded: &io::Loaded) -> TriMesh {
    let mut mesh = loaded.mesh.clone();
    let options = FairOptions::default()
        .with_rounds(1)
        .with_creases(None)
        .with_relaxation(Relaxation::Everywhere)
        .with_boundary(BoundaryMode::Fixed);
    fairing::fair(
        &mut mesh,
        &loaded.topology,
        &MethodOptions::Constrained(options),
    );
    mesh
}

/// Fairing slides the jittered inner vertices back along the plane; in every output format the
/// texture coordinates follow, so that each vertex shows what the texture held where it went.
#[test]
fn a_faired_plane_keeps_its_texture_in_place_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_obj(dir.path(), true);
    let loaded = io::load(&obj).unwrap();
    let mesh = faired(&loaded);
    let slide = fairmesh::metrics::tangential_slide(&loaded.mesh.positions, &mesh);
    assert!(slide > 0.01, "the vertices hardly slid: {slide}");
    for name in ["faired.obj", "faired.glb", "faired.gltf", "faired.ply"] {
        let out = dir.path().join(name);
        let report = io::save_with_source(&out, &mesh, &loaded.source).unwrap();
        assert!(report.texture_coordinates_follow, "{name}");
        assert_right_way_up(&out, 1e-4);
    }
    // And from the GLB on to OBJ again, faired once more: still in place.
    let glb = io::load(dir.path().join("faired.glb")).unwrap();
    let out = dir.path().join("faired_twice.obj");
    let again = faired(&glb);
    assert_ne!(
        again.positions, glb.mesh.positions,
        "the second fairing moved nothing"
    );
    io::save_with_source(&out, &again, &glb.source).unwrap();
    assert_right_way_up(&out, 1e-4);
}

/// `scene.glb` in `dir`: the plane's GLB with a second node, moved aside, whose mesh (over the
/// same accessors) has no material.
fn write_two_part_scene(dir: &Path) -> PathBuf {
    let glb = write_glb(dir);
    let bytes = std::fs::read(&glb).unwrap();
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut json: Value = serde_json::from_slice(&bytes[20..20 + length]).unwrap();
    json["meshes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"name": "bare", "primitives": [{
            "attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2}]}));
    json["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"mesh": 1, "name": "box", "translation": [0.0, 0.0, 2.0]}));
    json["scenes"][0]["nodes"] = json!([0, 1]);
    let mut text = serde_json::to_vec(&json).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let bin = bytes[20 + length..].to_vec();
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + text.len() + bin.len()) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(text);
    out.extend(bin);
    let scene = dir.join("scene.glb");
    std::fs::write(&scene, out).unwrap();
    scene
}

/// The OBJ at `obj` states a material before every group's faces, and the material-less part's
/// is glTF's default in the `.mtl`: white, fully metallic and rough, with no texture; the
/// textured part's has its texture.
fn assert_every_part_states_its_material(obj: &Path) {
    let text = std::fs::read_to_string(obj).unwrap();
    let mut materials_of_groups: Vec<(String, Option<String>)> = Vec::new();
    for line in text.lines() {
        if let Some(group) = line.strip_prefix("g ") {
            materials_of_groups.push((group.to_string(), None));
        } else if let Some(name) = line.strip_prefix("usemtl ") {
            if let Some(last) = materials_of_groups.last_mut() {
                last.1 = Some(name.to_string());
            }
        } else if line.starts_with("f ") {
            assert!(
                materials_of_groups.last().is_some_and(|(_, m)| m.is_some()),
                "faces before their group's usemtl:\n{text}"
            );
        }
    }
    assert_eq!(materials_of_groups.len(), 2, "{text}");
    let plane_material = materials_of_groups[0].1.clone().unwrap();
    let box_material = materials_of_groups[1].1.clone().unwrap();
    assert_ne!(plane_material, box_material);
    let mtl = std::fs::read_to_string(obj.with_extension("mtl")).unwrap();
    let entry = |name: &str| -> Vec<String> {
        let start = mtl
            .find(&format!("newmtl {name}\n"))
            .unwrap_or_else(|| panic!("no {name} in\n{mtl}"));
        mtl[start..]
            .lines()
            .skip(1)
            .take_while(|l| !l.starts_with("newmtl"))
            .map(str::to_string)
            .filter(|l| !l.is_empty())
            .collect()
    };
    let plain = entry(&box_material);
    assert_eq!(plain, ["Kd 1 1 1", "d 1", "Pm 1", "Pr 1"], "{mtl}");
    assert!(entry(&plane_material)
        .iter()
        .any(|l| l.starts_with("map_Kd")));
}

/// A glTF primitive without a material, after one with a textured material, gets glTF's
/// default material in the OBJ: its own `usemtl`, and a `.mtl` entry that is white, fully
/// metallic and rough, with no texture (before, it took the textured part's `usemtl`).
#[test]
fn a_part_of_a_gltf_scene_without_a_material_gets_one_without_a_texture_in_obj() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_two_part_scene(dir.path());
    let obj = dir.path().join("scene.obj");
    convert(&scene, &obj);
    assert_every_part_states_its_material(&obj);
    assert_right_way_up(&obj, 1e-6);
}

/// The level chain does the same: a coarser level of the two-part scene written as OBJ states
/// every part's material, and its kept vertices' UVs show red above blue in OBJ, GLB and PLY.
#[test]
fn a_coarser_level_states_every_parts_material_and_keeps_its_texture_in_place() {
    use fairmesh::hierarchy::{build_hierarchy, HierarchyOptions};
    let dir = tempfile::tempdir().unwrap();
    let loaded = io::load(write_two_part_scene(dir.path())).unwrap();
    // A small plane: levels down to a few vertices; its edges kept, so that every level lies
    // on the plane, where the input's texture map is known exactly.
    let options = HierarchyOptions::default()
        .with_min_vertices(8)
        .with_keep_boundary(true);
    let hierarchy = build_hierarchy(&loaded.mesh, &options, &mut fairmesh::NoProgress).unwrap();
    assert!(
        hierarchy.coarsest_level() >= 1,
        "the plane has coarser levels"
    );
    let level = hierarchy.coarsest_level().clamp(1, 2);
    let mesh = hierarchy.level_mesh(level);
    assert!(mesh.vertex_count() < loaded.mesh.vertex_count());
    let (vertex_origin, face_origin) = hierarchy.level_origins(level);
    let derivation = io::Derivation {
        base: hierarchy.base_mesh(),
        vertex_origin: &vertex_origin,
        face_origin: &face_origin,
    };
    for name in ["level.obj", "level.glb", "level.ply"] {
        let out = dir.path().join(name);
        let report =
            io::save_derived_with_source(&out, &mesh, &derivation, &loaded.source).unwrap();
        assert!(report.texture_coordinates_follow, "{name}");
        assert_right_way_up(&out, 1e-4);
    }
    assert_every_part_states_its_material(&dir.path().join("level.obj"));
}

/// Vertex colours that are not opaque lose their alpha in OBJ, and the save says so.
#[test]
fn alpha_into_obj_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let (positions, triangles) = plane(false);
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
         property uchar alpha\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        positions.len(),
        triangles.len()
    );
    for (k, p) in positions.iter().enumerate() {
        let alpha = if k % 3 == 0 { 128 } else { 255 };
        text += &format!("{} {} {} 10 20 30 {alpha}\n", p[0], p[1], p[2]);
    }
    for [a, b, c] in &triangles {
        text += &format!("3 {a} {b} {c}\n");
    }
    let ply = dir.path().join("translucent.ply");
    std::fs::write(&ply, &text).unwrap();
    let translucent = positions.len().div_ceil(3);
    let warnings = convert(&ply, &dir.path().join("translucent.obj")).join("\n");
    assert!(
        warnings.contains(&format!("alpha at {translucent} vertices")),
        "{warnings}"
    );
    // Into GLB, the alpha is kept and nothing is said about it.
    let warnings = convert(&ply, &dir.path().join("translucent.glb")).join("\n");
    assert!(!warnings.contains("alpha"), "{warnings}");
    // An opaque file says nothing of alpha.
    let opaque = text.replace(" 128\n", " 255\n");
    std::fs::write(&ply, opaque).unwrap();
    let warnings = convert(&ply, &dir.path().join("opaque.obj")).join("\n");
    assert!(!warnings.contains("alpha"), "{warnings}");
}
