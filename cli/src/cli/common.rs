//! What the commands share: reading the input mesh (a file, `@bunny`, or `-` for standard input),
//! saving the result into what it was loaded from, writing the report to standard output, and
//! the median timing `bench` reports.

use std::path::Path;
use std::time::Instant;

use fairmesh::io::{self, LoadOptions, Loaded};

use super::args::FormatArg;
use super::progress;

/// Whether `path` is `-`: standard input or output.
pub(crate) fn is_stdio(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// The format `--format` names for `-`, or an error saying it is needed.
pub(crate) fn stdio_format(format: Option<FormatArg>, what: &str) -> anyhow::Result<io::Format> {
    format.map(Into::into).ok_or_else(|| {
        anyhow::anyhow!(
            "{what} (`-`) needs --format to name the mesh format (obj, gltf, glb, ply, stl or off)"
        )
    })
}

/// Refuses `output` `-` without `--format`, before any work is done.
pub(crate) fn check_output_format(output: &Path, format: Option<FormatArg>) -> anyhow::Result<()> {
    if is_stdio(output) {
        stdio_format(format, "writing to standard output")?;
    }
    Ok(())
}

/// An input path as messages show it: `-` is "standard input".
pub(crate) fn display_input(path: &Path) -> String {
    if is_stdio(path) {
        "standard input (-)".into()
    } else {
        path.display().to_string()
    }
}

/// An output path as messages show it: `-` is "standard output".
pub(crate) fn display_output(path: &Path) -> String {
    if is_stdio(path) {
        "standard output (-)".into()
    } else {
        path.display().to_string()
    }
}

/// Loads an input mesh; `@bunny` is the bunny compiled into the binary. `-` is refused (the
/// command has no `--format`); see [`load_from`].
pub(crate) fn load(path: &Path, weld: bool) -> anyhow::Result<Loaded> {
    if is_stdio(path) {
        anyhow::bail!("this command reads files only, not standard input (`-`)");
    }
    load_from(path, weld, None)
}

/// [`load_from`] with a progress line on a terminal (see `progress`).
pub(crate) fn load_shown(
    path: &Path,
    weld: bool,
    format: Option<FormatArg>,
) -> anyhow::Result<Loaded> {
    progress::Step::run(format!("loading {}", display_input(path)), || {
        load_from(path, weld, format)
    })
}

/// [`load_shown`], then what the loader skipped or read leniently (faces with fewer than three
/// corners, point and line primitives, a stray header line, ...) as warnings on standard error,
/// for the commands that write a mesh: those parts are not in the output, and the user is told.
/// (`info` lists them in its report instead.)
pub(crate) fn load_input(
    path: &Path,
    weld: bool,
    format: Option<FormatArg>,
) -> anyhow::Result<Loaded> {
    let loaded = load_shown(path, weld, format)?;
    print_load_warnings(path, &loaded);
    Ok(loaded)
}

/// Each of the loader's warnings on standard error, with the input's name.
pub(crate) fn print_load_warnings(path: &Path, loaded: &Loaded) {
    for warning in &loaded.report.warnings {
        eprintln!("warning: {}: {warning}", display_input(path));
    }
}

/// Loads an input mesh: a file, `@bunny` (the bunny compiled into the binary), or `-`, standard
/// input in the format `format` names.
pub(crate) fn load_from(
    path: &Path,
    weld: bool,
    format: Option<FormatArg>,
) -> anyhow::Result<Loaded> {
    let options = LoadOptions { weld };
    if fairmesh::bundled::is_bunny_pseudo_path(path) {
        return Ok(fairmesh::bundled::load_bunny(&options)?);
    }
    if is_stdio(path) {
        let format = stdio_format(format, "reading from standard input")?;
        let stdin = std::io::stdin().lock();
        return Ok(io::load_from_reader(
            stdin,
            format,
            "standard input",
            &options,
        )?);
    }
    Ok(io::load_with(path, &options)?)
}

/// Saves `mesh` into what it was loaded from (see `fairmesh::io::save_with_source`) and prints, on
/// stderr, what the output could not keep. `-` writes the bare mesh to standard output in the
/// format `--format` names.
pub(crate) fn save_kept(
    path: &Path,
    mesh: &fairmesh::TriMesh,
    source: &io::Source,
    format: Option<FormatArg>,
) -> anyhow::Result<io::SaveReport> {
    let _step = progress::Step::start(format!("saving {}", display_output(path)));
    if is_stdio(path) {
        let format = stdio_format(format, "writing to standard output")?;
        let lost = source.contents();
        let mut stdout = std::io::BufWriter::with_capacity(1 << 20, std::io::stdout().lock());
        io::write_to(&mut stdout, mesh, format)?;
        if !lost.is_empty() {
            eprintln!(
                "warning: standard output gets a bare {format} mesh; not kept from the input: {}",
                lost.join("; ")
            );
        }
        return Ok(Default::default());
    }
    let report = io::save_with_source(path, mesh, source)?;
    for warning in &report.warnings {
        eprintln!("warning: {}: {warning}", path.display());
    }
    Ok(report)
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

/// Median wall time of `runs` calls of `f` (at least one), in milliseconds.
pub fn median_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}
