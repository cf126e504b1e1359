//! Wavefront OBJ: our own reader, written with `v` and `f` lines.
//!
//! Reading: `v x y z` (a fourth value is w and divides, six values are x y z r g b), `f` with
//! `v`, `v/vt`, `v//vn` or `v/vt/vn` corners, 1-based or negative (relative) indices, polygons
//! triangulated as fans from their first corner. Texture coordinates and normals are not needed
//! (fairing works on positions), so seams never split vertices; `l` polylines and `p` points are
//! skipped with a warning; everything else (`o`, `g`, `s`, `usemtl`, ...) is ignored.
//!
//! Why not tobj: tobj renumbers every object's vertices in the order its faces first use them,
//! so output files could not keep the input's vertex order (every other format does), and it
//! builds a `String` per line and a hash map per object (0.58 s CPU for a 1.2M-face file against
//! a parse floor of a few milliseconds). This reader keeps the file's order and parses chunks of
//! the file in parallel; indices are resolved after all chunks are read (negative ones relative
//! to the vertices before their line).
//!
//! Errors: the fast pass only says whether the file is good. When it is not, [`locate`] reads the
//! file again line by line to find the first line at fault and say what is wrong there, so every
//! message names the line.
//!
//! Writing: `v x y z` with Rust's shortest round-trip float formatting (`{}`), so every f32 reads
//! back bit for bit, and `f a b c` with 1-based indices.

use super::atomic;
use super::carry::{Gather, VertexAttributes};
use super::scene::{
    image_file_name, image_mime_type, Image, ImageData, Material, Part, Primitive, Scene,
    SceneVertex,
};
use super::source::{dvec, NormalTurns, Source};
use super::text::{lines, non_finite_kind, quote, tokens};
use super::{IoError, Parsed};
use crate::mesh::TriMesh;
use rayon::prelude::*;
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

/// What one chunk of lines holds.
#[derive(Default)]
struct Chunk {
    positions: Vec<[f32; 3]>,
    /// Triangle corners: absolute 0-based indices, except those listed in `relative`.
    triangles: Vec<[u32; 3]>,
    /// (triangle, corner, index relative to the chunk's first vertex) for negative OBJ indices.
    relative: Vec<(u32, u8, i64)>,
    polylines: usize,
    points: usize,
    short_faces: usize,
}

/// The chunk could not be read; `locate` says where and why.
struct Malformed;

pub(crate) fn parse(bytes: &[u8], path: &Path) -> Result<Parsed, IoError> {
    let chunks = split_at_lines(bytes, (rayon::current_num_threads() * 4).max(1), 1 << 20);
    let parsed: Result<Vec<Chunk>, Malformed> = chunks.par_iter().map(|c| parse_chunk(c)).collect();
    let located = || {
        locate(bytes, path)
            .unwrap_or_else(|| IoError::invalid(path, "the file is not a readable OBJ file"))
    };
    let chunks = parsed.map_err(|Malformed| located())?;

    let vertex_total: usize = chunks.iter().map(|c| c.positions.len()).sum();
    if u32::try_from(vertex_total).is_err() {
        return Err(IoError::invalid(
            path,
            format!("{vertex_total} vertices is more than 32-bit indices can address"),
        ));
    }
    let mut mesh = TriMesh {
        positions: Vec::with_capacity(vertex_total),
        triangles: Vec::with_capacity(chunks.iter().map(|c| c.triangles.len()).sum()),
    };
    let (mut polylines, mut points, mut short_faces) = (0, 0, 0);
    for chunk in chunks {
        let base = mesh.positions.len() as i64;
        let first_triangle = mesh.triangles.len();
        mesh.positions.extend_from_slice(&chunk.positions);
        mesh.triangles.extend_from_slice(&chunk.triangles);
        for (triangle, corner, local) in chunk.relative {
            let resolved = base + local;
            if resolved < 0 {
                return Err(located());
            }
            mesh.triangles[first_triangle + triangle as usize][corner as usize] =
                u32::try_from(resolved).map_err(|_| located())?;
        }
        polylines += chunk.polylines;
        points += chunk.points;
        short_faces += chunk.short_faces;
    }
    let count = mesh.positions.len() as u32;
    if mesh
        .triangles
        .par_iter()
        .any(|t| t.iter().any(|&v| v >= count))
    {
        return Err(located());
    }
    if mesh.triangles.is_empty() {
        // An unreadable line (binary garbage, say) says more than "no triangles".
        if let Some(located) = locate(bytes, path) {
            return Err(located);
        }
        return Err(IoError::invalid(
            path,
            format!(
                "no triangles: the file has {} vertices and no face (f) with 3 or more vertices",
                mesh.positions.len()
            ),
        ));
    }
    let mut parsed = Parsed::new(mesh);
    if polylines > 0 {
        parsed.warnings.push(super::text::skipped(
            polylines,
            "polyline (l)",
            "polylines (l)",
        ));
    }
    if points > 0 {
        parsed.warnings.push(super::text::skipped(
            points,
            "point element (p)",
            "point elements (p)",
        ));
    }
    if short_faces > 0 {
        parsed
            .warnings
            .push(super::text::short_faces_skipped(short_faces));
    }
    Ok(parsed)
}

/// About `pieces` slices of `bytes` (none smaller than `min_len` but the last), each ending
/// after a newline, so that no line is cut.
fn split_at_lines(bytes: &[u8], pieces: usize, min_len: usize) -> Vec<&[u8]> {
    let target = (bytes.len() / pieces).max(min_len);
    let mut out = Vec::with_capacity(pieces + 1);
    let mut rest = bytes;
    while rest.len() > target {
        let end = match rest[target..].iter().position(|&b| b == b'\n') {
            Some(offset) => target + offset + 1,
            None => rest.len(),
        };
        let (head, tail) = rest.split_at(end);
        out.push(head);
        rest = tail;
    }
    if !rest.is_empty() {
        out.push(rest);
    }
    out
}

