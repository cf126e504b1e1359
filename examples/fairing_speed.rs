//! Speed of one fairing iteration against the memory floor, on `assets/bunny00.obj` and on it
//! Loop-subdivided twice (about 1.2M faces) with noise.
//!
//! Run: `cargo run --release --example fairing_speed [-- MESH...]`
//!
//! Each MESH file given is measured too, as it is (no noise added): for instance the levels
//! `fairmesh hierarchy IN --write-levels DIR` writes, which are irregular meshes of every size.
//!
//! For each mesh and operator: median wall time per iteration (rayon's default pool), the
//! process CPU time per iteration (from /proc/self/stat, robust when other processes share the
//! cores), the bytes the iteration streams with this data layout, and the floor: those bytes
//! divided by the copy bandwidth measured here (a large `copy_from_slice`, read + write bytes).

use fairmesh::fairing::{baseline::UmbrellaStencil, BoundaryMode, ConstrainedFairing, FairVariant};
use fairmesh::noise::{add_noise, NoiseOptions};
use fairmesh::{Topology, TriMesh};
use std::time::Instant;

fn process_cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after_name = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = after_name.split_whitespace().collect();
    // Fields 14 and 15 (utime, stime) are at 11 and 12 after the name; ticks of 1/100 s.
    let ticks: f64 = fields.get(11).and_then(|f| f.parse().ok()).unwrap_or(0.0)
        + fields.get(12).and_then(|f| f.parse().ok()).unwrap_or(0.0);
    ticks / 100.0
}

/// Copy bandwidth (read + write bytes per second) of a buffer of `bytes`, best of several runs.
fn copy_bandwidth(bytes: usize) -> f64 {
    let source = vec![1u8; bytes];
    let mut target = vec![0u8; bytes];
    let mut best = f64::INFINITY;
    for _ in 0..15 {
        let start = Instant::now();
        target.copy_from_slice(&source);
        std::hint::black_box(&mut target);
        best = best.min(start.elapsed().as_secs_f64());
    }
    2.0 * bytes as f64 / best
}

fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn time_per_iteration(iterations: usize, mut step: impl FnMut()) -> (f64, f64) {
    step();
    let cpu_start = process_cpu_seconds();
    let times: Vec<f64> = (0..iterations)
        .map(|_| {
            let start = Instant::now();
            step();
            start.elapsed().as_secs_f64()
        })
        .collect();
    let cpu = (process_cpu_seconds() - cpu_start) / iterations as f64;
    (median(times) * 1e3, cpu * 1e3)
}

fn main() {
    let mut bunny = fairmesh::io::load(std::path::Path::new("assets/bunny00.obj"))
        .expect("assets/bunny00.obj")
        .mesh;
    let mut big = fairmesh::mesh::subdivide_loop(&fairmesh::mesh::subdivide_loop(&bunny));
    add_noise(&mut big, &NoiseOptions::default().with_sigma(0.3));
    add_noise(&mut bunny, &NoiseOptions::default().with_sigma(0.3));
    let threads = rayon::current_num_threads();
    let big_bandwidth = copy_bandwidth(256 << 20);
    println!("rayon threads: {threads}");
    println!(
        "copy bandwidth, 256 MiB buffers: {:.2} GB/s (read + write)",
        big_bandwidth / 1e9
    );
    // The operator renumbers vertices for locality itself (breadth-first, valence-sorted
    // blocks on small meshes), so the input order does not matter: the subdivision's order is as
    // fast.
    let mut meshes: Vec<(String, TriMesh)> = vec![
        ("bunny00".to_string(), bunny),
        ("bunny00 x16".to_string(), big),
    ];
    for path in std::env::args().skip(1) {
        let mesh = fairmesh::io::load(std::path::Path::new(&path))
            .unwrap_or_else(|e| panic!("{path}: {e}"))
            .mesh;
        meshes.push((path, mesh));
    }
    println!("\n| mesh | operation | wall ms (median) | CPU ms / iteration | MB streamed | floor ms | wall / floor |");
    println!("|---|---|---:|---:|---:|---:|---:|");
    for (name, mesh) in &meshes {
        let topology = Topology::build(mesh);
        let iterations = if mesh.positions.len() > 100_000 {
            30
        } else {
            300
        };
        for variant in [FairVariant::Paper, FairVariant::Improved] {
            let start = Instant::now();
            let mut fairing =
                ConstrainedFairing::new(mesh, &topology, variant, BoundaryMode::Curve);
            let precompute_ms = start.elapsed().as_secs_f64() * 1e3;
            let positions = mesh.positions.clone();
            fairing.load(&positions);
            let bytes = fairing.streamed_bytes_per_iteration();
            // The floor uses the bandwidth of a copy of the same size (cache effects included).
            let bandwidth = copy_bandwidth(bytes / 2);
            let floor_ms = bytes as f64 / bandwidth * 1e3;
            let (wall, cpu) = time_per_iteration(iterations, || {
                fairing.step();
            });
            println!(
                "| {name} | constrained iteration ({}) | {wall:.3} | {cpu:.3} | {:.1} | {floor_ms:.3} | {:.1} |",
                variant.name(),
                bytes as f64 / 1e6,
                wall / floor_ms
            );
            println!(
                "| {name} | precomputation ({}) | {precompute_ms:.1} | | | | |",
                variant.name()
            );
        }
        let stencil = UmbrellaStencil::new(&topology, BoundaryMode::Curve);
        let positions = mesh.positions.clone();
        let mut next = positions.clone();
        let (wall, cpu) = time_per_iteration(iterations, || {
            stencil.relax(&positions, &mut next, 0.5);
        });
        println!("| {name} | Laplacian iteration | {wall:.3} | {cpu:.3} | | | |");
    }
}
