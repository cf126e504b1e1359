//! `fairmesh multires`: multiresolution fairing (section 4.2 of the paper) from one or more start
//! levels of the decimation hierarchy (section 4.1, built as `fairmesh hierarchy` builds it), each
//! result timed and, with `--measure`, measured against the input before any noise.

use std::fmt::Write as _;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, ValueEnum};
use fairmesh::fairing::creases::{CreaseOptions, DEFAULT_CREASE_ANGLE};
use fairmesh::fairing::Mask;
use fairmesh::hierarchy::Hierarchy;
use fairmesh::hierarchy::HierarchyOptions;
use fairmesh::io::Source;
use fairmesh::multires::{
    fair_multires, Denoise, DenoiseOptions, Denoised, MultiresOptions, MultiresVariant,
    MultiresWorkspace,
};
use fairmesh::noise::{self, NoiseOptions};
use fairmesh::{metrics, Topology, TriMesh};
use serde_json::json;
use std::path::PathBuf;

use super::args::{BoundaryArg, StdioFormat};
use super::common::{check_output_format, emit, is_stdio, load_input, load_shown, save_kept};
use super::hierarchy::{build_with, check_crease_angle, levels_phrase, print_notes, BuildArgs};

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum VariantArg {
    /// The paper's section 4 and nothing else: its hierarchy (each collapse checked against its
    /// own level only, unless the improved variant is asked for too), split vertices at their
    /// 1-ring mean plus one Kobbelt step, no unfolding. With --denoise off --no-creases
    /// --fair-finest false it is the paper's recipe exactly.
    Paper,
    /// Kobbelt placement plus a low-passed volume restoration, each level's shrinkage taken back,
    /// and the edges a run leaves folded unfolded (see the multires module docs).
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
    /// How boundary vertices of open meshes move: `curve` smooths each boundary loop as a curve
    /// (paper section 3.3), `fixed` keeps them where they are.
    #[arg(long, default_value = "curve", value_parser = BoundaryArg::names_only_parser())]
    pub boundary: BoundaryArg,
    /// Also fair M0 after the last refinement (`--fair-finest false`: not): a light pass that
    /// unfolds the few edges the vertex splits leave folded.
    #[arg(long, default_value_t = true, num_args = 0..=1, default_missing_value = "true",
          action = clap::ArgAction::Set, value_name = "BOOL")]
    pub fair_finest: bool,
    /// The recipe (`paper`: the paper's section 4 exactly when run with --denoise off
    /// --no-creases --fair-finest false); several, comma separated, run one after another.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "improved")]
    pub variant: Vec<VariantArg>,
    /// Denoise the mesh first, once, as `fairmesh fair` does by default, and build the hierarchy
    /// on the result: level 0 is then exactly `fair`'s result and a coarser level removes detail
    /// on top of it (as the editor does). `auto`: the automatic strength (a clean mesh is left
    /// as it is); a number: that many rounds; `off`: the paper's multires alone (level 0 then
    /// fairs M0 with --iterations and --rounds).
    #[arg(long, default_value = "auto", value_parser = parse_denoise)]
    pub denoise: Denoise,
    /// Fair across sharp edges too, in the denoise and on every level (by default they are kept,
    /// as `fair` keeps them: found at --crease-angle, plus the file's own hard edges).
    #[arg(long, conflicts_with_all = ["keep_creases", "crease_angle"])]
    pub no_creases: bool,
    /// Add seeded normal noise of this many mean edge lengths first (the volume change, and with
    /// --measure the distances, are then taken against the clean input).
    #[arg(long)]
    pub noise: Option<f64>,
    /// Random seed of --noise: the same seed gives the same noise on every machine.
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

/// `--denoise`: `auto`, `off` or a number of rounds.
fn parse_denoise(text: &str) -> Result<Denoise, String> {
    match text {
        "auto" => Ok(Denoise::Automatic),
        "off" => Ok(Denoise::Off),
        rounds => rounds
            .parse()
            .map(Denoise::Rounds)
            .map_err(|_| format!("expected auto, off or a number of rounds, not `{text}`")),
    }
}

impl MultiresArgs {
    /// The hierarchy's options: those of `fairmesh hierarchy`, with sharp edges kept unless
    /// --no-creases, and the paper's hierarchy (no check of collapses against M0) when only the
    /// paper's variant is asked for.
    fn hierarchy_options(&self) -> HierarchyOptions {
        let paper_only = self.variant.iter().all(|&v| v == VariantArg::Paper);
        let options = self.build.options().with_keep_orientation(!paper_only);
        if self.no_creases || options.creases.is_some() {
            return options;
        }
        options.with_creases(Some(
            CreaseOptions::default().with_angle_degrees(DEFAULT_CREASE_ANGLE),
        ))
    }