fn parse_number<T: std::str::FromStr>(token: &[u8]) -> Result<T, Malformed> {
    std::str::from_utf8(token)
        .ok()
        .and_then(|t| t.parse().ok())
        .ok_or(Malformed)
}

fn parse_chunk(bytes: &[u8]) -> Result<Chunk, Malformed> {
    let mut chunk = Chunk::default();
    let mut corners: Vec<(i64, bool)> = Vec::with_capacity(8);
    for raw in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(raw);
        match words.next() {
            Some(b"v") => {
                let mut values = [0f32; 6];
                let mut count = 0;
                for token in words {
                    if count == 6 {
                        return Err(Malformed);
                    }
                    values[count] = parse_number(token)?;
                    count += 1;
                }
                let mut p = [values[0], values[1], values[2]];
                match count {
                    3 | 6 => {}
                    4 if values[3] != 0.0 => p = p.map(|c| c / values[3]),
                    _ => return Err(Malformed),
                }
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(Malformed);
                }
                chunk.positions.push(p);
            }
            Some(b"f") => {
                corners.clear();
                for corner in words {
                    let index_text = corner.split(|&b| b == b'/').next().unwrap_or(corner);
                    let index: i64 = parse_number(index_text)?;
                    match index {
                        0 => return Err(Malformed),
                        i if i > 0 => corners.push((i - 1, false)),
                        // -1 is the last vertex before this line.
                        i => corners.push((chunk.positions.len() as i64 + i, true)),
                    }
                }
                if corners.len() < 3 {
                    chunk.short_faces += 1;
                    continue;
                }
                for i in 1..corners.len() - 1 {
                    let fan = [corners[0], corners[i], corners[i + 1]];
                    let mut triangle = [0u32; 3];
                    for (slot, &(index, relative)) in fan.iter().enumerate() {
                        if relative {
                            chunk
                                .relative
                                .push((chunk.triangles.len() as u32, slot as u8, index));
                        } else {
                            triangle[slot] = u32::try_from(index).map_err(|_| Malformed)?;
                        }
                    }
                    chunk.triangles.push(triangle);
                }
            }
            Some(b"l") => chunk.polylines += 1,
            Some(b"p") => chunk.points += 1,
            _ => {}
        }
    }
    Ok(chunk)
}

