//! Broken input: a corpus of bad files per format, written into a temporary directory, each of
//! which must fail with a message that starts with the file's path and names the line, byte or
//! element at fault. Also: the CLI reports such errors with exit code 1, failed exports leave
//! nothing behind, and the inputs the fuzzers found (tests/data/fuzz/) load without panicking.

use fairmesh::io::{self, Format, LoadOptions};
use fairmesh::TriMesh;
use std::path::{Path, PathBuf};

fn tetrahedron() -> TriMesh {
    TriMesh::new(
        vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    )
}

/// The bytes of the tetrahedron saved in `ext`'s format.
fn saved(ext: &str) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("t.{ext}"));
    io::save(&path, &tetrahedron()).unwrap();
    std::fs::read(path).unwrap()
}

/// Write `bytes` as `name`, load it both from the file and from memory, and check that the
/// errors start with the path (or name) and contain every needle. Returns the file's message.
fn expect_error(dir: &Path, name: &str, bytes: &[u8], needles: &[&str]) -> String {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let message = match io::load(&path) {
        Ok(loaded) => panic!(
            "{name}: loaded {} faces, expected an error",
            loaded.mesh.face_count()
        ),
        Err(e) => e.to_string(),
    };
    assert!(
        message.starts_with(&format!("{}: ", path.display())),
        "{name}: message does not start with the path: {message}"
    );
    for needle in needles {
        assert!(
            message.contains(needle),
            "{name}: {message:?} lacks {needle:?}"
        );
    }
    let format = Format::from_path(&path).unwrap();
    if let Err(e) = io::load_from_bytes(bytes, format, name, &LoadOptions::default()) {
        let from_bytes = e.to_string();
        assert!(from_bytes.starts_with(&format!("{name}: ")), "{from_bytes}");
    } else {
        panic!("{name}: loaded from bytes, expected an error");
    }
    message
}

#[test]
fn broken_obj_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    expect_error(d, "empty.obj", b"", &["the file is empty"]);
    // A UTF-8 byte order mark (Windows editors write one) is skipped: the first vertex is
    // read (before, its line's keyword was not recognised and face 1 pointed past the end).
    // UTF-16 is refused with an error that says so, not "line 1 is not valid UTF-8".
    for (name, text) in [
        ("bom.obj", format!("{tri}f 1 2 3\n")),
        (
            "bom.off",
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_string(),
        ),
    ] {
        let path = d.join(name);
        std::fs::write(&path, [&b"\xEF\xBB\xBF"[..], text.as_bytes()].concat()).unwrap();
        let loaded = io::load(&path).unwrap();
        assert_eq!(
            (loaded.mesh.vertex_count(), loaded.mesh.face_count()),
            (3, 1),
            "{name}"
        );
    }
    let utf16: Vec<u8> = [0xFE, 0xFF]
        .into_iter()
        .chain(
            format!("{tri}f 1 2 3\n")
                .encode_utf16()
                .flat_map(u16::to_be_bytes),
        )
        .collect();
    expect_error(
        d,
        "utf16.obj",
        &utf16,
        &["UTF-16", "save it again as UTF-8"],
    );
    expect_error(
        d,
        "continued.obj",
        format!("{tri}f 1 \\\n 2 3\n").as_bytes(),
        &["line 4", "ends with a backslash", "join the two lines"],
    );
    let message = expect_error(
        d,
        "nan.obj",
        b"# comment\nv 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n",
        &["line 3", "vertex 2", "NaN"],
    );
    assert!(
        message.ends_with("nan.obj: line 3: vertex 2 has a NaN coordinate"),
        "{message}"
    );
    expect_error(
        d,
        "inf.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 -inf\nf 1 2 3\n",
        &["line 3", "vertex 3", "infinite"],
    );
    expect_error(
        d,
        "overflow.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 1e39\nf 1 2 3\n",
        &["line 3", "infinite"],
    );
    expect_error(
        d,
        "index.obj",
        format!("{tri}f 1 2 3\nf 1 2 9\n").as_bytes(),
        &[
            "line 5",
            "face 2",
            "vertex index 9 is out of range",
            "3 vertices",
        ],
    );
    expect_error(
        d,
        "relative.obj",
        format!("{tri}f -1 -2 -4\n").as_bytes(),
        &["line 4", "face 1", "-4"],
    );
    expect_error(
        d,
        "zero.obj",
        format!("{tri}f 0 1 2\n").as_bytes(),
        &["line 4", "start at 1"],
    );
    expect_error(
        d,
        "word.obj",
        format!("{tri}f 1 2 three\n").as_bytes(),
        &["line 4", "cannot read vertex index \"three\""],
    );
    expect_error(
        d,
        "coord.obj",
        b"v 0 0 0\nv 1 zero 0\n",
        &["line 2", "\"zero\""],
    );
    expect_error(d, "short.obj", b"v 0 0\n", &["line 1", "fewer than 3"]);
    expect_error(
        d,
        "lines.obj",
        format!("{tri}l 1 2 3\np 1\n").as_bytes(),
        &["no triangles"],
    );
    expect_error(
        d,
        "garbage.obj",
        // (Not starting with 0xff 0xfe: that is UTF-16's byte order mark, which has its own
        // error, tested above.)
        &[0x80, 0xfe, 0x00, 0x13, b'\n', 0x80, 0x81],
        &["line 1", "UTF-8"],
    );
}

