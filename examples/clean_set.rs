//! The default fairing on clean meshes: a smoother should leave a mesh with no noise on it (nearly)
//! as it is. The targets for default `fair` on every clean mesh of a set of at least 20:
//! mean surface distance (both ways) at most 0.02 mean edge lengths, Hausdorff distance at most
//! 0.25 mean edge lengths, |volume change| at most 0.1 %.
//!
//! Run: `cargo run --release --example clean_set [-- FILE_OR_FOLDER...]`.
//! Built in: the meshes shipped with the repository (`assets/bunny00.obj`, `tests/data/*.obj`) and
//! CAD-like parts from `mesh::shapes` (fine and coarse). Any further meshes named on the command
//! line (files, or folders whose OBJ/PLY/OFF/STL/glTF files are all taken) are added: the
//! measurements in `docs/measurements.md` add meshes installed from package registries that the
//! repository cannot ship. A file that cannot be loaded is listed with its error and counted as
//! not measured.

use fairmesh::fairing::{fair_constrained, FairOptions};
use fairmesh::mesh::shapes;
use fairmesh::metrics::{compare, mean_edge_length, signed_volume};
use fairmesh::{Topology, TriMesh};
use std::path::{Path, PathBuf};

const MEAN_LIMIT: f64 = 0.02;
const HAUSDORFF_LIMIT: f64 = 0.25;
const VOLUME_LIMIT: f64 = 0.1;

fn built_in() -> Vec<(String, Result<TriMesh, String>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut list: Vec<(String, Result<TriMesh, String>)> = [
        "assets/bunny00.obj",
        "tests/data/elephant.obj",
        "tests/data/bunny_npm.obj",
        "tests/data/mushroom_open.obj",
    ]
    .iter()
    .map(|file| load(&root.join(file)))
    .collect();
    let shapes = [
        ("cube", shapes::cuboid([1.0, 1.0, 1.0], 0.05)),
        ("coarse cube", shapes::cuboid([1.0, 1.0, 1.0], 0.25)),
        ("thin plate", shapes::cuboid([2.0, 1.5, 0.1], 0.05)),
        ("thin bar", shapes::cuboid([3.0, 0.2, 0.1], 0.05)),
        ("cylinder", shapes::cylinder(0.5, 1.5, 0.05)),
        ("coarse cylinder", shapes::cylinder(0.5, 1.5, 0.2)),
        ("gear", shapes::gear(16, 1.0, 1.25, 0.3, 0.04)),
        ("d prism", shapes::d_prism(1.0, 0.7, 0.5, 0.05)),
        ("cad cylinder 12", shapes::cad_cylinder(12, 0.5, 1.5)),
        ("cad cylinder 16", shapes::cad_cylinder(16, 0.5, 1.5)),
        ("cad cylinder 32", shapes::cad_cylinder(32, 0.5, 1.5)),
        ("cad cylinder 40", shapes::cad_cylinder(40, 0.5, 1.5)),
        ("cad cylinder 64", shapes::cad_cylinder(64, 0.5, 1.5)),
        (
            "cad box with holes 16",
            shapes::cad_box_with_holes([2.0, 1.4, 1.0], 0.05, 0.25, 16),
        ),
        (
            "cad box with holes 32",
            shapes::cad_box_with_holes([2.0, 1.4, 1.0], 0.05, 0.25, 32),
        ),
        (
            "cad box with holes 64, thin",
            shapes::cad_box_with_holes([2.0, 1.4, 1.0], 0.02, 0.3, 64),
        ),
    ];
    list.extend(
        shapes
            .into_iter()
            .map(|(name, mesh)| (name.to_string(), Ok(mesh))),
    );
    list
}

fn load(path: &Path) -> (String, Result<TriMesh, String>) {
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    (
        name,
        fairmesh::io::load(path)
            .map(|loaded| loaded.mesh)
            .map_err(|e| e.to_string()),
    )
}

/// The mesh files named: a file as it is, a folder's mesh files in name order.
fn named(args: &[String]) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for arg in args {
        let path = PathBuf::from(arg);
        if path.is_dir() {
            let mut inside: Vec<PathBuf> = std::fs::read_dir(&path)
                .map(|entries| entries.filter_map(|e| e.ok().map(|e| e.path())).collect())
                .unwrap_or_default();
            inside.retain(|p| fairmesh::io::Format::from_path(p).is_some());
            inside.sort();
            files.extend(inside);
        } else {
            files.push(path);
        }
    }
    files
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut meshes = built_in();
    meshes.extend(named(&args).iter().map(|p| load(p)));
    println!("| mesh | faces | noise estimate | rounds | mean | hausdorff | vol % | within |");
    println!("|---|---:|---:|---:|---:|---:|---:|---|");
    let (mut within, mut measured) = (0, 0);
    for (name, mesh) in meshes {
        let clean = match mesh {
            Ok(mesh) => mesh,
            Err(e) => {
                println!("| {name} | | | | | | | not loaded: {e} |");
                continue;
            }
        };
        let topology = Topology::build(&clean);
        let edge = mean_edge_length(&clean);
        let mut faired = clean.clone();
        let report = fair_constrained(&mut faired, &topology, &FairOptions::default());
        let c = compare(&clean, &faired);
        let v0 = signed_volume(&clean);
        let volume = if v0.abs() > 0.0 {
            100.0 * (signed_volume(&faired) - v0) / v0.abs()
        } else {
            0.0
        };
        let (mean, hausdorff) = (c.mean_surface_distance / edge, c.hausdorff / edge);
        let ok = mean <= MEAN_LIMIT && hausdorff <= HAUSDORFF_LIMIT && volume.abs() <= VOLUME_LIMIT;
        measured += 1;
        within += ok as usize;
        println!(
            "| {name} | {} | {:.3} | {} | {mean:.4} | {hausdorff:.3} | {volume:+.4} | {} |",
            clean.triangles.len(),
            report.noise_estimate.unwrap_or(f64::NAN),
            report.rounds_run,
            if ok { "yes" } else { "no" }
        );
    }
    println!(
        "\n{within} of {measured} meshes within the targets (mean <= {MEAN_LIMIT}, hausdorff <= \
         {HAUSDORFF_LIMIT} mean edge lengths, |volume change| <= {VOLUME_LIMIT} %)"
    );
}