/// Find the first line that is malformed or gives a bad vertex, and say why. Checks `v` (3
/// coordinates, optional w or colour), `vt`, `vn`, and `f` indices (1-based, negative = relative,
/// each within the file's counts).
fn locate(bytes: &[u8], path: &Path) -> Option<IoError> {
    let (mut total_v, mut total_vt, mut total_vn) = (0i64, 0i64, 0i64);
    for (_, line) in lines(bytes) {
        match tokens(line).next() {
            Some(b"v") => total_v += 1,
            Some(b"vt") => total_vt += 1,
            Some(b"vn") => total_vn += 1,
            _ => {}
        }
    }
    let (mut seen_v, mut seen_vt, mut seen_vn) = (0i64, 0i64, 0i64);
    let mut face_number = 0usize;
    for (number, line) in lines(bytes) {
        let at = |message: String| Some(IoError::at_line(path, number, message));
        if std::str::from_utf8(line).is_err() {
            return at("the line is not valid UTF-8".into());
        }
        // OBJ allows a long line to go on after a backslash at its end; fairmesh does not.
        if tokens(line).last() == Some(&b"\\"[..]) && !line.trim_ascii_start().starts_with(b"#") {
            return at(
                "the line ends with a backslash, continuing on the next line, which fairmesh \
                 does not read: join the two lines"
                    .into(),
            );
        }
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => {
                seen_v += 1;
                let values: Vec<&[u8]> = words.collect();
                let mut coords = [0f32; 3];
                for (axis, coord) in coords.iter_mut().enumerate() {
                    let Some(token) = values.get(axis) else {
                        return at(format!("vertex {seen_v} has fewer than 3 coordinates"));
                    };
                    match super::text::parse_f32(token) {
                        Some(value) => *coord = value,
                        None => {
                            return at(format!(
                                "vertex {seen_v}: cannot read coordinate {}",
                                quote(token)
                            ))
                        }
                    }
                }
                match values.len() {
                    3 | 6 => {}
                    4 => match values.get(3).and_then(|t| super::text::parse_f32(t)) {
                        Some(w) if w != 0.0 => coords = coords.map(|c| c / w),
                        Some(_) => return at(format!("vertex {seen_v} has w = 0")),
                        None => return at(format!("vertex {seen_v}: cannot read w")),
                    },
                    _ => {
                        return at(format!(
                            "vertex {seen_v} has {} values; expected 3 (x y z), 4 (x y z w) or 6 (x y z r g b)",
                            values.len()
                        ))
                    }
                }
                if let Some(bad) = coords.iter().find(|c| !c.is_finite()) {
                    return at(format!(
                        "vertex {seen_v} has {} coordinate",
                        non_finite_kind(*bad)
                    ));
                }
            }
            Some(kind @ (b"vt" | b"vn")) => {
                let needed = if kind == b"vt" { 2 } else { 3 };
                let name = if kind == b"vt" {
                    seen_vt += 1;
                    "texture coordinate"
                } else {
                    seen_vn += 1;
                    "normal"
                };
                let values: Vec<&[u8]> = words.collect();
                if values.len() < needed {
                    return at(format!("{name} has fewer than {needed} values"));
                }
                if let Some(bad) = values
                    .iter()
                    .take(needed)
                    .find(|t| super::text::parse_f32(t).is_none())
                {
                    return at(format!("{name}: cannot read {}", quote(bad)));
                }
            }
            Some(b"f") => {
                face_number += 1;
                for corner in words {
                    for (slot, part) in corner.split(|&b| b == b'/').enumerate() {
                        if part.is_empty() {
                            continue;
                        }
                        let (kind, kinds, total, seen) = match slot {
                            0 => ("vertex", "vertices", total_v, seen_v),
                            1 => (
                                "texture coordinate",
                                "texture coordinates",
                                total_vt,
                                seen_vt,
                            ),
                            2 => ("normal", "normals", total_vn, seen_vn),
                            _ => {
                                return at(format!(
                                    "face {face_number}: corner {} has more than 3 indices",
                                    quote(corner)
                                ))
                            }
                        };
                        let Some(index) = super::text::parse_i64(part) else {
                            return at(format!(
                                "face {face_number}: cannot read {kind} index {}",
                                quote(part)
                            ));
                        };
                        let resolved = if index < 0 {
                            seen.saturating_add(index).saturating_add(1)
                        } else {
                            index
                        };
                        if index == 0 || resolved < 1 || resolved > total {
                            return at(format!(
                                "face {face_number}: {kind} index {index} is out of range (the file has {total} {kinds}{})",
                                if index == 0 { "; OBJ indices start at 1" } else { "" }
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

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
    for [u, v] in uvs.into_iter().flatten() {
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

/// The parts of a line: its text without the line ending, and the ending (`\n`, `\r\n` or none).
fn split_ending(line: &[u8]) -> (&[u8], &[u8]) {
    let body = line.strip_suffix(b"\n").unwrap_or(line);
    let body = body.strip_suffix(b"\r").unwrap_or(body);
    line.split_at(body.len())
}

/// The position a `v` line gives (w divided out), as the reader reads it; `None` if unreadable.
fn vertex_of<'a>(words: impl Iterator<Item = &'a [u8]>) -> Option<[f32; 3]> {
    let mut values = [0f32; 6];
    let mut count = 0;
    for token in words {
        *values.get_mut(count)? = super::text::parse_f32(token)?;
        count += 1;
    }
    let p = [values[0], values[1], values[2]];
    match count {
        3 | 6 => Some(p),
        4 if values[3] != 0.0 => Some(p.map(|c| c / values[3])),
        _ => None,
    }
}

/// The 0-based index an OBJ index token refers to, given how many items came before its line.
fn resolve(token: &[u8], before: usize) -> Option<usize> {
    let index = super::text::parse_i64(token)?;
    match index {
        i if i > 0 => usize::try_from(i - 1).ok(),
        i if i < 0 => usize::try_from(before as i64 + i).ok(),
        _ => None,
    }
}

/// A face corner's vertex and texture coordinate (`v/vt`, `v/vt/vn`; relative indices resolved
/// against the `vertices` and `texture_coordinates` read so far), the coordinate only when it
/// is one of those.
fn vertex_and_uv(
    corner: &[u8],
    vertices: usize,
    texture_coordinates: usize,
) -> (Option<usize>, Option<usize>) {
    let mut parts = corner.split(|&b| b == b'/');
    let vertex = parts.next().and_then(|t| resolve(t, vertices));
    let uv = parts
        .next()
        .filter(|t| !t.is_empty())
        .and_then(|t| resolve(t, texture_coordinates))
        .filter(|&t| t < texture_coordinates);
    (vertex, uv)
}

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
/// `v/vt` corners) of an OBJ file, per welded vertex, for saving it in another format.
pub(crate) fn vertex_attributes(bytes: &[u8], source: &Source) -> VertexAttributes {
    let mut colours = Gather::<4>::new(source.welded_vertices, [1.0; 4]);
    let mut uvs = Gather::<2>::new(source.welded_vertices, [0.0; 2]);
    let (mut any_colour, mut any_uv) = (false, false);
    let mut vertices = 0usize;
    let mut texture_coordinates: Vec<[f32; 2]> = Vec::new();
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => {
                let values: Vec<f32> = words.filter_map(super::text::parse_f32).collect();
                if values.len() == 6 {
                    any_colour = true;
                    let rgb = [values[3], values[4], values[5]].map(|c| c.clamp(0.0, 1.0));
                    colours.put(source.welded(vertices), [rgb[0], rgb[1], rgb[2], 1.0]);
                }
                vertices += 1;
            }
            Some(b"vt") => {
                let u = words.next().and_then(super::text::parse_f32).unwrap_or(0.0);
                let v = words.next().and_then(super::text::parse_f32).unwrap_or(0.0);
                texture_coordinates.push([u, v]);
            }
            Some(b"f") => {
                for corner in words {
                    if let (Some(vertex), Some(t)) =
                        vertex_and_uv(corner, vertices, texture_coordinates.len())
                    {
                        any_uv = true;
                        uvs.put(source.welded(vertex), texture_coordinates[t]);
                    }
                }
            }
            _ => {}
        }
    }
    let mut out = VertexAttributes::default();
    if any_colour {
        let (values, merged) = colours.finish();
        out.colours = Some(values);
        out.colour_splits_merged = merged;
    }
    if any_uv {
        let (values, merged) = uvs.finish();
        out.uvs = Some(values);
        out.uv_splits_merged = merged;
    }
    out
}

/// The rest of a line after its keyword (`o`, `g`, `usemtl`, `mtllib`, `map_Kd`), words joined by
/// one space; `None` when empty.
fn rest_of<'a>(words: impl Iterator<Item = &'a [u8]>) -> Option<String> {
    let words: Vec<String> = words
        .map(|w| String::from_utf8_lossy(w).into_owned())
        .collect();
    (!words.is_empty()).then(|| words.join(" "))
}

/// The OBJ's parts (one per `o`/`g` pair), materials (from its `mtllib` files, read beside it),
/// and file vertices (one per distinct `v/vt/vn` corner), for saving in another format (see
/// [`super::scene`]). Normals turn with their faces to `mesh`'s positions, slot by `vn` line as
/// in [`write_back`].
pub(crate) fn scene(bytes: &[u8], source: &Source, mesh: &TriMesh) -> Scene {
    let mut scene = Scene {
        groups_under_objects: true,
        ..Scene::default()
    };
    let mut positions: Vec<[f32; 3]> = Vec::with_capacity(source.raw_vertices);
    let mut colours: Vec<Option<[f32; 3]>> = Vec::with_capacity(source.raw_vertices);
    let mut uvs: Vec<[f32; 2]> = Vec::new();
    let mut normals: Vec<[f32; 3]> = Vec::new();
    let mut libraries: Vec<String> = Vec::new();
    let mut material_names: Vec<String> = Vec::new();
    let mut corner_vertex: HashMap<(usize, usize, usize), u32> = HashMap::new();
    let mut parts: HashMap<(Option<String>, Option<String>), usize> = HashMap::new();
    let (mut object, mut group, mut material): (Option<String>, Option<String>, Option<usize>) =
        (None, None, None);
    // The part and primitive faces go to, until an `o`, `g` or `usemtl` changes it.
    let mut current: Option<(usize, usize)> = None;
    let mut corners: Vec<u32> = Vec::with_capacity(8);
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => {
                let values: Vec<&[u8]> = words.collect();
                positions.push(vertex_of(values.iter().copied()).unwrap_or([f32::NAN; 3]));
                colours.push((values.len() == 6).then(|| {
                    [3, 4, 5].map(|i| {
                        super::text::parse_f32(values[i])
                            .filter(|c| c.is_finite())
                            .map_or(1.0, |c| c.clamp(0.0, 1.0))
                    })
                }));
            }
            Some(b"vt") => {
                // Never a NaN in the output: what is not a finite number becomes 0.
                let mut number = || {
                    words
                        .next()
                        .and_then(super::text::parse_f32)
                        .filter(|c| c.is_finite())
                        .unwrap_or(0.0)
                };
                uvs.push([number(), number()]);
            }
            Some(b"vn") => normals.push(
                vertex_of(words.take(3))
                    .filter(|n| n.iter().all(|c| c.is_finite()))
                    .unwrap_or([0.0; 3]),
            ),
            Some(b"o") => {
                object = rest_of(words);
                current = None;
            }
            Some(b"g") => {
                group = rest_of(words);
                current = None;
            }
            Some(b"usemtl") => {
                material = rest_of(words).map(|name| {
                    material_names
                        .iter()
                        .position(|m| *m == name)
                        .unwrap_or_else(|| {
                            material_names.push(name);
                            material_names.len() - 1
                        })
                });
                current = None;
            }
            Some(b"mtllib") => libraries.extend(rest_of(words)),
            Some(b"f") => {
                corners.clear();
                for corner in words {
                    let mut parts = corner.split(|&b| b == b'/');
                    let v = parts.next().and_then(|t| resolve(t, positions.len()));
                    let vt = parts
                        .next()
                        .filter(|t| !t.is_empty())
                        .and_then(|t| resolve(t, uvs.len()))
                        .filter(|&t| t < uvs.len());
                    let vn = parts
                        .next()
                        .filter(|t| !t.is_empty())
                        .and_then(|t| resolve(t, normals.len()))
                        .filter(|&n| n < normals.len());
                    let Some(v) = v.filter(|&v| v < positions.len()) else {
                        corners.clear();
                        break;
                    };
                    let key = (v, vt.unwrap_or(usize::MAX), vn.unwrap_or(usize::MAX));
                    let index = *corner_vertex.entry(key).or_insert_with(|| {
                        let mut vertex = SceneVertex::new(source.welded(v), positions[v]);
                        if let Some(t) = vt {
                            vertex.uv = uvs[t];
                        }
                        if let Some([r, g, b]) = colours[v] {
                            vertex.colour = [r, g, b, 1.0];
                        }
                        if let Some(n) = vn {
                            vertex.normal = normals[n];
                            vertex.slot = n;
                        }
                        scene.vertices.push(vertex);
                        (scene.vertices.len() - 1) as u32
                    });
                    scene.uvs |= vt.is_some();
                    scene.normals |= vn.is_some();
                    scene.colours |= colours[v].is_some();
                    corners.push(index);
                }
                if corners.len() < 3 {
                    continue;
                }
                let (part, primitive) = *current.get_or_insert_with(|| {
                    let key = (object.clone(), group.clone());
                    let part = *parts.entry(key).or_insert_with(|| {
                        scene.parts.push(Part {
                            object: object.clone(),
                            group: group.clone(),
                            primitives: Vec::new(),
                        });
                        scene.parts.len() - 1
                    });
                    let primitives = &mut scene.parts[part].primitives;
                    let primitive = primitives
                        .iter()
                        .position(|p| p.material == material)
                        .unwrap_or_else(|| {
                            primitives.push(Primitive {
                                material,
                                triangles: Vec::new(),
                            });
                            primitives.len() - 1
                        });
                    (part, primitive)
                });
                let triangles = &mut scene.parts[part].primitives[primitive].triangles;
                for i in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[i], corners[i + 1]]);
                }
            }
            _ => {}
        }
    }
    scene.materials = read_materials(&material_names, &libraries, source, &mut scene.warnings);
    scene.drop_degenerate();
    scene.turn_normals(mesh);
    scene
}

