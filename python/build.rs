//! The run-time docs of the extension's functions, methods and properties come from the type
//! stubs, `fairmesh/__init__.pyi`, so that `help()` and an editor say the same thing from one
//! source. For every `def` with a docstring this writes `$OUT_DIR/doc/<Class.>name.txt`: for a
//! function or method, the text signature CPython reads (`name(params)\n--\n\n`, the stub's
//! parameters without their annotations, `$self` for a method's first) and then the docstring
//! cleaned as `inspect.cleandoc` cleans it; for a property, the docstring alone. The Rust code
//! takes each with `#[doc = include_str!(...)]`; `tests/test_docs.py` checks the result against
//! the stubs with Python's own parser.
//!
//! The stubs are read line by line, which their plain layout allows: a `class` at the left
//! margin opens a class until the next line at the margin; `@overload`s of a name give
//! their defaults to the parameters of the one with the docstring.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

const STUBS: &str = "fairmesh/__init__.pyi";

fn main() {
    println!("cargo:rerun-if-changed={STUBS}");
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(Path::new(&manifest).join(STUBS))
        .unwrap_or_else(|e| panic!("cannot read {STUBS}: {e}"));
    let out = Path::new(&std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("doc");
    std::fs::create_dir_all(&out).expect("OUT_DIR is writable");
    for (key, doc) in docs(&text) {
        std::fs::write(out.join(format!("{key}.txt")), doc).expect("OUT_DIR is writable");
    }
}

/// One `def` of the stubs.
struct Def {
    /// `name` or `Class.name`.
    key: String,
    name: String,
    property: bool,
    /// (parameter as written without its annotation, default), in order; `*` and `/` as such.
    parameters: Vec<(String, Option<String>)>,
    doc: Option<String>,
}

/// The doc file of every documented def, by key.
fn docs(text: &str) -> BTreeMap<String, String> {
    let defs = parse(text);
    let mut docs = BTreeMap::new();
    for def in defs.iter().filter(|d| d.doc.is_some()) {
        let doc = def.doc.as_deref().unwrap_or_default();
        if def.property {
            docs.insert(def.key.clone(), doc.to_string());
            continue;
        }
        let mut signature = String::new();
        for (i, (name, default)) in def.parameters.iter().enumerate() {
            if i > 0 {
                signature.push_str(", ");
            }
            let default = default.clone().or_else(|| {
                // An overload of the same name that gives the parameter a default.
                defs.iter()
                    .filter(|other| other.key == def.key)
                    .flat_map(|other| other.parameters.iter())
                    .find(|(other, default)| other == name && default.is_some())
                    .and_then(|(_, default)| default.clone())
            });
            let shown = if i == 0 && name == "self" {
                "$self"
            } else {
                name
            };
            signature.push_str(shown);
            if let Some(default) = default {
                let _ = write!(signature, "={default}");
            }
        }
        docs.insert(
            def.key.clone(),
            format!("{}({signature})\n--\n\n{doc}", def.name),
        );
    }
    docs
}

fn parse(text: &str) -> Vec<Def> {
    let lines: Vec<&str> = text.lines().collect();
    let mut defs = Vec::new();
    let mut class: Option<String> = None;
    let mut property = false;
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        let stripped = line.trim_start();
        let at_margin = stripped.len() == line.len() && !stripped.is_empty();
        if at_margin {
            class = stripped.strip_prefix("class ").map(|rest| {
                rest.split(['(', ':'])
                    .next()
                    .unwrap_or(rest)
                    .trim()
                    .to_string()
            });
            if let Some(name) = &class {
                // A class's docstring, as a doc alone.
                let next = lines.get(i + 1).map_or("", |l| l.trim_start());
                if let Some(body) = next.strip_prefix("\"\"\"") {
                    let (doc, end) = docstring(&lines, i + 1, body);
                    defs.push(Def {
                        key: name.clone(),
                        name: name.clone(),
                        property: true,
                        parameters: Vec::new(),
                        doc: Some(doc),
                    });
                    i = end;
                    continue;
                }
            }
        }
        if stripped.starts_with("@property") {
            property = true;
        }
        let Some(rest) = stripped.strip_prefix("def ") else {
            i += 1;
            continue;
        };
        // The header runs until its parentheses close and a `:` ends a line.
        let mut header = rest.to_string();
        while !(depth(&header) == 0 && header_ends(&header)) {
            i += 1;
            header.push(' ');
            header.push_str(lines[i].trim());
        }
        i += 1;
        let open = header.find('(').expect("a def has parameters");
        let name = header[..open].trim().to_string();
        let close = matching_paren(&header, open);
        let parameters = split_top_level(&header[open + 1..close])
            .into_iter()
            .map(|p| parameter(&p))
            .collect();
        let one_liner = header.trim_end().ends_with("...");
        let mut doc = None;
        if !one_liner {
            // The docstring: the next line opens it.
            let first = lines[i].trim_start();
            if let Some(body) = first.strip_prefix("\"\"\"") {
                let (text, end) = docstring(&lines, i, body);
                doc = Some(text);
                i = end;
            }
        }
        let key = match &class {
            Some(class) if !at_margin_def(line) => format!("{class}.{name}"),
            _ => name.clone(),
        };
        defs.push(Def {
            key,
            name,
            property,
            parameters,
            doc,
        });
        property = false;
    }
    defs
}

