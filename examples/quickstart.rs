//! The library in one page: load a mesh, damage it with noise, smooth it three ways (one round of
//! constrained fairing, five rounds, and multiresolution fairing from a middle level of the
//! decimation hierarchy), print how close each result comes back to the clean mesh and how much
//! volume it lost, and write the best one.
//!
//! Run: `cargo run --release --example quickstart [MESH] [OUT]`
//! (MESH defaults to the bunny compiled into the library; OUT, when given, receives the
//! multiresolution result, in the format its extension names).

use fairmesh::fairing::{fair_constrained, FairOptions};
use fairmesh::hierarchy::{build_hierarchy, HierarchyOptions};
use fairmesh::io::LoadOptions;
use fairmesh::multires::{fair_multires, MultiresOptions, MultiresWorkspace};
use fairmesh::noise::{add_noise, NoiseOptions};
use fairmesh::{metrics, NoProgress, TriMesh};
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let loaded = match args.next() {
        Some(path) => fairmesh::io::load(PathBuf::from(path).as_path())?,
        None => fairmesh::bundled::load_bunny(&LoadOptions::default())?,
    };
    let output = args.next().map(PathBuf::from);
    let clean = loaded.mesh;
    println!(
        "{} vertices, {} faces",
        clean.vertex_count(),
        clean.face_count()
    );

    let mut noisy = clean.clone();
    add_noise(&mut noisy, &NoiseOptions::default());
    report("noisy (0.3 mean edge lengths)", &clean, &noisy);

    let mut once = noisy.clone();
    let options = FairOptions::default().with_rounds(1);
    fair_constrained(&mut once, &loaded.topology, &options);
    report("constrained fairing, 1 round", &clean, &once);

    // The default estimates the noise and picks the rounds itself.
    let mut auto = noisy.clone();
    let chosen = fair_constrained(&mut auto, &loaded.topology, &FairOptions::default());
    report(
        &format!(
            "constrained fairing, default ({} rounds)",
            chosen.rounds_run
        ),
        &clean,
        &auto,
    );

    let mut five = noisy.clone();
    let options = FairOptions::default().with_rounds(5);
    fair_constrained(&mut five, &loaded.topology, &options);
    report("constrained fairing, 5 rounds", &clean, &five);

    // The hierarchy depends on the connectivity only, which noise leaves alone.
    let hierarchy = build_hierarchy(&noisy, &HierarchyOptions::default(), &mut NoProgress)?;
    let start_level = hierarchy.coarsest_level() / 2;
    let options = MultiresOptions::default().with_start_level(start_level);
    let mut workspace = MultiresWorkspace::default();
    let positions = fair_multires(&hierarchy, &options, &mut workspace, &mut NoProgress)?;
    // The positions come back in the input's vertex order, for the input's triangles.
    let multires = TriMesh::new(positions, hierarchy.base_mesh().triangles.clone());
    report(
        &format!(
            "multiresolution from level {start_level} of {}",
            hierarchy.coarsest_level()
        ),
        &clean,
        &multires,
    );

    if let Some(path) = output {
        fairmesh::io::save(path.as_path(), &multires)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// One line: mean surface distance to the clean mesh (in mean edge lengths) and volume change.
fn report(what: &str, clean: &TriMesh, mesh: &TriMesh) {
    let edge = metrics::mean_edge_length(clean);
    let comparison = metrics::compare(clean, mesh);
    let volume = comparison
        .volume_change_percent
        .map_or_else(|| "open mesh".to_owned(), |v| format!("{v:+.3}%"));
    println!(
        "{what:<45} distance to clean {:.4} edges, volume {volume}",
        comparison.mean_surface_distance / edge
    );
}
