//! The binary needs no files beside it: `@bunny` reads the bunny compiled into it from an empty
//! folder; STL is written like the other formats; an error says each thing once.
//! (`scripts/check_clean_clone.sh` checks the same with a copy of the binary in an empty folder,
//! and the editor in a real window.)

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

/// Runs the binary in `dir`.
fn fairmesh_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fairmesh"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the fairmesh binary runs")
}

fn json(out: &Output) -> Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

#[test]
fn the_bundled_bunny_is_read_without_any_file() {
    let empty = tempfile::tempdir().unwrap();
    let info = json(&fairmesh_in(empty.path(), &["info", "@bunny", "--json"]));
    assert_eq!(info["vertices"], 37706);
    assert_eq!(info["faces"], 75408);
    assert_eq!(info["closed"], true);
    // A real file of that name is reachable as `./@bunny` (here there is none).
    let out = fairmesh_in(empty.path(), &["info", "./@bunny"]);
    assert!(!out.status.success());
    // Every subcommand that reads a mesh takes it, and the files written hold the bunny.
    let same = json(&fairmesh_in(
        empty.path(),
        &["compare", "@bunny", "@bunny", "--json"],
    ));
    assert!(same["hausdorff"].as_f64().unwrap() < 1e-6, "{same}");
    assert_eq!(same["rms"], 0.0);
}

#[test]
fn stl_is_written_and_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let out = fairmesh_in(dir.path(), &["convert", "@bunny", "-o", "bunny.stl"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let info = json(&fairmesh_in(dir.path(), &["info", "bunny.stl", "--json"]));
    // STL stores every triangle's corners apart; welding on load joins them again.
    assert_eq!(info["vertices"], 37706);
    assert_eq!(info["faces"], 75408);
    let help = fairmesh_in(dir.path(), &["--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.contains(".stl .off, to read and to write"), "{help}");
}

/// `fairmesh info missing.glb` names the file and says why once (the cause used to be printed
/// twice: once in the error's message and once more as its source).
#[test]
fn a_missing_file_is_named_and_the_cause_said_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = fairmesh_in(dir.path(), &["info", "missing.glb"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("missing.glb"), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    // No clause of the message is repeated.
    let clauses: Vec<&str> = lines[0].split(": ").collect();
    for (i, clause) in clauses.iter().enumerate() {
        assert!(
            !clauses[i + 1..].contains(clause),
            "`{clause}` is said twice: {stderr}"
        );
    }
}
