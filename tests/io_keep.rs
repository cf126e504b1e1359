//! Fairing an artist's file changes its shape and nothing else: real files made by other tools
//! (`tests/data/roundtrip/`, see its README: trimesh, pygltflib, plyfile and a quad-mesh OBJ
//! writer) are faired, written back with `io::save_with_source`, read again, and compared item
//! by item with the input.

use fairmesh::fairing::{self, FairOptions, MethodOptions};
use fairmesh::io::{self, Loaded};
use fairmesh::TriMesh;
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/roundtrip")
        .join(name)
}

/// Load `name` from the round-trip data, fair it and save it back into `out`: the loaded file, the
/// faired mesh and the save report.
fn fair_and_save(name: &str, out: &Path) -> (Loaded, TriMesh, io::SaveReport) {
    let loaded = io::load(data(name)).unwrap();
    let mesh = faired(&loaded);
    let report = io::save_with_source(out, &mesh, &loaded.source).unwrap();
    (loaded, mesh, report)
}

/// The mesh after one round of constrained fairing without creases (the test files are clean:
/// the default would leave them as they are, and would keep the hard-surface block's edges, whose
/// normals these tests want to see turned).
fn faired(loaded: &Loaded) -> TriMesh {
    let mut mesh = loaded.mesh.clone();
    // The relaxation at every vertex, so that on these clean files every vertex slides and every
    // normal turns (the default relaxes only thin triangles on a mesh without noise along its
    // surface): what these tests check is that the rest of the file follows.
    let options = FairOptions::default()
        .with_rounds(1)
        .with_creases(None)
        .with_relaxation(fairing::Relaxation::Everywhere);
    fairing::fair(
        &mut mesh,
        &loaded.topology,
        &MethodOptions::Constrained(options),
    );
    assert_ne!(
        mesh.positions, loaded.mesh.positions,
        "fairing moved nothing"
    );
    mesh
}

// ---------------------------------------------------------------------------------------------
// glTF, read here with serde_json and our own accessor walk (independent of the library).

struct Gltf {
    json: Value,
    buffers: Vec<Vec<u8>>,
}

fn read_gltf(path: &Path) -> Gltf {
    let bytes = std::fs::read(path).unwrap();
    if bytes.starts_with(b"glTF") {
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
        let rest = &bytes[20 + json_len..];
        let bin = if rest.len() >= 8 {
            let len = u32::from_le_bytes(rest[0..4].try_into().unwrap()) as usize;
            assert_eq!(&rest[4..8], b"BIN\0");
            rest[8..8 + len].to_vec()
        } else {
            Vec::new()
        };
        Gltf {
            json,
            buffers: vec![bin],
        }
    } else {
        let json: Value = serde_json::from_slice(&bytes).unwrap();
        let buffers = json["buffers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| {
                let uri = b["uri"].as_str().unwrap().replace("%20", " ");
                std::fs::read(path.parent().unwrap().join(uri)).unwrap()
            })
            .collect();
        Gltf { json, buffers }
    }
}

impl Gltf {
    /// The bytes of each element of accessor `a`.
    fn elements(&self, a: usize) -> Vec<Vec<u8>> {
        let accessor = &self.json["accessors"][a];
        let view = &self.json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
        let size = match accessor["componentType"].as_u64().unwrap() {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            _ => 4,
        };
        let n = match accessor["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT4" => 16,
            other => panic!("type {other}"),
        };
        let stride = view["byteStride"].as_u64().map_or(size * n, |s| s as usize);
        let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
            + accessor["byteOffset"].as_u64().unwrap_or(0) as usize;
        let buffer = &self.buffers[view["buffer"].as_u64().unwrap() as usize];
        (0..accessor["count"].as_u64().unwrap() as usize)
            .map(|k| buffer[start + k * stride..start + k * stride + size * n].to_vec())
            .collect()
    }

    fn floats(&self, a: usize) -> Vec<Vec<f32>> {
        assert_eq!(self.json["accessors"][a]["componentType"], 5126);
        self.elements(a)
            .iter()
            .map(|e| {
                e.chunks(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                    .collect()
            })
            .collect()
    }

    fn indices(&self, a: usize) -> Vec<usize> {
        self.elements(a)
            .iter()
            .map(|e| match e.len() {
                1 => e[0] as usize,
                2 => u16::from_le_bytes([e[0], e[1]]) as usize,
                _ => u32::from_le_bytes(e[..4].try_into().unwrap()) as usize,
            })
            .collect()
    }

    fn primitives(&self) -> Vec<&Value> {
        self.json["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|m| m["primitives"].as_array().unwrap())
            .collect()
    }

    /// Accessors of the attributes that fairing may change: POSITION, NORMAL, TANGENT and the
    /// texture coordinates (TEXCOORD_n, which follow the vertices' slide along the surface).
    fn changing_accessors(&self) -> BTreeSet<usize> {
        self.primitives()
            .iter()
            .flat_map(|p| {
                p["attributes"]
                    .as_object()
                    .unwrap()
                    .iter()
                    .filter(|(name, _)| {
                        ["POSITION", "NORMAL", "TANGENT"].contains(&name.as_str())
                            || name.starts_with("TEXCOORD_")
                    })
                    .filter_map(|(_, a)| a.as_u64())
            })
            .map(|a| a as usize)
            .collect()
    }

    /// `bytes` appended to the first buffer (at a multiple of 4 bytes) as a new buffer view; its
    /// index.
    fn append_view(&mut self, bytes: &[u8]) -> usize {
        let buffer = &mut self.buffers[0];
        while !buffer.len().is_multiple_of(4) {
            buffer.push(0);
        }
        let offset = buffer.len();
        buffer.extend_from_slice(bytes);
        self.json["buffers"][0]["byteLength"] = buffer.len().into();
        let views = self.json["bufferViews"].as_array_mut().unwrap();
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}),
        );
        views.len() - 1
    }

    /// Attribute `name` of the first primitive of the first mesh.
    fn attribute_of_first_mesh(&self, name: &str) -> usize {
        self.json["meshes"][0]["primitives"][0]["attributes"][name]
            .as_u64()
            .unwrap() as usize
    }

    fn attribute(&self, mesh_name: &str, name: &str) -> usize {
        let mesh = self.json["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["name"] == mesh_name)
            .unwrap_or_else(|| panic!("no mesh {mesh_name}"));
        mesh["primitives"][0]["attributes"][name].as_u64().unwrap() as usize
    }
}

/// Everything but buffers, buffer view placement, POSITION bounds and external image URIs is
/// the same JSON; every accessor outside POSITION/NORMAL/TANGENT/TEXCOORD_n has the same bytes; positions
/// moved.
fn assert_only_shape_changed(input: &Gltf, output: &Gltf, what: &str) {
    let (a, b) = (
        input.json.as_object().unwrap(),
        output.json.as_object().unwrap(),
    );
    let skip = ["accessors", "bufferViews", "buffers", "images"];
    let keys_a: Vec<&String> = a.keys().collect();
    let keys_b: Vec<&String> = b.keys().collect();
    assert_eq!(keys_a, keys_b, "{what}: top-level keys");
    for key in a.keys().filter(|k| !skip.contains(&k.as_str())) {
        assert_eq!(a[key], b[key], "{what}: {key}");
    }
    let strip = |v: &Value, keys: &[&str]| {
        let mut v = v.clone();
        for key in keys {
            v.as_object_mut().unwrap().remove(*key);
        }
        v
    };
    let positions: BTreeSet<usize> = input
        .primitives()
        .iter()
        .filter_map(|p| p["attributes"]["POSITION"].as_u64())
        .map(|a| a as usize)
        .collect();
    let changing = input.changing_accessors();
    let accessors = a["accessors"].as_array().unwrap();
    assert_eq!(accessors.len(), b["accessors"].as_array().unwrap().len());
    for (i, accessor) in accessors.iter().enumerate() {
        let keys: &[&str] = if changing.contains(&i) {
            &["min", "max"]
        } else {
            &[]
        };
        assert_eq!(
            strip(accessor, keys),
            strip(&b["accessors"][i], keys),
            "{what}: accessor {i}"
        );
    }
    for (i, view) in a["bufferViews"].as_array().unwrap().iter().enumerate() {
        assert_eq!(
            strip(view, &["buffer", "byteOffset"]),
            strip(&b["bufferViews"][i], &["buffer", "byteOffset"]),
            "{what}: buffer view {i}"
        );
    }
    if let Some(images) = a.get("images") {
        for (i, image) in images.as_array().unwrap().iter().enumerate() {
            // An external image may move into a GLB (a buffer view and a MIME type); an image in
            // a buffer view stays as it was.
            let (keys_a, keys_b): (&[&str], &[&str]) = if image.get("uri").is_some() {
                (&["uri", "mimeType"], &["uri", "bufferView", "mimeType"])
            } else {
                (&[], &[])
            };
            assert_eq!(
                strip(image, keys_a),
                strip(&b["images"][i], keys_b),
                "{what}: image {i}"
            );
        }
    }
    for i in 0..accessors.len() {
        if !changing.contains(&i) {
            assert!(
                input.elements(i) == output.elements(i),
                "{what}: accessor {i} changed"
            );
        }
    }
    for &p in &positions {
        assert!(
            input.elements(p) != output.elements(p),
            "{what}: positions of accessor {p} did not move"
        );
        // The bounds are those of the data.
        let values = output.floats(p);
        for c in 0..3 {
            let lo = values.iter().map(|v| v[c]).fold(f32::INFINITY, f32::min);
            let hi = values
                .iter()
                .map(|v| v[c])
                .fold(f32::NEG_INFINITY, f32::max);
            assert_eq!(b["accessors"][p]["min"][c].as_f64().unwrap() as f32, lo);
            assert_eq!(b["accessors"][p]["max"][c].as_f64().unwrap() as f32, hi);
        }
    }
}

/// Reloading the output gives the faired mesh (up to the round trip through the node
/// transforms, which is exact for untransformed nodes).
fn assert_reloads_as(path: &Path, faired: &TriMesh, tolerance: f32) {
    let reloaded = io::load(path).unwrap().mesh;
    assert_eq!(reloaded.triangles, faired.triangles, "{}", path.display());
    let worst = reloaded
        .positions
        .iter()
        .zip(&faired.positions)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0f32, f32::max);
    assert!(worst <= tolerance, "{}: off by {worst}", path.display());
}

