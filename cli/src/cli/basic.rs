//! `info`, `noise`, `convert` and `compare`: the mesh-core subcommands.

use anyhow::Context;
use clap::{Args, ValueEnum};
use fairmesh::io::Loaded;
use fairmesh::metrics;
use fairmesh::noise::{self, NoiseMode, NoiseOptions};
use serde_json::json;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::args::StdioFormat;
use super::common::{
    check_output_format, display_output, emit, load, load_input, load_shown, save_kept,
};

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Mesh file (.obj .gltf .glb .ply .stl .off).
    pub file: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Keep vertices with identical positions apart (by default they are merged).
    #[arg(long)]
    pub no_weld: bool,
    #[command(flatten)]
    pub stdio: StdioFormat,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ModeArg {
    /// Each vertex moves along a random direction by a Gaussian distance.
    Direction,
    /// Independent Gaussian noise on each coordinate.
    Iso,
    /// Each vertex moves along its normal by a Gaussian distance.
    Normal,
}

#[derive(Args, Debug)]
pub struct NoiseArgs {
    /// Input mesh.
    pub input: PathBuf,
    /// Output mesh (format by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Standard deviation as a fraction of the mean edge length.
    #[arg(long, default_value_t = 0.3)]
    pub sigma: f64,
    /// Random seed: the same seed gives the same noise on every machine.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// How vertices move.
    #[arg(long, value_enum, default_value_t = ModeArg::Normal)]
    pub mode: ModeArg,
    #[command(flatten)]
    pub stdio: StdioFormat,
}

#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Input mesh.
    pub input: PathBuf,
    /// Output mesh; the format is chosen by its extension (.obj .gltf .glb .ply .stl .off).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Keep vertices with identical positions apart (by default they are merged).
    #[arg(long)]
    pub no_weld: bool,
    /// Loop-subdivide this many times first (4x the faces each time): makes large test meshes,
    /// e.g. `--subdivide 2` on the bundled bunny gives 1.2M faces.
    #[arg(long, default_value_t = 0)]
    pub subdivide: usize,
    #[command(flatten)]
    pub stdio: StdioFormat,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The mesh to measure against (e.g. the clean original).
    pub reference: PathBuf,
    /// The mesh to measure (e.g. the faired result).
    pub other: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn info(args: InfoArgs) -> anyhow::Result<()> {
    let loaded = load_shown(&args.file, !args.no_weld, args.stdio.format)?;
    let facts = Facts::of(&loaded);
    if args.json {
        let summary = info_json(&args.file, &loaded, &facts);
        return emit(&format!("{}\n", serde_json::to_string_pretty(&summary)?));
    }
    let mut out = String::new();
    writeln!(out, "{}", args.file.display())?;
    write_counts(&mut out, &loaded)?;
    write_topology(&mut out, &loaded, &facts)?;
    write_measures(&mut out, &loaded, &facts)?;
    write_load_report(&mut out, &loaded, &facts)?;
    emit(&out)
}

/// What `info` derives from a loaded mesh, for both its JSON and its text.
struct Facts {
    closed: bool,
    /// The enclosed volume, of a closed mesh only.
    volume: Option<f64>,
    bbox: Option<(fairmesh::glam::DVec3, fairmesh::glam::DVec3)>,
    /// What the default `fair` leaves out (`mesh::without_loose_triangles`).
    loose_triangles: usize,
    /// What the file holds beyond the mesh: kept when saving to the same format.
    contents: Vec<String>,
}

impl Facts {
    fn of(loaded: &Loaded) -> Self {
        let (mesh, topology) = (&loaded.mesh, &loaded.topology);
        let closed = topology.is_closed();
        Facts {
            closed,
            volume: closed.then(|| metrics::signed_volume(mesh)),
            bbox: metrics::bounding_box(mesh),
            loose_triangles: fairmesh::mesh::without_loose_triangles(mesh, topology)
                .map_or(0, |(loose, ..)| loose.len()),
            contents: loaded.source.contents(),
        }
    }
}

