//! Load and save benchmarks for the io module: `cargo bench --bench io`.
//!
//! On bunny00 (75k faces) in OBJ, binary PLY and GLB (the PLY and GLB copies are written to a
//! temporary directory at start). "load" is the whole of `io::load`: read, parse, weld, clean,
//! topology. With `FAIRMESH_BENCH_LARGE=1` it also Loop-subdivides bunny00 twice (1.2M faces),
//! writes `fairmesh-io-large.{obj,ply,glb}` to the system temp directory (kept, so that they can
//! be timed by other means, e.g. `/usr/bin/time -v fairmesh info FILE`) and benchmarks those.

use criterion::{criterion_group, criterion_main, Criterion};
use fairmesh::io;
use std::path::{Path, PathBuf};

fn bench_set(
    c: &mut Criterion,
    group_name: &str,
    mesh: &fairmesh::TriMesh,
    dir: &Path,
    obj: PathBuf,
    samples: usize,
) {
    let ply = dir.join(format!("{group_name}.ply"));
    let glb = dir.join(format!("{group_name}.glb"));
    if !obj.exists() {
        io::save(&obj, mesh).unwrap();
    }
    io::save(&ply, mesh).unwrap();
    io::save(&glb, mesh).unwrap();

    let mut group = c.benchmark_group(format!("load {group_name} ({} faces)", mesh.face_count()));
    group.sample_size(samples);
    for path in [&obj, &ply, &glb] {
        let ext = path.extension().unwrap().to_string_lossy().into_owned();
        group.bench_function(ext, |b| b.iter(|| io::load(path).unwrap()));
    }
    group.finish();

    let mut group = c.benchmark_group(format!("save {group_name} ({} faces)", mesh.face_count()));
    group.sample_size(samples);
    let out = tempfile::tempdir().unwrap();
    for ext in ["obj", "ply", "glb"] {
        let path = out.path().join(format!("out.{ext}"));
        group.bench_function(ext, |b| b.iter(|| io::save(&path, mesh).unwrap()));
    }
    group.finish();
}

fn io_benches(c: &mut Criterion) {
    let bunny = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/bunny00.obj");
    let mesh = io::load(&bunny).unwrap().mesh;
    let dir = tempfile::tempdir().unwrap();
    bench_set(c, "bunny00", &mesh, dir.path(), bunny, 20);

    if std::env::var_os("FAIRMESH_BENCH_LARGE").is_some() {
        let large = fairmesh::mesh::subdivide_loop(&fairmesh::mesh::subdivide_loop(&mesh));
        let keep = std::env::temp_dir();
        let obj = keep.join("fairmesh-io-large.obj");
        io::save(&obj, &large).unwrap();
        bench_set(c, "fairmesh-io-large", &large, &keep, obj, 10);
    }
}

criterion_group!(benches, io_benches);
criterion_main!(benches);
