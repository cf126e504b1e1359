//! What an OBJ file holds beyond positions and triangles: its texture coordinates and vertex
//! colours per welded vertex (for saving in another format), and its contents in plain words.

use super::line::vertex_and_uv;
use crate::io::carry::{Gather, VertexAttributes};
use crate::io::origin::Origin;
use crate::io::text::tokens;
use crate::io::uv_convention::into_library;
use crate::io::Format;

/// Whether a face corner of the OBJ file names a texture coordinate (`v/vt`, `v/vt/vn`) that a
/// `vt` line before it gives: what makes [`vertex_attributes`]' `uvs` `Some`, found without
/// reading them all (it stops at the first such corner, usually in the first face).
pub(crate) fn has_texture_coordinates(bytes: &[u8]) -> bool {
    let (mut vertices, mut texture_coordinates) = (0usize, 0usize);
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => vertices += 1,
            Some(b"vt") => texture_coordinates += 1,
            Some(b"f")
                if words.any(|corner| {
                    matches!(
                        vertex_and_uv(corner, vertices, texture_coordinates),
                        (Some(_), Some(_))
                    )
                }) =>
            {
                return true;
            }
            _ => {}
        }
    }
    false
}

/// The vertex colours (`v x y z r g b`) and texture coordinates (`vt`, through the faces'
/// `v/vt` corners) of an OBJ file, per welded vertex, for saving it in another format; texture
/// coordinates in the library's convention (see `io::uv_convention`).
pub(crate) fn vertex_attributes(bytes: &[u8], origin: &Origin) -> VertexAttributes {
    let mut colours = Gather::<4>::new(origin.welded_vertices, [1.0; 4]);
    let mut uvs = Gather::<2>::new(origin.welded_vertices, [0.0; 2]);
    let (mut any_colour, mut any_uv) = (false, false);
    let mut vertices = 0usize;
    let mut texture_coordinates: Vec<[f32; 2]> = Vec::new();
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => {
                let values: Vec<f32> = words.filter_map(crate::io::text::parse_f32).collect();
                if values.len() == 6 {
                    any_colour = true;
                    let rgb = [values[3], values[4], values[5]].map(|c| c.clamp(0.0, 1.0));
                    colours.put(origin.welded(vertices), [rgb[0], rgb[1], rgb[2], 1.0]);
                }
                vertices += 1;
            }
            Some(b"vt") => {
                let u = words
                    .next()
                    .and_then(crate::io::text::parse_f32)
                    .unwrap_or(0.0);
                let v = words
                    .next()
                    .and_then(crate::io::text::parse_f32)
                    .unwrap_or(0.0);
                texture_coordinates.push(into_library(Format::Obj, [u, v]));
            }
            Some(b"f") => {
                for corner in words {
                    if let (Some(vertex), Some(t)) =
                        vertex_and_uv(corner, vertices, texture_coordinates.len())
                    {
                        any_uv = true;
                        uvs.put(origin.welded(vertex), texture_coordinates[t]);
                    }
                }
            }
            _ => {}
        }
    }
    VertexAttributes::gathered(any_uv.then_some(uvs), any_colour.then_some(colours))
}

/// What an OBJ file holds beyond positions and triangles, in plain words.
pub(crate) fn contents(bytes: &[u8]) -> Vec<String> {
    let (mut uvs, mut normals, mut colours, mut polygons, mut groups, mut smoothing) =
        (0usize, 0usize, 0usize, 0usize, 0usize, false);
    let mut materials: Vec<String> = Vec::new();
    let mut libraries: Vec<String> = Vec::new();
    // Statements fairmesh does not read (free-form curves and surfaces, `vp`, `lod`, ...), by
    // keyword; polylines and points are said when the file is read.
    let mut other: Vec<(String, usize)> = Vec::new();
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") if words.by_ref().count() == 6 => colours += 1,
            Some(b"vt") => uvs += 1,
            Some(b"vn") => normals += 1,
            Some(b"f") if words.by_ref().count() > 3 => polygons += 1,
            Some(b"o" | b"g") => groups += 1,
            Some(b"s") => smoothing = true,
            Some(b"usemtl") => {
                let name = String::from_utf8_lossy(words.next().unwrap_or_default()).into_owned();
                if !materials.contains(&name) {
                    materials.push(name);
                }
            }
            Some(b"mtllib") => {
                libraries.extend(words.map(|w| String::from_utf8_lossy(w).into_owned()))
            }
            Some(b"v" | b"f" | b"l" | b"p") => {}
            Some(keyword) if !keyword.starts_with(b"#") => {
                let keyword = String::from_utf8_lossy(keyword).into_owned();
                if let Some((_, count)) = other.iter_mut().find(|(k, _)| *k == keyword) {
                    *count += 1;
                } else if other.len() < 64 {
                    other.push((keyword, 1));
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    if groups > 0 {
        out.push(format!("{groups} object and group names (o, g)"));
    }
    if !materials.is_empty() || !libraries.is_empty() {
        out.push(format!(
            "{} materials ({}) from the material library {}",
            materials.len(),
            materials.join(", "),
            libraries.join(", ")
        ));
    }
    if uvs > 0 {
        out.push(format!("texture coordinates ({uvs} vt)"));
    }
    if normals > 0 {
        out.push(format!("normals ({normals} vn)"));
    }
    if smoothing {
        out.push("smoothing groups (s)".into());
    }
    if colours > 0 {
        out.push("vertex colours".into());
    }
    if polygons > 0 {
        out.push(format!(
            "{polygons} quads and polygons (written as triangles)"
        ));
    }
    if !other.is_empty() {
        let count: usize = other.iter().map(|(_, n)| n).sum();
        let keywords: Vec<&str> = other.iter().take(8).map(|(k, _)| k.as_str()).collect();
        let more = if other.len() > 8 { ", ..." } else { "" };
        out.push(format!(
            "{count} statements fairmesh does not read ({}{more})",
            keywords.join(", ")
        ));
    }
    out
}
