//! Speed of what the default fairing and the crease-keeping hierarchy add before their own work
//! (the speed target: crease detection and the noise estimate add at most 10 % to a
//! default `fair` round on the 1.2M-face mesh, and at most 10 % to the hierarchy build), phase by
//! phase, against the memory floor of each phase.
//!
//! Run: `cargo run --release --example crease_speed [-- RUNS [phases|end]]`
//! (`phases` or `end`: only the phase rows or only the end-to-end rows).
//!
//! The mesh is `assets/bunny00.obj` Loop-subdivided twice (603k vertices, 1.2M faces), clean and
//! with noise 0.3 along the normals (seed 1), as `fairmesh convert --subdivide 2` and `fairmesh
//! noise` make it. Each row: median wall time of RUNS runs (default 5) and the process CPU time
//! per run (from /proc/self/stat: robust when other processes share the cores), and for the
//! phases the floor, the bytes the phase must read and write at least (below) divided by the copy
//! bandwidth measured here.
//!
//! The byte model (V vertices, F faces, about 2F edges' worth of one-ring entries 6V):
//! - noise estimate: positions 12V, triangles 12F (for the face normals), the one-ring and
//!   vertex-to-face lists 4·6V each, one f32 per vertex written and read back twice;
//! - edge test with the faces' own normals: positions and triangles for the normals, the
//!   vertex-to-face lists, and the normals read once more (12F);
//! - one guided filter pass: three sweeps over the faces (patches, guidance, filtered normal),
//!   each reading every face's triangle and its corners' face lists and the previous sweep's
//!   16-byte-per-face result and writing 16 bytes per face.

use fairmesh::fairing::creases::filtered_face_normals;
use fairmesh::fairing::{
    detect_creases, estimate_noise, fair_constrained, CreaseOptions, FairOptions,
};
use fairmesh::hierarchy::{build_hierarchy_with_topology, HierarchyOptions};
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

/// Median wall ms and mean CPU ms of `runs` calls of `f` (after one warm-up call).
fn time(runs: usize, mut f: impl FnMut()) -> (f64, f64) {
    f();
    let cpu_start = process_cpu_seconds();
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let cpu = (process_cpu_seconds() - cpu_start) * 1e3 / runs as f64;
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], cpu)
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5);
    let only = std::env::args().nth(2).unwrap_or_default();
    let bunny = fairmesh::io::load(std::path::Path::new("assets/bunny00.obj"))
        .expect("assets/bunny00.obj")
        .mesh;
    let clean = fairmesh::mesh::subdivide_loop(&fairmesh::mesh::subdivide_loop(&bunny));
    let mut noisy = clean.clone();
    add_noise(&mut noisy, &NoiseOptions::default().with_sigma(0.3));
    let topology = Topology::build(&clean);
    let bandwidth = copy_bandwidth(64 << 20);
    println!(
        "1.2M-face mesh: {} vertices, {} faces; rayon threads: {}; copy bandwidth {:.1} GB/s; \
         median of {runs} runs",
        clean.vertex_count(),
        clean.face_count(),
        rayon::current_num_threads(),
        bandwidth / 1e9
    );

    if only != "end" {
        phases(&clean, &noisy, &topology, runs, bandwidth);
    }
    if only != "phases" {
        end_to_end(&clean, &noisy, &topology, runs);
    }
}

