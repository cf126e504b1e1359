//! `completions` and `man`: the shell completion scripts and the manual pages, both generated from
//! the same clap definitions as `--help`, so that neither can say something `--help` does not.

use anyhow::Context;
use clap::{Args, CommandFactory};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct CompletionsArgs {
    /// The shell to write the completion script for.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

#[derive(Args, Debug)]
pub struct ManArgs {
    /// Folder to write the pages into (made when missing): fairmesh.1 and one page per command,
    /// fairmesh-fair.1 and so on. Read one with `man -l DIR/fairmesh.1`.
    pub dir: PathBuf,
}

/// Prints the completion script for `args.shell` to standard output.
pub fn completions(args: CompletionsArgs) -> anyhow::Result<()> {
    let mut command = super::Cli::command();
    let mut out = std::io::stdout().lock();
    clap_complete::generate(args.shell, &mut command, "fairmesh", &mut out);
    Ok(())
}

/// Writes the manual pages into `args.dir`, each file whole or not at all.
pub fn man(args: ManArgs) -> anyhow::Result<()> {
    std::fs::create_dir_all(&args.dir)
        .with_context(|| format!("cannot make the folder {}", args.dir.display()))?;
    let mut command = super::Cli::command().disable_help_subcommand(true);
    command.build();
    let mut written = Vec::new();
    write_pages(&command, &args.dir, &mut written)?;
    for path in &written {
        println!("{}", path.display());
    }
    Ok(())
}

/// Writes the page of `command` and, before it, those of its visible subcommands.
fn write_pages(
    command: &clap::Command,
    dir: &std::path::Path,
    written: &mut Vec<PathBuf>,
) -> anyhow::Result<()> {
    for sub in command.get_subcommands().filter(|sub| !sub.is_hide_set()) {
        write_pages(sub, dir, written)?;
    }
    let page = clap_mangen::Man::new(command.clone());
    let path = dir.join(page.get_filename());
    fairmesh::io::write_atomically(&path, |w| page.render(w))?;
    written.push(path);
    Ok(())
}
