//! The default fairing's table: on a set of clean meshes (scans and CAD-like parts), and on each
//! with noise of 0.3 mean edge lengths along the normals and per coordinate (isotropic), how far
//! default `fair` (automatic strength, creases kept) ends from the clean surface, next to the
//! previous default (one round of 10 iterations, no creases) and to fixed round counts.
//!
//! Run: `cargo run --release --example fairing_default [-- --trace]`
//! (`--only gear,cube` runs just those meshes; `--files a.obj,b.ply` adds meshes from files, named
//! by their stem; `--sigma 0.15` changes the noise, `--seed 2` its draw (1 unless told); `--default-only` prints the default's row
//! alone; `--save DIR` writes the clean meshes as PLY files and stops; `--tangential 0.1` gives the
//! default that tangential relaxation weight at every vertex, as `fair --tangential` does;
//! `--trace` also prints, per round, the noise estimate and the distance to the clean surface). `docs/measurements.md` holds what it printed and says which meshes the rules were
//! tuned on and which were kept out.
//!
//! Measures (lengths in mean edge lengths of the clean mesh): `mean`, `hausdorff`: surface
//! distance both ways (`metrics::compare`); `normal`: mean angle between corresponding face
//! normals, degrees; `vol`: volume change against the mesh that was faired, percent.

use fairmesh::fairing::{
    estimate_noise, fair_constrained, ConstrainedFairing, FairOptions, Relaxation,
};
use fairmesh::mesh::shapes;
use fairmesh::metrics::{compare, mean_edge_length, signed_volume};
use fairmesh::noise::{add_noise, NoiseMode, NoiseOptions};
use fairmesh::{Topology, TriMesh};
use std::path::Path;

fn meshes(files: &[String]) -> Vec<(String, TriMesh)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bundled = [
        "assets/bunny00.obj",
        "tests/data/elephant.obj",
        "tests/data/bunny_npm.obj",
        "tests/data/mushroom_open.obj",
    ];
    let mut list: Vec<(String, TriMesh)> = bundled
        .iter()
        .map(|file| root.join(file))
        .chain(files.iter().map(|file| Path::new(file).to_path_buf()))
        .map(|path| {
            let mesh = fairmesh::io::load(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .mesh;
            let name = path.file_stem().unwrap().to_string_lossy();
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
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
    };
    let list = |flag: &str| -> Option<Vec<String>> {
        value(flag).map(|list| list.split(',').map(str::to_string).collect())
    };
    let only = list("--only");
    let files = list("--files").unwrap_or_default();
    let sigma: f64 = value("--sigma").map_or(0.3, |s| s.parse().expect("--sigma: a number"));
    let seed: u64 = value("--seed").map_or(1, |s| s.parse().expect("--seed: a whole number"));
    let default_only = args.iter().any(|a| a == "--default-only");
    // `--tangential W`: the default with that tangential relaxation weight at every vertex.
    let default_options = match value("--tangential") {
        Some(w) => FairOptions::default()
            .with_tangential_relaxation(w.parse().expect("--tangential: a number"))
            .with_relaxation(Relaxation::Everywhere),
        None => FairOptions::default(),
    };
    // `--save DIR`: write each clean mesh as DIR/NAME.ply (for `scripts/peers/compare_peers.py`,
    // which takes files) and stop.
    let save = value("--save");
    for (name, clean) in meshes(&files) {
        if only.as_ref().is_some_and(|only| !only.contains(&name)) {
            continue;
        }
        if let Some(dir) = save {
            let path = Path::new(dir).join(format!("{}.ply", name.replace(' ', "_")));
            fairmesh::io::save(&path, &clean).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            println!("wrote {}", path.display());
            continue;
        }
        let topology = Topology::build(&clean);
        let edge = mean_edge_length(&clean);
        let inputs = [
            ("clean".to_string(), None),
            (format!("normal {sigma}"), Some(NoiseMode::Normal)),
            (format!("isotropic {sigma}"), Some(NoiseMode::Isotropic)),
        ];
        for (label, mode) in inputs {
            let label = label.as_str();
            let mut input = clean.clone();
            if let Some(mode) = mode {
                add_noise(
                    &mut input,
                    &NoiseOptions::default()
                        .with_sigma(sigma)
                        .with_mode(mode)
                        .with_seed(seed),
                );
            }
            let mut faired = input.clone();
            let report = fair_constrained(&mut faired, &topology, &default_options);
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
            if default_only {
                continue;
            }
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
            let mut everywhere = input.clone();
            let options = FairOptions::default().with_relaxation(Relaxation::Everywhere);
            let report = fair_constrained(&mut everywhere, &topology, &options);
            print(
                &name,
                label,
                &format!(
                    "default with the relaxation everywhere (until 2026-11-26): {} rounds",
                    report.rounds_run
                ),
                &measure(&clean, &input, &everywhere, edge),
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