#[test]
fn broken_ply_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let binary = saved("ply");
    let body = binary
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = String::from_utf8(binary[..body].to_vec()).unwrap();

    expect_error(d, "empty.ply", b"", &["the file is empty"]);
    expect_error(
        d,
        "garbage.ply",
        b"hello world\n",
        &["line 1", "not a PLY file"],
    );
    expect_error(
        d,
        "noend.ply",
        b"ply\nformat ascii 1.0\nelement vertex 0\n",
        &["no end_header"],
    );
    expect_error(
        d,
        "badtype.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n",
        &["line 4", "\"quaternion\""],
    );

    // Binary: cut inside the last face.
    let cut = body + 4 * 12 + 3 * 13 + 5;
    expect_error(
        d,
        "truncated.ply",
        &binary[..cut],
        &["byte ", "truncated", "face 3 of 4"],
    );
    // Binary: cut inside the vertices: the fixed-size check names the vertex.
    let cut = body + 12 + 6;
    expect_error(
        d,
        "truncated_vertices.ply",
        &binary[..cut],
        &[&format!("byte {}", body + 12), "vertex 1 of 4"],
    );

    // Binary: vertex 1's y is +inf.
    let mut inf = binary.clone();
    inf[body + 16..body + 20].copy_from_slice(&f32::INFINITY.to_le_bytes());
    expect_error(
        d,
        "inf.ply",
        &inf,
        &[&format!("byte {}", body + 12), "vertex 1", "infinite"],
    );

    // Binary: face 2's second index is 77.
    let mut index = binary.clone();
    let at = body + 4 * 12 + 2 * 13 + 1 + 4;
    index[at..at + 4].copy_from_slice(&77u32.to_le_bytes());
    expect_error(
        d,
        "index.ply",
        &index,
        &[
            &format!("byte {at}"),
            "face 2",
            "vertex index 77 is out of range",
        ],
    );

    // Absurd counts: must fail fast without allocating billions.
    let mut absurd = header
        .replace("element vertex 4", "element vertex 4000000000")
        .into_bytes();
    absurd.extend_from_slice(&binary[body..]);
    expect_error(
        d,
        "absurd_vertices.ply",
        &absurd,
        &["byte ", "truncated", "4000000000"],
    );
    let mut absurd = header
        .replace("element face 4", "element face 4000000000")
        .into_bytes();
    absurd.extend_from_slice(&binary[body..]);
    expect_error(
        d,
        "absurd_faces.ply",
        &absurd,
        &["byte ", "face 4 of 4000000000"],
    );
    let big_endian = header
        .replace("binary_little_endian", "binary_big_endian")
        .replace("element vertex 4", "element vertex 4294967295");
    expect_error(d, "absurd_be.ply", big_endian.as_bytes(), &["truncated"]);

    // ASCII.
    let ascii = |vertices: &str, faces: &str, nv: usize, nf: usize| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\n\
             property float z\nelement face {nf}\nproperty list uchar int vertex_indices\n\
             end_header\n{vertices}{faces}"
        )
    };
    let verts = "0 0 0\n1 0 0\n0 1 0\n";
    expect_error(
        d,
        "nan_ascii.ply",
        ascii("0 0 0\n1 nan 0\n0 1 0\n", "3 0 1 2\n", 3, 1).as_bytes(),
        &["line 11", "vertex 1", "NaN"],
    );
    expect_error(
        d,
        "index_ascii.ply",
        ascii(verts, "3 0 1 2\n3 0 2 7\n", 3, 2).as_bytes(),
        &["line 14", "face 1", "vertex index 7 is out of range"],
    );
    expect_error(
        d,
        "negative_ascii.ply",
        ascii(verts, "3 0 -1 2\n", 3, 1).as_bytes(),
        &["line 13", "face 0", "-1"],
    );
    expect_error(
        d,
        "absurd_ascii.ply",
        ascii(verts, "3 0 1 2\n", 3, 4_000_000_000).as_bytes(),
        &["line 13", "ends after 1 of 4000000000 face"],
    );
    expect_error(
        d,
        "notriangles.ply",
        ascii(verts, "2 0 1\n", 3, 1).as_bytes(),
        &["no triangles"],
    );
    expect_error(
        d,
        "nofaces.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
        &["no triangles"],
    );
    // A line that is no PLY keyword before the first element (old Blender exports write
    // "Created by Blender3D 247 ..." there) is read as a comment, with a warning that names it;
    // the same line among the elements could be a misspelt element or property, which would
    // misplace every value after it, so there it stays an error.
    let tetrahedron = "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                       element face 4\nproperty list uchar int vertex_indices\nend_header\n\
                       0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    let stray = d.join("stray.ply");
    std::fs::write(
        &stray,
        format!("ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org\n{tetrahedron}"),
    )
    .unwrap();
    let loaded = io::load(&stray).unwrap();
    assert_eq!(loaded.mesh.face_count(), 4);
    assert_eq!(
        loaded.report.warnings,
        [
            "header line 3 (\"Created by Blender3D 247 - www.blender.o...\") is not a PLY keyword \
          line: read as a comment"
        ]
    );
    let (first, rest) = tetrahedron.split_at(tetrahedron.find("element face").unwrap());
    expect_error(
        d,
        "stray_among_elements.ply",
        format!("ply\nformat ascii 1.0\n{first}elemnt face 4\n{rest}").as_bytes(),
        &["line 7", "unknown header keyword \"elemnt\""],
    );
    // A vertex element that declares a list its rows do not have (a Blender 2.77 export).
    expect_error(
        d,
        "vertex_list.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
          property float z\nproperty list uchar uint vertex_indices\nend_header\n0 0 0\n",
        &[
            "line 9",
            "vertex 0: missing value for the list vertex_indices",
        ],
    );
    expect_error(
        d,
        "noxyz.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
        &["no scalar property z"],
    );
}

