//! Round trips through every writable format, glTF features (seams, node transforms, strips and
//! fans, external and embedded buffers) and validation of exported glTF by the Khronos validator.
//!
//! The validator test needs node and `npm ci` (it fails, rather than skipping, when the package
//! is missing, so CI cannot silently stop validating).

use fairmesh::io::{self, Format, LoadOptions};
use fairmesh::TriMesh;
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use std::path::PathBuf;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every OBJ in assets/ and tests/data/.
fn real_meshes() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for dir in ["assets", "tests/data"] {
        for entry in std::fs::read_dir(repo().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "obj") {
                files.push(path);
            }
        }
    }
    files.sort();
    assert!(
        files.len() >= 4,
        "expected bunny00 and the three test meshes: {files:?}"
    );
    files
}

fn bits(mesh: &TriMesh) -> Vec<[u32; 3]> {
    mesh.positions.iter().map(|p| p.map(f32::to_bits)).collect()
}

fn assert_same(a: &TriMesh, b: &TriMesh, what: &str) {
    assert_eq!(
        a.triangles.len(),
        b.triangles.len(),
        "{what}: triangle count"
    );
    assert!(a.triangles == b.triangles, "{what}: triangles differ");
    assert!(bits(a) == bits(b), "{what}: positions differ bitwise");
}

/// For formats that store a triangle soup (STL, or a glTF without indices): the same triangles in
/// the same order, each corner at a bitwise equal position. Vertex numbering cannot survive a soup:
/// welding numbers vertices in order of first use.
fn assert_same_soup(a: &TriMesh, b: &TriMesh, what: &str) {
    assert_eq!(
        a.triangles.len(),
        b.triangles.len(),
        "{what}: triangle count"
    );
    assert_eq!(
        a.positions.len(),
        b.positions.len(),
        "{what}: vertex count after welding"
    );
    let corners = |m: &TriMesh| -> Vec<[u32; 3]> {
        m.triangles
            .iter()
            .flat_map(|t| t.map(|v| m.positions[v as usize].map(f32::to_bits)))
            .collect()
    };
    assert!(corners(a) == corners(b), "{what}: corner positions differ");
}

#[test]
fn real_meshes_survive_obj_glb_obj_and_obj_ply_obj_bit_exactly() {
    let dir = tempfile::tempdir().unwrap();
    for file in real_meshes() {
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        let original = io::load(&file).unwrap();
        assert!(original.mesh.face_count() > 1000, "{name}");
        for via in ["glb", "ply", "gltf", "stl", "off"] {
            let middle = dir.path().join(format!("{name}.{via}"));
            io::save(&middle, &original.mesh).unwrap();
            let loaded = io::load(&middle).unwrap();
            let back = dir.path().join(format!("{name}.from-{via}.obj"));
            io::save(&back, &loaded.mesh).unwrap();
            let again = io::load(&back).unwrap();
            if via == "stl" {
                assert_same_soup(&original.mesh, &loaded.mesh, &format!("{name} -> {via}"));
                assert_same(
                    &loaded.mesh,
                    &again.mesh,
                    &format!("{name} -> {via} -> obj"),
                );
            } else {
                assert_same(&original.mesh, &loaded.mesh, &format!("{name} -> {via}"));
                assert_same(
                    &original.mesh,
                    &again.mesh,
                    &format!("{name} -> {via} -> obj"),
                );
            }
        }
        // Topology survives too (elephant has genus 3, mushroom_open one hole).
        let reloaded = io::load(dir.path().join(format!("{name}.glb"))).unwrap();
        assert_eq!(
            reloaded.topology.components[0].genus,
            original.topology.components[0].genus
        );
        assert_eq!(
            reloaded.topology.boundary_loops.len(),
            original.topology.boundary_loops.len()
        );
    }
}

