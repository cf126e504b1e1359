//! Writes a large test mesh for the editor's responsiveness check: the bundled bunny after two
//! rounds of Loop subdivision (about 1.2M faces), as a plain OBJ.
//! `cargo run --release --example large_mesh -- /tmp/bunny_x16.obj`

use std::io::Write;
use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let out = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("bunny_x16.obj"));
    let bunny = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/bunny00.obj");
    let mesh = fairmesh::io::load(&bunny)?.mesh;
    let big = fairmesh::mesh::subdivide_loop(&fairmesh::mesh::subdivide_loop(&mesh));
    let mut file = std::io::BufWriter::new(std::fs::File::create(&out)?);
    for p in &big.positions {
        writeln!(file, "v {} {} {}", p[0], p[1], p[2])?;
    }
    for t in &big.triangles {
        writeln!(file, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    file.flush()?;
    println!(
        "{}: {} vertices, {} faces",
        out.display(),
        big.vertex_count(),
        big.face_count()
    );
    Ok(())
}
