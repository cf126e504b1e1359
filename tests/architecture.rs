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

/// The most named fields a struct of the editor or the web page may have: a bigger one is state
/// that any task can change, which the editor keeps in owned parts instead.
const MAX_STRUCT_FIELDS: usize = 20;

/// The folders whose structs [`MAX_STRUCT_FIELDS`] bounds.
const PARTED_FOLDERS: [&str; 2] = ["editor/src/", "web/src/"];

#[test]
fn no_struct_of_the_editor_or_the_web_page_has_more_than_20_fields() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = BTreeSet::new();
    for folder in PARTED_FOLDERS {
        rust_files(&root.join(folder), root, &mut files);
    }
    let mut structs = 0;
    let mut too_big = Vec::new();
    for file in &files {
        let source = std::fs::read_to_string(root.join(file)).expect("a source file is readable");
        for (name, fields) in struct_field_counts(&source) {
            structs += 1;
            if fields > MAX_STRUCT_FIELDS {
                too_big.push(format!("{file}: {name} has {fields} fields"));
            }
        }
    }
    assert!(
        too_big.is_empty(),
        "structs of more than {MAX_STRUCT_FIELDS} fields (split them into owned parts): {too_big:#?}"
    );
    assert!(
        structs > 50,
        "found only {structs} structs with named fields"
    );
}

#[test]
fn the_field_count_sees_past_comments_strings_attributes_and_nested_types() {
    let fields: String = (0..21)
        .map(|i| {
            format!(
                "    /// Field {i}, a: b.\n    #[serde(default)]\n    pub f{i}: Vec<(u32, u8)>,\n"
            )
        })
        .collect();
    let source = format!(
        "// struct Commented {{ a: u8, b: u8 }}\nconst S: &str = \"struct Quoted {{ a: u8 }}\";\n\
         pub struct Big<'a, T: Copy> where T: Send {{\n{fields}    call: fn(u8) -> Option<u8>,\n    \
         path: std::path::PathBuf,\n    tag: &'a T, /* c: u8, */\n}}\n\
         struct Tuple(u8, u8);\nstruct Unit;\nmacro_rules! m {{ () => {{ struct $name {{ a: u8 }} }} }}\n\
         struct Small {{ c: char, q: [u8; 2], }}\nconst C: char = '{{';\n"
    );
    assert_eq!(
        struct_field_counts(&source),
        vec![("Big".to_string(), 24), ("Small".to_string(), 2)]
    );
}

/// Each struct with named fields in `source` (a Rust file) and how many fields it has.
fn struct_field_counts(source: &str) -> Vec<(String, usize)> {
    let code: Vec<char> = code_only(source).chars().collect();
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut found = Vec::new();
    let mut at = 0;
    while at + 6 <= code.len() {
        let keyword = code[at..at + 6].iter().collect::<String>() == "struct"
            && (at == 0 || !is_ident(code[at - 1]) && code[at - 1] != '$')
            && code.get(at + 6).is_some_and(|c| c.is_whitespace());
        if !keyword {
            at += 1;
            continue;
        }
        at += 6;
        while code.get(at).is_some_and(|c| c.is_whitespace()) {
            at += 1;
        }
        let name_start = at;
        while code.get(at).is_some_and(|&c| is_ident(c)) {
            at += 1;
        }
        let name: String = code[name_start..at].iter().collect();
        if name.is_empty() || name.starts_with(|c: char| c.is_ascii_digit()) {
            continue;
        }
        // Past the generics and the where clause to the body: `{` (named fields), else a tuple
        // or unit struct.
        let mut angle = 0usize;
        while let Some(&c) = code.get(at) {
            match c {
                '<' => angle += 1,
                '>' if code[at - 1] != '-' => angle = angle.saturating_sub(1),
                '{' | ';' | '(' if angle == 0 => break,
                _ => {}
            }
            at += 1;
        }
        if code.get(at) != Some(&'{') {
            continue;
        }
        let (fields, end) = named_fields(&code, at);
        found.push((name, fields));
        at = end;
    }
    found
}

