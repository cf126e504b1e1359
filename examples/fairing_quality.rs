//! The fairing quality table: for each mesh, add noise of 0.3 mean edge lengths along the normals
//! (seed 1), then compare constrained fairing (1, 2, 3, 5, 10, 20, 30, 40, 60 rounds of 10 iterations, both
//! variants) with each baseline at its best iteration count (scanned), against the clean mesh.
//! Also measures how far each variant moves the vertices of the noise-free mesh.
//!
//! Run: `cargo run --release --example fairing_quality [DATA_DIR]`
//! (meshes bunny00, elephant, mushroom_open: read from DATA_DIR when given, otherwise from the
//! repository's `assets/` and `tests/data/`). `docs/measurements.md` holds the tables it printed.
//!
//! Measures (all lengths in mean edge lengths of the clean mesh):
//! - `surf mean`, `hausdorff`: `metrics::compare` (surface distance both ways through a BVH).
//!   The baselines' best iteration counts are picked with a cheaper local estimate of the mean
//!   surface distance (each vertex against the other mesh's triangles around the same vertex's
//!   3-ring; valid because both meshes share connectivity), then measured with `compare`.
//! - `rms`: vertex RMS distance to the clean mesh's same vertex (penalises sliding too).
//! - `normal`: mean angle between corresponding face normals, degrees.
//! - `vol`: volume change of the fairing against its noisy input, percent.

use fairmesh::fairing::{
    fair, BoundaryMode, FairOptions, FairVariant, HcOptions, LaplacianOptions, MethodOptions,
    TaubinOptions,
};
use fairmesh::metrics::{closest_point_on_triangle, mean_edge_length, signed_volume};
use fairmesh::noise::{add_noise, NoiseMode, NoiseOptions};
use fairmesh::{Topology, TriMesh};
use std::path::{Path, PathBuf};

/// Faces within the 3-ring of every vertex (shared connectivity), computed once per mesh.
fn local_faces(topology: &Topology, vertex_count: usize) -> Vec<Vec<u32>> {
    (0..vertex_count as u32)
        .map(|v| {
            let mut ring = vec![v];
            for _ in 0..2 {
                let mut grown = ring.clone();
                for &u in &ring {
                    grown.extend_from_slice(topology.neighbors(u));
                }
                grown.sort_unstable();
                grown.dedup();
                ring = grown;
            }
            let mut faces: Vec<u32> = ring
                .iter()
                .flat_map(|&u| topology.faces_of(u).to_vec())
                .collect();
            faces.sort_unstable();
            faces.dedup();
            faces
        })
        .collect()
}

struct Quality {
    surface_mean: f64,
    surface_max: f64,
    rms: f64,
    normal_degrees: f64,
    volume_percent: f64,
}

fn one_side(from: &TriMesh, to: &TriMesh, faces: &[Vec<u32>]) -> (f64, f64) {
    let mut sum = 0.0;
    let mut max: f64 = 0.0;
    for (v, near) in faces.iter().enumerate().take(from.positions.len()) {
        if near.is_empty() {
            continue;
        }
        let p = from.point(v as u32);
        let d = near
            .iter()
            .map(|&f| {
                let [a, b, c] = to.triangle_points(f as usize);
                (closest_point_on_triangle(p, a, b, c) - p).length()
            })
            .fold(f64::INFINITY, f64::min);
        sum += d;
        max = max.max(d);
    }
    (sum / from.positions.len() as f64, max)
}

/// Cheap two-sided mean surface distance (local search), used to pick the baselines' best
/// iteration counts; the table itself uses `metrics::compare`.
fn local_surface_distance(clean: &TriMesh, result: &TriMesh, faces: &[Vec<u32>]) -> f64 {
    0.5 * (one_side(result, clean, faces).0 + one_side(clean, result, faces).0)
}

fn quality(clean: &TriMesh, noisy: &TriMesh, result: &TriMesh, edge: f64) -> Quality {
    let comparison = fairmesh::metrics::compare(clean, result);
    let same = comparison
        .same_connectivity
        .expect("fairing keeps the connectivity");
    let v0 = signed_volume(noisy);
    Quality {
        surface_mean: comparison.mean_surface_distance / edge,
        surface_max: comparison.hausdorff / edge,
        rms: same.rms / edge,
        normal_degrees: same.normal_error_deg,
        volume_percent: 100.0 * (signed_volume(result) - v0) / v0.abs(),
    }
}

fn row(name: &str, setting: &str, q: &Quality) {
    println!(
        "| {name} | {setting} | {:.4} | {:.3} | {:.4} | {:.2} | {:+.4} |",
        q.surface_mean, q.surface_max, q.rms, q.normal_degrees, q.volume_percent
    );
}