fn validate(files: &[PathBuf]) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    assert!(
        root.join("node_modules/gltf-validator").exists(),
        "node_modules/gltf-validator is missing: run `npm ci` in the repository root"
    );
    let output = std::process::Command::new("node")
        .arg(root.join("tests/gltf_validate.mjs"))
        .args(files)
        .output()
        .expect("node must be installed to validate glTF output");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "validator: {stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(stdout.matches(" 0 errors").count(), files.len(), "{stdout}");
}

#[test]
fn gltf_scenes_keep_everything_but_their_shape() {
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for name in ["scene.glb", "scene.gltf", "morph.glb", "skinned.glb"] {
        let input_path = data(name);
        let loaded = io::load(&input_path).unwrap();
        let mesh = faired(&loaded);
        let stem = name.replace('.', "_");
        for ext in ["glb", "gltf"] {
            let out = dir.path().join(format!("{stem}.{ext}"));
            let report = io::save_with_source(&out, &mesh, &loaded.source).unwrap();
            assert!(report.warnings.is_empty(), "{name}: {:?}", report.warnings);
            let (input, output) = (read_gltf(&input_path), read_gltf(&out));
            assert_only_shape_changed(&input, &output, &format!("{name} -> {ext}"));
            assert_reloads_as(&out, &mesh, 2e-6);
            outputs.push(out);
        }
    }
    // The external texture of scene.gltf is copied beside a .gltf written elsewhere, and into a
    // GLB's binary chunk.
    let texture = std::fs::read(data("checker.png")).unwrap();
    let gltf = read_gltf(&dir.path().join("scene_gltf.gltf"));
    assert_eq!(gltf.json["images"][0]["uri"], "checker.png");
    assert_eq!(
        std::fs::read(dir.path().join("checker.png")).unwrap(),
        texture
    );
    let glb = read_gltf(&dir.path().join("scene_gltf.glb"));
    let image = &glb.json["images"][0];
    assert!(image.get("uri").is_none(), "{image}");
    assert_eq!(image["mimeType"], "image/png");
    let view = &glb.json["bufferViews"][image["bufferView"].as_u64().unwrap() as usize];
    let start = view["byteOffset"].as_u64().unwrap() as usize;
    let length = view["byteLength"].as_u64().unwrap() as usize;
    assert_eq!(glb.buffers[0][start..start + length], texture[..]);
    validate(&outputs);
}

#[test]
fn gltf_hard_edges_stay_flat_and_seams_stay_smooth() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scene.glb");
    fair_and_save("scene.glb", &out);
    let (input, output) = (read_gltf(&data("scene.glb")), read_gltf(&out));

    // The block is flat-shaded (every triangle has its own corners): each corner's normal is its
    // triangle's normal after fairing, as it was before.
    let block = input.json["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["name"] == "block_mesh")
        .unwrap();
    let primitive = &block["primitives"][0];
    let triangles = output.indices(primitive["indices"].as_u64().unwrap() as usize);
    let p = output.floats(output.attribute("block_mesh", "POSITION"));
    let n = output.floats(output.attribute("block_mesh", "NORMAL"));
    let n_before = input.floats(input.attribute("block_mesh", "NORMAL"));
    let mut tilted = 0;
    for t in triangles.chunks(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|v| glam::Vec3::from_slice(&p[v]));
        let face = (b - a).cross(c - a).normalize();
        for &v in t {
            let normal = glam::Vec3::from_slice(&n[v]);
            assert!(normal.dot(face) > 0.99999, "corner {v}: {normal} vs {face}");
            if glam::Vec3::from_slice(&n_before[v]).dot(normal) < 0.99999 {
                tilted += 1;
            }
        }
    }
    assert!(tilted > 0, "no block normal turned");

    // The ball's UV seam splits vertices with one smooth normal: the copies stay equal.
    let ball_p = input.floats(input.attribute("ball_mesh", "POSITION"));
    let ball_n_before = input.floats(input.attribute("ball_mesh", "NORMAL"));
    let ball_n = output.floats(output.attribute("ball_mesh", "NORMAL"));
    let mut seams = 0;
    for i in 0..ball_p.len() {
        for j in i + 1..ball_p.len() {
            if ball_p[i] == ball_p[j] && ball_n_before[i] == ball_n_before[j] {
                seams += 1;
                assert_eq!(ball_n[i], ball_n[j], "seam copies {i} and {j} split");
            }
        }
    }
    assert!(seams > 10, "expected a UV seam, found {seams} copies");
    assert!(ball_n != ball_n_before, "no ball normal turned");
}

#[test]
fn an_unchanged_mesh_writes_every_byte_back() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["textured.obj", "colored.ply", "colored_ascii.ply"] {
        let loaded = io::load(data(name)).unwrap();
        let out = dir.path().join(name);
        io::save_with_source(&out, &loaded.mesh, &loaded.source).unwrap();
        assert!(
            std::fs::read(&out).unwrap() == std::fs::read(data(name)).unwrap(),
            "{name} changed although nothing moved"
        );
    }
    for name in ["scene.glb", "morph.glb", "skinned.glb"] {
        let loaded = io::load(data(name)).unwrap();
        let out = dir.path().join(name);
        io::save_with_source(&out, &loaded.mesh, &loaded.source).unwrap();
        let (input, output) = (read_gltf(&data(name)), read_gltf(&out));
        for a in 0..input.json["accessors"].as_array().unwrap().len() {
            assert!(
                input.elements(a) == output.elements(a),
                "{name}: accessor {a}"
            );
        }
    }
}

#[test]
fn obj_keeps_every_line_but_the_moved_vertices_their_normals_and_texture_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("textured.obj");
    let (_, mesh, report) = fair_and_save("textured.obj", &out);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let before = std::fs::read_to_string(data("textured.obj")).unwrap();
    let after = std::fs::read_to_string(&out).unwrap();
    let (before, after): (Vec<&str>, Vec<&str>) =
        (before.lines().collect(), after.lines().collect());
    assert_eq!(before.len(), after.len());
    let (mut moved, mut turned, mut followed) = (0, 0, 0);
    for (a, b) in before.iter().zip(&after) {
        match a.split_whitespace().next() {
            Some("v") => moved += usize::from(a != b),
            Some("vn") => turned += usize::from(a != b),
            Some("vt") => followed += usize::from(a != b),
            _ => assert_eq!(a, b),
        }
    }
    // The relaxation slides vertices along the surface: their texture coordinates follow.
    assert!(
        moved > 300 && turned > 300 && followed > 300,
        "{moved} v, {turned} vn, {followed} vt changed"
    );
    let quads = after
        .iter()
        .filter(|l| l.starts_with("f ") && l.split_whitespace().count() == 5)
        .count();
    assert_eq!(quads, 384);
    // Positions read back bit for bit.
    assert_reloads_as(&out, &mesh, 0.0);
    // Each vn is still a unit normal close to its quad's corner normal.
    let normals: Vec<glam::Vec3> = after
        .iter()
        .filter(|l| l.starts_with("vn "))
        .map(|l| {
            let v: Vec<f32> = l
                .split_whitespace()
                .skip(1)
                .map(|t| t.parse().unwrap())
                .collect();
            glam::Vec3::from_slice(&v)
        })
        .collect();
    assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-5));
}

/// An OBJ written back into another folder takes its material library and the images it names
/// along (its `mtllib` line stays as it was; without them a viewer shows it untextured). A
/// different file of that name already there is never replaced, and what cannot be copied is
/// named in a warning.
#[test]
fn obj_written_elsewhere_takes_its_material_library_and_images_along() {
    let read = |path: PathBuf| std::fs::read(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("faired.obj");
    let (loaded, mesh, report) = fair_and_save("textured.obj", &out);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    for name in ["textured.mtl", "textured.png"] {
        assert_eq!(read(dir.path().join(name)), read(data(name)), "{name}");
    }
    // Saved there again: the files beside it are the same, so there is nothing to say.
    let report = io::save_with_source(&out, &mesh, &loaded.source).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);

    // A folder that already holds another textured.mtl: it stays, and a warning says so.
    let other = tempfile::tempdir().unwrap();
    std::fs::write(other.path().join("textured.mtl"), "newmtl mine\n").unwrap();
    let report =
        io::save_with_source(other.path().join("faired.obj"), &mesh, &loaded.source).unwrap();
    assert_eq!(read(other.path().join("textured.mtl")), b"newmtl mine\n");
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("textured.mtl") && w.contains("a different file of that name")),
        "{:?}",
        report.warnings
    );
    assert_eq!(
        read(other.path().join("textured.png")),
        read(data("textured.png"))
    );

    // An input whose image is missing: its library is copied, the image named in a warning.
    let input = tempfile::tempdir().unwrap();
    for name in ["textured.obj", "textured.mtl"] {
        std::fs::copy(data(name), input.path().join(name)).unwrap();
    }
    let lonely = io::load(input.path().join("textured.obj")).unwrap();
    let third = tempfile::tempdir().unwrap();
    let report =
        io::save_with_source(third.path().join("t.obj"), &lonely.mesh, &lonely.source).unwrap();
    assert_eq!(
        read(third.path().join("textured.mtl")),
        read(data("textured.mtl"))
    );
    assert!(!third.path().join("textured.png").exists());
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("image textured.png") && w.contains("not beside the input")),
        "{:?}",
        report.warnings
    );
}

/// The vertex property types of a PLY header, in order.
fn ply_vertex_properties(header: &str) -> Vec<(String, String)> {
    let mut in_vertex = false;
    let mut out = Vec::new();
    for line in header.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["element", name, _] => in_vertex = *name == "vertex",
            ["property", kind, name] if in_vertex => out.push((kind.to_string(), name.to_string())),
            _ => {}
        }
    }
    out
}