    /// The options of the run from `level` with `variant`, fairing within `mask` (if any).
    fn options(&self, level: usize, variant: VariantArg, mask: Option<Mask>) -> MultiresOptions {
        MultiresOptions::default()
            .with_start_level(level)
            .with_iterations(self.iterations)
            .with_rounds(self.rounds)
            .with_boundary(self.boundary.into())
            .with_fair_finest(self.fair_finest)
            .with_mask(mask)
            .with_variant(match variant {
                VariantArg::Paper => MultiresVariant::Paper,
                VariantArg::Improved => MultiresVariant::Improved,
            })
    }
}

/// The input of the runs, read and made ready for the hierarchy build.
struct Prepared {
    source: Arc<Source>,
    mask: Option<Mask>,
    /// The mesh's connectivity, kept only when creases are kept or the mesh is denoised first
    /// (both read it).
    topology: Option<Topology>,
    /// The file's own sharp edges, creases too when creases are kept.
    file_edges: Vec<[u32; 2]>,
    /// The input, with the noise `--noise` adds.
    input: TriMesh,
    /// The mesh `--reference` names.
    reference_file: Option<TriMesh>,
    /// The input before the noise, kept only to measure against it.
    clean: Option<TriMesh>,
    /// The volume the results' volume change is taken against: the reference's, else the input's
    /// before any noise.
    clean_volume: f64,
}

pub fn run(args: MultiresArgs) -> anyhow::Result<()> {
    let to_stdout = check_output(&args)?;
    check_crease_angle(&args.build)?;
    let measure = args.measure || args.reference.is_some();
    let mut prepared = prepare(&args, measure)?;
    let started = Instant::now();
    let denoised = denoise_first(&args, &prepared)?;
    // A mask fades the results into the input itself, not into the denoised mesh.
    let unmasked = prepared
        .mask
        .is_some()
        .then(|| prepared.input.positions.clone());
    let denoise_ms = started.elapsed().as_secs_f64() * 1e3;
    let (built_on, denoise_report) = match denoised {
        Some(Denoised { mesh, report }) => (mesh, Some(report)),
        None => (std::mem::take(&mut prepared.input), None),
    };
    let started = Instant::now();
    let hierarchy = build_with(
        &built_on,
        prepared.topology.as_ref(),
        &args.build,
        args.hierarchy_options(),
        prepared.file_edges,
    )?;
    drop(prepared.topology);
    drop(built_on);
    print_notes(&hierarchy, &args.input);
    // The hierarchy keeps its own copy of the (noisy) input as M0: the input goes, and the
    // results take their triangles from M0.
    drop(prepared.input);
    let base = hierarchy.base_mesh();
    let reference = measure.then(|| {
        (prepared.reference_file.as_ref())
            .or(prepared.clean.as_ref())
            .unwrap_or(base)
    });
    let hierarchy_ms = started.elapsed().as_secs_f64() * 1e3;
    note_levels_beyond(&args, hierarchy.coarsest_level());
    let runs = Runs {
        hierarchy: &hierarchy,
        mask: prepared.mask,
        unmasked,
        denoise: denoise_report.map(|report| (report, denoise_ms)),
        reference,
        clean_volume: prepared.clean_volume,
        hierarchy_ms,
    };
    let (results, last) = runs.fair_each(&args)?;
    if let (Some(path), Some(result)) = (&args.output, &last) {
        save_kept(path, result, &prepared.source, args.stdio.format)?;
    }
    let header = Header {
        hierarchy: &hierarchy,
        hierarchy_ms,
        denoise: runs.denoise.as_ref(),
    };
    print_results(&args, &header, measure, results, to_stdout)
}

/// The first stage (`--denoise`): the input faired as `fairmesh fair` fairs it, with the file's
/// own hard edges kept as `fair` keeps them; `None` with `--denoise off` or 0 rounds.
fn denoise_first(args: &MultiresArgs, prepared: &Prepared) -> anyhow::Result<Option<Denoised>> {
    let options = DenoiseOptions {
        denoise: args.denoise,
        creases: args
            .hierarchy_options()
            .creases
            .map(|creases| creases.with_file_edges(prepared.file_edges.clone())),
        boundary: args.boundary.into(),
    };
    if options.fair_options().is_none() {
        return Ok(None);
    }
    let Some(topology) = prepared.topology.as_ref() else {
        anyhow::bail!("the denoise needs the mesh's connectivity");
    };
    let mut step = super::progress::Step::start("denoising (the automatic default of fair)");
    let denoised = fairmesh::multires::denoise(&prepared.input, topology, &options, &mut step)
        .context("the denoise was cancelled")?;
    drop(step);
    Ok(denoised)
}