/// The materials `names` as the `.mtl` files `libraries` (beside the OBJ) define them: Kd and d
/// (or Tr) as the base colour, Pm and Pr, and map_Kd (resolved beside the `.mtl`). A material
/// or file that cannot be found is named in `warnings` and gets a white base colour.
fn read_materials(
    names: &[String],
    libraries: &[String],
    source: &Source,
    warnings: &mut Vec<String>,
) -> Vec<Material> {
    let mut materials: Vec<Material> = names
        .iter()
        .map(|name| Material {
            name: name.clone(),
            base_colour: [1.0; 4],
            metallic: 0.0,
            roughness: 1.0,
            texture: None,
        })
        .collect();
    if names.is_empty() {
        return materials;
    }
    let mut found = vec![false; names.len()];
    let mut unkept: Vec<String> = Vec::new();
    // The libraries that could not be read, each with why.
    let mut unread: Vec<String> = Vec::new();
    for library in libraries {
        let Some(base) = &source.base_dir else {
            unread.push(format!(
                "{library} (the input was read from memory, so it cannot be found)"
            ));
            continue;
        };
        let file = base.join(library);
        let text = match std::fs::read(&file) {
            Ok(text) => text,
            Err(e) => {
                let why = if e.kind() == std::io::ErrorKind::NotFound {
                    let obj = source.path.file_name().unwrap_or_default();
                    format!("not found beside {}", Path::new(obj).display())
                } else {
                    format!("{} cannot be read: {e}", file.display())
                };
                unread.push(format!("{library} ({why})"));
                continue;
            }
        };
        let folder = file.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut current: Option<usize> = None;
        for line in text.split(|&b| b == b'\n') {
            let mut words = tokens(line);
            let Some(keyword) = words.next() else {
                continue;
            };
            if keyword == b"newmtl" {
                current = rest_of(words).and_then(|name| names.iter().position(|n| *n == name));
                if let Some(m) = current {
                    found[m] = true;
                }
                continue;
            }
            let Some(m) = current else { continue };
            let material = &mut materials[m];
            let words: Vec<&[u8]> = words.collect();
            let numbers: Vec<f32> = words
                .iter()
                .map_while(|w| super::text::parse_f32(w))
                .filter(|v| v.is_finite())
                .collect();
            match keyword {
                b"Kd" if numbers.len() >= 3 => {
                    material.base_colour[..3].copy_from_slice(&numbers[..3]);
                }
                b"d" if !numbers.is_empty() => material.base_colour[3] = numbers[0],
                b"Tr" if !numbers.is_empty() => material.base_colour[3] = 1.0 - numbers[0],
                b"Pm" if !numbers.is_empty() => material.metallic = numbers[0],
                b"Pr" if !numbers.is_empty() => material.roughness = numbers[0],
                b"map_Kd" => {
                    // Options (-s 1 1 1, -clamp on, ...) come first; the file name is last.
                    let Some(name) = words
                        .last()
                        .map(|w| String::from_utf8_lossy(w).into_owned())
                    else {
                        continue;
                    };
                    let image = folder.join(name.replace('\\', "/"));
                    if image.is_file() {
                        material.texture = Some(Image {
                            name: image_file_name(
                                &image.file_name().map_or_else(
                                    || name.clone(),
                                    |n| n.to_string_lossy().into_owned(),
                                ),
                                image_mime_type(&[], &image),
                            ),
                            data: ImageData::File(image),
                        });
                    } else {
                        warnings.push(format!(
                            "the texture {name} of material '{}' (not found beside {})",
                            material.name,
                            file.display()
                        ));
                    }
                }
                b"Ka" | b"Ks" | b"Ke" | b"Ns" | b"Ni" | b"illum" | b"Tf" => {}
                other if other.starts_with(b"map_") || other == b"bump" || other == b"norm" => {
                    let what = format!("'{}' {}", material.name, String::from_utf8_lossy(other));
                    if !unkept.contains(&what) {
                        unkept.push(what);
                    }
                }
                _ => {}
            }
        }
    }
    let missing: Vec<&str> = names
        .iter()
        .zip(&found)
        .filter(|(_, found)| !**found)
        .map(|(name, _)| name.as_str())
        .collect();
    let quoted: Vec<String> = missing.iter().map(|name| format!("'{name}'")).collect();
    let quoted: Vec<&str> = quoted.iter().map(String::as_str).collect();
    if unread.len() == libraries.len() && !unread.is_empty() {
        // Nothing defines the materials: said once, with why.
        warnings.push(format!(
            "the material {} {}, so the materials {} are written white, without their colours and textures",
            if unread.len() == 1 { "library" } else { "libraries" },
            unread.join(" and "),
            super::and_list(&quoted)
        ));
    } else {
        for library in &unread {
            warnings.push(format!("the material library {library}"));
        }
        if !missing.is_empty() && !libraries.is_empty() {
            warnings.push(format!(
                "the definition of material(s) {} (not in {}): written white",
                missing.join(", "),
                libraries.join(", ")
            ));
        }
    }
    if !unkept.is_empty() {
        warnings.push(format!(
            "material maps other than the diffuse map ({})",
            unkept.join(", ")
        ));
    }
    materials
}

