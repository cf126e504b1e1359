//! Wavefront OBJ: read through tobj, written with `v` and `f` lines.
//!
//! Reading: tobj with `single_index: false` (positions are indexed on their own, so normal and UV
//! seams do not split vertices), `triangulate: true` (polygons become fans), points and lines
//! ignored, materials not loaded. tobj renumbers each object's vertices in order of first use by
//! its faces and drops unused ones; objects are concatenated. tobj's errors carry no line number,
//! so when it fails, or when what it returns is bad (a NaN or infinite coordinate), [`locate`]
//! scans the file once more to find the line at fault and say what is wrong there.
//!
//! Writing: `v x y z` with Rust's shortest round-trip float formatting (`{}`), so every f32 reads
//! back bit for bit, and `f a b c` with 1-based indices.

use super::text::{lines, non_finite_kind, quote, tokens};
use super::{IoError, Parsed};
use crate::mesh::TriMesh;
use std::borrow::Cow;
use std::io::Write;
use std::path::Path;

pub(crate) fn parse(bytes: &[u8], path: &Path) -> Result<Parsed, IoError> {
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // tobj reads `l` lines with 3 or more vertices as polygons; they are polylines, not faces.
    let (filtered, polylines) = comment_out_polylines(bytes);
    let mut reader: &[u8] = &filtered;
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|error| match locate(bytes, path) {
        Some(located) => located,
        None => IoError::invalid(path, format!("tobj could not read the file: {error}")),
    })?;

    let vertex_total: usize = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    if u32::try_from(vertex_total).is_err() {
        return Err(IoError::invalid(
            path,
            format!("{vertex_total} vertices is more than 32-bit indices can address"),
        ));
    }
    let triangle_total: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    let mut mesh = TriMesh {
        positions: Vec::with_capacity(vertex_total),
        triangles: Vec::with_capacity(triangle_total),
    };
    for model in &models {
        let base = mesh.positions.len() as u32; // < vertex_total, checked above
        let count = model.mesh.positions.len() / 3;
        mesh.positions.extend(
            model
                .mesh
                .positions
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]]),
        );
        for corners in model.mesh.indices.chunks_exact(3) {
            let triangle = [corners[0], corners[1], corners[2]];
            if triangle.iter().any(|&v| v as usize >= count) {
                // tobj checks this itself; kept so a tobj bug cannot make `finish` index out of
                // range.
                return Err(locate(bytes, path).unwrap_or_else(|| {
                    IoError::invalid(path, "a face refers to a vertex out of range")
                }));
            }
            mesh.triangles.push(triangle.map(|v| v + base));
        }
    }
    if mesh.first_non_finite_vertex().is_some() {
        return Err(locate(bytes, path).unwrap_or_else(|| {
            IoError::invalid(path, "a vertex has a NaN or infinite coordinate")
        }));
    }
    if mesh.triangles.is_empty() {
        let vertex_lines = lines(bytes)
            .filter(|(_, l)| tokens(l).next() == Some(b"v"))
            .count();
        return Err(IoError::invalid(
            path,
            format!(
                "no triangles: the file has {vertex_lines} vertices and no face (f) with 3 or more vertices"
            ),
        ));
    }
    let mut parsed = Parsed::new(mesh);
    if polylines > 0 {
        parsed
            .warnings
            .push(format!("{polylines} polylines (l) were skipped"));
    }
    Ok(parsed)
}

/// The file with every `l` line turned into a comment (same length, so line numbers and offsets
/// stay), and how many there were. Borrowed when there are none, which is the common case.
fn comment_out_polylines(bytes: &[u8]) -> (Cow<'_, [u8]>, usize) {
    let mut copy: Option<Vec<u8>> = None;
    let mut count = 0;
    let mut line_start = true;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'\n' {
            line_start = true;
        } else if line_start && b != b' ' && b != b'\t' {
            line_start = false;
            let next = bytes.get(i + 1).copied();
            if b == b'l' && next.is_none_or(|n| n.is_ascii_whitespace()) {
                count += 1;
                if let Some(slot) = copy.get_or_insert_with(|| bytes.to_vec()).get_mut(i) {
                    *slot = b'#';
                }
            }
        }
    }
    match copy {
        Some(copy) => (Cow::Owned(copy), count),
        None => (Cow::Borrowed(bytes), 0),
    }
}

/// Find the first line that tobj would reject or that gives a bad vertex, and say why. Checks
/// what tobj reads: `v` (3 coordinates, optional w or colour), `vt`, `vn`, and `f` indices
/// (1-based, negative = relative, each within the file's counts).
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
    writeln!(out, "# written by fairmesh")?;
    writeln!(
        out,
        "# {} vertices, {} triangles",
        mesh.positions.len(),
        mesh.triangles.len()
    )?;
    for [x, y, z] in &mesh.positions {
        writeln!(out, "v {x} {y} {z}")?;
    }
    for [a, b, c] in &mesh.triangles {
        // u32 + 1 in u64: no overflow.
        writeln!(
            out,
            "f {} {} {}",
            *a as u64 + 1,
            *b as u64 + 1,
            *c as u64 + 1
        )?;
    }
    Ok(())
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