#[test]
fn ply_keeps_colours_quality_and_face_properties() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["colored.ply", "colored_ascii.ply"] {
        let out = dir.path().join(name);
        let (loaded, mesh, report) = fair_and_save(name, &out);
        assert!(report.warnings.is_empty(), "{:?}", report.warnings);
        assert_reloads_as(&out, &mesh, 0.0);
        let (a, b) = (
            std::fs::read(data(name)).unwrap(),
            std::fs::read(&out).unwrap(),
        );
        let end = |bytes: &[u8]| {
            bytes
                .windows(11)
                .position(|w| w == b"end_header\n")
                .unwrap()
                + 11
        };
        assert_eq!(a[..end(&a)], b[..end(&b)], "{name}: header");
        let header = String::from_utf8_lossy(&a[..end(&a)]).into_owned();
        let properties = ply_vertex_properties(&header);
        let xyz: Vec<usize> = (0..properties.len())
            .filter(|&p| ["x", "y", "z"].contains(&properties[p].1.as_str()))
            .collect();
        assert_eq!(xyz, vec![0, 1, 2]);
        let vertices = loaded.mesh.positions.len();
        if name.contains("ascii") {
            let (la, lb): (Vec<&[u8]>, Vec<&[u8]>) = (
                a[end(&a)..].split(|&c| c == b'\n').collect(),
                b[end(&b)..].split(|&c| c == b'\n').collect(),
            );
            assert_eq!(la.len(), lb.len());
            for (row, (x, y)) in la.iter().zip(&lb).enumerate() {
                let tx: Vec<&[u8]> = x.split(|&c| c == b' ').filter(|t| !t.is_empty()).collect();
                let ty: Vec<&[u8]> = y.split(|&c| c == b' ').filter(|t| !t.is_empty()).collect();
                if row < vertices {
                    assert_eq!(tx[3..], ty[3..], "{name}: vertex {row}");
                } else {
                    assert_eq!(x, y, "{name}: row {row}");
                }
            }
        } else {
            let size = |kind: &str| match kind {
                "uchar" | "char" => 1,
                "short" | "ushort" => 2,
                "double" => 8,
                _ => 4,
            };
            let stride: usize = properties.iter().map(|(k, _)| size(k)).sum();
            let (ra, rb) = (&a[end(&a)..], &b[end(&b)..]);
            assert_eq!(ra.len(), rb.len());
            for row in 0..vertices {
                let at = row * stride;
                assert_eq!(
                    ra[at + 12..at + stride],
                    rb[at + 12..at + stride],
                    "{name}: vertex {row}"
                );
            }
            assert_eq!(
                ra[vertices * stride..],
                rb[vertices * stride..],
                "{name}: faces"
            );
        }
    }
}

#[test]
fn other_formats_and_other_connectivity_say_what_is_not_kept() {
    let dir = tempfile::tempdir().unwrap();
    let scene = io::load(data("scene.glb")).unwrap();
    let report =
        io::save_with_source(dir.path().join("scene.stl"), &scene.mesh, &scene.source).unwrap();
    let text = report.warnings.join("\n");
    for item in [
        "'root'",
        "'ball'",
        "'block'",
        "2 materials ('checker', 'paint')",
        "1 texture (",
        "normals",
        "UVs (TEXCOORD_0)",
        "vertex colours (COLOR_0)",
    ] {
        assert!(text.contains(item), "{item} not named in: {text}");
    }
    assert!(text.contains("as a bare STL mesh"), "{text}");

    let obj = io::load(data("textured.obj")).unwrap();
    let report = io::save_with_source(dir.path().join("t.ply"), &obj.mesh, &obj.source).unwrap();
    let text = report.warnings.join("\n");
    for item in [
        "the UV seams at",
        "checker",
        "paint",
        "quads",
        "smoothing groups",
    ] {
        assert!(text.contains(item), "{item} not named in: {text}");
    }

    // A mesh with other connectivity (a subdivided copy) is never written into the source.
    let finer = fairmesh::mesh::subdivide_loop(&obj.mesh);
    let out = dir.path().join("finer.obj");
    let report = io::save_with_source(&out, &finer, &obj.source).unwrap();
    assert!(
        report
            .warnings
            .join("\n")
            .contains("no longer has its connectivity"),
        "{:?}",
        report.warnings
    );
    assert_eq!(
        io::load(&out).unwrap().mesh.triangles.len(),
        finer.triangles.len()
    );

    // An OBJ whose only extras are things it cannot carry (texture coordinates no face uses,
    // statements fairmesh does not read) is written as a bare mesh, and the warning says so in
    // words (it once read "with its ;") and names those statements (once silently dropped).
    let unused_uvs = dir.path().join("unused_uvs.obj");
    std::fs::write(
        &unused_uvs,
        "# a comment\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvp 0.5\nvp 0.7\n\
         cstype bspline\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let obj = io::load(&unused_uvs).unwrap();
    for name in ["u.glb", "u.gltf"] {
        let report = io::save_with_source(dir.path().join(name), &obj.mesh, &obj.source).unwrap();
        let text = report.warnings.join("\n");
        assert!(
            text.contains("texture coordinates (2 vt)"),
            "{name}: {text}"
        );
        assert!(
            text.contains("3 statements fairmesh does not read (vp, cstype)"),
            "{name}: {text}"
        );
        assert!(text.contains("written as a bare"), "{name}: {text}");
        assert!(!text.contains("with its ;"), "{name}: {text}");
    }

    // A bare mesh has nothing to lose.
    let bare = io::load(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/elephant.obj"))
        .unwrap();
    let report = io::save_with_source(dir.path().join("e.glb"), &bare.mesh, &bare.source).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
}

#[test]
fn a_mesh_placed_twice_is_written_from_its_first_placement_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    // scene.gltf with a second node placing the ball mesh elsewhere.
    let mut json: Value =
        serde_json::from_slice(&std::fs::read(data("scene.gltf")).unwrap()).unwrap();
    let nodes = json["nodes"].as_array_mut().unwrap();
    nodes.push(serde_json::json!({"name": "ball_copy", "mesh": 0, "translation": [3.0, 0.0, 0.0]}));
    let copy = nodes.len() - 1;
    json["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(copy.into());
    let input = dir.path().join("twice.gltf");
    std::fs::write(&input, serde_json::to_vec(&json).unwrap()).unwrap();
    std::fs::copy(data("scene.bin"), dir.path().join("scene.bin")).unwrap();
    std::fs::copy(data("checker.png"), dir.path().join("checker.png")).unwrap();

    let loaded = io::load(&input).unwrap();
    let mesh = faired(&loaded);
    let out = dir.path().join("out.glb");
    let report = io::save_with_source(&out, &mesh, &loaded.source).unwrap();
    let text = report.warnings.join("\n");
    assert!(
        text.contains("'ball_mesh'") && text.contains("'ball_copy'") && text.contains("'ball'"),
        "{text}"
    );
    // A .gltf written beside its input refers to the same image file; nothing is copied.
    let out = dir.path().join("out.gltf");
    io::save_with_source(&out, &mesh, &loaded.source).unwrap();
    assert_eq!(read_gltf(&out).json["images"][0]["uri"], "checker.png");
    assert!(!dir.path().join("out_checker.png").exists());
}

// ---------------------------------------------------------------------------------------------
// Saving into another format family: what the target can hold per vertex is carried.

/// The world placement of each node of a glTF whose nodes carry matrices (trimesh writes them).
fn node_worlds(json: &Value) -> Vec<glam::DMat4> {
    let nodes = json["nodes"].as_array().unwrap();
    let local = |n: usize| {
        let m: Vec<f64> = nodes[n]["matrix"]
            .as_array()
            .map(|m| m.iter().map(|v| v.as_f64().unwrap()).collect())
            .unwrap_or_else(|| glam::DMat4::IDENTITY.to_cols_array().to_vec());
        assert!(nodes[n].get("translation").is_none() && nodes[n].get("rotation").is_none());
        glam::DMat4::from_cols_slice(&m)
    };
    let mut world = vec![glam::DMat4::IDENTITY; nodes.len()];
    let mut stack: Vec<(usize, glam::DMat4)> = json["scenes"][0]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| (n.as_u64().unwrap() as usize, glam::DMat4::IDENTITY))
        .collect();
    while let Some((n, parent)) = stack.pop() {
        world[n] = parent * local(n);
        for child in nodes[n]["children"].as_array().into_iter().flatten() {
            stack.push((child.as_u64().unwrap() as usize, world[n]));
        }
    }
    world
}

/// The values of attribute `name` of every vertex of `input` (a glTF read independently), with
/// the vertex's world position.
fn placed_values(input: &Gltf, name: &str) -> Vec<([f32; 3], Vec<f32>)> {
    let worlds = node_worlds(&input.json);
    let mut out = Vec::new();
    for (n, node) in input.json["nodes"].as_array().unwrap().iter().enumerate() {
        let Some(mesh) = node["mesh"].as_u64() else {
            continue;
        };
        for primitive in input.json["meshes"][mesh as usize]["primitives"]
            .as_array()
            .unwrap()
        {
            let Some(values) = primitive["attributes"][name].as_u64() else {
                continue;
            };
            let positions =
                input.floats(primitive["attributes"]["POSITION"].as_u64().unwrap() as usize);
            let values = input.elements(values as usize);
            let component = input.json["accessors"]
                [primitive["attributes"][name].as_u64().unwrap() as usize]["componentType"]
                .as_u64()
                .unwrap();
            for (p, value) in positions.iter().zip(values) {
                let world = worlds[n]
                    .transform_point3(glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
                    .as_vec3()
                    .to_array();
                let value: Vec<f32> = match component {
                    5126 => value
                        .chunks(4)
                        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                        .collect(),
                    5121 => value.iter().map(|&b| b as f32 / 255.0).collect(),
                    5123 => value
                        .chunks(2)
                        .map(|c| u16::from_le_bytes([c[0], c[1]]) as f32 / 65535.0)
                        .collect(),
                    other => panic!("component type {other}"),
                };
                out.push((world, value));
            }
        }
    }
    out
}

/// Whether `value` is (within `tolerance`) one of the values the input has at `position`.
fn is_a_value_at(
    placed: &[([f32; 3], Vec<f32>)],
    position: [f32; 3],
    value: &[f32],
    tolerance: f32,
) -> Option<bool> {
    let near = |a: [f32; 3]| (0..3).all(|c| (a[c] - position[c]).abs() < 1e-5);
    let mut candidates = placed.iter().filter(|(p, _)| near(*p)).peekable();
    candidates.peek()?;
    Some(candidates.any(|(_, v)| v.iter().zip(value).all(|(a, b)| (a - b).abs() <= tolerance)))
}

/// An OBJ read here, with its structure: per face, the `o`, `g` and `usemtl` in force and its
/// corners (v, vt, vn) 0-based.
struct ObjScene {
    vertices: Vec<Vec<f32>>,
    uvs: Vec<[f32; 2]>,
    normals: Vec<[f32; 3]>,
    mtllib: Option<String>,
    faces: Vec<ObjFace>,
}

struct ObjFace {
    object: Option<String>,
    group: Option<String>,
    material: Option<String>,
    corners: Vec<(usize, Option<usize>, Option<usize>)>,
}

fn read_obj_scene(path: &Path) -> ObjScene {
    let text = std::fs::read_to_string(path).unwrap();
    let mut out = ObjScene {
        vertices: Vec::new(),
        uvs: Vec::new(),
        normals: Vec::new(),
        mtllib: None,
        faces: Vec::new(),
    };
    let (mut object, mut group, mut material) = (None, None, None);
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let floats = |words: std::str::SplitWhitespace| -> Vec<f32> {
            words.map(|w| w.parse::<f32>().unwrap()).collect()
        };
        let index = |t: Option<&str>| {
            t.filter(|t| !t.is_empty())
                .map(|t| t.parse::<usize>().unwrap() - 1)
        };
        match words.next() {
            Some("v") => out.vertices.push(floats(words)),
            Some("vt") => {
                let uv = floats(words);
                out.uvs.push([uv[0], uv[1]]);
            }
            Some("vn") => {
                let n = floats(words);
                out.normals.push([n[0], n[1], n[2]]);
            }
            Some("mtllib") => out.mtllib = words.next().map(String::from),
            Some("o") => object = words.next().map(String::from),
            Some("g") => group = words.next().map(String::from),
            Some("usemtl") => material = words.next().map(String::from),
            Some("f") => out.faces.push(ObjFace {
                object: object.clone(),
                group: group.clone(),
                material: material.clone(),
                corners: words
                    .map(|corner| {
                        let mut parts = corner.split('/');
                        let v = index(parts.next()).unwrap();
                        (v, index(parts.next()), index(parts.next()))
                    })
                    .collect(),
            }),
            _ => {}
        }
    }
    out
}

/// An MTL read here: per material, its statements (keyword -> rest of line).
fn read_mtl(path: &Path) -> std::collections::BTreeMap<String, Vec<(String, String)>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut out: std::collections::BTreeMap<String, Vec<(String, String)>> = Default::default();
    let mut current = None;
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with('#') || line.is_empty() {
            continue;
        }
        let (keyword, rest) = line.split_once(' ').unwrap_or((line, ""));
        if keyword == "newmtl" {
            current = Some(rest.to_string());
            out.entry(rest.to_string()).or_default();
        } else if let Some(m) = &current {
            out.get_mut(m)
                .unwrap()
                .push((keyword.to_string(), rest.to_string()));
        }
    }
    out
}

