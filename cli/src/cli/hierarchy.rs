//! `fairmesh hierarchy`: build the decimation hierarchy of the paper's section 4.1 and print or
//! write its levels. Its build options ([`BuildArgs`]), the build and the notes on what it left
//! out serve `fairmesh multires` too; `bench_rows` gives `fairmesh bench` the hierarchy's and the
//! multiresolution fairing's timings.

use anyhow::Context;
use clap::{Args, ValueEnum};
use fairmesh::fairing::creases::CreaseOptions;
use fairmesh::hierarchy::{
    build_hierarchy, build_hierarchy_with_topology, Hierarchy, HierarchyOptions,
};
use fairmesh::io::{self, Loaded};
use fairmesh::multires::{fair_multires, MultiresOptions, MultiresWorkspace};
use fairmesh::{NoProgress, Topology, TriMesh};
use serde_json::json;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::common::{emit, load, median_ms, print_load_warnings};

#[derive(Args, Debug, Clone)]
pub struct BuildArgs {
    /// Weight of the shortest incident edge in the vertex cost.
    #[arg(long, default_value_t = 1.0)]
    pub alpha: f64,
    /// Weight of the longest incident edge in the vertex cost.
    #[arg(long, default_value_t = 0.01)]
    pub beta: f64,
    /// Stop when a level has at most this many vertices.
    #[arg(long, default_value_t = 100)]
    pub min_vertices: usize,
    /// At most this many levels above M0.
    #[arg(long, default_value_t = 64)]
    pub max_levels: usize,
    /// Never collapse boundary vertices.
    #[arg(long)]
    pub keep_boundary: bool,
    /// Keep sharp edges (CAD parts, machined edges): every level keeps the edges where the
    /// surface folds by more than --crease-angle (a vertex on one collapses only along it, the
    /// corners never), and multires fairs them as curves. `hierarchy` leaves them out unless
    /// asked; `multires` keeps them unless --no-creases, as `fair` does.
    #[arg(long)]
    pub keep_creases: bool,
    /// How many degrees the surface must fold at an edge to keep it sharp (implies
    /// --keep-creases; default 40).
    #[arg(long)]
    pub crease_angle: Option<f64>,
}

