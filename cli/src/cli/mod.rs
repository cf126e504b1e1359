//! The command-line tool: subcommands on top of the library. `basic.rs` holds `info`, `noise`,
//! `convert` and `compare`; `fair.rs` `fair`; `hierarchy.rs` `hierarchy`; `multires.rs`
//! `multires`; `bench.rs` `bench`. Beside them: `args.rs`, the argument types several commands share;
//! `common.rs`, loading the input, saving the result and writing the report; `mask.rs`, `--mask`;
//! `progress.rs`, the progress line of long steps; `shell.rs`, `completions` and `man`.

mod args;
mod basic;
mod bench;
mod common;
mod fair;
mod hierarchy;
mod mask;
mod multires;
mod progress;
mod shell;

use clap::{Parser, Subcommand};
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
    Multires(multires::MultiresArgs),
    /// Time the operations that matter on a mesh.
    Bench(bench::BenchArgs),
    /// Print a completion script for bash, zsh, fish, elvish or PowerShell.
    #[command(
        long_about = "Print a completion script for bash, zsh, fish, elvish or PowerShell to \
standard output. For bash: `fairmesh completions bash > ~/.local/share/bash-completion/completions/fairmesh`."
    )]
    Completions(shell::CompletionsArgs),
    /// Write the manual pages (fairmesh.1 and one per command) into a folder.
    Man(shell::ManArgs),
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
        Command::Hierarchy(args) => hierarchy::run(args),
        Command::Multires(args) => multires::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Completions(args) => shell::completions(args),
        Command::Man(args) => shell::man(args),
    }
}
