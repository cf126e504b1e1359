//! `docs/architecture.md` matches the tree: its "Source files" list names every Rust file under
//! `src/` by its path, and every path it names there exists.

use std::collections::BTreeSet;
use std::path::Path;

fn rust_files(dir: &Path, root: &Path, found: &mut BTreeSet<String>) {
    for entry in std::fs::read_dir(dir).expect("src/ is readable") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            rust_files(&path, root, found);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let relative = path.strip_prefix(root).expect("under src/");
            found.insert(relative.to_string_lossy().replace('\\', "/"));
        }
    }
}

/// The `src/...rs` paths named in the "Source files" section (between its heading and the next
/// `## ` heading), each written as `` `src/PATH.rs` ``.
fn named_files(doc: &str) -> BTreeSet<String> {
    let start = doc
        .find("\n## Source files")
        .expect("docs/architecture.md has a '## Source files' section");
    let section = &doc[start + 1..];
    let end = section[3..].find("\n## ").map_or(section.len(), |i| i + 3);
    let mut named = BTreeSet::new();
    for piece in section[..end].split('`').skip(1).step_by(2) {
        if let Some(path) = piece.strip_prefix("src/") {
            if path.ends_with(".rs") {
                named.insert(path.to_string());
            }
        }
    }
    named
}

#[test]
fn the_architecture_page_names_every_source_file_and_no_other() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = BTreeSet::new();
    rust_files(&root.join("src"), &root.join("src"), &mut files);
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).expect("the page exists");
    let named = named_files(&doc);
    let missing: Vec<_> = files.difference(&named).collect();
    let stale: Vec<_> = named.difference(&files).collect();
    assert!(
        missing.is_empty() && stale.is_empty(),
        "docs/architecture.md, 'Source files': not named: {missing:?}; named but not in src/: {stale:?}"
    );
    assert!(
        files.len() > 50,
        "found only {} files under src/",
        files.len()
    );
}