impl BuildArgs {
    pub(super) fn options(&self) -> HierarchyOptions {
        HierarchyOptions::default()
            .with_alpha(self.alpha)
            .with_beta(self.beta)
            .with_min_vertices(self.min_vertices)
            .with_max_levels(self.max_levels)
            .with_keep_boundary(self.keep_boundary)
            .with_creases((self.keep_creases || self.crease_angle.is_some()).then(|| {
                CreaseOptions::default().with_angle_degrees(
                    self.crease_angle
                        .unwrap_or(fairmesh::fairing::creases::DEFAULT_CREASE_ANGLE),
                )
            }))
    }
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum LevelFormat {
    Obj,
    Glb,
}

#[derive(Args, Debug)]
pub struct HierarchyArgs {
    /// Input mesh.
    pub input: PathBuf,
    /// Print one JSON object: {"levels":[{"level","vertices","faces","time_ms"}...]}.
    #[arg(long)]
    pub json: bool,
    /// Write every level's mesh into this directory (level_00.obj, level_01.obj, ...).
    #[arg(long)]
    pub write_levels: Option<PathBuf>,
    /// Format of the written levels.
    #[arg(long, value_enum, default_value_t = LevelFormat::Obj)]
    pub format: LevelFormat,
    /// Loop-subdivide the input this many times first (to time large meshes).
    #[arg(long, default_value_t = 0)]
    pub subdivide: usize,
    #[command(flatten)]
    pub build: BuildArgs,
}

/// Builds the hierarchy; `topology` (the mesh's, from loading) saves building it again when
/// creases are kept, and `file_edges` (the file's own sharp edges) are creases too then.
pub(super) fn build(
    mesh: &TriMesh,
    topology: Option<&Topology>,
    args: &BuildArgs,
    file_edges: Vec<[u32; 2]>,
) -> anyhow::Result<Hierarchy> {
    build_with(mesh, topology, args, args.options(), file_edges)
}

/// Refuses a --crease-angle outside (0, 180) degrees.
pub(super) fn check_crease_angle(args: &BuildArgs) -> anyhow::Result<()> {
    if let Some(angle) = args.crease_angle {
        anyhow::ensure!(
            angle > 0.0 && angle < 180.0,
            "--crease-angle must be between 0 and 180 degrees (got {angle})"
        );
    }
    Ok(())
}

/// [`build`] with `options` (made from `args`, perhaps changed), the file's own hard edges
/// added to its creases.
pub(super) fn build_with(
    mesh: &TriMesh,
    topology: Option<&Topology>,
    args: &BuildArgs,
    mut options: HierarchyOptions,
    file_edges: Vec<[u32; 2]>,
) -> anyhow::Result<Hierarchy> {
    check_crease_angle(args)?;
    let mut step = super::progress::Step::start("building the hierarchy");
    if let Some(creases) = &mut options.creases {
        *creases = creases.clone().with_file_edges(file_edges);
    }
    Ok(match topology {
        Some(topology) => build_hierarchy_with_topology(mesh, topology, &options, &mut step)?,
        None => build_hierarchy(mesh, &options, &mut step)?,
    })
}

pub fn run(args: HierarchyArgs) -> anyhow::Result<()> {
    let (loaded, topology, file_edges) = load_for_build(&args)?;
    let started = Instant::now();
    let hierarchy = build(&loaded.mesh, topology.as_ref(), &args.build, file_edges)
        .with_context(|| format!("building the hierarchy of {}", args.input.display()))?;
    drop(topology);
    let total_ms = started.elapsed().as_secs_f64() * 1e3;
    if let Some(dir) = &args.write_levels {
        write_levels(dir, args.format, &hierarchy, &loaded.source)?;
    }
    let record_bytes_per_vertex =
        hierarchy.record_bytes() as f64 / loaded.mesh.vertex_count().max(1) as f64;
    if args.json {
        let object = json!({
            "levels": levels_json(&hierarchy),
            "total_ms": total_ms,
            "crease_edges": hierarchy.crease_edge_count(),
            "non_manifold_vertices": hierarchy.non_manifold_vertices().len(),
            "loose_triangles": hierarchy.loose_triangles().len(),
            "record_bytes_per_vertex": record_bytes_per_vertex,
        });
        return emit(&format!("{}\n", serde_json::to_string_pretty(&object)?));
    }
    print_notes(&hierarchy, &args.input);
    emit(&levels_table(
        &args.input,
        &hierarchy,
        total_ms,
        record_bytes_per_vertex,
    )?)
}

/// Loads the input (a file: `hierarchy`'s --format is the levels' format) and makes it ready for
/// the build: the mesh (subdivided as asked), with its connectivity and the file's own sharp
/// edges where creases are kept, and the file's own content only where the levels are written.
fn load_for_build(
    args: &HierarchyArgs,
) -> anyhow::Result<(Loaded, Option<Topology>, Vec<[u32; 2]>)> {
    let mut loaded =
        super::progress::Step::run(format!("loading {}", args.input.display()), || {
            load(&args.input, true)
        })?;
    print_load_warnings(&args.input, &loaded);
    // The file's own sharp edges, like the connectivity below, serve the crease detection only.
    let keep_creases = args.subdivide == 0 && args.build.options().creases.is_some();
    let file_edges = if keep_creases {
        loaded.source.hard_edges(&loaded.mesh)
    } else {
        Vec::new()
    };
    // The file's own bytes serve only to write the levels in its format: without
    // `--write-levels` they go before the build, which would otherwise hold them through its
    // heap peak.
    if args.write_levels.is_none() {
        loaded.source = std::sync::Arc::new(io::Source::plain(&loaded.mesh));
    }
    // The connectivity serves the crease detection only (as in `multires`); otherwise it goes
    // before the build, likewise.
    let topology = std::mem::take(&mut loaded.topology);
    let topology = keep_creases.then_some(topology);
    for _ in 0..args.subdivide {
        loaded.mesh = fairmesh::mesh::subdivide_loop(&loaded.mesh);
    }
    Ok((loaded, topology, file_edges))
}

/// Writes every level into `dir` (`level_00.obj`, ...; kept in the input file's content where the
/// format allows), then says once, on standard error, what the levels could not keep.
fn write_levels(
    dir: &Path,
    format: LevelFormat,
    hierarchy: &Hierarchy,
    source: &io::Source,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let extension = match format {
        LevelFormat::Obj => "obj",
        LevelFormat::Glb => "glb",
    };
    let mut lost = Vec::new();
    for level in 0..hierarchy.level_count() {
        let path = dir.join(format!("level_{level:02}.{extension}"));
        let (mesh, vertex_origin, face_origin) = hierarchy.level_for_export(level);
        let derivation = io::Derivation {
            base: hierarchy.base_mesh(),
            vertex_origin: &vertex_origin,
            face_origin: &face_origin,
        };
        let report = super::progress::Step::run(format!("saving {}", path.display()), || {
            io::save_derived_with_source(&path, &mesh, &derivation, source)
        })
        .with_context(|| format!("writing level {level}"))?;
        lost.extend(report.warnings);
    }
    // Every coarse level loses the same things: say it once.
    lost.dedup();
    lost.extend(hierarchy.levels_warning());
    for warning in lost {
        eprintln!("warning: {}: {warning}", dir.display());
    }
    Ok(())
}

/// Each level's size and build time, for `--json`.
fn levels_json(hierarchy: &Hierarchy) -> Vec<serde_json::Value> {
    (0..hierarchy.level_count())
        .map(|level| {
            let info = hierarchy.level_info(level);
            json!({
                "level": level,
                "vertices": info.vertices,
                "faces": info.faces,
                "time_ms": hierarchy.level_build_ms(level),
            })
        })
        .collect()
}

/// The levels as a table, under a line on the whole build.
fn levels_table(
    input: &Path,
    hierarchy: &Hierarchy,
    total_ms: f64,
    record_bytes_per_vertex: f64,
) -> anyhow::Result<String> {
    let creases = match hierarchy.crease_edge_count() {
        0 => String::new(),
        edges => format!(", {edges} crease edges kept sharp"),
    };
    let mut out = format!(
        "{}: {} in {:.1} ms ({:.1} bytes of collapse records per vertex{creases})\nlevel  vertices     faces   time ms\n",
        input.display(),
        levels_phrase(hierarchy),
        total_ms,
        record_bytes_per_vertex
    );
    for level in 0..hierarchy.level_count() {
        let info = hierarchy.level_info(level);
        writeln!(
            out,
            "{level:>5} {:>9} {:>9} {:>9.2}",
            info.vertices,
            info.faces,
            hierarchy.level_build_ms(level)
        )?;
    }
    Ok(out)
}

/// "1 level" or "N levels": how many levels `hierarchy` has.
pub(super) fn levels_phrase(hierarchy: &Hierarchy) -> String {
    match hierarchy.level_count() {
        1 => "1 level".to_string(),
        count => format!("{count} levels"),
    }
}

/// What the build did with a mesh that is not an oriented 2-manifold, on stderr.
pub(super) fn print_notes(hierarchy: &Hierarchy, input: &Path) {
    if !hierarchy.loose_triangles().is_empty() {
        eprintln!(
            "note: {}: {} triangles lie loose at non-manifold edges (over other triangles, or \
             hanging from an edge as fins): the levels are built without them (level 0 is the \
             mesh without them), and they stay in a multires result",
            input.display(),
            hierarchy.loose_triangles().len()
        );
    }
    if let [first, ..] = hierarchy.non_manifold_vertices() {
        eprintln!(
            "note: {}: {} vertices where the mesh is not an oriented 2-manifold (e.g. vertex {first}) stay in every level, with their neighbours",
            input.display(),
            hierarchy.non_manifold_vertices().len()
        );
    }
}

/// Rows for `fairmesh bench`: (operation, milliseconds).
pub fn bench_rows(mesh: &TriMesh, topology: &Topology) -> Vec<(String, f64)> {
    let runs = 5;
    let options = HierarchyOptions::default();
    let mut hierarchy = None;
    let build_ms = median_ms(runs, || {
        hierarchy = build_hierarchy(mesh, &options, &mut NoProgress).ok();
    });
    let mut rows = vec![("hierarchy build".to_string(), build_ms)];
    // With `--keep-creases` (detection on the mesh, then the collapses kept along the creases),
    // from the loaded connectivity as the commands do.
    let with_creases =
        HierarchyOptions::default().with_creases(Some(fairmesh::fairing::CreaseOptions::default()));
    rows.push((
        "hierarchy build keeping creases".to_string(),
        median_ms(runs, || {
            std::hint::black_box(
                build_hierarchy_with_topology(mesh, topology, &with_creases, &mut NoProgress).ok(),
            );
        }),
    ));
    let Some(hierarchy) = hierarchy else {
        return rows;
    };
    let coarsest = hierarchy.coarsest_level();
    // What `fairmesh multires` pays once: its one run also sets up every level's fairing
    // (connectivity, valences, per-triangle matrices), level by level.
    let options = MultiresOptions::default().with_start_level(coarsest / 2);
    let first_ms = median_ms(runs, || {
        let _ = std::hint::black_box(fair_multires(
            &hierarchy,
            &options,
            &mut MultiresWorkspace::for_one_run(),
            &mut NoProgress,
        ));
    });
    rows.push((
        format!("multires from middle level {}, first run", coarsest / 2),
        first_ms,
    ));
    let mut workspace = MultiresWorkspace::new();
    for (name, level) in [("coarsest", coarsest), ("middle", coarsest / 2)] {
        let options = MultiresOptions::default().with_start_level(level);
        // Warm the workspace (per-level connectivity) once, then time.
        let _ = fair_multires(&hierarchy, &options, &mut workspace, &mut NoProgress);
        let ms = median_ms(runs, || {
            let _ = std::hint::black_box(fair_multires(
                &hierarchy,
                &options,
                &mut workspace,
                &mut NoProgress,
            ));
        });
        rows.push((format!("multires from {name} level {level}"), ms));
    }
    rows
}