/// Refuses `--json` with `-o -` (both would write to standard output), and `-o -` without
/// `--format`; returns whether the mesh goes to standard output.
fn check_output(args: &MultiresArgs) -> anyhow::Result<bool> {
    let to_stdout = args.output.as_deref().is_some_and(is_stdio);
    anyhow::ensure!(
        !(args.json && to_stdout),
        "--json and `-o -` would both write to standard output: write the mesh to a file"
    );
    if let Some(output) = &args.output {
        check_output_format(output, args.stdio.format)?;
    }
    Ok(to_stdout)
}

/// Loads the input, its mask and the `--reference`, and adds the noise `--noise` asks for
/// (keeping the clean input when `measure`d against).
fn prepare(args: &MultiresArgs, measure: bool) -> anyhow::Result<Prepared> {
    let loaded = load_input(&args.input, true, args.stdio.format)?;
    let source = loaded.source;
    let mask = super::mask::load_for(&args.mask, &source, &loaded.mesh, Some(&loaded.topology))?;
    // The connectivity serves the crease detection and the denoise only; otherwise it goes
    // before the build.
    let creases = args.hierarchy_options().creases.is_some();
    let denoise = args.denoise != Denoise::Off && args.denoise != Denoise::Rounds(0);
    let topology = (creases || denoise).then_some(loaded.topology);
    let file_edges = if creases {
        source.hard_edges(&loaded.mesh)
    } else {
        Vec::new()
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
    Ok(Prepared {
        source,
        mask,
        topology,
        file_edges,
        input,
        reference_file,
        clean,
        clean_volume,
    })
}

/// Says, on standard error, which of the asked start levels lie above the coarsest and so
/// start from it.
fn note_levels_beyond(args: &MultiresArgs, coarsest: usize) {
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
}

/// What every run shares: the hierarchy, the mask, what the results are measured against.
struct Runs<'a> {
    hierarchy: &'a Hierarchy,
    mask: Option<Mask>,
    /// With a mask: the input's positions (before the denoise), which it fades the results into.
    unmasked: Option<Vec<[f32; 3]>>,
    /// The denoise's report and milliseconds, when the mesh was denoised first.
    denoise: Option<(fairmesh::fairing::FairReport, f64)>,
    /// What each result is measured against; `None` without `--measure`.
    reference: Option<&'a TriMesh>,
    clean_volume: f64,
    hierarchy_ms: f64,
}

impl Runs<'_> {
    /// Runs every variant from every start level, one after another: each run's JSON row, and the
    /// last run's result.
    fn fair_each(
        &self,
        args: &MultiresArgs,
    ) -> anyhow::Result<(Vec<serde_json::Value>, Option<TriMesh>)> {
        // One run holds only the level it is at; several runs share every level's set-up.
        let mut workspace = if args.variant.len() * args.level.len() == 1 {
            MultiresWorkspace::for_one_run()
        } else {
            MultiresWorkspace::new()
        };
        let mut results = Vec::new();
        let mut last = None;
        for &variant in &args.variant {
            for &level in &args.level {
                // After a denoise the mask is applied here, against the input (`fair_one`).
                let mask = self.mask.clone().filter(|_| self.denoise.is_none());
                let options = args.options(level, variant, mask);
                let (result, row) = self.fair_one(&options, (level, variant), &mut workspace)?;
                results.push(row);
                last = Some(result);
            }
        }
        Ok((results, last))
    }

    /// One run from `level` with `variant` (both in `options`), timed whole (with the per-level
    /// set-up a first run on `workspace` does): the result and its JSON row.
    fn fair_one(
        &self,
        options: &MultiresOptions,
        (level, variant): (usize, VariantArg),
        workspace: &mut MultiresWorkspace,
    ) -> anyhow::Result<(TriMesh, serde_json::Value)> {
        let hierarchy = self.hierarchy;
        let start = level.min(hierarchy.coarsest_level());
        let mut step =
            super::progress::Step::start(format!("multiresolution fairing from level {start}"));
        let started = Instant::now();
        let (mut positions, folds_left) = if self.denoise.is_some() && start == 0 {
            // Level 0 is the denoised mesh itself (M0 keeps the input's numbering).
            (hierarchy.base_mesh().positions.clone(), 0)
        } else {
            let positions = fair_multires(hierarchy, options, workspace, &mut step)
                .context("multires fairing was cancelled")?;
            (positions, workspace.folds_left())
        };
        if let (Some(mask), Some(unmasked), Some(_)) = (&self.mask, &self.unmasked, &self.denoise) {
            if mask.check_fits(unmasked.len()).is_ok() {
                mask.blend(unmasked, &mut positions);
            }
        }
        let time_ms = started.elapsed().as_secs_f64() * 1e3;
        drop(step);
        if folds_left > 0 {
            eprintln!(
                "warning: {}",
                fairmesh::multires::folds_left_warning(start, folds_left)
            );
        }
        let result = TriMesh::new(positions, hierarchy.base_mesh().triangles.clone());
        let clean_volume = self.clean_volume;
        let volume_change_percent = (clean_volume != 0.0)
            .then(|| 100.0 * (metrics::signed_volume(&result) - clean_volume) / clean_volume.abs());
        let mut row = json!({
            "level": start,
            "level_vertices": hierarchy.level_info(start).vertices,
            "variant": format!("{variant:?}").to_lowercase(),
            "time_ms": time_ms,
            "hierarchy_ms": self.hierarchy_ms,
            "loose_triangles": hierarchy.loose_triangles().len(),
            "folds_left": folds_left,
            "volume_change_percent": volume_change_percent,
            "denoise": self.denoise.as_ref().map(|(report, time_ms)| json!({
                "rounds_run": report.rounds_run,
                "noise_estimate": report.noise_estimate,
                "crease_edges": report.crease_edges,
                "time_ms": time_ms,
            })),
        });
        if let Some(reference) = self.reference {
            add_measures(&mut row, reference, &result);
        }
        Ok((result, row))
    }
}