fn mtl_value<'a>(statements: &'a [(String, String)], keyword: &str) -> Option<&'a str> {
    statements
        .iter()
        .find(|(k, _)| k == keyword)
        .map(|(_, v)| v.as_str())
}

/// The output has the faired mesh's surface: the same triangles between the same positions
/// (whatever the order of its vertices and triangles, and its split vertices).
fn assert_same_surface(path: &Path, faired: &TriMesh) {
    let reloaded = io::load(path).unwrap().mesh;
    let index: std::collections::HashMap<[u32; 3], u32> = faired
        .positions
        .iter()
        .enumerate()
        .map(|(v, p)| (p.map(f32::to_bits), v as u32))
        .collect();
    assert_eq!(
        index.len(),
        faired.positions.len(),
        "faired positions repeat"
    );
    let canonical = |t: [u32; 3]| {
        let k = (0..3).min_by_key(|&k| t[k]).unwrap();
        [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
    };
    let mut got: Vec<[u32; 3]> = reloaded
        .triangles
        .iter()
        .map(|t| canonical(t.map(|v| index[&reloaded.positions[v as usize].map(f32::to_bits)])))
        .collect();
    let mut expected: Vec<[u32; 3]> = faired.triangles.iter().map(|&t| canonical(t)).collect();
    got.sort_unstable();
    expected.sort_unstable();
    assert_eq!(got, expected, "{}", path.display());
}

#[test]
fn a_gltf_scene_saved_as_obj_keeps_names_materials_uvs_colours_and_split_normals() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scene.obj");
    let (loaded, mesh, report) = fair_and_save("scene.glb", &out);
    let obj = read_obj_scene(&out);
    assert_eq!(obj.vertices.len(), mesh.vertex_count(), "one v per vertex");
    assert_same_surface(&out, &mesh);

    // Names and materials: node names as `o`, mesh names as `g`, one `usemtl` per primitive.
    let mut parts = BTreeSet::new();
    for face in &obj.faces {
        parts.insert((
            face.object.clone().unwrap(),
            face.group.clone().unwrap(),
            face.material.clone().unwrap(),
        ));
    }
    let expected: BTreeSet<(String, String, String)> = [
        ("ball", "ball_mesh", "checker"),
        ("block", "block_mesh", "paint"),
    ]
    .iter()
    .map(|(a, b, c)| (a.to_string(), b.to_string(), c.to_string()))
    .collect();
    assert_eq!(parts, expected);
    assert_eq!(obj.mtllib.as_deref(), Some("scene.mtl"));
    let mtl = read_mtl(&dir.path().join("scene.mtl"));
    assert_eq!(mtl.keys().collect::<Vec<_>>(), ["checker", "paint"]);
    let kd: Vec<f32> = mtl_value(&mtl["paint"], "Kd")
        .unwrap()
        .split(' ')
        .map(|v| v.parse().unwrap())
        .collect();
    let input = read_gltf(&data("scene.glb"));
    let factor = &input.json["materials"][1]["pbrMetallicRoughness"]["baseColorFactor"];
    for c in 0..3 {
        assert_eq!(kd[c], factor[c].as_f64().unwrap() as f32);
    }
    assert!(mtl_value(&mtl["paint"], "map_Kd").is_none());
    // The GLB's embedded image is written out beside the .mtl, byte for byte.
    let texture = mtl_value(&mtl["checker"], "map_Kd").unwrap();
    assert_eq!(
        std::fs::read(dir.path().join(texture)).unwrap(),
        std::fs::read(data("checker.png")).unwrap()
    );
    // Saved again into that folder: the image there has the same bytes, so it is used, not
    // written again under another name; a different image of that name is never replaced.
    io::save_with_source(dir.path().join("again.obj"), &mesh, &loaded.source).unwrap();
    let again = read_mtl(&dir.path().join("again.mtl"));
    assert_eq!(mtl_value(&again["checker"], "map_Kd"), Some(texture));
    assert!(!dir.path().join(format!("again_{texture}")).exists());
    std::fs::write(dir.path().join(texture), b"another image").unwrap();
    io::save_with_source(dir.path().join("third.obj"), &mesh, &loaded.source).unwrap();
    assert_eq!(
        std::fs::read(dir.path().join(texture)).unwrap(),
        b"another image"
    );
    let third = read_mtl(&dir.path().join("third.mtl"));
    let renamed = format!("third_{texture}");
    assert_eq!(
        mtl_value(&third["checker"], "map_Kd"),
        Some(renamed.as_str())
    );

    // UVs and colours: each corner has the input's UV at its place, in OBJ's convention (v
    // counted from the image's bottom row: 1 − the glTF's); seams stay split. The UVs are read
    // from the mesh as loaded, saved the same way: the faired one's follow the vertices' slide
    // (tests/texture_orientation.rs checks where to).
    let uvs = placed_values(&input, "TEXCOORD_0");
    let colours = placed_values(&input, "COLOR_0");
    let unmoved_path = dir.path().join("unmoved.obj");
    io::save_with_source(&unmoved_path, &loaded.mesh, &loaded.source).unwrap();
    let unmoved = read_obj_scene(&unmoved_path);
    let mut uvs_at: Vec<BTreeSet<[u32; 2]>> = vec![BTreeSet::new(); mesh.vertex_count()];
    let mut checked = 0;
    for face in &unmoved.faces {
        for &(v, t, n) in &face.corners {
            let [u, v_up] = unmoved.uvs[t.unwrap()];
            let uv = [u, (1.0 - f64::from(v_up)) as f32];
            assert!(n.is_some(), "every corner has a normal");
            let before = loaded.mesh.positions[v];
            if face.material.as_deref() == Some("checker") {
                assert_eq!(is_a_value_at(&uvs, before, &uv, 1e-6), Some(true), "{uv:?}");
                uvs_at[v].insert(uv.map(f32::to_bits));
                checked += 1;
            }
        }
    }
    assert!(checked >= 2000, "{checked}");
    let seams = uvs_at.iter().filter(|set| set.len() > 1).count();
    assert!(seams >= 10, "the ball's UV seam is kept split: {seams}");
    for (v, line) in obj.vertices.iter().enumerate() {
        assert_eq!(line.len(), 6);
        assert_eq!(&line[..3], &mesh.positions[v][..], "faired positions");
        match is_a_value_at(&colours, loaded.mesh.positions[v], &line[3..6], 1e-6) {
            Some(ok) => assert!(ok, "vertex {v}: colour {:?}", &line[3..6]),
            None => assert_eq!(&line[3..6], &[1.0, 1.0, 1.0], "vertex {v}"),
        }
    }

    // Normals: the block's hard edges stay split (each corner has its faired face's normal);
    // the ball's seam copies share one smooth normal.
    let mut ball_normals: Vec<BTreeSet<[u32; 3]>> = vec![BTreeSet::new(); mesh.vertex_count()];
    let mut block_corners = 0;
    for face in &obj.faces {
        let [a, b, c] = [0, 1, 2].map(|k| glam::Vec3::from(mesh.positions[face.corners[k].0]));
        let normal_of_face = (b - a).cross(c - a).normalize();
        for &(v, _, n) in &face.corners {
            let normal = glam::Vec3::from(obj.normals[n.unwrap()]);
            assert!((normal.length() - 1.0).abs() < 1e-5);
            if face.object.as_deref() == Some("block") {
                assert!(
                    normal.dot(normal_of_face) > 0.99999,
                    "{normal} vs {normal_of_face}"
                );
                block_corners += 1;
            } else {
                ball_normals[v].insert(normal.to_array().map(f32::to_bits));
            }
        }
    }
    assert_eq!(block_corners, 768 * 3);
    assert!(
        ball_normals.iter().all(|set| set.len() <= 1),
        "a ball seam split"
    );

    // Our reader and the report: what OBJ holds is not named as lost.
    let contents = io::load(&out).unwrap().source.contents().join("; ");
    for item in [
        "object and group names",
        "2 materials (checker, paint)",
        "texture coordinates",
        "normals",
        "vertex colours",
    ] {
        assert!(contents.contains(item), "{item}: {contents}");
    }
    let text = report.warnings.join("\n");
    assert!(
        text.contains(
            "as OBJ with its names, materials, textures, UVs, normals and vertex colours"
        ),
        "{text}"
    );
    assert!(
        text.contains("the node tree's hierarchy and transforms"),
        "{text}"
    );
    for item in [
        "2 materials",
        "1 texture",
        "TEXCOORD_0",
        "COLOR_0",
        "normals;",
    ] {
        assert!(!text.contains(item), "{item} named as lost: {text}");
    }
}