/// `info --json`: one object.
fn info_json(file: &Path, loaded: &Loaded, facts: &Facts) -> serde_json::Value {
    let (mesh, topology, report) = (&loaded.mesh, &loaded.topology, &loaded.report);
    let genus: Vec<Option<i64>> = topology.components.iter().map(|c| c.genus).collect();
    json!({
        "file": file.display().to_string(),
        "vertices": mesh.vertex_count(),
        "faces": mesh.face_count(),
        "edges": topology.edge_count(),
        "boundary_loops": topology.boundary_loops.len(),
        "boundary_loop_lengths": topology.boundary_loops.iter().map(|l| l.len()).collect::<Vec<_>>(),
        "components": topology.components.len(),
        "genus": genus,
        "euler_characteristic": topology.euler_characteristic(),
        "closed": facts.closed,
        "manifold": topology.is_manifold(),
        "oriented": topology.inconsistent_edges == 0,
        "non_manifold_edges": topology.non_manifold_edges.len(),
        "non_manifold_vertices": topology.non_manifold_vertices.len(),
        "loose_triangles": facts.loose_triangles,
        "inconsistently_oriented_edges": topology.inconsistent_edges,
        "volume": facts.volume,
        "area": metrics::area(mesh),
        "mean_edge_length": metrics::mean_edge_length(mesh),
        "bounding_box": facts.bbox.map(|(lo, hi)| json!({"min": lo.to_array(), "max": hi.to_array()})),
        "welded_vertices": report.welded_vertices,
        "removed_degenerate_faces": report.removed_degenerate_faces,
        "removed_repeated_faces": report.removed_repeated_faces,
        "removed_unreferenced_vertices": report.removed_unreferenced_vertices,
        "warnings": report.warnings,
        "file_contents": facts.contents,
    })
}

/// The counts, and the first ten components.
fn write_counts(out: &mut String, loaded: &Loaded) -> std::fmt::Result {
    let (mesh, topology) = (&loaded.mesh, &loaded.topology);
    writeln!(out, "  vertices            {}", mesh.vertex_count())?;
    writeln!(out, "  faces               {}", mesh.face_count())?;
    writeln!(out, "  edges               {}", topology.edge_count())?;
    writeln!(out, "  components          {}", topology.components.len())?;
    for (i, c) in topology.components.iter().enumerate().take(10) {
        let genus = c
            .genus
            .map_or("n/a (non-manifold)".to_string(), |g| g.to_string());
        writeln!(
            out,
            "    #{i}: {} vertices, {} faces, {} boundary loops, genus {genus}",
            c.vertices, c.faces, c.boundary_loops
        )?;
    }
    Ok(())
}

/// Boundary loops, whether the mesh is closed and a manifold, and its loose triangles.
fn write_topology(out: &mut String, loaded: &Loaded, facts: &Facts) -> std::fmt::Result {
    let topology = &loaded.topology;
    writeln!(
        out,
        "  boundary loops      {}",
        topology.boundary_loops.len()
    )?;
    writeln!(out, "  closed              {}", facts.closed)?;
    writeln!(
        out,
        "  manifold            {} ({} non-manifold edges, {} non-manifold vertices, {} inconsistently oriented edges)",
        topology.is_manifold(),
        topology.non_manifold_edges.len(),
        topology.non_manifold_vertices.len(),
        topology.inconsistent_edges
    )?;
    if facts.loose_triangles > 0 {
        writeln!(
            out,
            "  loose triangles     {} (over other triangles, or fins hanging from an \
             edge: the default fair smooths the surface without them)",
            facts.loose_triangles
        )?;
    }
    Ok(())
}

/// Volume, area, mean edge length and bounding box.
fn write_measures(out: &mut String, loaded: &Loaded, facts: &Facts) -> std::fmt::Result {
    let mesh = &loaded.mesh;
    match facts.volume {
        Some(v) => writeln!(out, "  volume              {v:.6e}")?,
        None => writeln!(out, "  volume              n/a (open mesh)")?,
    }
    writeln!(out, "  area                {:.6e}", metrics::area(mesh))?;
    writeln!(
        out,
        "  mean edge length    {:.6e}",
        metrics::mean_edge_length(mesh)
    )?;
    if let Some((lo, hi)) = facts.bbox {
        writeln!(
            out,
            "  bounding box        [{:.4}, {:.4}, {:.4}] .. [{:.4}, {:.4}, {:.4}]",
            lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
        )?;
    }
    Ok(())
}

/// What loading repaired, what else the file holds, and the loader's warnings.
fn write_load_report(out: &mut String, loaded: &Loaded, facts: &Facts) -> std::fmt::Result {
    let report = &loaded.report;
    writeln!(out, "  welded vertices     {}", report.welded_vertices)?;
    writeln!(
        out,
        "  removed             {} degenerate faces, {} repeated faces, {} unused vertices",
        report.removed_degenerate_faces,
        report.removed_repeated_faces,
        report.removed_unreferenced_vertices
    )?;
    if !facts.contents.is_empty() {
        writeln!(
            out,
            "  also in the file    (kept when saving as {}):",
            loaded.source.format()
        )?;
        for item in &facts.contents {
            writeln!(out, "    {item}")?;
        }
    }
    for warning in &report.warnings {
        writeln!(out, "  warning: {warning}")?;
    }
    Ok(())
}