/// Measures `result` against `reference` into the run's JSON `row`.
fn add_measures(row: &mut serde_json::Value, reference: &TriMesh, result: &TriMesh) {
    let Some(map) = row.as_object_mut() else {
        return;
    };
    let comparison = super::progress::Step::run("measuring the result", || {
        metrics::compare(reference, result)
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

/// What the table's header says: the hierarchy, its build time and the denoise.
struct Header<'a> {
    hierarchy: &'a Hierarchy,
    hierarchy_ms: f64,
    denoise: Option<&'a (fairmesh::fairing::FairReport, f64)>,
}

/// Prints the runs: with `--json` one object (several: an array of them), else a table (on
/// standard error when standard output holds the mesh).
fn print_results(
    args: &MultiresArgs,
    header: &Header,
    measure: bool,
    mut results: Vec<serde_json::Value>,
    to_stdout: bool,
) -> anyhow::Result<()> {
    if args.json {
        let value = if results.len() == 1 {
            results.pop().unwrap_or_default()
        } else {
            serde_json::Value::Array(results)
        };
        return emit(&format!("{}\n", serde_json::to_string_pretty(&value)?));
    }
    let out = results_table(args, header, measure, &results)?;
    if to_stdout {
        // Standard output holds the mesh.
        eprint!("{out}");
        Ok(())
    } else {
        emit(&out)
    }
}

/// The runs as a table: the hierarchy and the noise in a header line, then one row a run.
fn results_table(
    args: &MultiresArgs,
    header: &Header,
    measure: bool,
    results: &[serde_json::Value],
) -> anyhow::Result<String> {
    let mut out = format!(
        "{}: {}hierarchy of {} in {:.1} ms{}\nlevel  vertices  variant   time ms   volume %{}\n",
        args.input.display(),
        match header.denoise {
            Some((report, ms)) => format!("{}, ", denoise_phrase(report, *ms)),
            None => String::new(),
        },
        levels_phrase(header.hierarchy),
        header.hierarchy_ms,
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
    for r in results {
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
    Ok(out)
}

/// The denoise in words: "denoised in 35 ms (noise about 0.27 mean edge lengths: 12 rounds, 49
/// sharp edges kept)", or that it found the mesh clean.
fn denoise_phrase(report: &fairmesh::fairing::FairReport, ms: f64) -> String {
    if report.rounds_run == 0 {
        return format!("no noise to remove found in {ms:.1} ms");
    }
    let noise = report
        .noise_estimate
        .map(|noise| format!("noise about {noise:.2} mean edge lengths: "))
        .unwrap_or_default();
    format!(
        "denoised in {ms:.1} ms ({noise}{} rounds, {} sharp edges kept)",
        report.rounds_run, report.crease_edges
    )
}

/// One cell of the table, right-aligned in `width`. A value the row does not have (no volume to
/// change on a flat or open patch of zero volume, a measure that could not be made) prints as
/// "-", as in JSON it is null.
fn cell(value: &serde_json::Value, width: usize, format: fn(f64) -> String) -> String {
    let text = value
        .as_f64()
        .filter(|v| v.is_finite())
        .map_or_else(|| "-".to_string(), format);
    format!(" {text:>width$}")
}
