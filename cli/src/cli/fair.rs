//! `fairmesh fair`: smooth a mesh with constrained fairing (the paper's method) or one of the
//! baselines, and write the result; `bench_rows` gives `fairmesh bench` its fairing timings.
use anyhow::Context;
use clap::{Args, ValueEnum};
use fairmesh::fairing::strength::CLEAN_NOISE;
use fairmesh::fairing::{
    self, baseline::UmbrellaStencil, BoundaryMode, ConstrainedFairing, CreaseOptions, FairOutcome,
    FairReport, FairVariant, Mask, Method, MethodChoices, MethodOptions, ReportContext, Strength,
};
use fairmesh::io::{Format, Source};
use fairmesh::metrics::Comparison;
use fairmesh::NoProgress;
use fairmesh::{Topology, TriMesh};
use std::path::{Path, PathBuf};

use super::args::{BoundaryArg, StdioFormat};
use super::common::{
    check_output_format, display_output, emit, is_stdio, load_input, median_ms, save_kept,
};

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MethodArg {
    /// Constrained fairing (the paper's method): smooths without shrinking.
    Constrained,
    /// Umbrella Laplacian smoothing (shrinks; for comparison).
    Laplacian,
    /// Taubin's λ|μ smoothing (for comparison).
    Taubin,
    /// HC Laplacian of Vollmer et al. (for comparison).
    Hc,
}

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum VariantArg {
    /// The paper's operator exactly (vertices may slide along the surface).
    Paper,
    /// The paper's update projected on the vertex normal, so vertices do not slide (the
    /// default; "normal-projected" is its former name, still accepted).
    #[value(alias = "normal-projected", alias = "projected")]
    Improved,
}

#[derive(Args, Debug)]
#[command(after_help = "Examples:\n  \
    fairmesh fair noisy.obj -o smooth.obj\n  \
    fairmesh fair noisy.obj -o smoother.obj --rounds 5\n  \
    fairmesh fair scan.obj -o fixed.obj --mask region.txt --mask-falloff 3\n  \
    fairmesh fair noisy.obj -o taubin.obj --method taubin --iterations 20 --json")]
pub struct FairArgs {
    /// Mesh to smooth (.obj .gltf .glb .ply .stl .off).
    pub input: PathBuf,
    /// Where to write the smoothed mesh (format from the extension; `-`: standard output, with
    /// --format).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Smoothing method.
    #[arg(long, value_enum, default_value_t = MethodArg::Constrained)]
    pub method: MethodArg,
    /// Iterations (per round for constrained fairing, at most: a round ends once it has settled,
    /// see --tolerance). Constrained fairing settles after 5 to 10 iterations; use --rounds to
    /// smooth more.
    #[arg(long, default_value_t = 10)]
    pub iterations: usize,
    /// Constrained only: rounds; each round re-anchors the triangle centres at the current
    /// positions, so more rounds smooth more (and drift further from the input). Without it the
    /// noise is estimated (a clean mesh is left as it is) and rounds run while the estimated
    /// error of the result falls; the last round that lowered it clearly is kept.
    #[arg(long)]
    pub rounds: Option<usize>,
    /// Constrained, improved variant only: edges where the surface folds by more than this many
    /// degrees are kept sharp (faired along the crease; corners stay).
    #[arg(long, default_value_t = fairmesh::fairing::creases::DEFAULT_CREASE_ANGLE,
          conflicts_with = "no_creases")]
    pub crease_angle: f64,
    /// Constrained, improved variant only: fair across sharp edges too, as the paper does (for
    /// smooth shapes: thin triangles are then relaxed only where they fold, not along bends).
    #[arg(long)]
    pub no_creases: bool,
    /// Constrained, improved variant only: how much each iteration also evens out the triangles
    /// along the surface, at every vertex (0 to 1; 0 moves vertices only along their normals).
    /// Without it, 0.1 where needed: everywhere when the noise moved vertices along the surface
    /// too (it reads how much: `tangential_noise` in --json), until the mesh reads even, and
    /// around thin triangles, which moving along the normals alone leaves folded; elsewhere the
    /// vertices move along their normals only, which keeps a scan's denser sampling where it
    /// curves.
    #[arg(long)]
    pub tangential: Option<f64>,
    /// Constrained, improved variant only: do not give each part back its volume after every
    /// round (by default a uniform offset along the normals undoes the little each round loses).
    #[arg(long)]
    pub no_volume_correction: bool,
    /// Constrained only: stop a round early once no vertex moves more than this many mean edge
    /// lengths in one iteration [default: 0.001, the round has settled; 0: always run all
    /// iterations].
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// How boundary vertices of open meshes move.
    #[arg(long, value_enum, default_value_t = BoundaryArg::Curve)]
    pub boundary: BoundaryArg,
    /// Constrained only: the operator variant.
    #[arg(long, value_enum, default_value_t = VariantArg::Improved)]
    pub variant: VariantArg,
    /// Laplacian and Taubin: the (shrinking) step size λ [default: 0.5].
    #[arg(long)]
    pub lambda: Option<f64>,
    /// Taubin: the inflating step μ, negative [default: -0.53].
    #[arg(long, allow_hyphen_values = true)]
    pub mu: Option<f64>,
    /// HC: pull towards the input positions, 0 to 1 [default: 0].
    #[arg(long)]
    pub alpha: Option<f64>,
    /// HC: weight of a vertex's own correction against its neighbours' [default: 0.5].
    #[arg(long)]
    pub beta: Option<f64>,
    /// Print one JSON object (method, iterations_run, time_ms, volume_change_percent, max_move,
    /// ...) instead of a sentence.
    #[arg(long)]
    pub json: bool,
    /// Also measure the result against the input: two-way surface distance (mean and Hausdorff),
    /// vertex RMS and normal error. Costs more than the fairing on large meshes.
    #[arg(long)]
    pub measure: bool,
    #[command(flatten)]
    pub stdio: StdioFormat,
    #[command(flatten)]
    pub mask: super::mask::MaskArgs,
}

