//! `fairmesh hierarchy` and `fairmesh multires` (STUB: to be filled by the hierarchy work).
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct HierarchyArgs {
    pub input: PathBuf,
}

#[derive(Args, Debug)]
pub struct MultiresArgs {
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run_hierarchy(_args: HierarchyArgs) -> anyhow::Result<()> {
    anyhow::bail!("hierarchy is not implemented yet")
}

pub fn run_multires(_args: MultiresArgs) -> anyhow::Result<()> {
    anyhow::bail!("multires is not implemented yet")
}

/// Rows for `fairmesh bench`: (operation, milliseconds).
pub fn bench_rows(_mesh: &fairmesh::TriMesh) -> Vec<(String, f64)> {
    Vec::new()
}
