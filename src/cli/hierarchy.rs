//! `fairmesh hierarchy` (build the decimation hierarchy of section 4.1, print or write its
//! levels) and `fairmesh multires` (multiresolution fairing of section 4.2 from a start level).

use anyhow::Context;
use clap::{Args, ValueEnum};
use fairmesh::fairing::creases::CreaseOptions;
use fairmesh::hierarchy::{
    build_hierarchy, build_hierarchy_with_topology, Hierarchy, HierarchyOptions,
};
use fairmesh::multires::{fair_multires, MultiresOptions, MultiresVariant, MultiresWorkspace};
use fairmesh::noise::{self, NoiseOptions};
use fairmesh::{io, metrics, NoProgress, Topology, TriMesh};
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use super::args::{BoundaryArg, StdioFormat};
use super::common::{
    emit, is_stdio, load, load_input, load_shown, median_ms, print_load_warnings, save_kept,
    stdio_format,
};

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
    /// corners never), and multires fairs them as curves. Off by default: on noisy organic scans
    /// the detector finds a few false creases, which then stay as ridges.
    #[arg(long)]
    pub keep_creases: bool,
    /// How many degrees the surface must fold at an edge to keep it sharp (implies
    /// --keep-creases; default 40).
    #[arg(long)]
    pub crease_angle: Option<f64>,
}