pub fn noise(args: NoiseArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.sigma.is_finite() && args.sigma >= 0.0,
        "--sigma must be a finite number >= 0, got {}",
        args.sigma
    );
    check_output_format(&args.output, args.stdio.format)?;
    let mut loaded = load_input(&args.input, true, args.stdio.format)?;
    let mode = match args.mode {
        ModeArg::Direction => NoiseMode::Direction,
        ModeArg::Iso => NoiseMode::Isotropic,
        ModeArg::Normal => NoiseMode::Normal,
    };
    let absolute = noise::add_noise(
        &mut loaded.mesh,
        &NoiseOptions::default()
            .with_sigma(args.sigma)
            .with_seed(args.seed)
            .with_mode(mode),
    );
    save_kept(
        &args.output,
        &loaded.mesh,
        &loaded.source,
        args.stdio.format,
    )?;
    eprintln!(
        "wrote {} (sigma {:.4e} model units, {:?}, seed {})",
        display_output(&args.output),
        absolute,
        mode,
        args.seed
    );
    Ok(())
}

pub fn convert(args: ConvertArgs) -> anyhow::Result<()> {
    check_output_format(&args.output, args.stdio.format)?;
    let mut loaded = load_input(&args.input, !args.no_weld, args.stdio.format)?;
    for _ in 0..args.subdivide {
        loaded.mesh = fairmesh::mesh::subdivide_loop(&loaded.mesh);
    }
    save_kept(
        &args.output,
        &loaded.mesh,
        &loaded.source,
        args.stdio.format,
    )?;
    eprintln!(
        "wrote {} ({} vertices, {} faces)",
        display_output(&args.output),
        loaded.mesh.vertex_count(),
        loaded.mesh.face_count()
    );
    Ok(())
}

pub fn compare(args: CompareArgs) -> anyhow::Result<()> {
    let reference = load(&args.reference, true).context("loading the reference")?;
    let other = load(&args.other, true).context("loading the mesh to compare")?;
    let result = metrics::compare(&reference.mesh, &other.mesh);
    let mut object = json!({
        "reference": args.reference.display().to_string(),
        "other": args.other.display().to_string(),
        "mean_surface_distance": result.mean_surface_distance,
        "hausdorff": result.hausdorff,
        "volume_change_percent": result.volume_change_percent,
        "reference_to_other": result.reference_to_other,
        "other_to_reference": result.other_to_reference,
        "same_connectivity": result.same_connectivity.is_some(),
        "reference_mean_edge_length": metrics::mean_edge_length(&reference.mesh),
    });
    if let (Some(v), Some(map)) = (result.same_connectivity, object.as_object_mut()) {
        map.insert("rms".into(), json!(v.rms));
        map.insert("max_distance".into(), json!(v.max_distance));
        map.insert("normal_error_deg".into(), json!(v.normal_error_deg));
        map.insert("barycenter_drift".into(), json!(v.barycenter_drift));
    }
    let sharpened = metrics::sharpened_edges(&reference.mesh, &other.mesh);
    if let (Some(count), Some(map)) = (sharpened, object.as_object_mut()) {
        map.insert("sharpened_edges".into(), json!(count));
    }
    if args.json {
        return emit(&format!("{}\n", serde_json::to_string_pretty(&object)?));
    }
    let mut out = String::new();
    writeln!(
        out,
        "{} against {}",
        args.other.display(),
        args.reference.display()
    )?;
    writeln!(
        out,
        "  mean surface distance  {:.6e}",
        result.mean_surface_distance
    )?;
    writeln!(out, "  Hausdorff (estimate)   {:.6e}", result.hausdorff)?;
    match result.volume_change_percent {
        Some(p) => writeln!(out, "  volume change          {p:+.4}%")?,
        None => writeln!(
            out,
            "  volume change          n/a (reference encloses no volume)"
        )?,
    }
    match result.same_connectivity {
        Some(v) => {
            writeln!(out, "  vertex RMS             {:.6e}", v.rms)?;
            writeln!(out, "  max vertex distance    {:.6e}", v.max_distance)?;
            writeln!(
                out,
                "  mean normal error      {:.4} deg",
                v.normal_error_deg
            )?;
            writeln!(out, "  barycenter drift       {:.6e}", v.barycenter_drift)?;
            if let Some(count) = sharpened {
                writeln!(
                    out,
                    "  sharpened edges        {count} (bent over {}° beyond the reference)",
                    metrics::SHARPENED_DEGREES
                )?;
            }
        }
        None => writeln!(out, "  (different connectivity: no per-vertex measures)")?,
    }
    emit(&out)
}