/// Per (group, input position bits) of the input OBJ: the UVs its corners use.
fn obj_uvs_by_group(path: &Path) -> std::collections::HashMap<(String, [u32; 3]), Vec<[f32; 2]>> {
    let obj = read_obj_scene(path);
    let mut out: std::collections::HashMap<(String, [u32; 3]), Vec<[f32; 2]>> = Default::default();
    for face in &obj.faces {
        for &(v, t, _) in &face.corners {
            let p = &obj.vertices[v];
            let key = [p[0], p[1], p[2]].map(f32::to_bits);
            out.entry((face.group.clone().unwrap(), key))
                .or_default()
                .push(obj.uvs[t.unwrap()]);
        }
    }
    out
}

/// `loaded` (textured.obj) saved unmoved as glTF (`extension`) into `folder`: each corner has
/// its group's UV at its place, in glTF's convention (v counted from the image's top row: 1 −
/// the OBJ's). Unmoved, so that the UVs have not followed a slide (tests/texture_orientation.rs
/// checks where they go when they do).
fn assert_uvs_are_the_groups(
    loaded: &Loaded,
    input: &std::collections::HashMap<(String, [u32; 3]), Vec<[f32; 2]>>,
    extension: &std::ffi::OsStr,
    folder: &Path,
) {
    let path = folder.join("unmoved").with_extension(extension);
    io::save_with_source(&path, &loaded.mesh, &loaded.source).unwrap();
    let output = read_gltf(&path);
    let json = &output.json;
    let mut checked = 0;
    for node in json["nodes"].as_array().unwrap() {
        let (Some(group), Some(m)) = (node["name"].as_str(), node["mesh"].as_u64()) else {
            continue;
        };
        for primitive in json["meshes"][m as usize]["primitives"].as_array().unwrap() {
            let attributes = &primitive["attributes"];
            let positions = output.floats(attributes["POSITION"].as_u64().unwrap() as usize);
            let uvs = output.floats(attributes["TEXCOORD_0"].as_u64().unwrap() as usize);
            for k in 0..positions.len() {
                let before = [positions[k][0], positions[k][1], positions[k][2]].map(f32::to_bits);
                let choices = &input[&(group.to_string(), before)];
                let in_obj = [uvs[k][0], (1.0 - f64::from(uvs[k][1])) as f32];
                assert!(
                    choices
                        .iter()
                        .all(|c| (c[0] - in_obj[0]).abs() <= 1e-6 && (c[1] - in_obj[1]).abs() <= 1e-6),
                    "{group} vertex {k}: {:?} ({in_obj:?} from the bottom row) is not the group's UV {choices:?}",
                    uvs[k]
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 400, "every corner of textured.obj: {checked}");
}

#[test]
fn an_obj_saved_as_gltf_keeps_groups_materials_uvs_and_normals() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("textured.glb");
    let (loaded, mesh, report) = fair_and_save("textured.obj", &glb);
    let gltf = dir.path().join("sub/textured.gltf");
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    io::save_with_source(&gltf, &mesh, &loaded.source).unwrap();
    validate(&[glb.clone(), gltf.clone()]);
    let texture = std::fs::read(data("textured.png")).unwrap();
    let input = obj_uvs_by_group(&data("textured.obj"));
    let welded_of: std::collections::HashMap<[u32; 3], usize> = mesh
        .positions
        .iter()
        .enumerate()
        .map(|(v, p)| (p.map(f32::to_bits), v))
        .collect();
    let smooth = {
        let mut sums = vec![glam::Vec3::ZERO; mesh.vertex_count()];
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|v| glam::Vec3::from(mesh.positions[v as usize]));
            for &v in t {
                sums[v as usize] += (b - a).cross(c - a);
            }
        }
        sums.iter().map(|s| s.normalize()).collect::<Vec<_>>()
    };
    for path in [&glb, &gltf] {
        assert_same_surface(path, &mesh);
        let output = read_gltf(path);
        let json = &output.json;
        // The `o` is a node over one node and mesh per `g`; one primitive per material.
        let nodes = json["nodes"].as_array().unwrap();
        let root = json["scenes"][0]["nodes"][0].as_u64().unwrap() as usize;
        assert_eq!(json["scenes"][0]["nodes"].as_array().unwrap().len(), 1);
        assert_eq!(nodes[root]["name"], "quadsphere");
        let children: Vec<&str> = nodes[root]["children"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                nodes[c.as_u64().unwrap() as usize]["name"]
                    .as_str()
                    .unwrap()
            })
            .collect();
        assert_eq!(children, ["px", "nx", "py", "ny", "pz", "nz"]);
        let materials = json["materials"].as_array().unwrap();
        let material_names: Vec<&str> = materials
            .iter()
            .map(|m| m["name"].as_str().unwrap())
            .collect();
        assert_eq!(material_names, ["paint", "checker"]);
        let paint = &materials[0]["pbrMetallicRoughness"];
        assert_eq!(
            paint["baseColorFactor"],
            serde_json::json!([0.8, 0.25, 0.15, 1.0])
        );
        assert!(paint.get("baseColorTexture").is_none());
        let checker = &materials[1]["pbrMetallicRoughness"];
        let t = checker["baseColorTexture"]["index"].as_u64().unwrap() as usize;
        let image = &json["images"][json["textures"][t]["source"].as_u64().unwrap() as usize];
        let image_bytes = match image["uri"].as_str() {
            // A .gltf refers to a copy of the texture beside it.
            Some(uri) => std::fs::read(path.parent().unwrap().join(uri)).unwrap(),
            // A GLB embeds it.
            None => {
                let view = &json["bufferViews"][image["bufferView"].as_u64().unwrap() as usize];
                let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
                let length = view["byteLength"].as_u64().unwrap() as usize;
                output.buffers[0][start..start + length].to_vec()
            }
        };
        assert_eq!(image_bytes, texture, "{}", path.display());
        let mut triangles = 0;
        let mut normal_at: Vec<Option<Vec<f32>>> = vec![None; mesh.vertex_count()];
        for node in &nodes[root]["children"].as_array().unwrap()[..] {
            let node = &nodes[node.as_u64().unwrap() as usize];
            let group = node["name"].as_str().unwrap();
            let m = &json["meshes"][node["mesh"].as_u64().unwrap() as usize];
            assert_eq!(m["name"], group);
            let primitives = m["primitives"].as_array().unwrap();
            assert_eq!(primitives.len(), 1);
            // textured.obj: py and ny use `checker`, the other sides `paint`.
            let expected = if group == "py" || group == "ny" { 1 } else { 0 };
            assert_eq!(primitives[0]["material"], expected, "{group}");
            let attributes = &primitives[0]["attributes"];
            let positions = output.floats(attributes["POSITION"].as_u64().unwrap() as usize);
            let uvs = output.floats(attributes["TEXCOORD_0"].as_u64().unwrap() as usize);
            let normals = output.floats(attributes["NORMAL"].as_u64().unwrap() as usize);
            triangles += output
                .indices(primitives[0]["indices"].as_u64().unwrap() as usize)
                .len()
                / 3;
            for k in 0..positions.len() {
                let v = welded_of
                    [&[positions[k][0], positions[k][1], positions[k][2]].map(f32::to_bits)];
                let before = loaded.mesh.positions[v].map(f32::to_bits);
                assert!(input.contains_key(&(group.to_string(), before)));
                assert!(uvs[k].iter().all(|c| c.is_finite()));
                // Smooth normals stay smooth across the groups and follow the faired shape.
                let normal = glam::Vec3::from_slice(&normals[k]);
                assert!((normal.length() - 1.0).abs() < 1e-5);
                assert!(normal.dot(smooth[v]) > 0.99, "{normal} vs {}", smooth[v]);
                match &normal_at[v] {
                    None => normal_at[v] = Some(normals[k].clone()),
                    Some(n) => assert_eq!(n, &normals[k], "split smooth normal at {v}"),
                }
            }
        }
        assert_eq!(triangles, mesh.face_count());
        assert_uvs_are_the_groups(&loaded, &input, path.extension().unwrap(), dir.path());
    }
    let text = report.warnings.join("\n");
    assert!(
        text.contains("as GLB with its names, materials, textures, UVs and normals"),
        "{text}"
    );
    let lost = text.split("not kept from").nth(1).unwrap();
    assert!(lost.contains("quads"), "{text}");
    for item in [
        "materials",
        "texture coordinates",
        "normals",
        "object and group",
    ] {
        assert!(!lost.contains(item), "{item} named as lost: {text}");
    }
}