#[test]
fn real_meshes_have_expected_topology() {
    let elephant = io::load(repo().join("tests/data/elephant.obj")).unwrap();
    assert_eq!(elephant.mesh.vertex_count(), 2775);
    assert_eq!(elephant.mesh.face_count(), 5558);
    assert_eq!(elephant.topology.components[0].genus, Some(3));
    let mushroom = io::load(repo().join("tests/data/mushroom_open.obj")).unwrap();
    assert_eq!(mushroom.topology.boundary_loops.len(), 1);
    assert!(
        mushroom.report.warnings.is_empty(),
        "{:?}",
        mushroom.report.warnings
    );
}

#[test]
fn load_from_bytes_matches_load() {
    let file = repo().join("tests/data/bunny_npm.obj");
    let from_file = io::load(&file).unwrap();
    let bytes = std::fs::read(&file).unwrap();
    let from_bytes =
        io::load_from_bytes(&bytes, Format::Obj, "dropped.obj", &LoadOptions::default()).unwrap();
    assert_same(&from_file.mesh, &from_bytes.mesh, "bytes");
}

#[test]
fn hand_written_stl_and_off_load() {
    let dir = tempfile::tempdir().unwrap();
    // A tetrahedron, ASCII STL (facet normals deliberately wrong: they are ignored).
    let corners = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
    let faces = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    let mut stl = String::from("solid tetra\n");
    for f in faces {
        stl.push_str("  facet normal 0 0 0\n    outer loop\n");
        for v in f {
            let [x, y, z]: [f32; 3] = corners[v];
            stl.push_str(&format!("      vertex {x} {y} {z}\n"));
        }
        stl.push_str("    endloop\n  endfacet\n");
    }
    stl.push_str("endsolid tetra\n");
    let path = dir.path().join("tetra.stl");
    std::fs::write(&path, stl).unwrap();
    let loaded = io::load(&path).unwrap();
    assert_eq!(loaded.mesh.vertex_count(), 4);
    assert_eq!(loaded.report.welded_vertices, 8);
    assert!(loaded.topology.is_closed() && loaded.topology.is_oriented_manifold());
    let unwelded = io::load_with(&path, &LoadOptions { weld: false }).unwrap();
    assert_eq!(unwelded.mesh.vertex_count(), 12);
    assert_eq!(unwelded.topology.components.len(), 4);

    let off = "OFF\n# tetrahedron\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
    let path = dir.path().join("tetra.off");
    std::fs::write(&path, off).unwrap();
    let from_off = io::load(&path).unwrap();
    assert_eq!(
        from_off.mesh.triangles,
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]
    );
    assert!(from_off.topology.is_closed());
}

// ---------------------------------------------------------------------------------------------
// glTF files built in the tests with gltf-json.

struct Primitive {
    positions: Vec<[f32; 3]>,
    indices: Option<Vec<u32>>,
    mode: json::mesh::Mode,
}