#[test]
fn broken_stl_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let binary = saved("stl");
    assert_eq!(binary.len(), 84 + 4 * 50);

    expect_error(d, "empty.stl", b"", &["the file is empty"]);
    expect_error(d, "garbage.stl", b"hello", &["not an STL file"]);
    expect_error(
        d,
        "truncated.stl",
        &binary[..84 + 50 + 20],
        &["byte 134", "truncated", "triangle 1"],
    );
    let mut absurd = binary[..84 + 50].to_vec();
    absurd[80..84].copy_from_slice(&4_000_000_000u32.to_le_bytes());
    expect_error(
        d,
        "absurd.stl",
        &absurd,
        &["byte 134", "truncated", "4000000000"],
    );
    let mut zero = binary[..84].to_vec();
    zero[80..84].copy_from_slice(&0u32.to_le_bytes());
    expect_error(d, "zero.stl", &zero, &["no triangles"]);
    let mut nan = binary.clone();
    nan[108..112].copy_from_slice(&f32::NAN.to_le_bytes());
    expect_error(
        d,
        "nan.stl",
        &nan,
        &["byte 108", "triangle 0, corner 1", "NaN"],
    );

    let ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    expect_error(
        d,
        "inf_ascii.stl",
        ascii.replace("vertex 1 0 0", "vertex 1 0 inf").as_bytes(),
        &["line 5", "vertex 1", "infinite"],
    );
    expect_error(
        d,
        "word_ascii.stl",
        ascii.replace("vertex 0 1 0", "vertex 0 one 0").as_bytes(),
        &["line 6", "\"one\""],
    );
    expect_error(
        d,
        "short_loop.stl",
        ascii.replace("vertex 0 1 0\n", "").as_bytes(),
        &["line 6", "2 vertices"],
    );
    expect_error(
        d,
        "nofacet.stl",
        b"solid t\nendsolid t\n",
        &["no triangles"],
    );
}

