//! Reading an OBJ: the lines parsed in parallel chunks, indices resolved after all chunks are
//! read, and, when the fast pass finds the file bad, [`locate`] to name the line at fault.

use crate::io::text::{lines, non_finite_kind, quote, tokens};
use crate::io::{IoError, Parsed};
use crate::mesh::TriMesh;
use rayon::prelude::*;
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
        parsed.warnings.push(crate::io::text::skipped(
            polylines,
            "polyline (l)",
            "polylines (l)",
        ));
    }
    if points > 0 {
        parsed.warnings.push(crate::io::text::skipped(
            points,
            "point element (p)",
            "point elements (p)",
        ));
    }
    if short_faces > 0 {
        parsed
            .warnings
            .push(crate::io::text::short_faces_skipped(short_faces));
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
/// each within the file's counts). A parser's loop over the lines, which reads best in one
/// piece.
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
                    match crate::io::text::parse_f32(token) {
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
                    4 => match values.get(3).and_then(|t| crate::io::text::parse_f32(t)) {
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
                    .find(|t| crate::io::text::parse_f32(t).is_none())
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
                        let Some(index) = crate::io::text::parse_i64(part) else {
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
}