/// The docstring that opens on line `first` with `body` after its quotes, cleaned, and the
/// line after it.
fn docstring(lines: &[&str], first: usize, body: &str) -> (String, usize) {
    let mut raw = String::from(body);
    let mut i = first;
    while !raw.contains("\"\"\"") {
        i += 1;
        raw.push('\n');
        raw.push_str(lines[i]);
    }
    let end = raw.find("\"\"\"").unwrap_or(raw.len());
    // Copied as written: an escape would read differently here and in Python.
    assert!(
        !raw[..end].contains('\\'),
        "{STUBS}: a docstring holds a backslash, which the run-time docs would not read as \
         Python does: {}",
        &raw[..end]
    );
    (clean(&raw[..end]), i + 1)
}

fn at_margin_def(line: &str) -> bool {
    line.starts_with("def ")
}

fn header_ends(header: &str) -> bool {
    let trimmed = header.trim_end();
    trimmed.ends_with(':') || trimmed.ends_with(": ...")
}

/// Each character of `text` with its byte index and, outside strings, the depth of the
/// brackets open just after it (`None` for a quote or a character inside a string).
fn scan(text: &str) -> impl Iterator<Item = (usize, char, Option<i32>)> + '_ {
    let mut depth = 0;
    let mut quote: Option<char> = None;
    text.char_indices().map(move |(i, c)| {
        let outside = match (quote, c) {
            (Some(q), c) if c == q => {
                quote = None;
                false
            }
            (Some(_), _) => false,
            (None, '"' | '\'') => {
                quote = Some(c);
                false
            }
            (None, '(' | '[' | '{') => {
                depth += 1;
                true
            }
            (None, ')' | ']' | '}') => {
                depth -= 1;
                true
            }
            _ => true,
        };
        (i, c, outside.then_some(depth))
    })
}

/// Open brackets minus closed ones, outside strings.
fn depth(text: &str) -> i32 {
    scan(text)
        .filter_map(|(_, _, depth)| depth)
        .last()
        .unwrap_or(0)
}

/// The index of the bracket that closes the one at `open`.
fn matching_paren(text: &str, open: usize) -> usize {
    scan(&text[open..])
        .find(|&(_, c, depth)| matches!(c, ')' | ']' | '}') && depth == Some(0))
        .map(|(i, _, _)| open + i)
        .unwrap_or_else(|| panic!("unclosed parameters in {STUBS}: {text}"))
}

/// The comma-separated parts of `text` outside brackets and strings, trimmed, empty ones left out.
fn split_top_level(text: &str) -> Vec<String> {
    let mut parts = vec![String::new()];
    for (_, c, depth) in scan(text) {
        match (c, depth) {
            (',', Some(0)) => parts.push(String::new()),
            _ => parts.last_mut().expect("one part at least").push(c),
        }
    }
    parts
        .into_iter()
        .map(|p| p.trim().to_string())
        .filter(|p| !p.is_empty())
        .collect()
}

/// `name: annotation = default` as (name, default).
fn parameter(text: &str) -> (String, Option<String>) {
    let (head, default) = match split_top_level_once(text, '=') {
        Some((head, default)) => (head, Some(default.trim().to_string())),
        None => (text, None),
    };
    let name = head.split(':').next().unwrap_or(head).trim().to_string();
    (name, default)
}

/// `text` split at the first `separator` outside brackets and strings.
fn split_top_level_once(text: &str, separator: char) -> Option<(&str, &str)> {
    scan(text)
        .find(|&(_, c, depth)| c == separator && depth == Some(0))
        .map(|(i, _, _)| (&text[..i], &text[i + separator.len_utf8()..]))
}

/// A docstring cleaned as `inspect.cleandoc` does: the first line stripped of leading spaces,
/// the common indentation of the others removed, blank lines at either end dropped.
fn clean(raw: &str) -> String {
    let lines: Vec<&str> = raw.lines().collect();
    let indent = lines
        .iter()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.len() - l.trim_start().len())
        .min()
        .unwrap_or(0);
    let mut cleaned: Vec<String> = Vec::with_capacity(lines.len());
    for (i, line) in lines.iter().enumerate() {
        let line = if i == 0 {
            line.trim_start()
        } else if line.len() >= indent {
            &line[indent..]
        } else {
            line.trim_start()
        };
        cleaned.push(line.trim_end().to_string());
    }
    while cleaned.first().is_some_and(|l| l.is_empty()) {
        cleaned.remove(0);
    }
    while cleaned.last().is_some_and(|l| l.is_empty()) {
        cleaned.pop();
    }
    cleaned.join("\n")
}
