//! The angles between neighbouring faces that chose smooth shading's sharp-edge angle
//! (`render::normals::SHARP_EDGE_ANGLE`): for each mesh, the share of its edges (those with two
//! faces) whose faces' normals turn by more than 20°-80°, the 99th, 99.9th percentile and the
//! largest turn, on clean and noisy organic meshes (the noise a scan shows) and on CAD parts,
//! whose edges are either flat-ish or sharp.
//!
//! Run: `cargo run --example shading_angles` (a debug build is fast enough). With `-- --write
//! DIR` it also writes the CAD parts into DIR as OBJ files without normals (`cad_cylinder.obj`,
//! `cad_box.obj`), to look at them in the editor.

use fairmesh::mesh::{shapes, subdivide_loop, two_face_edges};
use fairmesh::noise::{add_noise, NoiseMode, NoiseOptions};
use fairmesh::TriMesh;
use fairmesh_editor::render::normals::sharp_split;

/// Every two-face edge's turn between its faces' normals, in degrees, ascending (edges with a
/// face without area left out).
fn turns(mesh: &TriMesh) -> Vec<f64> {
    let mut angles: Vec<f64> = two_face_edges(&mesh.triangles)
        .iter()
        .filter_map(|&[_, _, f, g]| {
            let (a, b) = (mesh.face_normal(f as usize), mesh.face_normal(g as usize));
            let (a, b) = (a.try_normalize()?, b.try_normalize()?);
            Some(a.dot(b).clamp(-1.0, 1.0).acos().to_degrees())
        })
        .collect();
    angles.sort_by(f64::total_cmp);
    angles
}

/// The share of `mesh`'s vertices that smooth shading splits at `angle` degrees, in percent.
fn split_share(mesh: &TriMesh, angle: f32) -> String {
    let split = sharp_split(&mesh.positions, &mesh.triangles, angle);
    let count = split.map_or(0, |s| s.split_vertex_count());
    format!("{:.2}", 100.0 * count as f64 / mesh.vertex_count() as f64)
}

fn split_row(name: &str, mesh: &TriMesh) {
    let shares: Vec<String> = SPLIT_ANGLES.iter().map(|&a| split_share(mesh, a)).collect();
    println!(
        "| {name} | {} | {} |",
        mesh.vertex_count(),
        shares.join(" | ")
    );
}

const SPLIT_ANGLES: [f32; 6] = [30.0, 45.0, 60.0, 70.0, 80.0, 85.0];

fn row(name: &str, mesh: &TriMesh) {
    let angles = turns(mesh);
    let n = angles.len().max(1);
    let percentile = |p: f64| angles[((n as f64 * p) as usize).min(n - 1)];
    let above = |limit: f64| {
        let count = angles.iter().filter(|&&a| a > limit).count();
        format!("{:.3}", 100.0 * count as f64 / n as f64)
    };
    println!(
        "| {name} | {} | {} | {} | {} | {} | {} | {} | {:.1}° | {:.1}° | {:.1}° |",
        angles.len(),
        above(20.0),
        above(30.0),
        above(40.0),
        above(50.0),
        above(60.0),
        above(80.0),
        percentile(0.99),
        percentile(0.999),
        angles.last().copied().unwrap_or(0.0),
    );
}

fn noisy(mesh: &TriMesh, sigma: f64, mode: NoiseMode) -> TriMesh {
    let mut copy = mesh.clone();
    add_noise(
        &mut copy,
        &NoiseOptions::default().with_sigma(sigma).with_mode(mode),
    );
    copy
}

