//! Mesh-core benchmarks on the bundled bunny (75k faces) and on it subdivided twice (1.2M faces):
//! topology, welding, and the surface-distance comparison.

use criterion::{criterion_group, criterion_main, Criterion};
use fairmesh::{io, mesh, metrics, Topology};
use std::hint::black_box;
use std::path::Path;

fn bunny() -> fairmesh::TriMesh {
    io::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny00.obj"))
        .expect("bundled bunny loads")
        .mesh
}

fn mesh_core(c: &mut Criterion) {
    let small = bunny();
    let large = mesh::subdivide_loop(&mesh::subdivide_loop(&small));
    let mut group = c.benchmark_group("mesh");
    group.sample_size(10);
    for (name, m) in [("bunny00", &small), ("bunny00x16", &large)] {
        group.bench_function(format!("topology/{name}"), |b| {
            b.iter(|| black_box(Topology::build(m)))
        });
        group.bench_function(format!("weld/{name}"), |b| {
            b.iter_batched(
                || m.clone(),
                |mut copy| black_box(mesh::weld(&mut copy)),
                criterion::BatchSize::LargeInput,
            )
        });
    }
    let mut noisy = small.clone();
    fairmesh::noise::add_noise(&mut noisy, &Default::default());
    group.bench_function("compare/bunny00", |b| {
        b.iter(|| black_box(metrics::compare(&small, &noisy)))
    });
    group.finish();
}

criterion_group!(benches, mesh_core);
criterion_main!(benches);
