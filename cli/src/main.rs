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
            eprintln!("error: {}", error_message(&error));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, `: ` between them, leaving out a cause that an earlier
/// message already says (errors that name their cause in their own message also return it as
/// their source: printing both would say it twice).
fn error_message(error: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in error.chain() {
        let text = cause.to_string();
        if message.contains(&text) {
            continue;
        }
        if !message.is_empty() {
            message.push_str(": ");
        }
        message.push_str(&text);
    }
    message
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
    fairmesh_editor::app::run(fairmesh_editor::app::AppOptions {
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

#[cfg(test)]
mod tests {
    use super::error_message;

    #[derive(Debug)]
    struct Wrapping(std::io::Error);
    impl std::fmt::Display for Wrapping {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "cannot read a.obj: {}", self.0)
        }
    }
    impl std::error::Error for Wrapping {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.0)
        }
    }

    fn not_found() -> std::io::Error {
        std::io::Error::new(std::io::ErrorKind::NotFound, "no such file")
    }

    #[test]
    fn a_cause_already_in_the_message_is_said_once() {
        let error = anyhow::Error::new(Wrapping(not_found()));
        assert_eq!(error_message(&error), "cannot read a.obj: no such file");
    }

    #[test]
    fn context_and_a_new_cause_are_all_said() {
        let error = anyhow::Error::new(not_found()).context("loading the reference");
        assert_eq!(error_message(&error), "loading the reference: no such file");
        let error = anyhow::Error::new(Wrapping(not_found())).context("loading the reference");
        assert_eq!(
            error_message(&error),
            "loading the reference: cannot read a.obj: no such file"
        );
    }
}
