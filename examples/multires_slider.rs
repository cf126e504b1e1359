//! The start-level slider's figures: what a run from each start level costs, and whether its
//! result turns any face over.
//!
//! Run: `cargo run --release --example multires_slider [-- MESH [SIGMA [LEVELS]]]`
//!
//! MESH is a mesh file or `big` (the default: `assets/bunny00.obj` Loop-subdivided twice, 603k
//! vertices, 1.2M faces, as `fairmesh convert @bunny --subdivide 2` makes it); SIGMA the noise
//! added first, in mean edge lengths along the normals, seed 1 (default 0.3; 0: none); LEVELS
//! the start levels, comma separated (default: every level). The mesh is then run as `fairmesh
//! multires` and the editor run it: denoised once by `fair`'s automatic default (sharp edges
//! kept), the hierarchy built on that with creases, the improved variant.
//!
//! Per start level K, as `fairmesh multires IN --level K,K-1` runs them: the first run from K
//! with a fresh workspace (it builds what the levels need), then the step to K-1 with that
//! workspace (the slider's step), each in wall milliseconds, in CPU milliseconds (robust when
//! other processes share the cores) and in times of one iteration of `fair`'s operator on M0
//! (measured here the same way); the floor of the step (the fairing iterations on levels K-1..1
//! and one pass over each level's split vertices, in M0 iterations: the levels' vertex counts
//! over M0's); and the faces of each result turned by more than 90 degrees against the same face
//! of M0 (`fair`'s result) and, with noise, against the clean mesh, beyond those the noisy
//! input itself has; and the share of the first run's vertices that the unfolding put back
//! where M0 has them (its last resort, `multires::unfold`): what share of that result is
//! `fair`'s result rather than a smoother one.

use fairmesh::fairing::creases::{CreaseOptions, DEFAULT_CREASE_ANGLE};
use fairmesh::fairing::{BoundaryMode, ConstrainedFairing, FairOptions, FairVariant, Strength};
use fairmesh::hierarchy::{build_hierarchy_with_topology, HierarchyOptions};
use fairmesh::multires::{
    denoise, fair_multires, DenoiseOptions, MultiresOptions, MultiresWorkspace,
};
use fairmesh::noise::{add_noise, NoiseOptions};
use fairmesh::{NoProgress, Topology, TriMesh};
use std::time::Instant;

fn process_cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after_name = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = after_name.split_whitespace().collect();
    let ticks: f64 = fields.get(11).and_then(|f| f.parse().ok()).unwrap_or(0.0)
        + fields.get(12).and_then(|f| f.parse().ok()).unwrap_or(0.0);
    ticks / 100.0
}

/// Wall and CPU milliseconds of `f`, and its value.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, f64) {
    let cpu = process_cpu_seconds();
    let start = Instant::now();
    let value = f();
    let wall = start.elapsed().as_secs_f64() * 1e3;
    (value, wall, (process_cpu_seconds() - cpu) * 1e3)
}