/// A document with one mesh per primitive (mesh i holds primitive i), no nodes or scenes yet,
/// and its binary buffer (buffer 0, uri unset).
fn document(primitives: &[Primitive]) -> (json::Root, Vec<u8>) {
    let mut root = json::Root::default();
    let mut bin = Vec::new();
    let buffer = json::Index::new(0);
    for p in primitives {
        let mut add_view = |root: &mut json::Root, bytes: Vec<u8>| {
            let view = root.push(json::buffer::View {
                buffer,
                byte_length: USize64(bytes.len() as u64),
                byte_offset: Some(USize64(bin.len() as u64)),
                byte_stride: None,
                name: None,
                target: None,
                extensions: None,
                extras: Default::default(),
            });
            bin.extend_from_slice(&bytes);
            view
        };
        let bytes: Vec<u8> = p
            .positions
            .iter()
            .flatten()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        let view = add_view(&mut root, bytes);
        let mut min = [f32::MAX; 3];
        let mut max = [f32::MIN; 3];
        for q in &p.positions {
            for a in 0..3 {
                min[a] = min[a].min(q[a]);
                max[a] = max[a].max(q[a]);
            }
        }
        let positions = root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(p.positions.len() as u64),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Valid(json::accessor::Type::Vec3),
            min: Some(json::Value::from(min.to_vec())),
            max: Some(json::Value::from(max.to_vec())),
            name: None,
            normalized: false,
            sparse: None,
        });
        let indices = p.indices.as_ref().map(|indices| {
            let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
            let view = add_view(&mut root, bytes);
            root.push(json::Accessor {
                buffer_view: Some(view),
                byte_offset: None,
                count: USize64(indices.len() as u64),
                component_type: Valid(json::accessor::GenericComponentType(
                    json::accessor::ComponentType::U32,
                )),
                extensions: None,
                extras: Default::default(),
                type_: Valid(json::accessor::Type::Scalar),
                min: None,
                max: None,
                name: None,
                normalized: false,
                sparse: None,
            })
        });
        root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: None,
            primitives: vec![json::mesh::Primitive {
                attributes: [(Valid(json::mesh::Semantic::Positions), positions)]
                    .into_iter()
                    .collect(),
                extensions: None,
                extras: Default::default(),
                indices,
                material: None,
                mode: Valid(p.mode),
                targets: None,
            }],
            weights: None,
        });
    }
    root.push(json::Buffer {
        byte_length: USize64(bin.len() as u64),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    (root, bin)
}

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// `.gltf` JSON with the buffer embedded as a data: URI.
fn embedded_gltf(mut root: json::Root, bin: &[u8]) -> Vec<u8> {
    root.buffers[0].uri = Some(format!(
        "data:application/octet-stream;base64,{}",
        base64(bin)
    ));
    json::serialize::to_vec_pretty(&root).unwrap()
}

fn glb(root: &json::Root, bin: &[u8]) -> Vec<u8> {
    let mut json_bytes = json::serialize::to_vec(root).unwrap();
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((28 + json_bytes.len() + bin.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// One node per mesh, all in the default scene.
fn one_node_per_mesh(root: &mut json::Root) {
    let nodes: Vec<_> = (0..root.meshes.len())
        .map(|m| {
            root.push(json::Node {
                mesh: Some(json::Index::new(m as u32)),
                ..Default::default()
            })
        })
        .collect();
    let scene = root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: None,
        nodes,
    });
    root.scene = Some(scene);
}

/// A unit cube stored as glTF exporters store it: 4 vertices per face (24 in all), split at
/// every edge because each face has its own normal.
fn seam_split_cube() -> Primitive {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = positions.len() as u32;
            for (a, b) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                let mut p = [0.0f32; 3];
                p[axis] = side;
                p[u] = a;
                p[v] = b;
                positions.push(p);
            }
            // Outward winding: (u, v, axis) is right-handed, so counter-clockwise in (u, v)
            // faces +axis.
            if side == 1.0 {
                indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
            } else {
                indices.extend([base, base + 2, base + 1, base, base + 3, base + 2]);
            }
        }
    }
    Primitive {
        positions,
        indices: Some(indices),
        mode: json::mesh::Mode::Triangles,
    }
}

#[test]
fn seam_split_gltf_welds_into_one_closed_manifold() {
    let dir = tempfile::tempdir().unwrap();
    let (mut root, bin) = document(&[seam_split_cube()]);
    one_node_per_mesh(&mut root);
    let path = dir.path().join("cube.gltf");
    std::fs::write(&path, embedded_gltf(root, &bin)).unwrap();

    let welded = io::load(&path).unwrap();
    assert_eq!(welded.mesh.vertex_count(), 8);
    assert_eq!(welded.mesh.face_count(), 12);
    assert_eq!(welded.report.welded_vertices, 16);
    assert_eq!(welded.topology.components.len(), 1);
    assert!(welded.topology.is_closed());
    assert!(welded.topology.is_oriented_manifold());
    assert_eq!(welded.topology.components[0].genus, Some(0));
    // Outward orientation: the volume is +1.
    let volume: f64 = (0..welded.mesh.face_count())
        .map(|t| {
            let [a, b, c] = welded.mesh.triangle_points(t);
            a.dot(b.cross(c)) / 6.0
        })
        .sum();
    assert!((volume - 1.0).abs() < 1e-12, "{volume}");

    let apart = io::load_with(&path, &LoadOptions { weld: false }).unwrap();
    assert_eq!(apart.mesh.vertex_count(), 24);
    assert_eq!(apart.topology.components.len(), 6);
    assert!(!apart.topology.is_closed());
}

