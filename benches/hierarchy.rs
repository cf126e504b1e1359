//! Criterion benchmarks of the decimation hierarchy (section 4.1) and multiresolution fairing
//! (4.2) on bunny00 and on bunny00 Loop-subdivided twice (about 1.2M faces).
//!
//! `cargo bench --bench hierarchy`

use criterion::{criterion_group, criterion_main, Criterion};
use fairmesh::hierarchy::{build_hierarchy, HierarchyOptions};
use fairmesh::multires::{fair_multires, MultiresOptions, MultiresWorkspace};
use fairmesh::{mesh, NoProgress, TriMesh};
use std::path::Path;

fn bunny() -> TriMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny00.obj");
    fairmesh::io::load(&path).expect("assets/bunny00.obj").mesh
}

fn bench_mesh(c: &mut Criterion, name: &str, mesh: &TriMesh) {
    let options = HierarchyOptions::default();
    c.bench_function(&format!("hierarchy build {name}"), |b| {
        b.iter(|| build_hierarchy(mesh, &options, &mut NoProgress).unwrap())
    });
    let hierarchy = build_hierarchy(mesh, &options, &mut NoProgress).unwrap();
    let mut workspace = MultiresWorkspace::new();
    let coarsest = hierarchy.coarsest_level();
    for (label, level) in [("coarsest", coarsest), ("middle", coarsest / 2)] {
        let options = MultiresOptions::default().with_start_level(level);
        // The first run builds the per-level connectivity into the workspace.
        let _ = fair_multires(&hierarchy, &options, &mut workspace, &mut NoProgress);
        c.bench_function(
            &format!("multires {name} from {label} level {level}"),
            |b| b.iter(|| fair_multires(&hierarchy, &options, &mut workspace, &mut NoProgress)),
        );
    }
}

fn benches(c: &mut Criterion) {
    let small = bunny();
    bench_mesh(c, "bunny00", &small);
    let large = mesh::subdivide_loop(&mesh::subdivide_loop(&small));
    bench_mesh(c, "bunny00x2 (1.2M faces)", &large);
}

criterion_group! {
    name = hierarchy;
    config = Criterion::default().sample_size(10);
    targets = benches
}
criterion_main!(hierarchy);
