//! `info`, `noise`, `convert`, `compare` (PROVISIONAL).
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct InfoArgs {
    pub file: PathBuf,
    #[arg(long)]
    pub json: bool,
}
#[derive(Args, Debug)]
pub struct NoiseArgs {
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
}
#[derive(Args, Debug)]
pub struct ConvertArgs {
    pub input: PathBuf,
    #[arg(short, long)]
    pub output: PathBuf,
}
#[derive(Args, Debug)]
pub struct CompareArgs {
    pub reference: PathBuf,
    pub other: PathBuf,
    #[arg(long)]
    pub json: bool,
}

pub fn info(args: InfoArgs) -> anyhow::Result<()> {
    let loaded = fairmesh::io::load(&args.file)?;
    println!(
        "{} vertices, {} faces",
        loaded.mesh.vertex_count(),
        loaded.mesh.face_count()
    );
    Ok(())
}
pub fn noise(_args: NoiseArgs) -> anyhow::Result<()> {
    anyhow::bail!("not yet")
}
pub fn convert(_args: ConvertArgs) -> anyhow::Result<()> {
    anyhow::bail!("not yet")
}
pub fn compare(_args: CompareArgs) -> anyhow::Result<()> {
    anyhow::bail!("not yet")
}