/// Faces of `positions` (on `mesh`'s triangles) whose normal is more than 90 degrees from the
/// same face's normal in `reference`.
fn turned_faces(positions: &[[f32; 3]], mesh: &TriMesh, reference: &TriMesh) -> usize {
    let result = TriMesh::new(positions.to_vec(), mesh.triangles.clone());
    (0..mesh.face_count())
        .filter(|&t| result.face_normal(t).dot(reference.face_normal(t)) < 0.0)
        .count()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().map_or("big", String::as_str);
    let sigma: f64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(0.3);
    // The repository's bunny wherever the example is run from.
    let bunny = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/bunny00.obj");
    let load = |path: &str| match fairmesh::io::load(std::path::Path::new(path)) {
        Ok(loaded) => loaded.mesh,
        Err(error) => {
            eprintln!("{error}");
            std::process::exit(1);
        }
    };
    let clean = if path == "big" {
        fairmesh::mesh::subdivide_loop(&fairmesh::mesh::subdivide_loop(&load(bunny)))
    } else {
        load(path)
    };
    let mut noisy = clean.clone();
    if sigma > 0.0 {
        add_noise(&mut noisy, &NoiseOptions::default().with_sigma(sigma));
    }
    let topology = Topology::build(&noisy);
    let (denoised, denoise_ms, _) = timed(|| {
        denoise(
            &noisy,
            &topology,
            &DenoiseOptions::default(),
            &mut NoProgress,
        )
        .expect("never cancelled")
        .map_or_else(|| noisy.clone(), |d| d.mesh)
    });
    let options = HierarchyOptions::default().with_creases(Some(
        CreaseOptions::default().with_angle_degrees(DEFAULT_CREASE_ANGLE),
    ));
    let (hierarchy, hierarchy_ms, _) = timed(|| {
        build_hierarchy_with_topology(&denoised, &topology, &options, &mut NoProgress)
            .expect("the hierarchy builds")
    });
    // One iteration of `fair`'s operator on M0, CPU and wall (median of 3 runs of 10).
    let mut fairing = ConstrainedFairing::new(
        &denoised,
        &topology,
        FairVariant::default(),
        BoundaryMode::Curve,
    );
    let iteration_options = FairOptions::default()
        .with_strength(Strength::Fixed)
        .with_rounds(1)
        .with_iterations(10);
    let mut positions = denoised.positions.clone();
    let mut samples: Vec<(f64, f64)> = (0..3)
        .map(|_| {
            let (_, wall, cpu) = timed(|| fairing.run(&mut positions, &iteration_options));
            (wall / 10.0, cpu / 10.0)
        })
        .collect();
    drop(fairing);
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (iteration_wall, iteration_cpu) = samples[1];
    let v0 = hierarchy.level_info(0).vertices as f64;
    println!(
        "{path}: {} vertices, noise {sigma} (seed 1); rayon threads {}; denoise {denoise_ms:.0} ms, \
         hierarchy of {} levels {hierarchy_ms:.0} ms; one M0 iteration {iteration_wall:.1} ms \
         wall, {iteration_cpu:.1} ms CPU",
        noisy.vertex_count(),
        rayon::current_num_threads(),
        hierarchy.level_count(),
    );
    let levels: Vec<usize> = match args.get(2) {
        Some(list) => list.split(',').filter_map(|l| l.parse().ok()).collect(),
        None => (1..hierarchy.level_count()).rev().collect(),
    };
    println!(
        "\n| K | first ms (CPU) | = M0 its | step to K-1 ms (CPU) | = M0 its | floor its | \
         turned vs M0 (K, K-1) | vs clean | at M0 |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let base = hierarchy.base_mesh();
    let input_turned = turned_faces(&noisy.positions, base, &clean);
    for k in levels {
        let k = k.min(hierarchy.coarsest_level()).max(1);
        let mut workspace = MultiresWorkspace::new();
        let mut run = |level: usize| {
            let options = MultiresOptions::default().with_start_level(level);
            timed(|| fair_multires(&hierarchy, &options, &mut workspace, &mut NoProgress))
        };
        let (first, first_wall, first_cpu) = run(k);
        let (step, step_wall, step_cpu) = run(k - 1);
        let (first, step) = (
            first.expect("never cancelled"),
            step.expect("never cancelled"),
        );
        // Five iterations on each level faired, one pass over each level's vertices to refine.
        let floor: f64 = (1..k)
            .map(|l| 6.0 * hierarchy.level_info(l).vertices as f64 / v0)
            .sum();
        let against = |reference: &TriMesh| {
            format!(
                "{}, {}",
                turned_faces(&first, base, reference),
                turned_faces(&step, base, reference)
            )
        };
        let clean_column = if sigma > 0.0 {
            let extra = |p: &[[f32; 3]]| turned_faces(p, base, &clean).saturating_sub(input_turned);
            format!("{}, {}", extra(&first), extra(&step))
        } else {
            "-".to_string()
        };
        let at_m0 = first
            .iter()
            .zip(&base.positions)
            .filter(|(p, q)| p == q)
            .count() as f64
            / first.len().max(1) as f64;
        println!(
            "| {k} | {first_wall:.0} ({first_cpu:.0}) | {:.0} | {step_wall:.0} ({step_cpu:.0}) | \
             {:.0} | {floor:.0} | {} | {clean_column} | {:.1} % |",
            first_cpu / iteration_cpu,
            step_cpu / iteration_cpu,
            against(base),
            100.0 * at_m0,
        );
    }
}