fn main() {
    let repository = Path::new(env!("CARGO_MANIFEST_DIR"));
    let data_dirs = match std::env::args().nth(1) {
        Some(dir) => vec![PathBuf::from(dir)],
        None => vec![repository.join("assets"), repository.join("tests/data")],
    };
    for name in ["bunny00", "elephant", "mushroom_open"] {
        let file = format!("{name}.obj");
        let Some(path) = data_dirs
            .iter()
            .map(|d| d.join(&file))
            .find(|p| p.is_file())
        else {
            eprintln!("{file} is in none of {data_dirs:?}");
            std::process::exit(1);
        };
        let loaded =
            fairmesh::io::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let (clean, topology) = (loaded.mesh, loaded.topology);
        let edge = mean_edge_length(&clean);
        let faces = local_faces(&topology, clean.positions.len());

        println!(
            "\n### {name} ({} vertices, {} faces, {})",
            clean.vertex_count(),
            clean.face_count(),
            if topology.is_closed() {
                "closed"
            } else {
                "open"
            }
        );
        println!("\nNoise-free input, one run of 10 iterations:\n");
        println!("| variant | mean vertex move (edges) | max move (edges) | volume change % |\n|---|---:|---:|---:|");
        for variant in [FairVariant::Paper, FairVariant::Improved] {
            let mut faired = clean.clone();
            fair(
                &mut faired,
                &topology,
                &MethodOptions::Constrained(
                    FairOptions::default()
                        .with_variant(variant)
                        .with_rounds(1)
                        .with_creases(None)
                        .with_tangential_relaxation(0.0),
                ),
            );
            let moves: Vec<f64> = clean
                .positions
                .iter()
                .zip(&faired.positions)
                .map(|(a, b)| {
                    (0..3)
                        .map(|k| ((a[k] - b[k]) as f64).powi(2))
                        .sum::<f64>()
                        .sqrt()
                        / edge
                })
                .collect();
            let v0 = signed_volume(&clean);
            println!(
                "| {} | {:.4} | {:.3} | {:+.4} |",
                variant.name(),
                moves.iter().sum::<f64>() / moves.len() as f64,
                moves.iter().cloned().fold(0.0, f64::max),
                100.0 * (signed_volume(&faired) - v0) / v0.abs()
            );
        }

        let mut noisy = clean.clone();
        add_noise(
            &mut noisy,
            &NoiseOptions::default()
                .with_sigma(0.3)
                .with_seed(1)
                .with_mode(NoiseMode::Normal),
        );
        println!("\nNoise 0.3 mean edge lengths along normals (seed 1):\n");
        println!("| method | setting | surf mean | hausdorff | rms | normal ° | vol % |\n|---|---|---:|---:|---:|---:|---:|");
        row("noisy input", "-", &quality(&clean, &noisy, &noisy, edge));
        for variant in [FairVariant::Paper, FairVariant::Improved] {
            for rounds in [1, 2, 3, 5, 10, 20, 30, 40, 60] {
                let mut faired = noisy.clone();
                fair(
                    &mut faired,
                    &topology,
                    &MethodOptions::Constrained(
                        FairOptions::default()
                            .with_iterations(10)
                            .with_rounds(rounds)
                            .with_variant(variant)
                            .with_creases(None)
                            .with_tangential_relaxation(0.0)
                            .with_boundary(BoundaryMode::Curve)
                            .with_tolerance(0.0),
                    ),
                );
                row(
                    &format!("constrained {}", variant.name()),
                    &format!("{rounds} rounds"),
                    &quality(&clean, &noisy, &faired, edge),
                );
            }
        }
        // Baselines: one iteration at a time, keeping the best surface distance.
        let baselines: [(&str, MethodOptions, usize); 3] = [
            (
                "laplacian λ=0.5",
                MethodOptions::Laplacian(LaplacianOptions {
                    iterations: 1,
                    ..Default::default()
                }),
                60,
            ),
            (
                "taubin 0.5/-0.53",
                MethodOptions::Taubin(TaubinOptions {
                    iterations: 1,
                    ..Default::default()
                }),
                200,
            ),
            (
                "hc β=0.5",
                MethodOptions::Hc(HcOptions {
                    iterations: 1,
                    ..Default::default()
                }),
                200,
            ),
        ];
        for (label, options, max_iterations) in baselines {
            let mut current = noisy.clone();
            let mut best: Option<(usize, f64)> = None;
            for iteration in 1..=max_iterations {
                fair(&mut current, &topology, &options);
                let score = local_surface_distance(&clean, &current, &faces);
                if best.is_none_or(|(_, b)| score < b) {
                    best = Some((iteration, score));
                }
            }
            let (iterations, _) = best.expect("at least one iteration");
            let mut at_best = noisy.clone();
            for _ in 0..iterations {
                fair(&mut at_best, &topology, &options);
            }
            let q = quality(&clean, &noisy, &at_best, edge);
            row(
                label,
                &format!("best: {iterations} it. (of {max_iterations})"),
                &q,
            );
        }
    }
}
