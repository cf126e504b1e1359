//! `fairmesh fair` (STUB: to be filled by the fairing work).
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct FairArgs {
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(_args: FairArgs) -> anyhow::Result<()> {
    anyhow::bail!("fair is not implemented yet")
}

/// Rows for `fairmesh bench`: (operation, milliseconds).
pub fn bench_rows(_mesh: &fairmesh::TriMesh, _topology: &fairmesh::Topology) -> Vec<(String, f64)> {
    Vec::new()
}