fn phases(clean: &TriMesh, noisy: &TriMesh, topology: &Topology, runs: usize, bandwidth: f64) {
    let (v, f) = (clean.vertex_count() as f64, clean.face_count() as f64);
    let floor = |bytes: f64| bytes / bandwidth * 1e3;
    let estimate_bytes = 12.0 * v + 12.0 * f + 2.0 * 24.0 * v + 12.0 * f + 3.0 * 4.0 * v;
    let edge_bytes = 12.0 * v + 12.0 * f + 24.0 * v + 12.0 * f + 12.0 * f;
    let pass_bytes = 3.0 * (12.0 * f + 24.0 * v + 32.0 * f);

    println!("\n| phase | wall ms | CPU ms | floor ms |");
    println!("|---|---:|---:|---:|");
    let row = |name: &str, (wall, cpu): (f64, f64), floor: Option<f64>| {
        println!(
            "| {name} | {wall:.1} | {cpu:.1} | {} |",
            floor.map_or(String::new(), |f| format!("{f:.1}"))
        );
    };
    row(
        "topology (Topology::build)",
        time(runs, || {
            std::hint::black_box(Topology::build(clean));
        }),
        None,
    );
    for (name, mesh) in [("clean", clean), ("noisy", noisy)] {
        row(
            &format!("noise estimate, {name}"),
            time(runs, || {
                std::hint::black_box(estimate_noise(mesh, topology));
            }),
            Some(floor(estimate_bytes)),
        );
    }
    row(
        "crease detection, faces' own normals, clean",
        time(runs, || {
            std::hint::black_box(detect_creases(clean, topology, &CreaseOptions::default()));
        }),
        Some(floor(edge_bytes)),
    );
    row(
        "guided normal filter, 1 pass, noisy",
        time(runs, || {
            std::hint::black_box(filtered_face_normals(noisy, topology, 1, 0.5));
        }),
        Some(floor(pass_bytes)),
    );
    row(
        "crease detection, 5 filter passes, noisy",
        time(runs, || {
            std::hint::black_box(detect_creases(
                noisy,
                topology,
                &CreaseOptions::default().with_normal_filtering(5),
            ));
        }),
        Some(floor(edge_bytes + 5.0 * pass_bytes)),
    );
}

fn end_to_end(clean: &TriMesh, noisy: &TriMesh, topology: &Topology, runs: usize) {
    // End to end, the runs of each pair interleaved (A B A B ...) so that both see the same load.
    println!(
        "\n| end to end (interleaved pairs) | wall ms, median | wall ms, min | CPU ms, mean |"
    );
    println!("|---|---:|---:|---:|");
    let one_round = FairOptions::default()
        .with_rounds(1)
        .with_tangential_relaxation(0.0);
    fn pair(name: &str, runs: usize, a: &mut dyn FnMut(), b: &mut dyn FnMut()) {
        let mut times = [Vec::new(), Vec::new()];
        let mut cpu = [0.0, 0.0];
        a();
        b();
        for _ in 0..runs {
            for k in 0..2 {
                let (c, start) = (process_cpu_seconds(), Instant::now());
                if k == 0 {
                    a()
                } else {
                    b()
                }
                times[k].push(start.elapsed().as_secs_f64() * 1e3);
                cpu[k] += (process_cpu_seconds() - c) * 1e3 / runs as f64;
            }
        }
        for (k, label) in ["without", "with"].into_iter().enumerate() {
            times[k].sort_by(f64::total_cmp);
            println!(
                "| {name}, {label} | {:.1} | {:.1} | {:.1} |",
                times[k][times[k].len() / 2],
                times[k][0],
                cpu[k]
            );
        }
    }
    for (name, mesh) in [("clean", clean), ("noisy", noisy)] {
        let without = one_round.clone().with_creases(None);
        pair(
            &format!("fair --rounds 1 --tangential 0, {name}: estimate + creases"),
            runs,
            &mut || {
                let mut copy = mesh.clone();
                std::hint::black_box(fair_constrained(&mut copy, topology, &without));
            },
            &mut || {
                let mut copy = mesh.clone();
                std::hint::black_box(fair_constrained(&mut copy, topology, &one_round));
            },
        );
    }
    let without = HierarchyOptions::default();
    let with = HierarchyOptions::default().with_creases(Some(CreaseOptions::default()));
    // With the loaded connectivity, as `fairmesh hierarchy` and `multires` build it (creases
    // read it; without them it is not read).
    let build = |options: &HierarchyOptions| {
        build_hierarchy_with_topology(clean, topology, options, &mut NoProgress).unwrap()
    };
    pair(
        "hierarchy build (loaded topology), clean: creases",
        runs,
        &mut || {
            std::hint::black_box(build(&without));
        },
        &mut || {
            std::hint::black_box(build(&with));
        },
    );
}
