//! The default fairing's table: on a set of clean meshes (scans and CAD-like parts), and on each
//! with noise of 0.3 mean edge lengths along the normals and per coordinate (isotropic), how far
//! default `fair` (automatic strength, creases kept) ends from the clean surface, next to the
//! previous default (one round of 10 iterations, no creases) and to fixed round counts.
//!
//! Run: `cargo run --release --no-default-features --example fairing_default [-- --trace]`
//! (`--only gear,cube` runs just those meshes; `--trace` also prints, per round, the noise estimate and the distance to the clean surface,
//! the data the automatic rule was tuned on). `docs/measurements.md` holds what it printed and
//! says which meshes the rule was tuned on and which were kept out.
//!
//! Measures (lengths in mean edge lengths of the clean mesh): `mean`, `hausdorff`: surface
//! distance both ways (`metrics::compare`); `normal`: mean angle between corresponding face
//! normals, degrees; `vol`: volume change against the mesh that was faired, percent.

use fairmesh::fairing::{estimate_noise, fair_constrained, ConstrainedFairing, FairOptions};
use fairmesh::mesh::shapes;
use fairmesh::metrics::{compare, mean_edge_length, signed_volume};
use fairmesh::noise::{add_noise, NoiseMode, NoiseOptions};
use fairmesh::{Topology, TriMesh};
use std::path::Path;

fn meshes() -> Vec<(String, TriMesh)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut list: Vec<(String, TriMesh)> = [
        "assets/bunny00.obj",
        "tests/data/elephant.obj",
        "tests/data/bunny_npm.obj",
        "tests/data/mushroom_open.obj",
    ]
    .iter()
    .map(|file| {
        let path = root.join(file);
        let mesh = fairmesh::io::load(&path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .mesh;
        let name = Path::new(file).file_stem().unwrap().to_string_lossy();
        (name.into_owned(), mesh)
    })
    .collect();
    list.extend([
        ("cube".to_string(), shapes::cuboid([1.0, 1.0, 1.0], 0.05)),
        (
            "thin plate".to_string(),
            shapes::cuboid([2.0, 1.5, 0.1], 0.05),
        ),
        ("cylinder".to_string(), shapes::cylinder(0.5, 1.5, 0.05)),
        ("gear".to_string(), shapes::gear(16, 1.0, 1.25, 0.3, 0.04)),
        ("d prism".to_string(), shapes::d_prism(1.0, 0.7, 0.5, 0.05)),
    ]);
    list
}

struct Row {
    mean: f64,
    hausdorff: f64,
    normal: f64,
    volume: f64,
}

fn measure(clean: &TriMesh, input: &TriMesh, result: &TriMesh, edge: f64) -> Row {
    let c = compare(clean, result);
    let v0 = signed_volume(input);
    Row {
        mean: c.mean_surface_distance / edge,
        hausdorff: c.hausdorff / edge,
        normal: c.same_connectivity.map_or(f64::NAN, |s| s.normal_error_deg),
        volume: 100.0 * (signed_volume(result) - v0) / v0.abs(),
    }
}

fn print(mesh: &str, input: &str, setting: &str, r: &Row) {
    println!(
        "| {mesh} | {input} | {setting} | {:.4} | {:.3} | {:.2} | {:+.4} |",
        r.mean, r.hausdorff, r.normal, r.volume
    );
}

fn main() {
    let trace = std::env::args().any(|a| a == "--trace");
    println!("| mesh | input | setting | mean | hausdorff | normal ° | vol % |");
    println!("|---|---|---|---:|---:|---:|---:|");
    // `--only NAME[,NAME]`: just those meshes.
    let args: Vec<String> = std::env::args().collect();
    let only: Option<Vec<String>> = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .map(|list| list.split(',').map(str::to_string).collect());
    for (name, clean) in meshes() {
        if only.as_ref().is_some_and(|only| !only.contains(&name)) {
            continue;
        }
        let topology = Topology::build(&clean);
        let edge = mean_edge_length(&clean);
        let inputs = [
            ("clean", None),
            ("normal 0.3", Some(NoiseMode::Normal)),
            ("isotropic 0.3", Some(NoiseMode::Isotropic)),
        ];
        for (label, mode) in inputs {
            let mut input = clean.clone();
            if let Some(mode) = mode {
                add_noise(
                    &mut input,
                    &NoiseOptions::default().with_sigma(0.3).with_mode(mode),
                );
            }
            let mut faired = input.clone();
            let report = fair_constrained(&mut faired, &topology, &FairOptions::default());
            print(
                &name,
                label,
                &format!(
                    "default: noise {:.3}, {} rounds, {} crease edges",
                    report.noise_estimate.unwrap_or(f64::NAN),
                    report.rounds_run,
                    report.crease_edges
                ),
                &measure(&clean, &input, &faired, edge),
            );
            let mut normal_only = input.clone();
            let options = FairOptions::default().with_tangential_relaxation(0.0);
            let report = fair_constrained(&mut normal_only, &topology, &options);
            print(
                &name,
                label,
                &format!(
                    "default without tangential relaxation: {} rounds",
                    report.rounds_run
                ),
                &measure(&clean, &input, &normal_only, edge),
            );
            let mut no_volume = input.clone();
            let options = FairOptions::default().with_keep_volume(false);
            let report = fair_constrained(&mut no_volume, &topology, &options);
            print(
                &name,
                label,
                &format!(
                    "default without the volume correction: {} rounds",
                    report.rounds_run
                ),
                &measure(&clean, &input, &no_volume, edge),
            );
            let mut old = input.clone();
            let old_options = FairOptions::default()
                .with_rounds(1)
                .with_creases(None)
                .with_tangential_relaxation(0.0)
                .with_keep_volume(false);
            fair_constrained(&mut old, &topology, &old_options);
            print(
                &name,
                label,
                "previous default",
                &measure(&clean, &input, &old, edge),
            );
            if trace && mode.is_some() {
                let options = FairOptions::default()
                    .with_rounds(1)
                    .with_creases(None)
                    .with_tangential_relaxation(0.0);
                let mut fairing =
                    ConstrainedFairing::new(&input, &topology, options.variant, options.boundary);
                let mut current = input.clone();
                fairing.load(&current.positions);
                let mut report = Default::default();
                for round in 1..=60 {
                    if round > 1 {
                        fairing.reanchor();
                    }
                    fairing.run_round(&options, &mut report);
                    fairing.store(&mut current.positions);
                    if [1, 2, 3, 5, 8, 12, 20, 30, 45, 60].contains(&round) {
                        let noise = estimate_noise(&current, &topology).unwrap_or(f64::NAN);
                        print(
                            &name,
                            label,
                            &format!("{round} rounds, noise left {noise:.4}"),
                            &measure(&clean, &input, &current, edge),
                        );
                    }
                }
            }
        }
    }
}
