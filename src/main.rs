//! fairmesh: with no subcommand the editor on the bundled bunny; otherwise the command-line tool.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    let result = match args.command {
        None => run_editor(cli::EditArgs::default()),
        Some(cli::Command::Edit(args)) => run_editor(args),
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
fn run_editor(args: cli::EditArgs) -> anyhow::Result<()> {
    let log_frames_over = match args.log_frames {
        Some(ms) if ms.is_finite() && ms >= 0.0 => {
            Some(std::time::Duration::from_secs_f64(ms / 1e3))
        }
        Some(ms) => anyhow::bail!("--log-frames needs a number of milliseconds >= 0, not {ms}"),
        None => None,
    };
    fairmesh::app::run(fairmesh::app::AppOptions {
        file: args.file,
        log_frames_over,
        exit_when_settled: args.exit_when_settled,
        ..Default::default()
    })
}

#[cfg(not(feature = "gui"))]
fn run_editor(_args: cli::EditArgs) -> anyhow::Result<()> {
    anyhow::bail!(
        "this fairmesh was built without the editor (feature `gui`); use a subcommand, see --help"
    )
}