impl FairArgs {
    /// The options of the chosen method on `mesh` (loaded from `source`, of mean edge length
    /// `mean_edge_length`): the file's own sharp edges (split normals, material boundaries) are
    /// creases too.
    fn options_for(&self, mesh: &TriMesh, source: &Source, mean_edge_length: f64) -> MethodOptions {
        self.choices()
            .options(mean_edge_length, || source.hard_edges(mesh))
    }

    /// The options as the library takes them ([`MethodChoices`], shared with the Python
    /// package).
    fn choices(&self) -> MethodChoices {
        MethodChoices {
            method: match self.method {
                MethodArg::Constrained => Method::Constrained,
                MethodArg::Laplacian => Method::Laplacian,
                MethodArg::Taubin => Method::Taubin,
                MethodArg::Hc => Method::Hc,
            },
            iterations: self.iterations,
            rounds: self.rounds,
            crease_angle: self.crease_angle,
            no_creases: self.no_creases,
            tangential: self.tangential,
            no_volume_correction: self.no_volume_correction,
            tolerance: self.tolerance,
            boundary: BoundaryMode::from(self.boundary),
            paper_variant: self.variant == VariantArg::Paper,
            lambda: self.lambda,
            mu: self.mu,
            alpha: self.alpha,
            beta: self.beta,
        }
    }
}

/// A textured file's vertices sliding along the surface by at least this many mean edge lengths
/// (root mean square) is worth a warning: the texture moves with them.
const TEXTURE_SLIDE_WARNING: f64 = 0.02;

/// What one fairing did, for the report: the fairing's own report and what the command measured
/// around it.
struct Outcome {
    /// The run as the library measured it (its volume change `None`, JSON null and "n/a" in
    /// words, when the input encloses no volume to change).
    faired: FairOutcome,
    /// Whether the mesh is closed (its volume change is then more than indicative).
    closed: bool,
    texture: Option<TextureSlide>,
    measures: Option<Comparison>,
}

/// How far the tangential relaxation slid a textured file's vertices along the surface.
#[derive(Clone, Copy)]
struct TextureSlide {
    /// Root mean square, in mean edge lengths of the input.
    slide: f64,
    /// Whether the written file's texture coordinates followed the slide (into any format that
    /// holds them, see `SaveReport::texture_coordinates_follow`).
    follows: bool,
}

