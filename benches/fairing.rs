//! Criterion benchmarks of one fairing iteration: constrained (both variants) and Laplacian, and
//! of the tangential relaxation's shares set before every round of the default, on
//! `assets/bunny00.obj` (75k faces) and on it Loop-subdivided twice (1.2M faces) with noise.
//! Run: `cargo bench --bench fairing`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fairmesh::fairing::relaxation::Slivers;
use fairmesh::fairing::{baseline::UmbrellaStencil, BoundaryMode, ConstrainedFairing, FairVariant};
use fairmesh::noise::{add_noise, NoiseOptions};
use fairmesh::{Topology, TriMesh};
use std::hint::black_box;

fn meshes() -> Vec<(&'static str, TriMesh)> {
    let bunny = fairmesh::io::load(std::path::Path::new("assets/bunny00.obj"))
        .expect("assets/bunny00.obj")
        .mesh;
    let mut big = fairmesh::mesh::subdivide_loop(&fairmesh::mesh::subdivide_loop(&bunny));
    add_noise(&mut big, &NoiseOptions::default().with_sigma(0.3));
    let mut noisy_bunny = bunny;
    add_noise(&mut noisy_bunny, &NoiseOptions::default().with_sigma(0.3));
    vec![("bunny00", noisy_bunny), ("bunny00_x16", big)]
}

fn fairing_iteration(c: &mut Criterion) {
    let mut group = c.benchmark_group("fairing_iteration");
    group.sample_size(20);
    for (name, mesh) in meshes() {
        let topology = Topology::build(&mesh);
        for variant in [FairVariant::Paper, FairVariant::Improved] {
            let mut fairing =
                ConstrainedFairing::new(&mesh, &topology, variant, BoundaryMode::Curve);
            let positions = mesh.positions.clone();
            fairing.load(&positions);
            group.bench_function(
                BenchmarkId::new(format!("constrained_{}", variant.name()), name),
                |b| b.iter(|| black_box(fairing.step())),
            );
            if variant == FairVariant::Improved {
                // The shares of the default's later rounds: the relaxation only at thin
                // triangles (every one, as with creases).
                fairing.load(&positions);
                group.bench_function(BenchmarkId::new("relax_where_needed", name), |b| {
                    b.iter(|| fairing.relax_where_needed(black_box(0.0), Slivers::All))
                });
            }
        }
        let stencil = UmbrellaStencil::new(&topology, BoundaryMode::Curve);
        let positions = mesh.positions.clone();
        let mut next = positions.clone();
        group.bench_function(BenchmarkId::new("laplacian", name), |b| {
            b.iter(|| black_box(stencil.relax(&positions, &mut next, 0.5)))
        });
    }
    group.finish();
}

criterion_group!(benches, fairing_iteration);
criterion_main!(benches);