/// An OBJ of `scene` at `path`, with a `.mtl` beside it (`<stem>.mtl`) when it has materials and
/// their textures copied or written beside it (see [`Scene::place_images`]): `v` per welded
/// vertex of `mesh` (with the vertex colour when the source had them), `vt` and `vn` per distinct
/// value, `o`, `g` and `usemtl` per part and material. Every file is staged and renamed into
/// place only when all are complete.
pub(crate) fn write_scene(
    path: &Path,
    scene: &Scene,
    mesh: &TriMesh,
    merged_colours: &mut usize,
) -> Result<(), IoError> {
    let mtl_path = path.with_extension("mtl");
    let mtl_name = mtl_path.file_name().map_or_else(
        || "materials.mtl".into(),
        |n| n.to_string_lossy().into_owned(),
    );
    let placed = scene.place_images(path);
    let used = |v: &&SceneVertex| v.welded != u32::MAX;
    // One colour per `v` line: the first file vertex's.
    let colours = scene.colours.then(|| {
        let mut gather = Gather::<4>::new(mesh.positions.len(), [1.0; 4]);
        for vertex in scene.vertices.iter().filter(used) {
            gather.put(Some(vertex.welded as usize), vertex.colour);
        }
        let (values, merged) = gather.finish();
        *merged_colours = merged;
        values
    });
    // Distinct values, numbered in first use.
    fn numbered<const N: usize>(
        values: impl Iterator<Item = [f32; N]>,
    ) -> (Vec<[f32; N]>, HashMap<[u32; N], usize>) {
        let mut list = Vec::new();
        let mut index = HashMap::new();
        for value in values {
            index.entry(value.map(f32::to_bits)).or_insert_with(|| {
                list.push(value);
                list.len() - 1
            });
        }
        (list, index)
    }
    let (uv_list, uv_index) = numbered(scene.vertices.iter().filter(used).map(|v| v.uv));
    let (normal_list, normal_index) =
        numbered(scene.vertices.iter().filter(used).map(|v| v.normal));
    let name_token = |name: &str| name.split_whitespace().collect::<Vec<_>>().join("_");

    let write_obj = |out: &mut dyn Write| -> std::io::Result<()> {
        writeln!(out, "# written by fairmesh")?;
        writeln!(
            out,
            "# {} vertices, {} triangles",
            mesh.positions.len(),
            scene.triangle_count()
        )?;
        if !scene.materials.is_empty() {
            writeln!(out, "mtllib {mtl_name}")?;
        }
        for (v, [x, y, z]) in mesh.positions.iter().enumerate() {
            match &colours {
                Some(colours) => {
                    let [r, g, b, _] = colours[v];
                    writeln!(out, "v {x} {y} {z} {r} {g} {b}")?
                }
                None => writeln!(out, "v {x} {y} {z}")?,
            }
        }
        if scene.uvs {
            for [u, v] in &uv_list {
                writeln!(out, "vt {u} {v}")?;
            }
        }
        if scene.normals {
            for [x, y, z] in &normal_list {
                writeln!(out, "vn {x} {y} {z}")?;
            }
        }
        let mut last_object: Option<&str> = None;
        for part in &scene.parts {
            if let Some(object) = part.object.as_deref() {
                if last_object != Some(object) {
                    writeln!(out, "o {object}")?;
                    last_object = Some(object);
                }
            }
            if let Some(group) = &part.group {
                writeln!(out, "g {}", name_token(group))?;
            }
            for primitive in &part.primitives {
                if let Some(m) = primitive.material {
                    writeln!(out, "usemtl {}", name_token(&scene.materials[m].name))?;
                }
                for t in &primitive.triangles {
                    out.write_all(b"f")?;
                    for &corner in t {
                        let vertex = &scene.vertices[corner as usize];
                        let v = vertex.welded as u64 + 1;
                        let vt = uv_index
                            .get(&vertex.uv.map(f32::to_bits))
                            .map_or(1, |i| i + 1);
                        let vn = normal_index
                            .get(&vertex.normal.map(f32::to_bits))
                            .map_or(1, |i| i + 1);
                        match (scene.uvs, scene.normals) {
                            (true, true) => write!(out, " {v}/{vt}/{vn}")?,
                            (true, false) => write!(out, " {v}/{vt}")?,
                            (false, true) => write!(out, " {v}//{vn}")?,
                            (false, false) => write!(out, " {v}")?,
                        }
                    }
                    out.write_all(b"\n")?;
                }
            }
        }
        Ok(())
    };
    let write_mtl = |out: &mut dyn Write| -> std::io::Result<()> {
        writeln!(out, "# written by fairmesh")?;
        for (m, material) in scene.materials.iter().enumerate() {
            let [r, g, b, a] = material.base_colour;
            writeln!(out, "\nnewmtl {}", name_token(&material.name))?;
            writeln!(out, "Kd {r} {g} {b}")?;
            writeln!(out, "d {a}")?;
            writeln!(out, "Pm {}", material.metallic)?;
            writeln!(out, "Pr {}", material.roughness)?;
            if let Some(Some(image)) = placed.get(m) {
                writeln!(out, "map_Kd {}", image.uri_name)?;
            }
        }
        Ok(())
    };
    let mut staged = Vec::new();
    for (target, data) in placed.iter().flatten().filter_map(|p| p.write.as_ref()) {
        let bytes = data.bytes().map_err(|source| IoError::Read {
            path: match data {
                ImageData::File(file) => file.clone(),
                ImageData::Bytes(_) => target.clone(),
            },
            source,
        })?;
        staged.push(atomic::stage(target, |w| w.write_all(&bytes))?);
    }
    if !scene.materials.is_empty() {
        staged.push(atomic::stage(&mtl_path, write_mtl)?);
    }
    staged.push(atomic::stage(path, write_obj)?);
    for file in staged {
        file.commit()?;
    }
    Ok(())
}

