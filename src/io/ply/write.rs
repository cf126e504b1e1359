//! Writing a bare mesh as binary little endian PLY, with per-vertex normals, UVs and colours
//! where given (UVs turned from the library's convention into PLY's, see `io::uv_convention`).

use crate::io::carry::VertexAttributes;
use crate::io::uv_convention::into_file;
use crate::io::Format;
use crate::mesh::TriMesh;
use std::io::Write;

pub(crate) fn write(out: &mut dyn Write, mesh: &TriMesh) -> std::io::Result<()> {
    write_with(out, mesh, &VertexAttributes::default(), None)
}

/// A binary PLY of `mesh` with, per vertex, the normals `normals` (`nx ny nz` float), and the UVs
/// (`s t` float) and colours (`red green blue alpha` uchar) of `extra` where it has them (one
/// value per vertex of `mesh`; ignored otherwise).
pub(crate) fn write_with(
    out: &mut dyn Write,
    mesh: &TriMesh,
    extra: &VertexAttributes,
    normals: Option<&[[f32; 3]]>,
) -> std::io::Result<()> {
    let n = mesh.positions.len();
    let index_type = if n > i32::MAX as usize { "uint" } else { "int" };
    let normals = normals.filter(|normals| normals.len() == n);
    let uvs = extra.uvs.as_ref().filter(|uvs| uvs.len() == n);
    let colours = extra.colours.as_ref().filter(|colours| colours.len() == n);
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by fairmesh\n\
         element vertex {n}\nproperty float x\nproperty float y\nproperty float z\n"
    );
    if normals.is_some() {
        header.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    if uvs.is_some() {
        header.push_str("property float s\nproperty float t\n");
    }
    if colours.is_some() {
        header.push_str(
            "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n",
        );
    }
    header.push_str(&format!(
        "element face {}\nproperty list uchar {index_type} vertex_indices\nend_header\n",
        mesh.triangles.len()
    ));
    out.write_all(header.as_bytes())?;
    let mut buffer = Vec::with_capacity(1 << 16);
    for (v, p) in mesh.positions.iter().enumerate() {
        for c in p {
            buffer.extend_from_slice(&c.to_le_bytes());
        }
        for c in normals.map_or(&[][..], |normals| &normals[v][..]) {
            buffer.extend_from_slice(&c.to_le_bytes());
        }
        if let Some(uvs) = uvs {
            for c in into_file(Format::Ply, uvs[v]) {
                buffer.extend_from_slice(&c.to_le_bytes());
            }
        }
        if let Some(colours) = colours {
            // 0..1 to 0..255, rounded; `Gather` keeps values finite.
            buffer.extend(colours[v].map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8));
        }
        if buffer.len() >= 1 << 16 {
            out.write_all(&buffer)?;
            buffer.clear();
        }
    }
    for t in &mesh.triangles {
        buffer.push(3);
        for v in t {
            buffer.extend_from_slice(&v.to_le_bytes());
        }
        if buffer.len() >= 1 << 16 {
            out.write_all(&buffer)?;
            buffer.clear();
        }
    }
    out.write_all(&buffer)
}
