//! Object File Format (OFF), text: our own parser and writer.
//!
//! Reading: `#` comments and blank lines are skipped anywhere. The header keyword is `OFF` or a
//! variant with per-vertex extras (`COFF`, `NOFF`, `STOFF`, `CNOFF`, ...: only the first three
//! numbers of a vertex line are used); `4OFF`, `nOFF` and binary OFF are refused with a clear
//! message. The counts (vertices, faces, edges) may follow the keyword on the same line. Each
//! vertex and each face is on its own line (what every writer produces); a face is its corner
//! count then the indices (0-based), anything after them (a colour) is ignored; polygons are
//! fan-triangulated and faces with fewer than three corners skipped with a warning. Preallocation
//! is capped by what the remaining bytes could hold, so an absurd count in the header allocates
//! nothing big.
//!
//! Writing: `OFF`, counts, `x y z` lines with shortest round-trip floats, `3 a b c` lines.

use super::text::{lines, non_finite_kind, parse_f32, parse_i64, quote, strip_comment, tokens};
use super::{IoError, Parsed};
use crate::mesh::TriMesh;
use std::io::Write;
use std::path::Path;

/// Parses an OFF file: the header line (OFF, COFF, NOFF, ...), the counts, the vertex lines and
/// the face lines, each checked and named by its line in errors. A parser's state machine over
/// the lines, which reads best in one piece.
pub(crate) fn parse(bytes: &[u8], path: &Path) -> Result<Parsed, IoError> {
    let mut rows = lines(bytes)
        .map(|(n, line)| (n, strip_comment(line)))
        .filter(|(_, line)| tokens(line).next().is_some());
    let Some((header_line, header)) = rows.next() else {
        return Err(IoError::invalid(
            path,
            "the file has only comments and blank lines",
        ));
    };
    let mut words = tokens(header);
    let keyword = words.next().unwrap_or_default();
    let at_header = |message: String| IoError::at_line(path, header_line, message);
    let Some(prefix) = keyword.strip_suffix(b"OFF") else {
        return Err(at_header(format!(
            "not an OFF file: expected the keyword OFF, found {}",
            quote(keyword)
        )));
    };
    if prefix.contains(&b'4') || prefix.contains(&b'n') {
        return Err(at_header(format!(
            "{} (4D or n-dimensional OFF) is not supported",
            quote(keyword)
        )));
    }
    if !prefix.iter().all(|b| b"STCN".contains(b)) {
        return Err(at_header(format!("unknown OFF variant {}", quote(keyword))));
    }
    let mut rest: Vec<&[u8]> = words.collect();
    if rest.first() == Some(&&b"BINARY"[..]) {
        return Err(at_header("binary OFF is not supported".into()));
    }
    // The per-vertex extras of COFF, NOFF, STOFF... are read past, not kept.
    let mut extras = Vec::new();
    if prefix.windows(2).any(|w| w == b"ST") {
        extras.push("texture coordinates");
    }
    if prefix.contains(&b'C') {
        extras.push("colours");
    }
    if prefix.contains(&b'N') {
        extras.push("normals");
    }
    let variant = String::from_utf8_lossy(keyword).into_owned();
    let mut counts_line = header_line;
    if rest.is_empty() {
        let Some((n, line)) = rows.next() else {
            return Err(at_header(
                "the file ends before the vertex and face counts".into(),
            ));
        };
        counts_line = n;
        rest = tokens(line).collect();
    }
    let count = |i: usize, what: &str| -> Result<usize, IoError> {
        let token = rest.get(i).copied().unwrap_or_default();
        parse_i64(token)
            .and_then(|c| usize::try_from(c).ok())
            .ok_or_else(|| {
                IoError::at_line(
                    path,
                    counts_line,
                    format!("cannot read the {what} count {}", quote(token)),
                )
            })
    };
    let vertex_count = count(0, "vertex")?;
    let face_count = count(1, "face")?;
    if vertex_count > u32::MAX as usize {
        return Err(IoError::at_line(
            path,
            counts_line,
            format!("{vertex_count} vertices is more than 32-bit indices can address"),
        ));
    }

    // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line 8 ("3 0 1 2\n").
    let mut mesh = TriMesh {
        positions: Vec::with_capacity(vertex_count.min(bytes.len() / 6)),
        triangles: Vec::with_capacity(face_count.min(bytes.len() / 8)),
    };
    let mut last_line = counts_line;
    for v in 0..vertex_count {
        let Some((number, line)) = rows.next() else {
            return Err(IoError::at_line(
                path,
                last_line,
                format!("the file ends after {v} of {vertex_count} vertices"),
            ));
        };
        last_line = number;
        let at = |message: String| IoError::at_line(path, number, message);
        let mut words = tokens(line);
        let mut p = [0f32; 3];
        for c in &mut p {
            let token = words.next().unwrap_or_default();
            *c = parse_f32(token).ok_or_else(|| {
                at(format!(
                    "vertex {v}: cannot read coordinate {}",
                    quote(token)
                ))
            })?;
        }
        if let Some(bad) = p.iter().find(|c| !c.is_finite()) {
            return Err(at(format!(
                "vertex {v} has {} coordinate",
                non_finite_kind(*bad)
            )));
        }
        mesh.positions.push(p);
    }
    let mut short_faces = 0usize;
    for f in 0..face_count {
        let Some((number, line)) = rows.next() else {
            return Err(IoError::at_line(
                path,
                last_line,
                format!("the file ends after {f} of {face_count} faces"),
            ));
        };
        last_line = number;
        let at = |message: String| IoError::at_line(path, number, message);
        let mut words = tokens(line);
        let count_token = words.next().unwrap_or_default();
        let corners = parse_i64(count_token)
            .and_then(|c| usize::try_from(c).ok())
            .ok_or_else(|| {
                at(format!(
                    "face {f}: cannot read its corner count {}",
                    quote(count_token)
                ))
            })?;
        let mut index = |k: usize| -> Result<u32, IoError> {
            let token = words.next().ok_or_else(|| {
                at(format!(
                    "face {f}: has {k} indices, fewer than its count {corners}"
                ))
            })?;
            let value = parse_i64(token).ok_or_else(|| {
                at(format!(
                    "face {f}: cannot read vertex index {}",
                    quote(token)
                ))
            })?;
            match usize::try_from(value) {
                Ok(i) if i < vertex_count => Ok(i as u32),
                _ => Err(at(format!(
                    "face {f}: vertex index {value} is out of range (the file has {vertex_count} vertices)"
                ))),
            }
        };
        if corners < 3 {
            for k in 0..corners {
                index(k)?;
            }
            short_faces += 1;
            continue;
        }
        let first = index(0)?;
        let mut previous = index(1)?;
        for k in 2..corners {
            let next = index(k)?;
            mesh.triangles.push([first, previous, next]);
            previous = next;
        }
    }
    if mesh.triangles.is_empty() {
        return Err(IoError::invalid(
            path,
            format!("no triangles: {vertex_count} vertices and no face with 3 or more corners"),
        ));
    }
    let mut parsed = Parsed::new(mesh);
    if !extras.is_empty() {
        parsed.unkept = vec![format!("per-vertex {} ({variant})", extras.join(", "))];
    }
    if short_faces > 0 {
        parsed
            .warnings
            .push(super::text::short_faces_skipped(short_faces));
    }
    Ok(parsed)
}