/// Write the OBJ `source` back with `mesh`'s positions: every line but the `v` lines of moved
/// vertices, the `vn` lines of normals whose faces moved and the `vt` lines of texture
/// coordinates whose vertex slid comes back byte for byte. A moved vertex is written `v x y z`
/// (shortest round-trip floats; a w is folded in), followed by the line's vertex colour if it had
/// one. Normals turn with their faces (see [`super::source`]); texture coordinates follow their
/// vertex's slide along the surface, so that the texture stays where it was
/// ([`super::uv_follow`]), written `vt u v` (f32 shortest round-trip, a w kept as written).
/// Returns how many texture coordinates several moved vertices share (those stay).
pub(crate) fn write_back(
    out: &mut dyn Write,
    bytes: &[u8],
    source: &Source,
    mesh: &TriMesh,
) -> std::io::Result<usize> {
    // The file's own positions (as the reader read them), and each vertex's new position.
    let mut before: Vec<[f32; 3]> = Vec::with_capacity(source.raw_vertices);
    let mut normal_count = 0usize;
    let mut uvs: Vec<[f64; 2]> = Vec::new();
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => before.push(vertex_of(words).unwrap_or([f32::NAN; 3])),
            Some(b"vn") => normal_count += 1,
            Some(b"vt") => uvs.push(texture_coordinate_of(words).unwrap_or([f64::NAN; 2])),
            _ => {}
        }
    }
    let after: Vec<[f32; 3]> = (0..before.len())
        .map(|k| source.welded(k).map_or(before[k], |w| mesh.positions[w]))
        .collect();
    let moved = |k: usize| before[k] != after[k] && !before[k][0].is_nan();
    let any_moved = (0..before.len()).any(moved);
    // One pass over the faces: the normals' turns and the triangles the texture coordinates
    // follow on, each where the file has them.
    let mut turns = (normal_count > 0 && any_moved).then(|| NormalTurns::new(normal_count));
    let mut triangles = (!uvs.is_empty() && any_moved).then(Vec::new);
    if turns.is_some() || triangles.is_some() {
        let (mut normal_corners, mut uv_corners) = (Vec::new(), Vec::new());
        for_each_face(bytes, |face| {
            if let Some(turns) = &mut turns {
                add_turns(turns, face, &before, &after, &mut normal_corners);
            }
            if let Some(triangles) = &mut triangles {
                let counts = (before.len(), uvs.len());
                add_uv_triangles(triangles, face, counts, &mut uv_corners);
            }
        });
    }
    let followed =
        triangles.map(|triangles| super::uv_follow::follow(&before, &after, &triangles, &uvs));

    let mut vertex = 0usize;
    let mut normal = 0usize;
    let mut texture_coordinate = 0usize;
    for line in bytes.split_inclusive(|&b| b == b'\n') {
        let (text, ending) = split_ending(line);
        let mut words = tokens(text);
        match words.next() {
            Some(b"v") => {
                let k = vertex;
                vertex += 1;
                if moved(k) {
                    let [x, y, z] = after[k];
                    write!(out, "v {x} {y} {z}")?;
                    let rest: Vec<&[u8]> = words.collect();
                    if rest.len() == 6 {
                        // x y z r g b: keep the colour as written.
                        for colour in &rest[3..] {
                            out.write_all(b" ")?;
                            out.write_all(colour)?;
                        }
                    }
                    out.write_all(ending)?;
                    continue;
                }
            }
            Some(b"vn") => {
                let k = normal;
                normal += 1;
                let turn = turns.as_ref().and_then(|t| t.turn(k));
                if let (Some(turn), Some(n)) = (turn, vertex_of(words.take(3))) {
                    let [x, y, z] = turn.normal(n);
                    write!(out, "vn {x} {y} {z}")?;
                    out.write_all(ending)?;
                    continue;
                }
            }
            Some(b"vt") => {
                let k = texture_coordinate;
                texture_coordinate += 1;
                let uv = followed
                    .as_ref()
                    .and_then(|f| f.moved.get(k).copied().flatten());
                // Written as f32 (what the reader reads); unchanged values keep their text.
                let as_read = uvs[k].map(|c| c as f32);
                let written = uv.map(|uv| uv.map(|c| c as f32));
                if let Some([u, v]) = written.filter(|&w| w != as_read) {
                    write!(out, "vt {u} {v}")?;
                    for w in words.skip(2) {
                        out.write_all(b" ")?;
                        out.write_all(w)?;
                    }
                    out.write_all(ending)?;
                    continue;
                }
            }
            _ => {}
        }
        out.write_all(line)?;
    }
    Ok(followed.map_or(0, |f| f.shared))
}