impl BuildArgs {
    fn options(&self) -> HierarchyOptions {
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

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum VariantArg {
    /// The paper's placement of split vertices (1-ring mean plus one Kobbelt step).
    Paper,
    /// Kobbelt placement plus a low-passed volume restoration (see the multires module docs).
    Improved,
}

#[derive(Args, Debug)]
pub struct MultiresArgs {
    /// Input mesh.
    pub input: PathBuf,
    /// Output mesh (format by extension; `-`: standard output, with --format); optional when
    /// only timing or measuring.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Start level(s): 0 is M0 (single-level fairing), larger is coarser and smoother. Several,
    /// comma separated, run one after another (with --json: one object each, as an array).
    #[arg(long, value_delimiter = ',', default_value = "1")]
    pub level: Vec<usize>,
    /// Fairing iterations per level and round.
    #[arg(long, default_value_t = 5)]
    pub iterations: usize,
    /// Fairing rounds per level (each re-imposes the constraints).
    #[arg(long, default_value_t = 1)]
    pub rounds: usize,
    #[arg(long, default_value = "curve", value_parser = BoundaryArg::names_only_parser())]
    pub boundary: BoundaryArg,
    /// Also fair M0 after the last refinement.
    #[arg(long)]
    pub fair_finest: bool,
    /// Placement of split vertices; several, comma separated, run one after another.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "improved")]
    pub variant: Vec<VariantArg>,
    /// Add seeded normal noise of this many mean edge lengths first (the volume change, and with
    /// --measure the distances, are then taken against the clean input).
    #[arg(long)]
    pub noise: Option<f64>,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Measure each result against the input (before any noise): two-way surface distance (mean
    /// and Hausdorff), vertex RMS and normal error. Costs more than the fairing on large meshes.
    #[arg(long)]
    pub measure: bool,
    /// Measure the result against this mesh instead of the input (implies --measure).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Print JSON instead of text: the time of each run and of the hierarchy build, the volume
    /// change, and with --measure the distances.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub stdio: StdioFormat,
    #[command(flatten)]
    pub build: BuildArgs,
    #[command(flatten)]
    pub mask: super::mask::MaskArgs,
}

/// Builds the hierarchy; `topology` (the mesh's, from loading) saves building it again when
/// creases are kept, and `file_edges` (the file's own sharp edges) are creases too then.
fn build(
    mesh: &TriMesh,
    topology: Option<&Topology>,
    args: &BuildArgs,
    file_edges: Vec<[u32; 2]>,
) -> anyhow::Result<Hierarchy> {
    if let Some(angle) = args.crease_angle {
        anyhow::ensure!(
            angle > 0.0 && angle < 180.0,
            "--crease-angle must be between 0 and 180 degrees (got {angle})"
        );
    }
    let mut step = super::progress::Step::start("building the hierarchy");
    let mut options = args.options();
    if let Some(creases) = &mut options.creases {
        *creases = creases.clone().with_file_edges(file_edges);
    }
    Ok(match topology {
        Some(topology) => build_hierarchy_with_topology(mesh, topology, &options, &mut step)?,
        None => build_hierarchy(mesh, &options, &mut step)?,
    })
}

pub fn run_hierarchy(args: HierarchyArgs) -> anyhow::Result<()> {
    // (Its --format is the levels' format: it reads files only.)
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
    // `--write-levels` they go before the build (on 1.2M faces 23 of its 162 MB heap peak).
    if args.write_levels.is_none() {
        loaded.source = std::sync::Arc::new(fairmesh::io::Source::plain(&loaded.mesh));
    }
    // The connectivity serves the crease detection only (as in `multires`); otherwise it goes
    // before the build (on 1.2M faces 36 MB of the build's 199 MB heap peak).
    let topology = std::mem::take(&mut loaded.topology);
    let topology = keep_creases.then_some(topology);
    for _ in 0..args.subdivide {
        loaded.mesh = fairmesh::mesh::subdivide_loop(&loaded.mesh);
    }
    let started = Instant::now();
    let hierarchy = build(&loaded.mesh, topology.as_ref(), &args.build, file_edges)
        .with_context(|| format!("building the hierarchy of {}", args.input.display()))?;
    drop(topology);
    let total_ms = started.elapsed().as_secs_f64() * 1e3;
    if let Some(dir) = &args.write_levels {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let extension = match args.format {
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
                io::save_derived_with_source(&path, &mesh, &derivation, &loaded.source)
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
    }
    let levels: Vec<_> = (0..hierarchy.level_count())
        .map(|level| {
            let info = hierarchy.level_info(level);
            json!({
                "level": level,
                "vertices": info.vertices,
                "faces": info.faces,
                "time_ms": hierarchy.level_build_ms(level),
            })
        })
        .collect();
    if args.json {
        let object = json!({
            "levels": levels,
            "total_ms": total_ms,
            "crease_edges": hierarchy.crease_edge_count(),
            "non_manifold_vertices": hierarchy.non_manifold_vertices().len(),
            "loose_triangles": hierarchy.loose_triangles().len(),
            "record_bytes_per_vertex":
                hierarchy.record_bytes() as f64 / loaded.mesh.vertex_count().max(1) as f64,
        });
        return emit(&format!("{}\n", serde_json::to_string_pretty(&object)?));
    }
    let creases = match hierarchy.crease_edge_count() {
        0 => String::new(),
        edges => format!(", {edges} crease edges kept sharp"),
    };
    print_notes(&hierarchy, &args.input);
    let mut out = format!(
        "{}: {} level{} in {:.1} ms ({:.1} bytes of collapse records per vertex{creases})\nlevel  vertices     faces   time ms\n",
        args.input.display(),
        hierarchy.level_count(),
        if hierarchy.level_count() == 1 { "" } else { "s" },
        total_ms,
        hierarchy.record_bytes() as f64 / loaded.mesh.vertex_count().max(1) as f64
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
    emit(&out)
}

/// What the build did with a mesh that is not an oriented 2-manifold, on stderr.
fn print_notes(hierarchy: &Hierarchy, input: &std::path::Path) {
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

pub fn run_multires(args: MultiresArgs) -> anyhow::Result<()> {
    let to_stdout = args.output.as_deref().is_some_and(is_stdio);
    anyhow::ensure!(
        !(args.json && to_stdout),
        "--json and `-o -` would both write to standard output: write the mesh to a file"
    );
    if to_stdout {
        stdio_format(args.stdio.format, "writing to standard output")?;
    }
    let measure = args.measure || args.reference.is_some();
    let loaded = load_input(&args.input, true, args.stdio.format)?;
    let source = loaded.source;
    let mask = super::mask::load_for(&args.mask, &source, &loaded.mesh, Some(&loaded.topology))?;
    // The connectivity serves the crease detection only; otherwise it goes before the build.
    let topology = args
        .build
        .options()
        .creases
        .is_some()
        .then_some(loaded.topology);
    // The file's own sharp edges are creases too, when creases are kept.
    let file_edges = match topology {
        Some(_) => source.hard_edges(&loaded.mesh),
        None => Vec::new(),
    };
    let mut input = loaded.mesh;
    let reference_file = match &args.reference {
        Some(path) => Some(load_shown(path, true, None)?.mesh),
        None => None,
    };
    // Results are measured against the input before any noise: keep a copy only when the noise
    // would change it and the distances are asked for.
    let clean =
        (measure && reference_file.is_none() && args.noise.is_some()).then(|| input.clone());
    let clean_volume = match &reference_file {
        Some(reference) => metrics::signed_volume(reference),
        None => metrics::signed_volume(&input),
    };
    if let Some(sigma) = args.noise {
        noise::add_noise(
            &mut input,
            &NoiseOptions::default()
                .with_sigma(sigma)
                .with_seed(args.seed),
        );
    }
    let started = Instant::now();
    let hierarchy = build(&input, topology.as_ref(), &args.build, file_edges)?;
    drop(topology);
    print_notes(&hierarchy, &args.input);
    // The hierarchy keeps its own copy of the (noisy) input as M0: the input goes, and the
    // results take their triangles from M0 (18 bytes per face less at the peak).
    drop(input);
    let base = hierarchy.base_mesh();
    let reference = measure.then(|| reference_file.as_ref().or(clean.as_ref()).unwrap_or(base));
    let hierarchy_ms = started.elapsed().as_secs_f64() * 1e3;
    // One run holds only the level it is at; several runs share every level's set-up.
    let mut workspace = if args.variant.len() * args.level.len() == 1 {
        MultiresWorkspace::for_one_run()
    } else {
        MultiresWorkspace::new()
    };
    let mut results = Vec::new();
    let mut last = None;
    let coarsest = hierarchy.coarsest_level();
    let mut beyond: Vec<usize> = args
        .level
        .iter()
        .copied()
        .filter(|&l| l > coarsest)
        .collect();
    beyond.sort_unstable();
    beyond.dedup();
    if !beyond.is_empty() {
        let levels: Vec<String> = beyond.iter().map(usize::to_string).collect();
        eprintln!(
            "note: {}: the hierarchy has levels 0 to {coarsest}, so {} {} {} from level {coarsest}, \
             its coarsest",
            args.input.display(),
            if beyond.len() == 1 { "level" } else { "levels" },
            levels.join(", "),
            if beyond.len() == 1 { "starts" } else { "start" }
        );
    }
    for &variant in &args.variant {
        for &level in &args.level {
            let options = MultiresOptions::default()
                .with_start_level(level)
                .with_iterations(args.iterations)
                .with_rounds(args.rounds)
                .with_boundary(args.boundary.into())
                .with_fair_finest(args.fair_finest)
                .with_mask(mask.clone())
                .with_variant(match variant {
                    VariantArg::Paper => MultiresVariant::Paper,
                    VariantArg::Improved => MultiresVariant::Improved,
                });
            let start = level.min(coarsest);
            // One run, timed whole: with the per-level set-up a first run on this workspace does.
            let mut step =
                super::progress::Step::start(format!("multiresolution fairing from level {start}"));
            let started = Instant::now();
            let positions = fair_multires(&hierarchy, &options, &mut workspace, &mut step)
                .context("multires fairing was cancelled")?;
            let time_ms = started.elapsed().as_secs_f64() * 1e3;
            drop(step);
            let result = TriMesh::new(positions, base.triangles.clone());
            let volume_change_percent = (clean_volume != 0.0).then(|| {
                100.0 * (metrics::signed_volume(&result) - clean_volume) / clean_volume.abs()
            });
            let mut row = json!({
                "level": start,
                "level_vertices": hierarchy.level_info(start).vertices,
                "variant": format!("{variant:?}").to_lowercase(),
                "time_ms": time_ms,
                "hierarchy_ms": hierarchy_ms,
                "loose_triangles": hierarchy.loose_triangles().len(),
                "volume_change_percent": volume_change_percent,
            });
            if let (Some(reference), Some(map)) = (reference, row.as_object_mut()) {
                let comparison = super::progress::Step::run("measuring the result", || {
                    metrics::compare(reference, &result)
                });
                map.insert(
                    "mean_surface_distance".into(),
                    json!(comparison.mean_surface_distance),
                );
                map.insert(
                    "mean_surface_distance_edges".into(),
                    json!(comparison.mean_surface_distance / metrics::mean_edge_length(reference)),
                );
                map.insert("hausdorff".into(), json!(comparison.hausdorff));
                map.insert(
                    "normal_error_deg".into(),
                    json!(comparison.same_connectivity.map(|c| c.normal_error_deg)),
                );
                map.insert(
                    "rms".into(),
                    json!(comparison.same_connectivity.map(|c| c.rms)),
                );
            }
            results.push(row);
            last = Some(result);
        }
    }
    if let (Some(path), Some(result)) = (&args.output, &last) {
        save_kept(path, result, &source, args.stdio.format)?;
    }
    if args.json {
        let value = if results.len() == 1 {
            results.pop().unwrap_or_default()
        } else {
            serde_json::Value::Array(results)
        };
        return emit(&format!("{}\n", serde_json::to_string_pretty(&value)?));
    }
    let mut out = format!(
        "{}: hierarchy of {} level{} in {:.1} ms{}\nlevel  vertices  variant   time ms   volume %{}\n",
        args.input.display(),
        hierarchy.level_count(),
        if hierarchy.level_count() == 1 { "" } else { "s" },
        hierarchy_ms,
        match args.noise {
            Some(s) => format!(", noise {s} mean edge lengths (seed {})", args.seed),
            None => String::new(),
        },
        if measure {
            "   mean dist (edges)  normal err deg"
        } else {
            ""
        }
    );
    // A value the row does not have (no volume to change on a flat or open patch of zero volume,
    // a measure that could not be made) prints as "-", as in JSON it is null.
    let cell = |value: &serde_json::Value, width: usize, format: fn(f64) -> String| {
        let text = value
            .as_f64()
            .filter(|v| v.is_finite())
            .map_or_else(|| "-".to_string(), format);
        format!(" {text:>width$}")
    };
    for r in &results {
        write!(
            out,
            "{:>5} {:>9}  {:<8} {:>8.2}",
            // as numbers: a JSON value ignores the column width
            r["level"].as_u64().unwrap_or(0),
            r["level_vertices"].as_u64().unwrap_or(0),
            r["variant"].as_str().unwrap_or(""),
            r["time_ms"].as_f64().unwrap_or(0.0),
        )?;
        out += &cell(&r["volume_change_percent"], 10, |v| format!("{v:+.4}"));
        if measure {
            out += &cell(&r["mean_surface_distance_edges"], 18, |v| format!("{v:.5}"));
            out += &cell(&r["normal_error_deg"], 15, |v| format!("{v:.3}"));
        }
        out.push('\n');
    }
    if to_stdout {
        // Standard output holds the mesh.
        eprint!("{out}");
        Ok(())
    } else {
        emit(&out)
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
        std::hint::black_box(fair_multires(
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
            std::hint::black_box(fair_multires(
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