fn main() {
    let load = |path: &str| {
        fairmesh::io::load(std::path::Path::new(path))
            .expect(path)
            .mesh
    };
    let bunny = load("assets/bunny00.obj");
    let elephant = load("tests/data/elephant.obj");
    let big = subdivide_loop(&subdivide_loop(&bunny));
    let cad_cylinder = shapes::cad_cylinder(32, 1.0, 2.0);
    let cad_box = shapes::cad_box_with_holes([4.0, 3.0, 2.0], 0.2, 0.5, 16);
    let cube = shapes::cuboid([1.0, 1.0, 1.0], 0.05);
    let cylinder = shapes::cylinder(1.0, 2.0, 0.1);
    let gear = shapes::gear(16, 1.0, 1.25, 0.5, 0.05);
    let args: Vec<String> = std::env::args().collect();
    if let Some(dir) = args
        .iter()
        .position(|a| a == "--write")
        .and_then(|i| args.get(i + 1))
    {
        let dir = std::path::Path::new(dir);
        for (name, mesh) in [
            ("cad_cylinder.obj", &cad_cylinder),
            ("cad_box.obj", &cad_box),
        ] {
            fairmesh::io::save(dir.join(name), mesh).expect("written");
        }
    }
    println!(
        "| mesh | edges | % over 20° | 30° | 40° | 50° | 60° | 80° | 99th pct | 99.9th pct | max |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let (normal, iso, direction) = (
        NoiseMode::Normal,
        NoiseMode::Isotropic,
        NoiseMode::Direction,
    );
    row("bunny00", &bunny);
    row("bunny00, noise 0.3 normal", &noisy(&bunny, 0.3, normal));
    row("bunny00, noise 0.3 iso", &noisy(&bunny, 0.3, iso));
    row(
        "bunny00, noise 0.3 direction",
        &noisy(&bunny, 0.3, direction),
    );
    row("bunny00, noise 0.5 normal", &noisy(&bunny, 0.5, normal));
    row(
        "1.2M-face bunny, noise 0.3 normal",
        &noisy(&big, 0.3, normal),
    );
    row("elephant", &elephant);
    row("elephant, noise 0.3 normal", &noisy(&elephant, 0.3, normal));
    row("cad_cylinder(32)", &cad_cylinder);
    row("cad_box_with_holes(16)", &cad_box);
    row("cuboid, spacing 0.05", &cube);
    row("cuboid, noise 0.3 normal", &noisy(&cube, 0.3, normal));
    row("cylinder, spacing 0.1", &cylinder);
    row("gear(16)", &gear);

    println!("\n| mesh | vertices | % split at 30° | 45° | 60° | 70° | 80° | 85° |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    split_row("bunny00", &bunny);
    for sigma in [0.1, 0.2, 0.3] {
        for (mode, name) in [(normal, "normal"), (iso, "iso")] {
            let label = format!("bunny00, noise {sigma} {name}");
            split_row(&label, &noisy(&bunny, sigma, mode));
        }
    }
    split_row("elephant", &elephant);
    split_row("elephant, noise 0.3 normal", &noisy(&elephant, 0.3, normal));
    split_row("cad_cylinder(32)", &cad_cylinder);
    split_row("cad_box_with_holes(16)", &cad_box);
    split_row("cuboid, spacing 0.05", &cube);
    for sigma in [0.1, 0.2, 0.3] {
        split_row(
            &format!("cuboid, noise {sigma} normal"),
            &noisy(&cube, sigma, normal),
        );
    }
    split_row("gear(16)", &gear);

    println!("\n| noisy cuboid | rim vertices split at 45° | 60° | 70° | 80° | others split at 45° | 60° | 70° | 80° |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    let rim = split_flags(&cube, 60.0);
    for sigma in [0.1, 0.2, 0.3] {
        let mesh = noisy(&cube, sigma, normal);
        let (mut on, mut off) = (Vec::new(), Vec::new());
        for angle in [45.0, 60.0, 70.0, 80.0] {
            let flags = split_flags(&mesh, angle);
            let count = |want: bool| {
                rim.iter()
                    .zip(&flags)
                    .filter(|&(&r, &f)| r == want && f)
                    .count()
            };
            let total = |want: bool| rim.iter().filter(|&&r| r == want).count();
            on.push(format!(
                "{:.1}",
                100.0 * count(true) as f64 / total(true) as f64
            ));
            off.push(format!(
                "{:.2}",
                100.0 * count(false) as f64 / total(false) as f64
            ));
        }
        println!("| σ {sigma} | {} | {} |", on.join(" | "), off.join(" | "));
    }
}

/// Which vertices of `mesh` smooth shading splits at `angle`.
fn split_flags(mesh: &TriMesh, angle: f32) -> Vec<bool> {
    let mut flags = vec![false; mesh.vertex_count()];
    if let Some(split) = sharp_split(&mesh.positions, &mesh.triangles, angle) {
        for &v in &split.vertex_of()[mesh.vertex_count()..] {
            flags[v as usize] = true;
        }
    }
    flags
}
