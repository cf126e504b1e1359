//! The command-line tool end to end: `info`, `noise`, `convert`, `compare` on the real meshes, and
//! errors (exit code 1, the file named on stderr).

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn fairmesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fairmesh"))
        .args(args)
        .output()
        .expect("the fairmesh binary runs")
}

fn json_of(args: &[&str]) -> Value {
    let out = fairmesh(args);
    assert!(
        out.status.success(),
        "fairmesh {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

fn data(name: &str) -> String {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path: PathBuf = if name == "bunny00.obj" {
        dir.join("assets").join(name)
    } else {
        dir.join("tests/data").join(name)
    };
    path.to_string_lossy().into_owned()
}

#[test]
fn info_reports_the_topology_of_the_real_meshes() {
    // (file, vertices, faces, boundary loops, genus)
    for (file, vertices, faces, loops, genus) in [
        ("bunny00.obj", 37706, 75408, 0, 0),
        ("bunny_npm.obj", 1839, 3674, 0, 0),
        ("elephant.obj", 2775, 5558, 0, 3),
        ("mushroom_open.obj", 2337, 4608, 1, 0),
    ] {
        let info = json_of(&["info", &data(file), "--json"]);
        assert_eq!(info["vertices"], vertices, "{file}");
        assert_eq!(info["faces"], faces, "{file}");
        assert_eq!(info["boundary_loops"], loops, "{file}");
        assert_eq!(info["components"], 1, "{file}");
        assert_eq!(info["genus"][0], genus, "{file}");
        assert_eq!(info["closed"], loops == 0, "{file}");
        assert_eq!(info["manifold"], true, "{file}");
        assert_eq!(info["welded_vertices"], 0, "{file}");
        assert!(
            info["area"].as_f64().unwrap() > 0.0
                && info["mean_edge_length"].as_f64().unwrap() > 0.0
        );
        // Euler: V - E + F = 2 - 2g - b.
        let euler = vertices as i64 - info["edges"].as_i64().unwrap() + faces as i64;
        assert_eq!(euler, 2 - 2 * genus - loops, "{file}");
        if loops == 0 {
            assert!(
                info["volume"].as_f64().unwrap() > 0.0,
                "{file}: outward-oriented closed mesh"
            );
        } else {
            assert!(
                info["volume"].is_null(),
                "{file}: an open mesh has no volume"
            );
        }
    }
    assert_eq!(
        json_of(&["info", &data("mushroom_open.obj"), "--json"])["boundary_loop_lengths"][0],
        64
    );
}

#[test]
fn noise_is_seeded_and_as_large_as_asked() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let input = data("elephant.obj");
    for (name, seed) in [("a.obj", "5"), ("b.obj", "5"), ("c.obj", "6")] {
        let result = fairmesh(&[
            "noise",
            &input,
            "-o",
            &out(name),
            "--sigma",
            "0.3",
            "--seed",
            seed,
            "--mode",
            "normal",
        ]);
        assert!(
            result.status.success(),
            "{}",
            String::from_utf8_lossy(&result.stderr)
        );
    }
    let read = |name: &str| std::fs::read(out(name)).unwrap();
    assert_eq!(
        read("a.obj"),
        read("b.obj"),
        "the same seed gives the same file"
    );
    assert_ne!(
        read("a.obj"),
        read("c.obj"),
        "another seed gives other noise"
    );

    let compare = json_of(&["compare", &input, &out("a.obj"), "--json"]);
    let mean_edge = compare["reference_mean_edge_length"].as_f64().unwrap();
    let rms = compare["rms"]
        .as_f64()
        .expect("noise keeps the connectivity");
    assert!(
        (rms / (0.3 * mean_edge) - 1.0).abs() < 0.1,
        "vertex RMS {rms} against sigma {}",
        0.3 * mean_edge
    );
    assert!(compare["mean_surface_distance"].as_f64().unwrap() > 0.1 * mean_edge);
    assert!(
        compare["hausdorff"].as_f64().unwrap() >= compare["max_distance"].as_f64().unwrap() * 0.5
    );

    for mode in ["direction", "iso"] {
        let result = fairmesh(&[
            "noise",
            &input,
            "-o",
            &out("m.ply"),
            "--sigma",
            "0.1",
            "--mode",
            mode,
        ]);
        assert!(
            result.status.success(),
            "{mode}: {}",
            String::from_utf8_lossy(&result.stderr)
        );
    }
}

#[test]
fn compare_of_a_mesh_with_itself_is_zero_and_of_a_scaled_copy_is_not() {
    let input = data("bunny_npm.obj");
    let same = json_of(&["compare", &input, &input, "--json"]);
    for key in [
        "mean_surface_distance",
        "hausdorff",
        "rms",
        "max_distance",
        "normal_error_deg",
        "barycenter_drift",
    ] {
        assert!(
            same[key].as_f64().unwrap().abs() < 1e-9,
            "{key} = {}",
            same[key]
        );
    }
    assert_eq!(same["volume_change_percent"].as_f64().unwrap(), 0.0);

    // Scale the mesh by 2% about the origin in a hand-written OBJ: volume grows by 6.12%.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(&input).unwrap();
    let scaled: String = text
        .lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(rest) => {
                let c: Vec<f64> = rest
                    .split_whitespace()
                    .map(|x| x.parse::<f64>().unwrap() * 1.02)
                    .collect();
                format!("v {} {} {}\n", c[0], c[1], c[2])
            }
            None => format!("{line}\n"),
        })
        .collect();
    let scaled_path = dir.path().join("scaled.obj");
    std::fs::write(&scaled_path, scaled).unwrap();
    let result = json_of(&["compare", &input, scaled_path.to_str().unwrap(), "--json"]);
    let change = result["volume_change_percent"].as_f64().unwrap();
    assert!(
        (change - (1.02f64.powi(3) - 1.0) * 100.0).abs() < 1e-3,
        "volume change {change}%"
    );
    assert!(result["mean_surface_distance"].as_f64().unwrap() > 0.0);
}

#[test]
fn errors_name_the_file_and_exit_with_code_1() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no_such_mesh.obj");
    let out = fairmesh(&["info", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("no_such_mesh.obj"), "stderr: {stderr}");
    assert!(out.stdout.is_empty());

    let bad_sigma = fairmesh(&[
        "noise",
        &data("elephant.obj"),
        "-o",
        dir.path().join("x.obj").to_str().unwrap(),
        "--sigma",
        "NaN",
    ]);
    assert_eq!(bad_sigma.status.code(), Some(1));
    assert!(!dir.path().join("x.obj").exists());
}