pub(crate) fn write(out: &mut dyn Write, mesh: &TriMesh) -> std::io::Result<()> {
    writeln!(out, "OFF")?;
    writeln!(out, "# written by fairmesh")?;
    writeln!(out, "{} {} 0", mesh.positions.len(), mesh.triangles.len())?;
    for [x, y, z] in &mesh.positions {
        writeln!(out, "{x} {y} {z}")?;
    }
    for [a, b, c] in &mesh.triangles {
        writeln!(out, "3 {a} {b} {c}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_comments_inline_counts_and_quads() {
        let text =
            "# a square\nOFF 4 1 0\n0 0 0\n1 0 0 # corner\n\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n";
        let parsed = parse(text.as_bytes(), Path::new("q.off")).unwrap();
        assert_eq!(parsed.mesh.positions.len(), 4);
        assert_eq!(parsed.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn vertex_colours_are_named_as_not_kept() {
        let text =
            b"COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n";
        let parsed = parse(text, Path::new("c.off")).unwrap();
        assert_eq!(parsed.unkept, vec!["per-vertex colours (COFF)".to_string()]);
        let plain = parse(
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            Path::new("p.off"),
        );
        assert!(plain.unwrap().unkept.is_empty());
    }

    #[test]
    fn errors_name_the_line() {
        let err = parse(
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
            Path::new("e.off"),
        )
        .unwrap_err();
        assert_eq!(
            err.to_string(),
            "e.off: line 6: face 0: vertex index 3 is out of range (the file has 3 vertices)"
        );
        let err = parse(b"OFF\n4000000000 1 0\n0 0 0\n", Path::new("e.off")).unwrap_err();
        assert!(err.to_string().contains("line 3"), "{err}");
    }
}