/// An OBJ saved as glTF loads back vertex for vertex: the vertex `i` that was saved is the vertex
/// `i` that is loaded (the editor shows, compares and exports by vertex index), even when the
/// faces first use the vertices in another order and a UV seam splits one of them in the file.
#[test]
fn an_obj_saved_as_gltf_loads_back_in_its_own_vertex_order() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("order.obj");
    // A tetrahedron, outward facing; the faces first use its vertices in the order 4 2 3 1, and
    // vertex 4 has two UVs (a seam).
    std::fs::write(
        &input,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
         vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n\
         f 4/4 2/2 3/3\nf 4/1 3/3 1/1\nf 4/4 1/1 2/2\nf 1/1 3/3 2/2\n",
    )
    .unwrap();
    let loaded = io::load(&input).unwrap();
    assert_eq!(loaded.mesh.positions[0], [0.0, 0.0, 0.0], "OBJ order");
    assert_eq!(loaded.mesh.positions[3], [0.0, 0.0, 1.0], "OBJ order");
    // Moved as fairing moves them: every vertex somewhere else.
    let mut moved = loaded.mesh.clone();
    for (v, p) in moved.positions.iter_mut().enumerate() {
        *p = p.map(|c| c * 1.5 + 0.25 * v as f32);
    }
    for name in ["order.glb", "order.gltf"] {
        let out = dir.path().join(name);
        let report = io::save_with_source(&out, &moved, &loaded.source).unwrap();
        let json = read_gltf(&out).json;
        let attributes = &json["meshes"][0]["primitives"][0]["attributes"];
        assert!(
            attributes.get("TEXCOORD_0").is_some(),
            "{name}: the UVs are carried ({:?})",
            report.warnings
        );
        let back = io::load(&out).unwrap().mesh;
        assert_eq!(back.positions, moved.positions, "{name}");
        assert_eq!(back.triangles, moved.triangles, "{name}");
    }
}

#[test]
fn gltf_and_obj_saved_as_ply_keep_colours_uvs_and_normals_and_name_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scene.ply");
    let (loaded, mesh, report) = fair_and_save("scene.glb", &out);
    assert_reloads_as(&out, &mesh, 0.0);
    let reloaded = io::load(&out).unwrap();
    let contents = reloaded.source.contents().join("; ");
    assert!(
        contents.contains("vertex properties nx, ny, nz, s, t, red, green, blue, alpha"),
        "{contents}"
    );
    // The PLY's own values, read here: x y z nx ny nz s t (floats) r g b a (bytes).
    let bytes = std::fs::read(&out).unwrap();
    let body = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let input = read_gltf(&data("scene.glb"));
    let colours = placed_values(&input, "COLOR_0");
    let uvs = placed_values(&input, "TEXCOORD_0");
    let normals = mesh.vertex_normals();
    // The UVs of the mesh as loaded, saved the same way (the faired one's follow the slide):
    // PLY's s t count v from the image's bottom row, 1 − the glTF's.
    let unmoved_path = dir.path().join("unmoved.ply");
    io::save_with_source(&unmoved_path, &loaded.mesh, &loaded.source).unwrap();
    let unmoved = std::fs::read(&unmoved_path).unwrap();
    let (mut coloured, mut textured) = (0, 0);
    for v in 0..mesh.vertex_count() {
        let row = &bytes[body + v * 36..body + (v + 1) * 36];
        let unmoved_row = &unmoved[body + v * 36..body + (v + 1) * 36];
        let st = |k: usize| f32::from_le_bytes(unmoved_row[4 * k..4 * k + 4].try_into().unwrap());
        let f = |k: usize| f32::from_le_bytes(row[4 * k..4 * k + 4].try_into().unwrap());
        assert_eq!([f(0), f(1), f(2)], mesh.positions[v]);
        let n = glam::Vec3::new(f(3), f(4), f(5));
        assert!(
            n.dot(normals[v].normalize().as_vec3()) > 0.9999,
            "recomputed normal"
        );
        let before = loaded.mesh.positions[v];
        let uv = [st(6), (1.0 - f64::from(st(7))) as f32];
        if let Some(ok) = is_a_value_at(&uvs, before, &uv, 1e-6) {
            assert!(ok);
            textured += 1;
        }
        let rgba: Vec<f32> = row[32..36].iter().map(|&c| c as f32 / 255.0).collect();
        if let Some(ok) = is_a_value_at(&colours, before, &rgba, 0.5 / 255.0) {
            assert!(ok, "vertex {v}: {rgba:?}");
            coloured += 1;
        }
    }
    assert!(textured >= 400 && coloured >= 300, "{textured} {coloured}");
    let text = report.warnings.join("\n");
    assert!(
        text.contains("as PLY with its UVs, vertex colours and normals (recomputed)"),
        "{text}"
    );
    for item in [
        "the node tree",
        "2 materials",
        "1 texture",
        "the split normals (hard edges, seams) at ",
    ] {
        assert!(text.contains(item), "{item} not named in: {text}");
    }

    let out = dir.path().join("textured.ply");
    let (_, mesh, report) = fair_and_save("textured.obj", &out);
    assert_reloads_as(&out, &mesh, 0.0);
    let contents = io::load(&out).unwrap().source.contents().join("; ");
    assert!(
        contents.contains("vertex properties nx, ny, nz, s, t"),
        "{contents}"
    );
    let text = report.warnings.join("\n");
    for item in ["materials", "object and group names", "the UV seams at"] {
        assert!(text.contains(item), "{item} not named in: {text}");
    }
}

#[test]
fn a_coloured_ply_saved_as_glb_keeps_its_colours() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("colored.glb");
    let (loaded, mesh, report) = fair_and_save("colored_ascii.ply", &out);
    validate(std::slice::from_ref(&out));
    assert_reloads_as(&out, &mesh, 0.0);
    // The input's rows, read here: x y z red green blue alpha quality.
    let text = std::fs::read_to_string(data("colored_ascii.ply")).unwrap();
    let body = text.split("end_header\n").nth(1).unwrap();
    let mut input: std::collections::HashMap<[u32; 3], [f32; 4]> = Default::default();
    for row in body.lines().take(1536) {
        let v: Vec<f32> = row.split_whitespace().map(|w| w.parse().unwrap()).collect();
        let colour = [v[3], v[4], v[5], v[6]].map(|c| c / 255.0);
        input.insert([v[0], v[1], v[2]].map(f32::to_bits), colour);
    }
    let output = read_gltf(&out);
    let primitive = &output.json["meshes"][0]["primitives"][0];
    let colours = output.floats(primitive["attributes"]["COLOR_0"].as_u64().unwrap() as usize);
    assert_eq!(colours.len(), mesh.vertex_count());
    let mut translucent = 0;
    for (v, colour) in colours.iter().enumerate() {
        let expected = input[&loaded.mesh.positions[v].map(f32::to_bits)];
        for c in 0..4 {
            assert!(
                (colour[c] - expected[c]).abs() < 1e-6,
                "vertex {v}: {colour:?} vs {expected:?}"
            );
        }
        translucent += usize::from(colour[3] < 1.0);
    }
    assert!(translucent > 0, "alpha carried");
    let text = report.warnings.join("\n");
    assert!(text.contains("with its vertex colours"), "{text}");
    // The face colours have no place in glTF: named. The vertex colours are not.
    assert!(text.contains("vertex properties quality;"), "{text}");
    assert!(text.contains("face properties red, green, blue"), "{text}");
}