/// The named fields of the struct body opening at `open` (a `{`), and where the body ends.
fn named_fields(code: &[char], open: usize) -> (usize, usize) {
    let mut depth = 0usize;
    let mut segments = Vec::new();
    let mut segment = String::new();
    let mut at = open;
    while let Some(&c) = code.get(at) {
        at += 1;
        match c {
            '{' | '(' | '[' | '<' => depth += 1,
            '>' if code[at - 2] == '-' => {}
            '}' | ')' | ']' | '>' => {
                depth -= 1;
                if depth == 0 {
                    break;
                }
            }
            ',' if depth == 1 => {
                segments.push(std::mem::take(&mut segment));
                continue;
            }
            _ => {}
        }
        // Everything inside the body but its opening brace.
        if depth > 1 || c != '{' {
            segment.push(c);
        }
    }
    segments.push(segment);
    let named = segments
        .iter()
        .filter(|segment| {
            let mut rest = segment.trim();
            // Attributes, then the visibility.
            while let Some(attribute) = rest.strip_prefix("#[") {
                let close = attribute.find(']').map_or(attribute.len(), |i| i + 1);
                rest = attribute[close..].trim_start();
            }
            if let Some(public) = rest.strip_prefix("pub") {
                rest = public.trim_start();
                if rest.starts_with('(') {
                    rest = rest[rest.find(')').map_or(rest.len(), |i| i + 1)..].trim_start();
                }
            }
            let name_end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == '#'))
                .unwrap_or(rest.len());
            let after = rest[name_end..].trim_start();
            name_end > 0
                && !rest.starts_with(|c: char| c.is_ascii_digit())
                && after.starts_with(':')
                && !after.starts_with("::")
        })
        .count();
    (named, at)
}

/// `source` with its comments, strings and character literals blanked out (lifetimes kept).
fn code_only(source: &str) -> String {
    let chars: Vec<char> = source.chars().collect();
    let mut code = String::with_capacity(source.len());
    let mut at = 0;
    while at < chars.len() {
        let c = chars[at];
        let next = chars.get(at + 1).copied();
        if c == '/' && next == Some('/') {
            while at < chars.len() && chars[at] != '\n' {
                at += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while at < chars.len() {
                if chars[at] == '/' && chars.get(at + 1) == Some(&'*') {
                    depth += 1;
                    at += 2;
                } else if chars[at] == '*' && chars.get(at + 1) == Some(&'/') {
                    depth -= 1;
                    at += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    at += 1;
                }
            }
            code.push(' ');
        } else if c == 'r' && (next == Some('"') || next == Some('#') && raw_string_at(&chars, at))
        {
            // A raw string: r"…", r#"…"#, …
            at += 1;
            let mut hashes = 0;
            while chars.get(at) == Some(&'#') {
                hashes += 1;
                at += 1;
            }
            at += 1;
            while at < chars.len() {
                if chars[at] == '"' && (1..=hashes).all(|i| chars.get(at + i) == Some(&'#')) {
                    at += 1 + hashes;
                    break;
                }
                at += 1;
            }
            code.push_str("\"\"");
        } else if c == '"' {
            at += 1;
            while at < chars.len() && chars[at] != '"' {
                at += if chars[at] == '\\' { 2 } else { 1 };
            }
            at += 1;
            code.push_str("\"\"");
        } else if c == '\'' && (next == Some('\\') || chars.get(at + 2) == Some(&'\'')) {
            // A character literal ('x', '\n', '\u{..}'); otherwise a lifetime.
            at += 1;
            while at < chars.len() && chars[at] != '\'' {
                at += if chars[at] == '\\' { 2 } else { 1 };
            }
            at += 1;
            code.push_str("' '");
        } else {
            code.push(c);
            at += 1;
        }
    }
    code
}

/// Whether `r#` at `at` opens a raw string (`r#"`), not a raw identifier (`r#type`).
fn raw_string_at(chars: &[char], at: usize) -> bool {
    let mut after = at + 1;
    while chars.get(after) == Some(&'#') {
        after += 1;
    }
    chars.get(after) == Some(&'"')
}
