//! What smooth shading's sharp edges cost (`render::normals`): the normals of a move, which the
//! editor computes on every fairing result, level and noise, before (`vertex_normals`: area
//! weights, never split) and now (`shading_normals` with the corner table kept: the sharp-edge
//! test of every edge, then the split's normals where there is one), and the corner table built
//! once per mesh; on the 1.2M-face mesh clean (an organic surface: nothing splits), with noise
//! 0.3 along the normals (the editor's default noise: some vertices split), and on a box of about
//! as many faces (a CAD-like part: its edges split). Beside each, the vertices split and the
//! bytes the extra draw vertices add on the GPU (56 per draw vertex: position, normal, heat-map
//! value, mask weight, texture coordinates, colour).
//!
//! Run: `cargo run --release --example shading_speed [-- RUNS]` (median wall time of RUNS runs,
//! default 7, after one warm-up run).

use fairmesh::noise::{add_noise, NoiseOptions};
use fairmesh::TriMesh;
use fairmesh_editor::render::normals::{
    shading_normals, vertex_normals, CornerTable, SHARP_EDGE_ANGLE,
};
use std::hint::black_box;
use std::time::Instant;

/// Bytes on the GPU per draw vertex (`render::pipeline::buffers`).
const GPU_BYTES_PER_DRAW_VERTEX: usize = 56;

/// Median milliseconds of `runs` calls of `f` (after one warm-up call).
fn median_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn rows(name: &str, mesh: &TriMesh, runs: usize) {
    let (positions, triangles) = (&mesh.positions, &mesh.triangles);
    let table = CornerTable::new(positions.len(), triangles);
    let before = median_ms(runs, || {
        black_box(vertex_normals(positions, triangles));
    });
    let now = median_ms(runs, || {
        black_box(shading_normals(
            positions,
            triangles,
            Some(&table),
            SHARP_EDGE_ANGLE,
        ));
    });
    let build = median_ms(runs, || {
        black_box(CornerTable::new(positions.len(), triangles));
    });
    let (split, _) = shading_normals(positions, triangles, Some(&table), SHARP_EDGE_ANGLE);
    let (split_vertices, extra) = split.as_ref().map_or((0, 0), |s| {
        (
            s.split_vertex_count(),
            s.vertex_of().len() - positions.len(),
        )
    });
    println!(
        "| {name} | {} | {} | {before:.1} | {now:.1} | {:.2}× | {build:.1} | {:.1} | {split_vertices} | {extra} | {:.2} |",
        positions.len(),
        triangles.len(),
        now / before,
        table.bytes() as f64 / 1e6,
        (extra * GPU_BYTES_PER_DRAW_VERTEX) as f64 / 1e6,
    );
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(7);
    let bunny = fairmesh::io::load(std::path::Path::new("assets/bunny00.obj"))
        .expect("assets/bunny00.obj")
        .mesh;
    let clean = fairmesh::mesh::subdivide_loop(&fairmesh::mesh::subdivide_loop(&bunny));
    let mut noisy = clean.clone();
    add_noise(&mut noisy, &NoiseOptions::default().with_sigma(0.3));
    let block = fairmesh::mesh::shapes::cuboid([1.0, 1.0, 1.0], 0.0037);
    println!(
        "rayon threads: {}; median of {runs} runs; sharp-edge angle {SHARP_EDGE_ANGLE}°\n",
        rayon::current_num_threads()
    );
    println!(
        "| mesh | vertices | faces | before ms | now ms | now / before | corner table ms | table MB | split vertices | extra draw vertices | extra GPU MB |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    rows("1.2M-face bunny, clean", &clean, runs);
    rows("1.2M-face bunny, noise 0.3", &noisy, runs);
    rows("box, spacing 0.0037", &block, runs);
}
