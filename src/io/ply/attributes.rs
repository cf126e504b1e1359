//! What a PLY file holds beyond positions and triangles: its vertex colours and texture
//! coordinates per welded vertex (for saving in another format), and its contents in plain words.

use super::header::{find_layout, parse_header, Element, Property, Scalar};
use super::rows::{uv_properties, vertex_rows, vertex_triples};
use crate::io::carry::{Gather, VertexAttributes};
use crate::io::origin::Origin;
use crate::io::uv_convention::into_library;
use crate::io::Format;
use std::path::Path;

/// Whether the PLY file's vertices have texture coordinates ([`super::rows::uv_properties`]): what makes
/// [`vertex_attributes`]' `uvs` `Some`, read from the header alone.
pub(crate) fn has_texture_coordinates(bytes: &[u8]) -> bool {
    let path = Path::new("");
    let Ok(header) = parse_header(bytes, path) else {
        return false;
    };
    let Ok(layout) = find_layout(&header, path) else {
        return false;
    };
    uv_properties(&header.elements[layout.vertex_element]).is_some()
}

/// Whether the PLY file's faces hold texture coordinates of their own (a `texcoord` list per
/// face, as MeshLab writes a wedge-textured mesh): written back they stay as they are, so they
/// cannot follow a slide of their vertices.
pub(crate) fn has_face_texture_coordinates(bytes: &[u8]) -> bool {
    let path = Path::new("");
    let Ok(header) = parse_header(bytes, path) else {
        return false;
    };
    let Ok(layout) = find_layout(&header, path) else {
        return false;
    };
    layout.face_element.is_some_and(|f| {
        header.elements[f]
            .properties
            .iter()
            .any(|p| matches!(p, Property::List { name, .. } if name == b"texcoord"))
    })
}

/// The vertex colours (red green blue [alpha]) and UVs (s t, u v or texture_u texture_v) of a
/// PLY file, per welded vertex, for saving it in another format; UVs in the library's
/// convention (a PLY's v counts from the image's bottom row, see `io::uv_convention`).
pub(crate) fn vertex_attributes(bytes: &[u8], origin: &Origin) -> VertexAttributes {
    let path = Path::new("");
    let Ok(header) = parse_header(bytes, path) else {
        return VertexAttributes::default();
    };
    let Ok(layout) = find_layout(&header, path) else {
        return VertexAttributes::default();
    };
    let Some(rows) = vertex_rows(bytes, &header, &layout) else {
        return VertexAttributes::default();
    };
    let element = &header.elements[layout.vertex_element];
    let find = |name: &[u8]| {
        element
            .properties
            .iter()
            .position(|p| matches!(p, Property::Scalar { name: n, .. } if n == name))
    };
    // Integer colours are 0..255 (0..65535 for 16 bits); float colours are 0..1.
    let scale = |p: usize| match &element.properties[p] {
        Property::Scalar {
            kind: Scalar::U16, ..
        } => 1.0 / 65535.0,
        Property::Scalar { kind, .. } if kind.is_integer() => 1.0 / 255.0,
        _ => 1.0,
    };
    let rgb = [b"red".as_slice(), b"green", b"blue"].map(find);
    let mut colours_gathered = None;
    if let [Some(r), Some(g), Some(b)] = rgb {
        let colours = vertex_triples(bytes, &header, &rows, element, [r, g, b]);
        let alphas = find(b"alpha").map(|a| {
            (
                vertex_triples(bytes, &header, &rows, element, [a, a, a]),
                scale(a),
            )
        });
        let mut gather = Gather::<4>::new(origin.welded_vertices, [1.0; 4]);
        for (k, c) in colours.iter().enumerate() {
            let alpha = alphas
                .as_ref()
                .map_or(1.0, |(values, scale)| values[k][0] * scale);
            let rgba = [c[0] * scale(r), c[1] * scale(g), c[2] * scale(b), alpha];
            gather.put(origin.welded(k), rgba.map(|v| v.clamp(0.0, 1.0)));
        }
        colours_gathered = Some(gather);
    }
    let mut uvs_gathered = None;
    if let Some((u, v)) = uv_properties(element) {
        let mut gather = Gather::<2>::new(origin.welded_vertices, [0.0; 2]);
        for (k, uv) in vertex_triples(bytes, &header, &rows, element, [u, v, v])
            .iter()
            .enumerate()
        {
            gather.put(origin.welded(k), into_library(Format::Ply, [uv[0], uv[1]]));
        }
        uvs_gathered = Some(gather);
    }
    VertexAttributes::gathered(uvs_gathered, colours_gathered)
}

/// What a PLY file holds beyond positions and triangles, in plain words.
pub(crate) fn contents(bytes: &[u8]) -> Vec<String> {
    let path = Path::new("");
    let Ok(header) = parse_header(bytes, path) else {
        return Vec::new();
    };
    let Ok(layout) = find_layout(&header, path) else {
        return Vec::new();
    };
    let names = |element: &Element, skip: &[usize]| -> Vec<String> {
        (0..element.properties.len())
            .filter(|p| !skip.contains(p))
            .map(|p| String::from_utf8_lossy(element.properties[p].name()).into_owned())
            .collect()
    };
    let mut out = Vec::new();
    let vertex = names(&header.elements[layout.vertex_element], &layout.xyz);
    if !vertex.is_empty() {
        out.push(format!("vertex properties {}", vertex.join(", ")));
    }
    if let Some(f) = layout.face_element {
        let face = names(&header.elements[f], &[layout.face_list]);
        if !face.is_empty() {
            out.push(format!("face properties {}", face.join(", ")));
        }
    }
    for (e, element) in header.elements.iter().enumerate() {
        if e != layout.vertex_element && Some(e) != layout.face_element {
            out.push(format!("{} {} elements", element.count, element.label()));
        }
    }
    out
}