pub fn run(args: FairArgs) -> anyhow::Result<()> {
    check_output(&args)?;
    let loaded = load_input(&args.input, true, args.stdio.format)?;
    let (mut mesh, topology, source) = (loaded.mesh, loaded.topology, loaded.source);
    let edge = fairmesh::metrics::mean_edge_length(&mesh);
    let options = args.options_for(&mesh, &source, edge);
    let mask = super::mask::load_for(&args.mask, &source, &mesh, Some(&topology))?;
    // The input is kept only to measure against it.
    let input = args.measure.then(|| mesh.clone());
    let step = super::progress::Step::start("fairing");
    let textured = source.has_texture_coordinates();
    let faired = fairing::fair_measured(
        &mut mesh,
        &topology,
        &options,
        mask.as_ref(),
        textured,
        &mut NoProgress,
    )
    .context("the fairing was cancelled")?;
    drop(step);
    let saved = save_kept(&args.output, &mesh, &source, args.stdio.format)?;
    let texture = faired.texture_slide.map(|slide| TextureSlide {
        slide,
        follows: saved.texture_coordinates_follow,
    });
    warn_texture_slide(&args.input, &args.output, texture);
    note_loose_triangles(&args.input, faired.report.loose_triangles);
    let measures = input.map(|input| {
        super::progress::Step::run("measuring against the input", || {
            fairmesh::metrics::compare(&input, &mesh)
        })
    });
    let outcome = Outcome {
        faired,
        closed: topology.is_closed(),
        texture,
        measures,
    };
    print_outcome(&args, &mesh, &options, mask.as_ref(), &outcome)
}

/// Refuses `--json` with `-o -` (both would write to standard output), and `-o -` without
/// `--format`.
fn check_output(args: &FairArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        !(args.json && is_stdio(&args.output)),
        "--json and `-o -` would both write to standard output: write the mesh to a file"
    );
    check_output_format(&args.output, args.stdio.format)?;
    Ok(())
}

/// Warns, on standard error, when the texture moved with vertices that slid along the surface:
/// the output holds texture coordinates (`output`'s format) and they did not follow. An output
/// that holds none has them named among what it does not keep, by the save.
fn warn_texture_slide(input: &Path, output: &Path, texture: Option<TextureSlide>) {
    let holds = matches!(
        Format::from_path(output),
        Some(Format::Obj | Format::Ply | Format::Glb | Format::Gltf)
    );
    if let Some(TextureSlide { slide, .. }) =
        texture.filter(|t| t.slide >= TEXTURE_SLIDE_WARNING && !t.follows && holds)
    {
        eprintln!(
            "warning: {}: its texture coordinates stay with their vertices, and the tangential \
             relaxation slid the vertices along the surface by {slide:.2} mean edge lengths \
             (root mean square): the texture moved with them. `--tangential 0` keeps every \
             vertex on its normal line (noise that moved vertices along the surface then stays).",
            input.display()
        );
    }
}

/// Says, on standard error, what became of the triangles that lie loose at non-manifold edges.
fn note_loose_triangles(input: &Path, loose_triangles: usize) {
    if loose_triangles > 0 {
        eprintln!(
            "note: {}: {} triangles lie loose at non-manifold edges (over other triangles, or \
             hanging from an edge as fins) and were left out of the smoothing, which would have \
             held their corners with their noise; they are kept in the output, their corners on \
             the surface smoothed with it and a fin's own tip left where it was",
            input.display(),
            loose_triangles
        );
    }
}

/// Prints the outcome: one JSON object with `--json`, else a sentence (on standard error when
/// standard output holds the mesh).
fn print_outcome(
    args: &FairArgs,
    mesh: &TriMesh,
    options: &MethodOptions,
    mask: Option<&Mask>,
    outcome: &Outcome,
) -> anyhow::Result<()> {
    if args.json {
        return emit(&format!(
            "{}\n",
            json_report(args, mesh, options, mask, outcome)
        ));
    }
    let sentence = sentence(args, options, mask, outcome);
    if is_stdio(&args.output) {
        // Standard output holds the mesh.
        eprint!("{sentence}");
        Ok(())
    } else {
        emit(&sentence)
    }
}

/// The `--json` report: the library's, with this run's files.
fn json_report(
    args: &FairArgs,
    mesh: &TriMesh,
    options: &MethodOptions,
    mask: Option<&Mask>,
    outcome: &Outcome,
) -> serde_json::Value {
    let (input, output) = (
        args.input.display().to_string(),
        args.output.display().to_string(),
    );
    let context = ReportContext {
        input: Some(&input),
        output: Some(&output),
        closed: outcome.closed,
        mask,
        texture_follows: outcome.texture.map(|t| t.follows),
        measures: outcome.measures.as_ref(),
    };
    outcome.faired.to_json(options, mesh, &context)
}

