//! In-memory folders (`fairmesh::io::MemoryFolder`): a file set held in memory loads and saves as
//! the same files on disk do: an OBJ finds its `.mtl` and texture, a `.gltf` its `.bin` and
//! image, and a save writes the same files with the same bytes into another memory folder as
//! into a folder on disk.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use fairmesh::io::{self, MemoryFolder};

const ROUNDTRIP: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/roundtrip");

/// The files of a folder on disk, by name, with their bytes.
fn files_on_disk(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|entry| {
            let path = entry.unwrap().path();
            let name = PathBuf::from(path.file_name().unwrap());
            (name, std::fs::read(&path).unwrap())
        })
        .collect()
}

/// A memory folder at `root` holding `names` from the round-trip assets.
fn memory_copy(root: &str, names: &[&str]) -> MemoryFolder {
    let folder = MemoryFolder::new(root);
    for name in names {
        folder.insert(
            name,
            std::fs::read(Path::new(ROUNDTRIP).join(name)).unwrap(),
        );
    }
    folder
}

/// Loads `main` from disk and from a memory copy of `names`, moves both meshes the same way and
/// saves each to `out_name` (on disk and in memory): the same mesh, the same warnings, the same
/// files written.
fn same_as_on_disk(tag: &str, names: &[&str], main: &str, out_name: &str) {
    let input = memory_copy(&format!("/fairmesh-test-io-memory/{tag}/in"), names);
    let from_disk = io::load(Path::new(ROUNDTRIP).join(main)).unwrap();
    let from_memory = io::load(input.path(main)).unwrap();
    assert_eq!(from_memory.mesh.positions, from_disk.mesh.positions);
    assert_eq!(from_memory.mesh.triangles, from_disk.mesh.triangles);
    assert_eq!(from_memory.report.warnings, from_disk.report.warnings);

    let mut moved = from_disk.mesh.clone();
    for p in &mut moved.positions {
        p[1] += 0.01 * p[0];
    }
    let dir = tempfile::tempdir().unwrap();
    let disk_report =
        io::save_with_source(dir.path().join(out_name), &moved, &from_disk.source).unwrap();
    let output = MemoryFolder::new(format!("/fairmesh-test-io-memory/{tag}/out"));
    let memory_report =
        io::save_with_source(output.path(out_name), &moved, &from_memory.source).unwrap();
    assert_eq!(memory_report.warnings, disk_report.warnings);
    let written: BTreeMap<PathBuf, Vec<u8>> = output.files().into_iter().collect();
    let on_disk = files_on_disk(dir.path());
    assert_eq!(
        written.keys().collect::<Vec<_>>(),
        on_disk.keys().collect::<Vec<_>>()
    );
    assert!(
        written == on_disk,
        "{tag}: a file differs between memory and disk"
    );
    // The write-back read back from memory is the moved mesh.
    let again = io::load(output.path(out_name)).unwrap();
    assert_eq!(again.mesh.triangles.len(), moved.triangles.len());
}

#[test]
fn an_obj_with_its_mtl_and_texture_loads_and_saves_from_memory_as_from_disk() {
    same_as_on_disk(
        "obj",
        &["textured.obj", "textured.mtl", "textured.png"],
        "textured.obj",
        "faired.obj",
    );
}

#[test]
fn a_gltf_with_its_bin_and_image_loads_and_saves_from_memory_as_from_disk() {
    same_as_on_disk(
        "gltf",
        &["scene.gltf", "scene.bin", "checker.png"],
        "scene.gltf",
        "faired.gltf",
    );
    // Saved as a GLB the image is embedded: one file.
    same_as_on_disk(
        "glb",
        &["scene.gltf", "scene.bin", "checker.png"],
        "scene.gltf",
        "faired.glb",
    );
}

#[test]
fn a_missing_companion_is_named_as_on_disk() {
    // The .mtl is not given: the OBJ loads, and its export into another folder names the
    // library it cannot copy, as it does when the .mtl is missing on disk.
    let input = memory_copy("/fairmesh-test-io-memory/missing/in", &["textured.obj"]);
    let loaded = io::load(input.path("textured.obj")).unwrap();
    let output = MemoryFolder::new("/fairmesh-test-io-memory/missing/out");
    let report =
        io::save_with_source(output.path("out.obj"), &loaded.mesh, &loaded.source).unwrap();
    let alone = tempfile::tempdir().unwrap();
    std::fs::copy(
        Path::new(ROUNDTRIP).join("textured.obj"),
        alone.path().join("textured.obj"),
    )
    .unwrap();
    let on_disk = io::load(alone.path().join("textured.obj")).unwrap();
    let out_dir = tempfile::tempdir().unwrap();
    let disk_report = io::save_with_source(
        out_dir.path().join("out.obj"),
        &on_disk.mesh,
        &on_disk.source,
    )
    .unwrap();
    let warnings = report.warnings.join("\n");
    assert!(warnings.contains("textured.mtl"), "{warnings}");
    // The same words, the folders apart.
    let in_words = |warnings: &[String], input: &Path, output: &Path| -> Vec<String> {
        let (input, output) = (input.display().to_string(), output.display().to_string());
        warnings
            .iter()
            .map(|w| w.replace(&input, "IN").replace(&output, "OUT"))
            .collect()
    };
    assert_eq!(
        in_words(&report.warnings, input.root(), output.root()),
        in_words(&disk_report.warnings, alone.path(), out_dir.path())
    );
    assert_eq!(output.files().len(), 1);
    // A glTF whose buffer is missing fails with the file named.
    let input = memory_copy("/fairmesh-test-io-memory/missing/gltf", &["scene.gltf"]);
    let error = io::load(input.path("scene.gltf")).unwrap_err().to_string();
    assert!(error.contains("scene.bin"), "{error}");
}

#[test]
fn a_failed_save_into_memory_leaves_nothing() {
    let output = MemoryFolder::new("/fairmesh-test-io-memory/failed/out");
    let mut mesh = io::load(Path::new(ROUNDTRIP).join("textured.obj"))
        .unwrap()
        .mesh;
    mesh.positions[0][0] = f32::NAN;
    assert!(io::save(output.path("bad.obj"), &mesh).is_err());
    assert!(output.files().is_empty());
}