#[test]
fn a_binary_stl_header_is_written_back_or_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = vec![0u8; 80];
    let title = b"exported by SomeCAD 2024, units mm";
    bytes[..title.len()].copy_from_slice(title);
    let tetrahedron = [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
    let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    bytes.extend_from_slice(&(faces.len() as u32).to_le_bytes());
    for face in faces {
        bytes.extend_from_slice(&[0u8; 12]);
        for v in face {
            for c in tetrahedron[v] {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        bytes.extend_from_slice(&[0, 0]);
    }
    let input = dir.path().join("part.stl");
    std::fs::write(&input, &bytes).unwrap();
    let loaded = io::load(&input).unwrap();
    assert!(
        loaded.source.contents().join(" ").contains("SomeCAD"),
        "{:?}",
        loaded.source.contents()
    );
    let mut moved = loaded.mesh.clone();
    moved.positions[3][2] = 0.5;
    let back = dir.path().join("back.stl");
    let report = io::save_with_source(&back, &moved, &loaded.source).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let written = std::fs::read(&back).unwrap();
    assert_eq!(written[..80], bytes[..80], "header kept");
    assert_eq!(io::load(&back).unwrap().mesh.positions.len(), 4);
    let report = io::save_with_source(dir.path().join("part.obj"), &moved, &loaded.source).unwrap();
    let text = report.warnings.join("\n");
    assert!(
        text.contains("\"exported by SomeCAD 2024, units mm\""),
        "{text}"
    );
}

#[test]
fn a_coarse_level_keeps_names_materials_and_the_kept_vertices_uvs_and_colours() {
    use fairmesh::hierarchy::{build_hierarchy, HierarchyOptions};
    let dir = tempfile::tempdir().unwrap();
    let loaded = io::load(data("scene.glb")).unwrap();
    let hierarchy = build_hierarchy(
        &loaded.mesh,
        &HierarchyOptions::default(),
        &mut fairmesh::NoProgress,
    )
    .unwrap();
    let level = (hierarchy.coarsest_level() / 2).max(1);
    let mesh = hierarchy.level_mesh(level);
    assert!(mesh.vertex_count() < loaded.mesh.vertex_count() / 2);
    let (vertex_origin, face_origin) = hierarchy.level_origins(level);
    let derivation = io::Derivation {
        base: hierarchy.base_mesh(),
        vertex_origin: &vertex_origin,
        face_origin: &face_origin,
    };
    let glb = dir.path().join("level.glb");
    let obj = dir.path().join("level.obj");
    let report = io::save_derived_with_source(&glb, &mesh, &derivation, &loaded.source).unwrap();
    io::save_derived_with_source(&obj, &mesh, &derivation, &loaded.source).unwrap();
    validate(std::slice::from_ref(&glb));
    assert_same_surface(&glb, &mesh);
    assert_same_surface(&obj, &mesh);
    let input = read_gltf(&data("scene.glb"));
    let uvs = placed_values(&input, "TEXCOORD_0");
    let colours = placed_values(&input, "COLOR_0");
    let output = read_gltf(&glb);
    let json = &output.json;
    let names: BTreeSet<&str> = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, BTreeSet::from(["ball", "block"]));
    let mut checked = (0, 0);
    for node in json["nodes"].as_array().unwrap() {
        let m = &json["meshes"][node["mesh"].as_u64().unwrap() as usize];
        let primitive = &m["primitives"][0];
        let material = &json["materials"][primitive["material"].as_u64().unwrap() as usize];
        let attributes = &primitive["attributes"];
        let positions = output.floats(attributes["POSITION"].as_u64().unwrap() as usize);
        let texcoords = output.floats(attributes["TEXCOORD_0"].as_u64().unwrap() as usize);
        let rgba = output.floats(attributes["COLOR_0"].as_u64().unwrap() as usize);
        for k in 0..positions.len() {
            let p = [positions[k][0], positions[k][1], positions[k][2]];
            if node["name"] == "ball" {
                assert_eq!(material["name"], "checker");
                assert!(material["pbrMetallicRoughness"]["baseColorTexture"].is_object());
                assert_eq!(is_a_value_at(&uvs, p, &texcoords[k], 1e-6), Some(true));
                checked.0 += 1;
            } else {
                assert_eq!(material["name"], "paint");
                assert_eq!(is_a_value_at(&colours, p, &rgba[k], 1e-6), Some(true));
                checked.1 += 1;
            }
        }
    }
    assert!(checked.0 > 50 && checked.1 > 50, "{checked:?}");
    let text = report.warnings.join("\n");
    for item in [
        "a coarser level has fewer vertices",
        "with the names, materials, textures, UVs, normals and vertex colours of the kept vertices",
        "recomputed, smooth",
        "the node tree",
    ] {
        assert!(text.contains(item), "{item} not in: {text}");
    }
    let obj_text = std::fs::read_to_string(&obj).unwrap();
    for line in [
        "mtllib level.mtl",
        "o ball",
        "usemtl checker",
        "o block",
        "usemtl paint",
    ] {
        assert!(obj_text.contains(line), "{line}");
    }
}

#[test]
fn non_finite_uvs_normals_and_colours_never_reach_another_format() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("bad.obj");
    std::fs::write(
        &input,
        "v 0 0 0 nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt nan inf\nvt 0.5 0.5\nvn nan 0 0\nvn 0 0 1\n\
         f 1/1/1 3/2/2 2/2/2\nf 1/1/1 2/2/2 4/2/2\nf 1/2/1 4/2/2 3/2/2\nf 2/2/2 3/2/2 4/1/1\n",
    )
    .unwrap();
    let loaded = io::load(&input).unwrap();
    let mut moved = loaded.mesh.clone();
    moved.positions[3][2] = 1.5;
    let out = dir.path().join("bad.glb");
    io::save_with_source(&out, &moved, &loaded.source).unwrap();
    validate(std::slice::from_ref(&out));
    let output = read_gltf(&out);
    for primitive in output.primitives() {
        for (_, a) in primitive["attributes"].as_object().unwrap() {
            for value in output.floats(a.as_u64().unwrap() as usize) {
                assert!(value.iter().all(|c| c.is_finite()), "{value:?}");
            }
        }
    }
}

/// `gltf` written as a GLB file at `path` (its one buffer as the BIN chunk).
fn write_glb(gltf: &Gltf, path: &Path) {
    let mut json = serde_json::to_vec(&gltf.json).unwrap();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = gltf.buffers[0].clone();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    std::fs::write(path, out).unwrap();
}