/// The report in words, one line.
fn sentence(
    args: &FairArgs,
    options: &MethodOptions,
    mask: Option<&Mask>,
    outcome: &Outcome,
) -> String {
    let report = &outcome.faired.report;
    let volume = match outcome.faired.volume_change_percent {
        Some(change) if outcome.closed => format!("{change:+.4}%"),
        Some(change) => format!("{change:+.4}% (the mesh is open: volume is only indicative)"),
        None => "n/a (the mesh encloses no volume)".to_string(),
    };
    let measured = outcome
        .measures
        .as_ref()
        .map(|m| {
            format!(
                ", mean surface distance to the input {:.3e} (Hausdorff {:.3e})",
                m.mean_surface_distance, m.hausdorff
            )
        })
        .unwrap_or_default();
    let strength = strength_words(report, options);
    let creases = match report.crease_edges {
        0 => String::new(),
        n => format!("{n} crease edges kept sharp; "),
    };
    format!(
        "{}{}: {}{strength}{creases}{} iterations in {:.1} ms, volume change {volume}, last \
         largest move {:.3e}{}; wrote {}\n",
        options.method().name(),
        options
            .variant_name()
            .map(|v| format!(" ({v})"))
            .unwrap_or_default(),
        super::mask::describe(mask),
        report.iterations_run,
        outcome.faired.time_ms,
        report.max_move,
        measured,
        display_output(&args.output)
    )
}

/// What the automatic strength decided, in words (empty when the strength was not automatic).
fn strength_words(report: &FairReport, options: &MethodOptions) -> String {
    match (report.noise_estimate, options) {
        (Some(noise), MethodOptions::Constrained(o)) if o.strength == Strength::Auto => {
            if report.rounds_run == 0 && noise > CLEAN_NOISE {
                format!(
                    "noise estimate {noise:.3} edge lengths, all of it at sharp edges or in \
                     faces that still lie flat (a CAD part): clean, left as it is (--rounds N \
                     fairs anyway); "
                )
            } else if report.rounds_run == 0 {
                format!(
                    "noise estimate {noise:.3} edge lengths: clean, left as it is (--rounds N \
                     fairs anyway); "
                )
            } else {
                format!(
                    "noise estimate {noise:.3} edge lengths, {} rounds (where the estimated \
                     error of the result was least); ",
                    report.rounds_run
                )
            }
        }
        _ => String::new(),
    }
}

/// Rows for `fairmesh bench`: (operation, milliseconds), medians of several runs.
pub fn bench_rows(mesh: &TriMesh, topology: &Topology) -> Vec<(String, f64)> {
    if mesh.positions.is_empty() {
        return Vec::new();
    }
    // Iterations come in runs; time blocks of them, as a run gets them back to back.
    const BLOCK: usize = 10;
    let mut rows = Vec::new();
    let precompute = median_ms(5, || {
        std::hint::black_box(ConstrainedFairing::new(
            mesh,
            topology,
            FairVariant::Improved,
            BoundaryMode::Curve,
        ));
    });
    rows.push(("fair: constrained precomputation".to_string(), precompute));
    for variant in [FairVariant::Paper, FairVariant::Improved] {
        let mut fairing = ConstrainedFairing::new(mesh, topology, variant, BoundaryMode::Curve);
        let positions = mesh.positions.clone();
        fairing.load(&positions);
        fairing.step();
        let ms = median_ms(7, || {
            for _ in 0..BLOCK {
                fairing.step();
            }
        }) / BLOCK as f64;
        rows.push((
            format!("fair: constrained iteration ({})", variant.name()),
            ms,
        ));
    }
    let stencil = UmbrellaStencil::new(topology, BoundaryMode::Curve);
    let positions = mesh.positions.clone();
    let mut next = positions.clone();
    let ms = median_ms(7, || {
        for _ in 0..BLOCK {
            stencil.relax(&positions, &mut next, 0.5);
        }
    }) / BLOCK as f64;
    rows.push(("fair: Laplacian iteration".to_string(), ms));
    rows
}

/// `bench` rows of the crease detection, `runs` runs each.
pub fn crease_bench_rows(mesh: &TriMesh, topology: &Topology, runs: usize) -> Vec<(String, f64)> {
    let mut rows = Vec::new();
    // Crease detection: on the faces' own normals (a clean mesh), and the guided normal filter
    // a noisy one runs first (one pass and three, so a pass's own cost is their difference / 2).
    let options = CreaseOptions::default();
    rows.push((
        "creases: detection (no filtering)".to_string(),
        median_ms(runs, || {
            std::hint::black_box(fairing::detect_creases(mesh, topology, &options));
        }),
    ));
    for passes in [1, 3] {
        rows.push((
            format!("creases: guided normal filter, {passes} pass(es)"),
            median_ms(runs, || {
                std::hint::black_box(fairing::creases::filtered_face_normals(
                    mesh,
                    topology,
                    passes,
                    fairing::creases::NORMAL_SIGMA,
                ));
            }),
        ));
    }
    rows
}
