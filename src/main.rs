//! fairmesh: with no subcommand the editor on the bundled bunny; otherwise the command-line tool.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    let result = match args.command {
        None => run_editor(None),
        Some(cli::Command::Edit { file }) => run_editor(file),
        Some(command) => cli::run(command),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(feature = "gui")]
fn run_editor(file: Option<std::path::PathBuf>) -> anyhow::Result<()> {
    fairmesh::app::run(file)
}

#[cfg(not(feature = "gui"))]
fn run_editor(_file: Option<std::path::PathBuf>) -> anyhow::Result<()> {
    anyhow::bail!(
        "this fairmesh was built without the editor (feature `gui`); use a subcommand, see --help"
    )
}
