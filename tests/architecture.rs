//! `docs/architecture.md` matches the tree: its "Source files" list names every Rust file of the
//! library (`src/`), the editor (`editor/src/`), the binary (`cli/src/`) and the web page's entry
//! point (`web/src/`) by its path from the
//! repository's root, and every path it names there exists.

use std::collections::BTreeSet;
use std::path::Path;

fn rust_files(dir: &Path, root: &Path, found: &mut BTreeSet<String>) {
    for entry in std::fs::read_dir(dir).expect("src/ is readable") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            rust_files(&path, root, found);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let relative = path.strip_prefix(root).expect("under the repository");
            found.insert(relative.to_string_lossy().replace('\\', "/"));
        }
    }
}

/// The folders whose Rust files the page lists, from the repository's root.
const SOURCE_FOLDERS: [&str; 4] = ["src/", "editor/src/", "cli/src/", "web/src/"];

/// The `.rs` paths under [`SOURCE_FOLDERS`] named in the "Source files" section (between its
/// heading and the next `## ` heading), each written as `` `FOLDER/PATH.rs` ``.
fn named_files(doc: &str) -> BTreeSet<String> {
    let start = doc
        .find("\n## Source files")
        .expect("docs/architecture.md has a '## Source files' section");
    let section = &doc[start + 1..];
    let end = section[3..].find("\n## ").map_or(section.len(), |i| i + 3);
    let mut named = BTreeSet::new();
    for piece in section[..end].split('`').skip(1).step_by(2) {
        if piece.ends_with(".rs") && SOURCE_FOLDERS.iter().any(|f| piece.starts_with(f)) {
            named.insert(piece.to_string());
        }
    }
    named
}

#[test]
fn the_architecture_page_names_every_source_file_and_no_other() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = BTreeSet::new();
    for folder in SOURCE_FOLDERS {
        rust_files(&root.join(folder), root, &mut files);
    }
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).expect("the page exists");
    let named = named_files(&doc);
    let missing: Vec<_> = files.difference(&named).collect();
    let stale: Vec<_> = named.difference(&files).collect();
    assert!(
        missing.is_empty() && stale.is_empty(),
        "docs/architecture.md, 'Source files': not named: {missing:?}; named but not in the tree: {stale:?}"
    );
    assert!(files.len() > 150, "found only {} source files", files.len());
}

/// The library stands alone: none of the GUI stack is among its dependencies, direct or
/// transitive (the editor is a crate of its own, `fairmesh-editor`, that uses the library), on
/// the machine's own target and on the web page's (`wasm32-unknown-unknown`). Reads `cargo tree`
/// of the package offline, from `Cargo.lock`.
#[test]
fn the_library_depends_on_no_gui_crate() {
    for target in ["", "wasm32-unknown-unknown"] {
        library_depends_on_no_gui_crate(target);
    }
}

/// [`the_library_depends_on_no_gui_crate`] on `target` (empty: the machine's own).
fn library_depends_on_no_gui_crate(target: &str) {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let mut command = std::process::Command::new(cargo);
    command.current_dir(env!("CARGO_MANIFEST_DIR")).args([
        "tree",
        "--offline",
        "--locked",
        "-p",
        "fairmesh",
        "-e",
        "normal",
    ]);
    if !target.is_empty() {
        command.args(["--target", target]);
    }
    let output = command
        .args(["--prefix", "none", "--format", "{p}"])
        .output()
        .expect("cargo runs");
    assert!(
        output.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let tree = String::from_utf8_lossy(&output.stdout);
    let crates: BTreeSet<&str> = tree
        .lines()
        .filter_map(|line| line.split_whitespace().next())
        .collect();
    assert!(
        crates.contains("glam") && crates.contains("rayon"),
        "{tree}"
    );
    for gui in [
        "eframe",
        "egui",
        "egui-wgpu",
        "wgpu",
        "winit",
        "rfd",
        "clap",
        "anyhow",
    ] {
        assert!(
            !crates.contains(gui),
            "the library depends on {gui}:\n{tree}"
        );
    }
}