#[test]
fn elephant_with_every_corner_duplicated_welds_back() {
    let elephant = io::load(repo().join("tests/data/elephant.obj"))
        .unwrap()
        .mesh;
    let positions: Vec<[f32; 3]> = elephant
        .triangles
        .iter()
        .flat_map(|t| t.map(|v| elephant.positions[v as usize]))
        .collect();
    let (mut root, bin) = document(&[Primitive {
        positions,
        indices: None,
        mode: json::mesh::Mode::Triangles,
    }]);
    one_node_per_mesh(&mut root);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("elephant_soup.glb");
    std::fs::write(&path, glb(&root, &bin)).unwrap();

    let welded = io::load(&path).unwrap();
    assert_same_soup(&elephant, &welded.mesh, "elephant soup welded");
    assert_eq!(welded.topology.components.len(), 1);
    assert!(welded.topology.is_closed() && welded.topology.is_oriented_manifold());

    let apart = io::load_with(&path, &LoadOptions { weld: false }).unwrap();
    assert_eq!(apart.mesh.vertex_count(), 3 * elephant.face_count());
    assert_eq!(apart.topology.components.len(), elephant.face_count());
}

fn triangle() -> Primitive {
    Primitive {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        indices: None,
        mode: json::mesh::Mode::Triangles,
    }
}

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5)
}

#[test]
fn node_transforms_are_composed_and_mirrors_keep_winding() {
    let (mut root, bin) = document(&[triangle()]);
    let mesh = Some(json::Index::new(0));
    // parent: translate (10, 0, 0), uniform scale 2; child: rotate 90 degrees about +Z.
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let child = root.push(json::Node {
        mesh,
        rotation: Some(json::scene::UnitQuaternion([0.0, 0.0, s, s])),
        ..Default::default()
    });
    let parent = root.push(json::Node {
        translation: Some([10.0, 0.0, 0.0]),
        scale: Some([2.0, 2.0, 2.0]),
        children: Some(vec![child]),
        ..Default::default()
    });
    // A mirror (negative determinant) given as a matrix: x -> -x, then moved to z = 5.
    let mirror = root.push(json::Node {
        mesh,
        matrix: Some([
            -1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 5.0, 1.0,
        ]),
        ..Default::default()
    });
    // A node outside the scene must not be read.
    root.push(json::Node {
        mesh,
        translation: Some([0.0, 0.0, -50.0]),
        ..Default::default()
    });
    let scene = root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: None,
        nodes: vec![parent, mirror],
    });
    root.scene = Some(scene);
    let loaded = io::load_from_bytes(
        &glb(&root, &bin),
        Format::Glb,
        "nodes.glb",
        &LoadOptions::default(),
    )
    .unwrap();
    let mesh = &loaded.mesh;
    assert_eq!(mesh.face_count(), 2);
    let corners = |t: usize| mesh.triangles[t].map(|v| mesh.positions[v as usize]);
    // (1,0,0) -> rotate -> (0,1,0) -> scale -> (0,2,0) -> translate -> (10,2,0).
    let first = corners(0);
    assert!(close(first[0], [10.0, 0.0, 0.0]), "{first:?}");
    assert!(close(first[1], [10.0, 2.0, 0.0]), "{first:?}");
    assert!(close(first[2], [8.0, 0.0, 0.0]), "{first:?}");
    // The mirrored copy lies at z = 5 and still faces +Z.
    let second = corners(1);
    assert!(second.iter().all(|p| p[2] == 5.0), "{second:?}");
    assert!(
        second.iter().any(|p| close(*p, [-1.0, 0.0, 5.0])),
        "{second:?}"
    );
    assert!(mesh.face_normal(1).z > 0.0);
    assert!(mesh.face_normal(0).z > 0.0);
}

