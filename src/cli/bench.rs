//! `fairmesh bench` (PROVISIONAL).
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct BenchArgs {
    pub input: PathBuf,
}

pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    let loaded = fairmesh::io::load(&args.input)?;
    for (name, ms) in super::fair::bench_rows(&loaded.mesh, &loaded.topology)
        .into_iter()
        .chain(super::hierarchy::bench_rows(&loaded.mesh))
    {
        println!("{name:<40} {ms:>10.3} ms");
    }
    Ok(())
}