#[test]
fn broken_off_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    expect_error(d, "empty.off", b"", &["the file is empty"]);
    expect_error(d, "comments.off", b"# nothing\n\n", &["only comments"]);
    expect_error(
        d,
        "garbage.off",
        b"PLY\n1 2 3\n",
        &["line 1", "not an OFF file"],
    );
    expect_error(
        d,
        "nan.off",
        good.replace("1 0 0", "1 0 nan").as_bytes(),
        &["line 4", "vertex 1", "NaN"],
    );
    expect_error(
        d,
        "inf.off",
        good.replace("0 1 0", "0 1e40 0").as_bytes(),
        &["line 5", "vertex 2", "infinite"],
    );
    expect_error(
        d,
        "index.off",
        good.replace("3 0 1 2", "3 0 1 3").as_bytes(),
        &["line 6", "face 0", "vertex index 3 is out of range"],
    );
    expect_error(
        d,
        "missing.off",
        good.replace("3 0 1 2", "4 0 1 2").as_bytes(),
        &["line 6", "face 0", "fewer than its count 4"],
    );
    expect_error(
        d,
        "absurd.off",
        good.replace("3 1 0", "4000000000 4000000000 0").as_bytes(),
        &["line 6", "ends after 4 of 4000000000 vertices"],
    );
    expect_error(
        d,
        "absurd_faces.off",
        good.replace("3 1 0", "3 4000000000 0").as_bytes(),
        &["line 6", "ends after 1 of 4000000000 faces"],
    );
    expect_error(
        d,
        "counts.off",
        good.replace("3 1 0", "three 1 0").as_bytes(),
        &["line 2", "vertex count"],
    );
    expect_error(
        d,
        "notriangles.off",
        good.replace("3 0 1 2", "2 0 1").as_bytes(),
        &["no triangles"],
    );
    expect_error(d, "binary.off", b"OFF BINARY\n", &["line 1", "binary OFF"]);
}

/// The exported tetrahedron GLB split into (JSON value, BIN chunk).
fn glb_parts() -> (serde_json::Value, Vec<u8>) {
    let bytes = saved("glb");
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = bytes[20 + json_len + 8..].to_vec();
    (json, bin)
}

/// Faces of a GLB that loads.
fn good_faces(glb: &[u8]) -> usize {
    io::load_from_bytes(glb, Format::Glb, "good.glb", &LoadOptions::default())
        .unwrap()
        .mesh
        .face_count()
}

