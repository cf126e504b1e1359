//! The command-line tool: subcommands on top of the library.

mod basic;
mod bench;
mod fair;
mod hierarchy;
mod mask;
mod progress;

use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(
    name = "fairmesh",
    version,
    about = "Remove noise and unwanted detail from triangle meshes without shrinking them.",
    long_about = "Remove noise and unwanted detail from triangle meshes without shrinking them \
(constrained fairing, after Liu, Bao, Heng, Wong and Peng).\n\nWith no subcommand, opens the editor on \
the bundled Stanford bunny. Formats are chosen by file extension: .obj .gltf .glb .ply .stl .off, \
to read and to write. Wherever a mesh is read, `@bunny` names the bunny compiled into the binary \
(a file of that name is `./@bunny`). Where a command reads or writes one mesh, `-` is standard \
input or output, with --format naming the format."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(clap::Args, Debug, Default)]
pub struct EditArgs {
    /// The mesh to open; the bundled bunny when left out.
    pub file: Option<PathBuf>,
    /// Print every UI frame that takes more than MS milliseconds of CPU time to standard error,
    /// split into its parts (applying results, uploading to the GPU, widgets, viewport draw);
    /// also every frame whose input waited more than MS (at least 50) milliseconds since the
    /// previous frame began, and when each background result arrived.
    #[arg(long, value_name = "MS")]
    pub log_frames: Option<f64>,
    /// Close the window once the mesh is loaded and all work is done, printing one line about it
    /// (a smoke test of the editor in a real window; used by CI).
    #[arg(long, hide = true)]
    pub exit_when_settled: bool,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Open the editor on FILE (or on the bundled bunny).
    Edit(EditArgs),
    /// Print counts, topology and measures of a mesh.
    Info(basic::InfoArgs),
    /// Add seeded Gaussian noise to a mesh.
    Noise(basic::NoiseArgs),
    /// Convert between formats (chosen by extension).
    Convert(basic::ConvertArgs),
    /// Compare OTHER against REFERENCE: surface distance, volume change, per-vertex errors.
    Compare(basic::CompareArgs),
    /// Smooth a mesh: constrained fairing or one of the baselines.
    Fair(fair::FairArgs),
    /// Build the decimation hierarchy and print its levels.
    Hierarchy(hierarchy::HierarchyArgs),
    /// Multiresolution fairing from a chosen start level.
    Multires(hierarchy::MultiresArgs),
    /// Time the operations that matter on a mesh.
    Bench(bench::BenchArgs),
}

/// Runs a non-editor subcommand.
pub fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Edit { .. } => unreachable!("the editor is started by main"),
        Command::Info(args) => basic::info(args),
        Command::Noise(args) => basic::noise(args),
        Command::Convert(args) => basic::convert(args),
        Command::Compare(args) => basic::compare(args),
        Command::Fair(args) => fair::run(args),
        Command::Hierarchy(args) => hierarchy::run_hierarchy(args),
        Command::Multires(args) => hierarchy::run_multires(args),
        Command::Bench(args) => bench::run(args),
    }
}

/// The format of a mesh read from standard input or written to standard output (`-`).
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum FormatArg {
    Obj,
    Gltf,
    Glb,
    Ply,
    Stl,
    Off,
}

impl From<FormatArg> for fairmesh::io::Format {
    fn from(format: FormatArg) -> Self {
        use fairmesh::io::Format;
        match format {
            FormatArg::Obj => Format::Obj,
            FormatArg::Gltf => Format::Gltf,
            FormatArg::Glb => Format::Glb,
            FormatArg::Ply => Format::Ply,
            FormatArg::Stl => Format::Stl,
            FormatArg::Off => Format::Off,
        }
    }
}

/// `--format`, for the commands that read or write one mesh.
#[derive(clap::Args, Debug, Clone, Copy, Default)]
pub struct StdioFormat {
    /// Format of the mesh read from standard input or written to standard output, where the
    /// input or the output is `-` (files are known by their extension).
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
}

/// Whether `path` is `-`: standard input or output.
pub(crate) fn is_stdio(path: &std::path::Path) -> bool {
    path.as_os_str() == "-"
}

/// The format `--format` names for `-`, or an error saying it is needed.
pub(crate) fn stdio_format(
    format: Option<FormatArg>,
    what: &str,
) -> anyhow::Result<fairmesh::io::Format> {
    format.map(Into::into).ok_or_else(|| {
        anyhow::anyhow!(
            "{what} (`-`) needs --format to name the mesh format (obj, gltf, glb, ply, stl or off)"
        )
    })
}

/// Saves `mesh` into what it was loaded from (see `fairmesh::io::save_with_source`) and prints, on
/// stderr, what the output could not keep. `-` writes the bare mesh to standard output in the
/// format `--format` names.
pub(crate) fn save_kept(
    path: &std::path::Path,
    mesh: &fairmesh::TriMesh,
    source: &fairmesh::io::Source,
    format: Option<FormatArg>,
) -> anyhow::Result<fairmesh::io::SaveReport> {
    let _step = progress::Step::start(format!("saving {}", display_output(path)));
    if is_stdio(path) {
        let format = stdio_format(format, "writing to standard output")?;
        let lost = source.contents();
        let mut stdout = std::io::BufWriter::with_capacity(1 << 20, std::io::stdout().lock());
        fairmesh::io::write_to(&mut stdout, mesh, format)?;
        if !lost.is_empty() {
            eprintln!(
                "warning: standard output gets a bare {format} mesh; not kept from the input: {}",
                lost.join("; ")
            );
        }
        return Ok(Default::default());
    }
    let report = fairmesh::io::save_with_source(path, mesh, source)?;
    for warning in &report.warnings {
        eprintln!("warning: {}: {warning}", path.display());
    }
    Ok(report)
}

/// An input path as messages show it: `-` is "standard input".
pub(crate) fn display_input(path: &std::path::Path) -> String {
    if is_stdio(path) {
        "standard input (-)".into()
    } else {
        path.display().to_string()
    }
}

/// An output path as messages show it: `-` is "standard output".
pub(crate) fn display_output(path: &std::path::Path) -> String {
    if is_stdio(path) {
        "standard output (-)".into()
    } else {
        path.display().to_string()
    }
}

/// Writes command output to stdout. A reader that closes the pipe early (`| head`) ends the output
/// quietly instead of failing.
pub fn emit(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
    {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}