/// The (u, v) a `vt` line gives (a missing v reads 0, as the reader reads it); `None` if
/// unreadable.
fn texture_coordinate_of<'a>(mut words: impl Iterator<Item = &'a [u8]>) -> Option<[f64; 2]> {
    let u = super::text::parse_f32(words.next()?)?;
    let v = words.next().map_or(Some(0.0), super::text::parse_f32)?;
    Some([u as f64, v as f64])
}

/// Adds a face's triangles (a polygon as a fan from its first corner) of (vertex, texture
/// coordinate) corners, for [`super::uv_follow::follow`]; a face with a corner that names no
/// vertex (of `counts.0`) is left out, a coordinate past `counts.1` is none.
fn add_uv_triangles(
    triangles: &mut Vec<super::uv_follow::UvTriangle>,
    face: &[[Option<usize>; 3]],
    (vertex_count, uv_count): (usize, usize),
    corners: &mut Vec<[u32; 2]>,
) {
    corners.clear();
    for &[v, t, _] in face {
        match v {
            Some(v) if v < vertex_count => corners.push([
                v as u32,
                t.filter(|&t| t < uv_count)
                    .map_or(super::uv_follow::NO_UV, |t| t as u32),
            ]),
            _ => return,
        }
    }
    for i in 1..corners.len().saturating_sub(1) {
        triangles.push([corners[0], corners[i], corners[i + 1]]);
    }
}