#[test]
fn strips_and_fans_become_consistently_oriented_triangles() {
    let quad_strip = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    let fan = vec![
        [5.0, 5.0, 0.0],
        [6.0, 5.0, 0.0],
        [6.0, 6.0, 0.0],
        [5.0, 6.0, 0.0],
        [4.0, 6.0, 0.0],
    ];
    let (mut root, bin) = document(&[
        Primitive {
            positions: quad_strip,
            indices: None,
            mode: json::mesh::Mode::TriangleStrip,
        },
        Primitive {
            positions: fan,
            indices: Some(vec![0, 1, 2, 3, 4]),
            mode: json::mesh::Mode::TriangleFan,
        },
        Primitive {
            positions: vec![[9.0, 9.0, 9.0], [8.0, 8.0, 8.0]],
            indices: None,
            mode: json::mesh::Mode::Lines,
        },
    ]);
    one_node_per_mesh(&mut root);
    let loaded = io::load_from_bytes(
        &embedded_gltf(root, &bin),
        Format::Gltf,
        "strips.gltf",
        &LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(loaded.mesh.face_count(), 2 + 3);
    for t in 0..loaded.mesh.face_count() {
        assert!(
            loaded.mesh.face_normal(t).z > 0.0,
            "triangle {t} is flipped"
        );
    }
    assert_eq!(loaded.topology.components.len(), 2);
    assert!(loaded.topology.is_oriented_manifold());
    assert!(
        loaded
            .report
            .warnings
            .iter()
            .any(|w| w == "1 line primitive was skipped"),
        "{:?}",
        loaded.report.warnings
    );
}

#[test]
fn external_buffer_is_read_relative_to_the_gltf() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("models");
    std::fs::create_dir(&sub).unwrap();
    let (mut root, bin) = document(&[seam_split_cube()]);
    one_node_per_mesh(&mut root);
    root.buffers[0].uri = Some("cube%20data.bin".into());
    std::fs::write(sub.join("cube data.bin"), &bin).unwrap();
    let path = sub.join("cube.gltf");
    std::fs::write(&path, json::serialize::to_vec(&root).unwrap()).unwrap();
    let loaded = io::load(&path).unwrap();
    assert_eq!(loaded.mesh.vertex_count(), 8);
    // From memory there is no directory to look in: a clear error, not a panic.
    let bytes = std::fs::read(&path).unwrap();
    let err = io::load_from_bytes(&bytes, Format::Gltf, "cube.gltf", &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("cube.gltf: buffer 0: "), "{err}");
}

#[test]
fn saved_gltf_writes_bin_beside_it_and_glb_is_self_contained() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = io::load(repo().join("tests/data/bunny_npm.obj"))
        .unwrap()
        .mesh;
    let path = dir.path().join("my bunny.gltf");
    io::save(&path, &mesh).unwrap();
    assert!(dir.path().join("my bunny.bin").exists());
    let json_text = std::fs::read_to_string(&path).unwrap();
    assert!(json_text.contains("my%20bunny.bin"), "{json_text}");
    assert!(json_text.contains("\"generator\": \"fairmesh\""));
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, vec!["my bunny.bin", "my bunny.gltf"]);
}

fn validator_script() -> PathBuf {
    let package = repo().join("node_modules/gltf-validator");
    assert!(
        package.exists(),
        "node_modules/gltf-validator is missing: run `npm ci` in the repository root (needs node)"
    );
    repo().join("tests/gltf_validate.mjs")
}

#[test]
fn exported_gltf_and_glb_pass_the_khronos_validator() {
    let script = validator_script();
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for name in ["bunny_npm", "mushroom_open", "elephant"] {
        let mesh = io::load(repo().join(format!("tests/data/{name}.obj")))
            .unwrap()
            .mesh;
        for ext in ["glb", "gltf"] {
            let path = dir.path().join(format!("{name}.{ext}"));
            io::save(&path, &mesh).unwrap();
            files.push(path);
        }
    }
    // A mesh whose vertex normals cancel out (two faces back to back) and one isolated vertex.
    let awkward = TriMesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [7.0, 7.0, 7.0],
        ],
        vec![[0, 1, 2], [0, 2, 1]],
    );
    let path = dir.path().join("awkward.glb");
    io::save(&path, &awkward).unwrap();
    files.push(path);

    let output = std::process::Command::new("node")
        .arg(&script)
        .args(&files)
        .output()
        .expect("node must be installed to validate glTF output");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "validator failed:\n{stdout}\n{stderr}"
    );
    assert_eq!(stdout.matches(" 0 errors").count(), files.len(), "{stdout}");
}