#[test]
fn tangents_turn_with_their_normals_and_keep_length_and_handedness() {
    // The ball of scene.glb with a TANGENT accessor added: per vertex a direction across its
    // normal (length 1 or 2, handedness +1 or -1 by turns).
    let dir = tempfile::tempdir().unwrap();
    let mut input = read_gltf(&data("scene.glb"));
    let normals = input.floats(input.attribute("ball_mesh", "NORMAL"));
    let mut bytes = Vec::new();
    for (k, n) in normals.iter().enumerate() {
        let n = glam::Vec3::from_slice(n);
        let across = if n.y.abs() < 0.9 {
            glam::Vec3::Y
        } else {
            glam::Vec3::X
        };
        let length = if k % 3 == 0 { 2.0 } else { 1.0 };
        let t = n.cross(across).normalize() * length;
        let w = if k % 2 == 0 { 1.0f32 } else { -1.0 };
        for c in [t.x, t.y, t.z, w] {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    let view = input.append_view(&bytes);
    let json = &mut input.json;
    let accessors = json["accessors"].as_array_mut().unwrap();
    accessors.push(serde_json::json!({
        "bufferView": view, "componentType": 5126, "count": normals.len(), "type": "VEC4"
    }));
    let tangent = accessors.len() - 1;
    for mesh in json["meshes"].as_array_mut().unwrap() {
        if mesh["name"] == "ball_mesh" {
            mesh["primitives"][0]["attributes"]["TANGENT"] = tangent.into();
        }
    }
    let with_tangents = dir.path().join("tangents.glb");
    write_glb(&input, &with_tangents);

    let loaded = io::load(&with_tangents).unwrap();
    let mesh = faired(&loaded);
    let out = dir.path().join("faired.glb");
    io::save_with_source(&out, &mesh, &loaded.source).unwrap();
    let output = read_gltf(&out);
    assert_only_shape_changed(&input, &output, "tangents.glb");
    let before = input.floats(tangent);
    let after = output.floats(output.attribute("ball_mesh", "TANGENT"));
    let turned_normals = output.floats(output.attribute("ball_mesh", "NORMAL"));
    assert_eq!(after.len(), before.len());
    let mut turned = 0;
    for k in 0..before.len() {
        let (t0, t1) = (
            glam::Vec3::from_slice(&before[k][..3]),
            glam::Vec3::from_slice(&after[k][..3]),
        );
        let n = glam::Vec3::from_slice(&turned_normals[k]);
        assert_eq!(
            after[k][3].to_bits(),
            before[k][3].to_bits(),
            "handedness of {k}"
        );
        assert!(
            (t1.length() - t0.length()).abs() < 1e-5,
            "length of {k}: {t0} -> {t1}"
        );
        assert!(
            t1.dot(n).abs() < 1e-4 * t1.length(),
            "tangent {k} {t1} not across normal {n}"
        );
        if t1.normalize().dot(t0.normalize()) < 0.99999 {
            turned += 1;
        }
    }
    assert!(
        turned > before.len() / 4,
        "only {turned} of {} tangents turned",
        before.len()
    );
}

#[test]
fn a_quantized_gltf_is_written_back_in_its_own_integer_types_or_as_floats_past_their_range() {
    // gltfpack's default output (KHR_mesh_quantization): positions as unsigned 16-bit integers on
    // a 14-bit grid over the bounding box (so the grid starts at 0 on every axis), placed by the
    // node's scale and translation; normals as normalized signed bytes.
    let dir = tempfile::tempdir().unwrap();
    let input = read_gltf(&data("quantized.glb"));
    assert_eq!(input.json["extensionsRequired"][0], "KHR_mesh_quantization");
    let position = input.attribute_of_first_mesh("POSITION");
    let normal = input.attribute_of_first_mesh("NORMAL");
    assert_eq!(input.json["accessors"][position]["componentType"], 5123);
    assert_eq!(input.json["accessors"][normal]["componentType"], 5120);
    let node = &input.json["nodes"][0];
    let step = node["scale"][0].as_f64().unwrap();
    let shift: Vec<f64> = (0..3)
        .map(|c| node["translation"][c].as_f64().unwrap())
        .collect();

    // Read through the node: every position is a grid point.
    let loaded = io::load(data("quantized.glb")).unwrap();
    for p in &loaded.mesh.positions {
        for c in 0..3 {
            let q = (p[c] as f64 - shift[c]) / step;
            assert!((q - q.round()).abs() < 1e-3, "{p:?} is off the grid");
        }
    }

    // Faired, then pulled 2 % towards the middle so that every vertex stays on the grid's range:
    // the file keeps its types, each vertex goes to the grid point nearest it, and every normal
    // that turned is still of unit length as a validator measures it.
    let mut mesh = faired(&loaded);
    let (lo, hi) = fairmesh::metrics::bounding_box(&mesh).unwrap();
    let middle = (lo + hi) * 0.5;
    for p in &mut mesh.positions {
        let q = middle + (glam::DVec3::from(p.map(f64::from)) - middle) * 0.98;
        *p = q.as_vec3().to_array();
    }
    let inside = dir.path().join("inside.glb");
    let report = io::save_with_source(&inside, &mesh, &loaded.source).unwrap();
    assert!(
        report.warnings.iter().all(|w| !w.contains("32-bit floats")),
        "{:?}",
        report.warnings
    );
    let output = read_gltf(&inside);
    assert_eq!(
        output.json["extensionsRequired"],
        input.json["extensionsRequired"]
    );
    assert_eq!(output.json["accessors"][position]["componentType"], 5123);
    assert_eq!(output.json["accessors"][normal]["componentType"], 5120);
    assert_reloads_as(&inside, &mesh, (step * 0.5 * 1.001) as f32);
    let unit_bytes = |gltf: &Gltf| -> Vec<[f64; 3]> {
        (gltf.elements(normal).iter())
            .map(|e| [0, 1, 2].map(|c| (e[c] as i8 as f64 / 127.0).max(-1.0)))
            .collect()
    };
    let (before, after) = (unit_bytes(&input), unit_bytes(&output));
    let turned = before.iter().zip(&after).filter(|(a, b)| a != b).count();
    assert!(
        turned > before.len() / 2,
        "{turned} of {} normals turned",
        before.len()
    );
    for (k, n) in after.iter().enumerate() {
        let length = glam::DVec3::from(*n).length();
        // The Khronos validator's tolerance for unit vectors.
        assert!(
            (length - 1.0).abs() < 0.00465,
            "normal {k} {n:?}: length {length}, was {:?}",
            before[k]
        );
    }

    // One vertex pulled below the grid's low corner, where no unsigned integer reaches: the
    // positions are written as floats (in a buffer view of their own), with a warning, and
    // reload where they were put; the normals keep their bytes' type.
    let lowest = (0..mesh.positions.len())
        .min_by(|&a, &b| mesh.positions[a][0].total_cmp(&mesh.positions[b][0]))
        .unwrap();
    mesh.positions[lowest][0] -= 0.1 * (hi - lo).x as f32;
    let outside = dir.path().join("outside.glb");
    let report = io::save_with_source(&outside, &mesh, &loaded.source).unwrap();
    assert!(
        report.warnings.iter().any(|w| w.contains(
            "1 vertex moved past what its quantized positions (unsigned 16-bit integers, \
             KHR_mesh_quantization) can hold, so its positions are written as 32-bit floats"
        )),
        "{:?}",
        report.warnings
    );
    let output = read_gltf(&outside);
    let accessor = &output.json["accessors"][position];
    assert_eq!(accessor["componentType"], 5126);
    assert!(accessor.get("normalized").is_none() && accessor.get("byteOffset").is_none());
    assert_eq!(output.json["accessors"][normal]["componentType"], 5120);
    assert_reloads_as(&outside, &mesh, 1e-5);
    validate(&[inside, outside]);
}

#[test]
fn texture_coordinates_that_follow_past_their_quantized_range_are_written_as_floats() {
    // gltfpack's output of scene.glb: two primitives of one mesh sharing one buffer view of
    // unsigned 16-bit positions, the ball's texture coordinates as normalized unsigned 16-bit
    // integers over their bounding box (KHR_texture_transform scales them back), normals as
    // signed bytes.
    let dir = tempfile::tempdir().unwrap();
    let input = read_gltf(&data("scene_quantized.glb"));
    let uv = input.attribute_of_first_mesh("TEXCOORD_0");
    assert_eq!(input.json["accessors"][uv]["componentType"], 5123);
    assert_eq!(input.json["accessors"][uv]["normalized"], true);
    let decode =
        |e: &[u8]| [0, 1].map(|c| u16::from_le_bytes([e[2 * c], e[2 * c + 1]]) as f32 / 65535.0);
    let before: Vec<[f32; 2]> = input.elements(uv).iter().map(|e| decode(e)).collect();

    let loaded = io::load(data("scene_quantized.glb")).unwrap();
    let mesh = faired(&loaded);
    let out = dir.path().join("faired.glb");
    let report = io::save_with_source(&out, &mesh, &loaded.source).unwrap();
    let output = read_gltf(&out);
    // Where the ball's seam runs along the chart's outline, coordinates walk past the grid's
    // range: stored as integers they would be clamped to [0, 1].
    assert!(
        report.warnings.iter().any(|w| w
            .starts_with(&format!("texture coordinate accessor {uv}: "))
            && w.ends_with("so its texture coordinates are written as 32-bit floats")),
        "{:?}",
        report.warnings
    );
    let after = output.floats(uv);
    let outside = after
        .iter()
        .flatten()
        .filter(|c| !(0.0..=1.0).contains(*c))
        .count();
    assert!(outside > 0, "no coordinate left the grid's range");
    // The rest are the file's own values; many moved.
    let moved = before
        .iter()
        .zip(&after)
        .filter(|(b, a)| b[..] != a[..])
        .count();
    assert!(
        moved > before.len() / 4,
        "{moved} of {} moved",
        before.len()
    );
    for (b, a) in before.iter().zip(&after) {
        assert!(
            (b[0] - a[0]).abs() < 0.05 && (b[1] - a[1]).abs() < 0.05,
            "{b:?} -> {a:?}"
        );
    }
    validate(&[out]);
}

/// A 2 x 2 checker as a lossless WebP (written by Pillow 12).
const WEBP_CHECKER: [u8; 42] = [
    82, 73, 70, 70, 34, 0, 0, 0, 87, 69, 66, 80, 86, 80, 56, 76, 22, 0, 0, 0, 47, 1, 64, 0, 0, 15,
    112, 33, 243, 11, 153, 95, 200, 124, 254, 227, 1, 43, 16, 209, 255, 8,
];

#[test]
fn a_texture_whose_image_is_webp_only_is_loaded_and_carried() {
    // scene.glb with the checker material's texture given only as EXT_texture_webp (as web
    // pipelines write KTX2 or WebP textures with no PNG fallback; the extension is then
    // required). fairmesh decodes no image, so it reads the file and carries the image.
    let dir = tempfile::tempdir().unwrap();
    let mut input = read_gltf(&data("scene.glb"));
    let view = input.append_view(&WEBP_CHECKER);
    let json = &mut input.json;
    let images = json["images"].as_array_mut().unwrap();
    images.push(
        serde_json::json!({"bufferView": view, "mimeType": "image/webp", "name": "checker_webp"}),
    );
    let image = images.len() - 1;
    let texture = &mut json["textures"][0];
    texture.as_object_mut().unwrap().remove("source");
    texture["extensions"] = serde_json::json!({"EXT_texture_webp": {"source": image}});
    for key in ["extensionsUsed", "extensionsRequired"] {
        json[key] = serde_json::json!(["EXT_texture_webp"]);
    }
    let webp = dir.path().join("webp.glb");
    write_glb(&input, &webp);

    let (loaded, mesh, out, output) = faired_and_written_back(&input, &webp);
    // Written back: the texture and its image as they were.
    assert_eq!(output.json["textures"], input.json["textures"]);
    let image_view = &output.json["bufferViews"]
        [output.json["images"][image]["bufferView"].as_u64().unwrap() as usize];
    let at = image_view["byteOffset"].as_u64().unwrap() as usize;
    assert_eq!(output.buffers[0][at..at + WEBP_CHECKER.len()], WEBP_CHECKER);
    validate(&[webp, out]);
    // As OBJ: the material's texture is the WebP file, beside the MTL.
    let obj = dir.path().join("faired.obj");
    io::save_with_source(&obj, &mesh, &loaded.source).unwrap();
    let mtl = std::fs::read_to_string(dir.path().join("faired.mtl")).unwrap();
    let map = mtl
        .lines()
        .find_map(|l| l.trim().strip_prefix("map_Kd "))
        .unwrap_or_else(|| panic!("no texture in\n{mtl}"));
    assert!(map.ends_with(".webp"), "{map}");
    assert_eq!(std::fs::read(dir.path().join(map)).unwrap(), WEBP_CHECKER);
}

/// Loads the glTF `input` written at `path` (an extension required), fairs it and writes it back
/// beside it as `faired.glb`, whose required extensions must be `input`'s: the load, the faired
/// mesh, the written file and what it holds.
fn faired_and_written_back(input: &Gltf, path: &Path) -> (Loaded, TriMesh, PathBuf, Gltf) {
    let loaded = io::load(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mesh = faired(&loaded);
    let out = path.with_file_name("faired.glb");
    io::save_with_source(&out, &mesh, &loaded.source).unwrap();
    let output = read_gltf(&out);
    assert_eq!(
        output.json["extensionsRequired"],
        input.json["extensionsRequired"]
    );
    (loaded, mesh, out, output)
}

#[test]
fn a_texture_transform_is_written_back_carried_into_a_new_gltf_and_named_for_obj() {
    // scene.glb with the checker texture placed by KHR_texture_transform (and the extension
    // required, as exporters without a fallback set of texture coordinates write it).
    let dir = tempfile::tempdir().unwrap();
    let mut input = read_gltf(&data("scene.glb"));
    let transform =
        serde_json::json!({"offset": [0.25, 0.5], "rotation": 0.3, "scale": [2.0, 2.0]});
    let json = &mut input.json;
    assert_eq!(json["materials"][0]["name"], "checker");
    json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] =
        serde_json::json!({ "KHR_texture_transform": transform });
    for key in ["extensionsUsed", "extensionsRequired"] {
        json[key] = serde_json::json!(["KHR_texture_transform"]);
    }
    let placed = dir.path().join("placed.glb");
    write_glb(&input, &placed);

    // Read although the extension is required; written back: the materials as they were.
    let (loaded, mesh, back, output) = faired_and_written_back(&input, &placed);
    assert_eq!(output.json["materials"], input.json["materials"]);

    // A coarse level is a new document: the transform is carried as it came, and not named.
    use fairmesh::hierarchy::{build_hierarchy, HierarchyOptions};
    let hierarchy = build_hierarchy(
        &loaded.mesh,
        &HierarchyOptions::default(),
        &mut fairmesh::NoProgress,
    )
    .unwrap();
    let level = (hierarchy.coarsest_level() / 2).max(1);
    let (vertex_origin, face_origin) = hierarchy.level_origins(level);
    let derivation = io::Derivation {
        base: hierarchy.base_mesh(),
        vertex_origin: &vertex_origin,
        face_origin: &face_origin,
    };
    let coarse = dir.path().join("level.glb");
    let report = io::save_derived_with_source(
        &coarse,
        &hierarchy.level_mesh(level),
        &derivation,
        &loaded.source,
    )
    .unwrap();
    let written = read_gltf(&coarse);
    let checker = (written.json["materials"].as_array().unwrap().iter())
        .find(|m| m["name"] == "checker")
        .expect("the checker material");
    assert_eq!(
        checker["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"],
        transform
    );
    assert_eq!(
        written.json["extensionsUsed"],
        serde_json::json!(["KHR_texture_transform"])
    );
    assert!(
        !report
            .warnings
            .iter()
            .any(|w| w.contains("KHR_texture_transform")),
        "{:?}",
        report.warnings
    );
    validate(&[placed, back, coarse]);

    // As OBJ, which has no rotation for a texture: named as not kept.
    let obj = dir.path().join("faired.obj");
    let report = io::save_with_source(&obj, &mesh, &loaded.source).unwrap();
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("KHR_texture_transform")),
        "{:?}",
        report.warnings
    );
}