fn make_glb(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut json_bytes = serde_json::to_vec(json).unwrap();
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((28 + json_bytes.len() + bin.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out
}

#[test]
fn broken_gltf_and_glb_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (json, bin) = glb_parts();
    let good = make_glb(&json, &bin);
    assert!(io::load_from_bytes(&good, Format::Glb, "good.glb", &LoadOptions::default()).is_ok());

    expect_error(d, "empty.glb", b"", &["the file is empty"]);
    expect_error(d, "empty.gltf", b"", &["the file is empty"]);
    expect_error(
        d,
        "truncated.glb",
        &good[..good.len() - 10],
        &["byte 8", "GLB container", "truncated"],
    );
    expect_error(
        d,
        "header.glb",
        &good[..10],
        &["byte 0", "GLB container", "truncated"],
    );
    let mut short = good.clone();
    short[8..12].copy_from_slice(&4u32.to_le_bytes());
    expect_error(d, "length.glb", &short, &["byte 8", "less than the header"]);
    // glTF 1.0's binary container is version 1; the error says which glTF it is, not where
    // its other layout first fails to parse.
    let mut version_1 = good.clone();
    version_1[4..8].copy_from_slice(&1u32.to_le_bytes());
    expect_error(
        d,
        "version1.glb",
        &version_1,
        &[
            "byte 4",
            "GLB container version 1 (glTF 1.0)",
            "reads glTF 2.0",
        ],
    );
    // A glTF 1.0 JSON (objects keyed by name where 2.0 has arrays).
    expect_error(
        d,
        "v1.gltf",
        br#"{"asset": {"version": "1.0"}, "accessors": {"a": {"bufferView": "b", "count": 3}}, "meshes": {}}"#,
        &["asset.version", "glTF 1.0", "reads glTF 2.0"],
    );
    let mut chunk = good.clone();
    chunk[12..16].copy_from_slice(&100_000u32.to_le_bytes());
    expect_error(d, "chunk.glb", &chunk, &["GLB container", "invalid GLB"]);
    expect_error(
        d,
        "syntax.gltf",
        b"{\n  \"asset\": {\"version\": \"2.0\"},\n  \"meshes\": [ oops ]\n}\n",
        &["line 3", "invalid glTF JSON"],
    );
    expect_error(d, "garbage.gltf", b"\x00\x01binary junk", &["line 1"]);

    let mut nan = bin.clone();
    nan[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    expect_error(
        d,
        "nan.glb",
        &make_glb(&json, &nan),
        &["node 0, mesh 0, primitive 0", "vertex 1", "NaN"],
    );
    let mut index = bin.clone();
    let at = 2 * 4 * 12 + 4 * 4; // index element 4
    index[at..at + 4].copy_from_slice(&99u32.to_le_bytes());
    expect_error(
        d,
        "index.glb",
        &make_glb(&json, &index),
        &[
            "node 0, mesh 0, primitive 0",
            "element 4",
            "index 99 is out of range",
        ],
    );

    let edit = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut j = json.clone();
        f(&mut j);
        make_glb(&j, &bin)
    };
    expect_error(
        d,
        "absurd_count.glb",
        &edit(&|j| j["accessors"][0]["count"] = 4_000_000_000u64.into()),
        &[
            "POSITION accessor 0",
            "4000000000 elements",
            "buffer view 0 has 48",
        ],
    );
    expect_error(
        d,
        "view_past_end.glb",
        &edit(&|j| j["bufferViews"][2]["byteLength"] = 4096.into()),
        &["buffer view 2", "runs past the end of buffer 0"],
    );
    expect_error(
        d,
        "points.glb",
        &edit(&|j| j["meshes"][0]["primitives"][0]["mode"] = 0.into()),
        &["no triangles", "only point and line primitives"],
    );
    expect_error(
        d,
        "lines.glb",
        &edit(&|j| j["meshes"][0]["primitives"][0]["mode"] = 1.into()),
        &[
            "no triangles",
            "only point and line primitives (0 point, 1 line)",
        ],
    );
    // Not an error: a line primitive beside the triangles is skipped with a warning that counts
    // it in words ("1 line primitive was skipped"; it once read "0 point and 1 line
    // primitives were skipped").
    let with_lines = edit(&|j| {
        let mut lines = j["meshes"][0]["primitives"][0].clone();
        lines["mode"] = 1.into();
        j["meshes"][0]["primitives"]
            .as_array_mut()
            .unwrap()
            .push(lines);
    });
    let loaded = io::load_from_bytes(
        &with_lines,
        Format::Glb,
        "lines.glb",
        &LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(loaded.mesh.face_count(), good_faces(&good));
    assert!(
        loaded
            .report
            .warnings
            .contains(&"1 line primitive was skipped".to_string()),
        "{:?}",
        loaded.report.warnings
    );
    // A Draco-compressed file: its accessors have no buffer views, but the error names the
    // extension the file needs rather than the first accessor.
    expect_error(
        d,
        "draco.glb",
        &edit(&|j| {
            j["extensionsUsed"] = serde_json::json!(["KHR_draco_mesh_compression"]);
            j["extensionsRequired"] = serde_json::json!(["KHR_draco_mesh_compression"]);
            j["accessors"][0]
                .as_object_mut()
                .unwrap()
                .remove("bufferView");
        }),
        &[
            "extensionsRequired[0]",
            "KHR_draco_mesh_compression (Draco-compressed geometry)",
            "does not support",
        ],
    );
    expect_error(
        d,
        "cycle.glb",
        &edit(&|j| j["nodes"][0]["children"] = serde_json::json!([0])),
        &["node 0", "reached twice"],
    );
    expect_error(
        d,
        "dangling.glb",
        &edit(&|j| j["accessors"][0]["bufferView"] = 17.into()),
        &["accessors[0].bufferView", "invalid glTF"],
    );
    expect_error(
        d,
        "no_accessors.glb",
        &edit(&|j| j["accessors"] = serde_json::json!([])),
        &[
            "meshes[0].primitives[0].attributes.POSITION",
            "accessor 0 does not exist",
        ],
    );
    expect_error(
        d,
        "sparse.glb",
        &edit(&|j| {
            j["accessors"][0]["sparse"] = serde_json::json!({
                "count": 1,
                "indices": {"bufferView": 2, "componentType": 5125},
                "values": {"bufferView": 0}
            })
        }),
        &["POSITION accessor 0", "sparse"],
    );
    expect_error(
        d,
        "noscene.gltf",
        br#"{"asset": {"version": "2.0"}}"#,
        &["no triangles"],
    );
    let mut external = json.clone();
    external["buffers"][0]["uri"] = "missing.bin".into();
    let text = serde_json::to_vec(&external).unwrap();
    expect_error(d, "external.gltf", &text, &["buffer 0", "missing.bin"]);
    let mut bad_uri = json.clone();
    bad_uri["buffers"][0]["uri"] = "data:application/octet-stream;base64,@@@@".into();
    expect_error(
        d,
        "datauri.gltf",
        &serde_json::to_vec(&bad_uri).unwrap(),
        &["buffer 0", "bad base64 at character 0"],
    );
}

#[test]
fn unknown_extension_and_unreadable_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mesh.xyz");
    std::fs::write(&path, "v 0 0 0\n").unwrap();
    let message = io::load(&path).unwrap_err().to_string();
    assert!(
        message.starts_with(&format!("{}: ", path.display())),
        "{message}"
    );
    assert!(
        message.contains("unknown file extension \"xyz\""),
        "{message}"
    );

    let missing = dir.path().join("missing.obj");
    let message = io::load(&missing).unwrap_err().to_string();
    assert!(
        message.starts_with(&format!("{}: cannot read the file", missing.display())),
        "{message}"
    );

    let directory = dir.path().join("folder.ply");
    std::fs::create_dir(&directory).unwrap();
    let message = io::load(&directory).unwrap_err().to_string();
    assert!(
        message.starts_with(&format!("{}: cannot read", directory.display())),
        "{message}"
    );
}

#[test]
fn non_manifold_input_loads_with_warnings() {
    let dir = tempfile::tempdir().unwrap();
    // Three triangles on one edge.
    let path = dir.path().join("fin.off");
    std::fs::write(
        &path,
        "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n",
    )
    .unwrap();
    let loaded = io::load(&path).unwrap();
    assert!(!loaded.topology.is_manifold());
    let warnings = loaded.report.warnings.join("\n");
    assert!(warnings.contains("1 non-manifold edges"), "{warnings}");

    // Two triangles that traverse their shared edge the same way: one is flipped on load, and
    // the warning says so.
    let path = dir.path().join("flipped.off");
    std::fs::write(
        &path,
        "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n3 0 1 2\n3 0 1 3\n",
    )
    .unwrap();
    let loaded = io::load(&path).unwrap();
    assert_eq!(loaded.topology.inconsistent_edges, 0);
    assert_eq!(
        loaded.mesh.triangles[0],
        [0, 1, 2],
        "the first keeps its orientation"
    );
    let warnings = loaded.report.warnings.join("\n");
    assert!(
        warnings.contains("1 triangles faced the other way from their neighbours and were flipped"),
        "{warnings}"
    );
}

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn failed_export_leaves_existing_files_unchanged_and_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let mut nan = tetrahedron();
    nan.positions[2][1] = f32::NAN;
    for ext in ["obj", "glb", "gltf", "ply", "stl", "off"] {
        let path = dir.path().join(format!("mesh.{ext}"));
        std::fs::write(&path, b"previous content").unwrap();
        let message = io::save(&path, &nan).unwrap_err().to_string();
        assert!(
            message.starts_with(&format!("{}: refusing to write", path.display())),
            "{message}"
        );
        assert!(message.contains("vertex 2"), "{message}");
        assert_eq!(std::fs::read(&path).unwrap(), b"previous content", "{ext}");
    }
    let expected: Vec<String> = ["glb", "gltf", "obj", "off", "ply", "stl"]
        .iter()
        .map(|e| format!("mesh.{e}"))
        .collect();
    assert_eq!(listing(dir.path()), expected);

    // A directory that does not exist: a write error, nothing created.
    let nowhere = dir.path().join("no/such/dir/mesh.glb");
    let message = io::save(&nowhere, &tetrahedron()).unwrap_err().to_string();
    assert!(
        message.starts_with(&format!("{}: cannot write", nowhere.display())),
        "{message}"
    );
    assert_eq!(listing(dir.path()), expected);

    // A successful save replaces the file and leaves no temporary behind.
    io::save(dir.path().join("mesh.gltf"), &tetrahedron()).unwrap();
    let mut with_bin = expected.clone();
    with_bin.push("mesh.bin".into());
    with_bin.sort();
    assert_eq!(listing(dir.path()), with_bin);
}

/// Inputs kept from fuzzing (tests/data/fuzz/<format>/): each must load or fail, never panic.
#[test]
fn fuzz_regressions_do_not_panic() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz");
    let mut count = 0;
    for (dir, format) in [
        ("obj", Format::Obj),
        ("gltf", Format::Glb),
        ("ply", Format::Ply),
        ("stl", Format::Stl),
        ("off", Format::Off),
    ] {
        let Ok(entries) = std::fs::read_dir(root.join(dir)) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if let Err(e) = io::load_from_bytes(&bytes, format, &name, &LoadOptions::default()) {
                assert!(e.to_string().starts_with(&format!("{name}: ")), "{e}");
            }
            count += 1;
        }
    }
    assert!(
        count > 0,
        "no fuzz regression inputs found under {}",
        root.display()
    );
}