#[test]
fn the_validator_script_catches_broken_files() {
    let script = validator_script();
    let dir = tempfile::tempdir().unwrap();
    let mesh = TriMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    );
    let path = dir.path().join("t.glb");
    io::save(&path, &mesh).unwrap();
    // Corrupt the position accessor's max (the validator checks min/max against the data).
    let mut bytes = std::fs::read(&path).unwrap();
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let at = text
        .find("\"max\":[1.0,1.0,0.0]")
        .expect("max as serialised");
    bytes[at + 7] = b'7';
    std::fs::write(&path, &bytes).unwrap();
    let output = std::process::Command::new("node")
        .arg(&script)
        .arg(&path)
        .output()
        .unwrap();
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stdout).contains("ACCESSOR_MAX_MISMATCH"));
}

#[test]
fn save_as_ignores_the_extension() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = TriMesh::new(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    );
    let path = dir.path().join("mesh.dat");
    io::save_as(&path, &mesh, Format::Ply).unwrap();
    assert!(std::fs::read(&path).unwrap().starts_with(b"ply\n"));
    let loaded = io::load_from_bytes(
        &std::fs::read(&path).unwrap(),
        Format::Ply,
        "mesh.dat",
        &LoadOptions::default(),
    )
    .unwrap();
    assert_same(&mesh, &loaded.mesh, "ply via save_as");
    assert!(
        io::save(&path, &mesh).is_err(),
        ".dat is no known extension"
    );
}

#[test]
fn readers_and_writers_round_trip_every_format_in_memory() {
    let mesh = io::load(repo().join("tests/data/mushroom_open.obj"))
        .unwrap()
        .mesh;
    for format in Format::ALL {
        let mut bytes = Vec::new();
        io::write_to(&mut bytes, &mesh, format).unwrap();
        let name = format!("memory.{}", format.extension());
        let back =
            io::load_from_reader(bytes.as_slice(), format, &name, &LoadOptions::default()).unwrap();
        match format {
            // STL stores corners, not shared vertices: compare triangle by triangle.
            Format::Stl => assert_same_soup(&mesh, &back.mesh, &name),
            _ => assert_same(&mesh, &back.mesh, &name),
        }
    }
    // A .gltf written to a writer carries its buffer inside (no .bin to find).
    let mut text = Vec::new();
    io::write_to(&mut text, &mesh, Format::Gltf).unwrap();
    assert!(String::from_utf8_lossy(&text).contains("data:application/octet-stream;base64,"));
}

#[test]
fn triangles_facing_the_wrong_way_are_flipped_on_load_with_a_warning() {
    // An octahedron (outward) with two faces written the other way round.
    let text = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
                f 1 3 5\nf 3 2 5\nf 2 5 4\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 6 4 1\n";
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flipped.obj");
    std::fs::write(&path, text).unwrap();
    let loaded = fairmesh::io::load(&path).unwrap();
    assert_eq!(loaded.topology.inconsistent_edges, 0);
    assert!(
        loaded
            .report
            .warnings
            .iter()
            .any(|w| w.contains("2 triangles faced the other way")),
        "{:?}",
        loaded.report.warnings
    );
    let volume = fairmesh::metrics::signed_volume(&loaded.mesh);
    assert!((volume - 4.0 / 3.0).abs() < 1e-6, "volume {volume}");
    // Written back, the file keeps its own faces: only positions change.
    let out = dir.path().join("out.obj");
    fairmesh::io::save_with_source(&out, &loaded.mesh, &loaded.source).unwrap();
    let written = std::fs::read_to_string(&out).unwrap();
    assert!(written.contains("f 2 5 4") && written.contains("f 6 4 1"));
}
