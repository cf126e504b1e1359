//! Writing a bare mesh as OBJ: `v x y z` with Rust's shortest round-trip float formatting, so
//! every f32 reads back bit for bit, and `f a b c` with 1-based indices; per-vertex colours and
//! UVs where given (turned from the library's texture-coordinate convention into `vt`'s, see
//! `io::uv_convention`).

use crate::io::carry::VertexAttributes;
use crate::io::uv_convention::into_file;
use crate::io::Format;
use crate::mesh::TriMesh;
use std::io::Write;

pub(crate) fn write(out: &mut dyn Write, mesh: &TriMesh) -> std::io::Result<()> {
    write_with(out, mesh, &VertexAttributes::default())
}

/// An OBJ of `mesh`, with the per-vertex colours of `extra` after each `v`'s x y z (RGB; alpha
/// has no place in OBJ) and its UVs as one `vt` per vertex, referred to by the faces.
pub(crate) fn write_with(
    out: &mut dyn Write,
    mesh: &TriMesh,
    extra: &VertexAttributes,
) -> std::io::Result<()> {
    let n = mesh.positions.len();
    let uvs = extra.uvs.as_ref().filter(|uvs| uvs.len() == n);
    let colours = extra.colours.as_ref().filter(|colours| colours.len() == n);
    writeln!(out, "# written by fairmesh")?;
    writeln!(out, "# {n} vertices, {} triangles", mesh.triangles.len())?;
    for (v, [x, y, z]) in mesh.positions.iter().enumerate() {
        match colours {
            Some(colours) => {
                let [r, g, b, _] = colours[v];
                writeln!(out, "v {x} {y} {z} {r} {g} {b}")?
            }
            None => writeln!(out, "v {x} {y} {z}")?,
        }
    }
    for &uv in uvs.into_iter().flatten() {
        let [u, v] = into_file(Format::Obj, uv);
        writeln!(out, "vt {u} {v}")?;
    }
    for triangle in &mesh.triangles {
        // u32 + 1 in u64: no overflow.
        let [a, b, c] = triangle.map(|v| v as u64 + 1);
        if uvs.is_some() {
            writeln!(out, "f {a}/{a} {b}/{b} {c}/{c}")?;
        } else {
            writeln!(out, "f {a} {b} {c}")?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::read::parse;
    use super::*;
    use std::path::Path;

    #[test]
    fn writes_shortest_round_trip_floats() {
        let mesh = TriMesh::new(
            vec![
                [0.1, -0.0, 1e-30],
                [3.4028235e38, 1.0, 2.5],
                [0.0, 1.0, 7.0],
            ],
            vec![[0, 1, 2]],
        );
        let mut out = Vec::new();
        write(&mut out, &mesh).unwrap();
        let parsed = parse(&out, Path::new("w.obj")).unwrap();
        let bits = |m: &TriMesh| -> Vec<[u32; 3]> {
            m.positions.iter().map(|p| p.map(f32::to_bits)).collect()
        };
        assert_eq!(bits(&parsed.mesh), bits(&mesh));
        assert_eq!(parsed.mesh.triangles, mesh.triangles);
    }

    #[test]
    fn writes_each_vertexs_uv_as_a_vt_counted_from_the_bottom_row() {
        let mesh = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
        );
        // The library's v runs down from the image's top row; OBJ's `vt` up from its bottom row.
        let extra = VertexAttributes {
            uvs: Some(vec![[0.25, 0.0], [0.5, 0.25], [1.0, 0.75]]),
            ..Default::default()
        };
        let mut out = Vec::new();
        write_with(&mut out, &mesh, &extra).unwrap();
        let text = String::from_utf8(out).unwrap();
        // Read by hand: every `vt` line, and each face corner's texture index.
        let vts: Vec<[f32; 2]> = text
            .lines()
            .filter_map(|l| l.strip_prefix("vt "))
            .map(|rest| {
                let mut values = rest.split_whitespace().map(|x| x.parse::<f32>().unwrap());
                [values.next().unwrap(), values.next().unwrap()]
            })
            .collect();
        assert_eq!(vts, vec![[0.25, 1.0], [0.5, 0.75], [1.0, 0.25]], "{text}");
        let faces: Vec<&str> = text.lines().filter(|l| l.starts_with("f ")).collect();
        assert_eq!(faces, vec!["f 1/1 2/2 3/3"], "{text}");
    }
}