/// Adds a face to the turns of the `vn` normals: every corner `v//vn` or `v/vt/vn` adds the area
/// of its fan triangles to its normal (a face with a corner without both is left out).
fn add_turns(
    turns: &mut NormalTurns,
    face: &[[Option<usize>; 3]],
    before: &[[f32; 3]],
    after: &[[f32; 3]],
    corners: &mut Vec<(usize, usize)>,
) {
    corners.clear();
    for &[v, _, n] in face {
        match (v, n) {
            (Some(v), Some(n)) if v < before.len() => corners.push((v, n)),
            _ => return,
        }
    }
    for i in 1..corners.len().saturating_sub(1) {
        let fan = [corners[0], corners[i], corners[i + 1]];
        turns.add(
            fan.map(|(_, n)| n),
            fan.map(|(v, _)| dvec(before[v])),
            fan.map(|(v, _)| dvec(after[v])),
        );
    }
}

/// Calls `visit` with the corners of every `f` line: per corner its vertex, texture coordinate
/// and normal, as 0-based indices resolved against the items before the line (`None` where the
/// corner has none or names none).
fn for_each_face(bytes: &[u8], mut visit: impl FnMut(&[[Option<usize>; 3]])) {
    let (mut vertices, mut uvs, mut normals) = (0usize, 0usize, 0usize);
    let mut corners: Vec<[Option<usize>; 3]> = Vec::with_capacity(8);
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => vertices += 1,
            Some(b"vt") => uvs += 1,
            Some(b"vn") => normals += 1,
            Some(b"f") => {
                corners.clear();
                for corner in words {
                    let mut parts = corner.split(|&b| b == b'/');
                    let mut index = |count: usize| {
                        parts
                            .next()
                            .filter(|t| !t.is_empty())
                            .and_then(|t| resolve(t, count))
                    };
                    corners.push([index(vertices), index(uvs), index(normals)]);
                }
                visit(&corners);
            }
            _ => {}
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(text: &str) -> Result<Parsed, IoError> {
        parse(text.as_bytes(), Path::new("t.obj"))
    }

    #[test]
    fn reads_polygons_as_fans_and_ignores_seams() {
        let parsed = parse_str(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1 4/1/1\n",
        )
        .unwrap();
        assert_eq!(parsed.mesh.positions.len(), 4);
        assert_eq!(parsed.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn locates_nan_and_bad_indices() {
        let err = parse_str("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n").unwrap_err();
        assert_eq!(
            err.to_string(),
            "t.obj: line 2: vertex 2 has a NaN coordinate"
        );
        let err = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n").unwrap_err();
        assert!(
            err.to_string()
                .starts_with("t.obj: line 5: face 1: vertex index 4 is out of range"),
            "{err}"
        );
        let err = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n").unwrap_err();
        assert!(err.to_string().contains("line 4"), "{err}");
        let err = parse_str("v 0 0 0\nv 1 x 0\n").unwrap_err();
        assert!(err.to_string().contains("line 2"), "{err}");
        let err = parse_str("v 0 0 0\nv 1 0 0\nl 1 2\n").unwrap_err();
        assert!(err.to_string().contains("no triangles"), "{err}");
    }

    #[test]
    fn keeps_the_files_vertex_order() {
        // Faces use the vertices in another order than the file lists them; tobj would renumber.
        let parsed = parse_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 4 3 2\nf 4 2 1\n").unwrap();
        assert_eq!(
            parsed.mesh.positions,
            vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]]
        );
        assert_eq!(parsed.mesh.triangles, vec![[3, 2, 1], [3, 1, 0]]);
    }

    #[test]
    fn negative_indices_count_back_from_the_line_also_across_chunks() {
        let mut text = String::new();
        for i in 0..200 {
            text.push_str(&format!("v {i} 0 0\nv {i} 1 0\nv {i} 0 1\nf -3 -2 -1\n"));
        }
        text.push_str("l 1 2\nf 1 2\n");
        let bytes = text.as_bytes();
        let whole = parse_chunk(bytes).ok().unwrap();
        assert!(whole.relative.len() == 600 && whole.polylines == 1 && whole.short_faces == 1);
        // Small pieces: every chunk boundary falls between a face and the vertices it refers to
        // somewhere; the result must not change.
        let pieces = split_at_lines(bytes, 64, 10);
        assert!(pieces.len() > 20);
        assert_eq!(pieces.concat(), bytes);
        let parsed = parse(bytes, Path::new("t.obj")).unwrap();
        let expected: Vec<[u32; 3]> = (0..200u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        assert_eq!(parsed.mesh.triangles, expected);
        assert_eq!(parsed.warnings.len(), 2, "{:?}", parsed.warnings);
    }

    #[test]
    fn reads_w_and_vertex_colours_and_rejects_other_counts() {
        let parsed = parse_str("v 2 4 6 2\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert_eq!(parsed.mesh.positions[0], [1., 2., 3.]);
        assert_eq!(parsed.mesh.positions[1], [1., 0., 0.]);
        let err = parse_str("v 1 2\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap_err();
        assert!(err.to_string().contains("line 1"), "{err}");
        let err = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n").unwrap_err();
        assert!(err.to_string().contains("line 4"), "{err}");
    }

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
}
