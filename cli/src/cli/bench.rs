//! `fairmesh bench FILE`: a table of the timings that matter on one mesh, as medians of several
//! runs. Each part of the library adds its own rows (`fair::bench_rows`, `hierarchy::bench_rows`).

use clap::Args;
use fairmesh::{io, mesh, metrics, Topology, TriMesh};
use std::path::PathBuf;

use super::common::{emit, load, median_ms};

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Mesh to time the operations on.
    pub input: PathBuf,
    /// Runs per operation (the median is shown).
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Subdivide the mesh this many times first (Loop; each time 4x the faces), to time large meshes.
    #[arg(long, default_value_t = 0)]
    pub subdivide: usize,
    /// Time only these groups of operations (comma-separated: load, save, mesh, fair, creases,
    /// hierarchy); all of them when left out.
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<BenchGroup>,
}

/// A group of operations `bench` times.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchGroup {
    /// Loading (with weld, clean and topology).
    Load,
    /// Saving, into the kept file and bare.
    Save,
    /// Topology, weld, volume, area, edge length.
    Mesh,
    /// A constrained fairing set-up and iterations, and a Laplacian iteration.
    Fair,
    /// Crease detection and the guided normal filter.
    Creases,
    /// The hierarchy build.
    Hierarchy,
}

impl BenchArgs {
    fn wants(&self, group: BenchGroup) -> bool {
        self.only.is_empty() || self.only.contains(&group)
    }
}

/// Saving a moved copy of the mesh in the input's format: written into the kept file
/// (`io::save_with_source`) and as a bare mesh (`io::save`), to a temporary folder.
fn save_rows(args: &BenchArgs, loaded: &io::Loaded) -> anyhow::Result<Vec<(String, f64)>> {
    let Some(format) = io::Format::from_path(&args.input) else {
        return Ok(Vec::new());
    };
    if matches!(format, io::Format::Off) {
        return Ok(Vec::new());
    }
    // Every vertex moves (as after fairing), so every position and normal is written anew.
    let mut moved = loaded.mesh.clone();
    for p in &mut moved.positions {
        *p = p.map(|c| c * 1.0001 + 1e-4);
    }
    let dir = tempfile_dir()?;
    let path = dir.join(format!("bench.{}", format.extension()));
    let mut result = Ok(());
    let kept = median_ms(args.runs, || {
        if let Err(e) = io::save_with_source(&path, &moved, &loaded.source) {
            result = Err(e);
        }
    });
    let bare = median_ms(args.runs, || {
        if let Err(e) = io::save(&path, &moved) {
            result = Err(e);
        }
    });
    let _ = std::fs::remove_dir_all(&dir);
    result?;
    Ok(vec![
        (
            format!("save {format}, keeping the input file's content"),
            kept,
        ),
        (format!("save {format}, bare mesh"), bare),
    ])
}

/// A fresh folder in the system's temporary directory.
fn tempfile_dir() -> anyhow::Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("fairmesh-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// The rows timed on the (subdivided) mesh: its topology, weld and measures, fairing, creases
/// and the hierarchy, as `args` asks.
fn mesh_rows(args: &BenchArgs, mesh: &TriMesh) -> Vec<(String, f64)> {
    let mut rows = Vec::new();
    let topology = Topology::build(mesh);
    if args.wants(BenchGroup::Mesh) {
        rows.push((
            "topology".into(),
            median_ms(args.runs, || {
                std::hint::black_box(Topology::build(mesh));
            }),
        ));
        rows.push((
            "weld (already welded mesh)".into(),
            median_ms(args.runs, || {
                let mut copy = mesh.clone();
                mesh::weld(&mut copy);
            }),
        ));
        rows.push((
            "volume + area + mean edge length".into(),
            median_ms(args.runs, || {
                std::hint::black_box((
                    metrics::signed_volume(mesh),
                    metrics::area(mesh),
                    metrics::mean_edge_length(mesh),
                ));
            }),
        ));
    }
    if args.wants(BenchGroup::Fair) {
        rows.extend(super::fair::bench_rows(mesh, &topology));
    }
    if args.wants(BenchGroup::Creases) {
        rows.extend(super::fair::crease_bench_rows(mesh, &topology, args.runs));
    }
    if args.wants(BenchGroup::Hierarchy) {
        rows.extend(super::hierarchy::bench_rows(mesh, &topology));
    }
    rows
}

pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    let mut rows: Vec<(String, f64)> = Vec::new();
    if args.wants(BenchGroup::Load) {
        let load_ms = median_ms(args.runs, || {
            let _ = load(&args.input, true);
        });
        rows.push(("load + weld + clean + topology".into(), load_ms));
    }
    let mut loaded = load(&args.input, true)?;
    if args.subdivide == 0 && args.wants(BenchGroup::Save) {
        rows.extend(save_rows(&args, &loaded)?);
    }
    let on_the_mesh = [
        BenchGroup::Mesh,
        BenchGroup::Fair,
        BenchGroup::Creases,
        BenchGroup::Hierarchy,
    ];
    // Only these read the (subdivided) mesh and its topology: not built for `--only load,save`.
    let subdivisions = if on_the_mesh.iter().any(|&group| args.wants(group)) {
        for _ in 0..args.subdivide {
            loaded.mesh = mesh::subdivide_loop(&loaded.mesh);
        }
        rows.extend(mesh_rows(&args, &loaded.mesh));
        args.subdivide
    } else {
        0
    };
    let mesh = loaded.mesh;

    let mut out = format!(
        "{}: {} vertices, {} faces{} ({} threads; median of {} runs)\n",
        args.input.display(),
        mesh.vertex_count(),
        mesh.face_count(),
        if subdivisions > 0 {
            format!(" after {subdivisions} subdivisions")
        } else {
            String::new()
        },
        rayon::current_num_threads(),
        args.runs
    );
    out.push_str(&format!("{:<48} {:>12}\n", "operation", "ms"));
    for (name, ms) in rows {
        out.push_str(&format!("{name:<48} {ms:>12.3}\n"));
    }
    emit(&out)
}
