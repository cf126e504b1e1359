//! STL, ASCII and binary; written as binary.
//!
//! Detection: a file is binary when its size is exactly `84 + 50 * n`, `n` being the triangle
//! count at byte 80, whatever its first bytes say (many binary writers start the header with
//! "solid"). Otherwise a file that starts with "solid" (in any case, as its keywords may be)
//! and holds no NUL byte is ASCII; anything
//! else is a binary file of the wrong size, reported as truncated (or, if longer, read with a
//! warning about the trailing bytes).
//!
//! STL stores three corners per triangle and shares nothing: every corner becomes its own vertex
//! and welding (on by default) joins them. Facet normals are ignored on reading and written as the
//! unit face normal (zero for a degenerate triangle). A binary file's 80-byte header text is kept
//! ([`StlSource`]): written back when the mesh is saved as STL, named when saved as another format.

use super::text::{lines, non_finite_kind, parse_f32, quote, tokens};
use super::{IoError, Parsed};
use crate::mesh::TriMesh;
use std::io::Write;
use std::path::Path;

const HEADER: usize = 84;
const RECORD: usize = 50;

pub(crate) fn parse(bytes: &[u8], path: &Path) -> Result<Parsed<StlSource>, IoError> {
    let declared = bytes
        .get(80..84)
        .and_then(|b| b.try_into().ok())
        .map(u32::from_le_bytes);
    let binary_size = declared.map(|n| HEADER as u64 + RECORD as u64 * n as u64);
    if binary_size == Some(bytes.len() as u64) {
        return read_binary(bytes, path);
    }
    let starts_solid = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .and_then(|start| bytes.get(start..start + 5))
        .is_some_and(|word| word.eq_ignore_ascii_case(b"solid"));
    if starts_solid && !bytes.contains(&0) {
        return read_ascii(bytes, path);
    }
    if declared.is_some() {
        return read_binary(bytes, path);
    }
    Err(IoError::invalid(
        path,
        format!(
            "not an STL file: {} bytes, too short for a binary STL (84-byte header) and not ASCII (\"solid ...\")",
            bytes.len()
        ),
    ))
}

/// Reads a binary STL: the header, the declared count checked against the file's size, and
/// each facet's corners. A parser that reads best in one piece.
fn read_binary(bytes: &[u8], path: &Path) -> Result<Parsed<StlSource>, IoError> {
    let declared = bytes
        .get(80..84)
        .and_then(|b| b.try_into().ok())
        .map(u32::from_le_bytes)
        .unwrap_or(0) as usize;
    let body = bytes.get(HEADER..).unwrap_or_default();
    let available = body.len() / RECORD;
    if available < declared {
        return Err(IoError::at_byte(
            path,
            HEADER + available * RECORD,
            format!(
                "the file is truncated: the header declares {declared} triangles ({} bytes) but triangle {available} is cut off at {} bytes",
                HEADER as u64 + RECORD as u64 * declared as u64,
                bytes.len()
            ),
        ));
    }
    if declared
        .checked_mul(3)
        .is_none_or(|c| c > u32::MAX as usize)
    {
        return Err(IoError::invalid(
            path,
            format!("{declared} triangles is more than 32-bit indices can address"),
        ));
    }
    let mut parsed = Parsed::new(TriMesh {
        positions: Vec::with_capacity(declared * 3),
        triangles: Vec::with_capacity(declared),
    });
    let trailing = body.len() - declared * RECORD;
    if trailing > 0 {
        parsed.warnings.push(format!(
            "{trailing} bytes after the {declared} declared triangles were ignored"
        ));
    }
    for (t, record) in body.chunks_exact(RECORD).take(declared).enumerate() {
        for corner in 0..3 {
            let mut p = [0f32; 3];
            for (axis, c) in p.iter_mut().enumerate() {
                let at = 12 + 12 * corner + 4 * axis;
                *c = record
                    .get(at..at + 4)
                    .and_then(|b| b.try_into().ok())
                    .map(f32::from_le_bytes)
                    .unwrap_or(f32::NAN);
            }
            if let Some(bad) = p.iter().find(|c| !c.is_finite()) {
                return Err(IoError::at_byte(
                    path,
                    HEADER + t * RECORD + 12 + 12 * corner,
                    format!(
                        "triangle {t}, corner {corner} has {} coordinate",
                        non_finite_kind(*bad)
                    ),
                ));
            }
            parsed.mesh.positions.push(p);
        }
        let base = (3 * t) as u32; // 3 * declared fits in u32, checked above
        parsed.mesh.triangles.push([base, base + 1, base + 2]);
    }
    if parsed.mesh.triangles.is_empty() {
        return Err(IoError::invalid(
            path,
            "no triangles: the binary STL header declares 0 triangles",
        ));
    }
    // Some writers keep a colour per facet in its two attribute bytes; fairmesh writes zeros.
    let coloured = body
        .chunks_exact(RECORD)
        .take(declared)
        .filter(|record| record[48..50] != [0, 0])
        .count();
    let mut unkept = Vec::new();
    if coloured > 0 {
        unkept.push(format!(
            "the attribute bytes (colours, for some writers) of {coloured} facets"
        ));
    }
    let header: [u8; 80] = bytes[..80].try_into().unwrap_or([0; 80]);
    if header_text(&header).is_some() {
        parsed.kept = Some(StlSource { header, unkept });
    } else {
        parsed.unkept = unkept;
    }
    Ok(parsed)
}

fn read_ascii(bytes: &[u8], path: &Path) -> Result<Parsed<StlSource>, IoError> {
    let mut mesh = TriMesh::default();
    let mut corners: Vec<u32> = Vec::new();
    let mut in_loop = false;
    for (number, line) in lines(bytes) {
        let at = |message: String| IoError::at_line(path, number, message);
        let mut words = tokens(line);
        let Some(keyword) = words.next() else {
            continue;
        };
        // Keywords in any case: some writers use capitals ("SOLID", "FACET NORMAL"). (Lowered
        // in a buffer as long as the longest keyword, "endsolid": no allocation per line.)
        let mut lowered = [0u8; 8];
        let keyword_lowered = match lowered.get_mut(..keyword.len()) {
            Some(buffer) => {
                buffer.copy_from_slice(keyword);
                buffer.make_ascii_lowercase();
                &*buffer
            }
            None => keyword,
        };
        match keyword_lowered {
            b"solid" | b"endsolid" | b"facet" | b"endfacet" => {}
            b"outer" => {
                in_loop = true;
                corners.clear();
            }
            b"vertex" => {
                if !in_loop {
                    return Err(at("vertex outside an \"outer loop\"".into()));
                }
                let mut p = [0f32; 3];
                for c in &mut p {
                    let token = words.next().unwrap_or_default();
                    *c = parse_f32(token)
                        .ok_or_else(|| at(format!("cannot read coordinate {}", quote(token))))?;
                }
                if let Some(bad) = p.iter().find(|c| !c.is_finite()) {
                    return Err(at(format!(
                        "vertex {} has {} coordinate",
                        mesh.positions.len(),
                        non_finite_kind(*bad)
                    )));
                }
                let index = u32::try_from(mesh.positions.len())
                    .map_err(|_| at("too many vertices for 32-bit indices".into()))?;
                mesh.positions.push(p);
                corners.push(index);
            }
            b"endloop" => {
                if corners.len() < 3 {
                    return Err(at(format!(
                        "the loop has {} vertices; a facet needs 3",
                        corners.len()
                    )));
                }
                for pair in corners[1..].windows(2) {
                    mesh.triangles.push([corners[0], pair[0], pair[1]]);
                }
                in_loop = false;
            }
            _ => {
                return Err(at(format!("unexpected {} in an ASCII STL", quote(keyword))));
            }
        }
    }
    if mesh.triangles.is_empty() {
        return Err(IoError::invalid(
            path,
            "no triangles: the ASCII STL has no complete facet",
        ));
    }
    Ok(Parsed::new(mesh))
}

/// What a binary STL holds beyond its triangles: the 80-byte header, whose text (a title, the
/// writing program, units) is written back when the mesh is saved as STL, and what is not kept.
#[derive(Debug)]
pub(crate) struct StlSource {
    pub header: [u8; 80],
    pub unkept: Vec<String>,
}

impl StlSource {
    /// In plain words, for `info` and for saying what another format does not keep.
    pub(crate) fn contents(&self) -> Vec<String> {
        let mut out: Vec<String> = header_text(&self.header)
            .map(|text| format!("the 80-byte STL header text {text:?}"))
            .into_iter()
            .collect();
        out.extend(self.unkept.iter().cloned());
        out
    }
}

/// The text of a binary STL header (up to its first NUL, trimmed), when it says something other
/// than what fairmesh itself writes there.
fn header_text(header: &[u8; 80]) -> Option<String> {
    let end = header.iter().position(|&b| b == 0).unwrap_or(header.len());
    let text = String::from_utf8_lossy(&header[..end]).trim().to_string();
    (!text.is_empty() && text != FAIRMESH_TITLE).then_some(text)
}

const FAIRMESH_TITLE: &str = "binary STL written by fairmesh";

pub(crate) fn write(out: &mut dyn Write, mesh: &TriMesh) -> std::io::Result<()> {
    let mut header = [b' '; 80];
    header[..FAIRMESH_TITLE.len()].copy_from_slice(FAIRMESH_TITLE.as_bytes());
    write_with_header(out, mesh, &header)
}

/// A binary STL with the given 80-byte header.
pub(crate) fn write_with_header(
    out: &mut dyn Write,
    mesh: &TriMesh,
    header: &[u8; 80],
) -> std::io::Result<()> {
    let count = u32::try_from(mesh.triangles.len()).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "binary STL holds at most 2^32 - 1 triangles",
        )
    })?;
    out.write_all(header)?;
    out.write_all(&count.to_le_bytes())?;
    let mut record = [0u8; RECORD];
    for t in 0..mesh.triangles.len() {
        let normal = mesh.face_normal(t).normalize_or_zero().as_vec3().to_array();
        let corners = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
        let values = std::iter::once(normal).chain(corners).flatten();
        for (slot, value) in record.chunks_exact_mut(4).zip(values) {
            slot.copy_from_slice(&value.to_le_bytes());
        }
        out.write_all(&record)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binary_with_solid_header_is_detected_by_size() {
        let mesh = TriMesh::new(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]],
            vec![[0, 1, 2]],
        );
        let mut bytes = Vec::new();
        write(&mut bytes, &mesh).unwrap();
        bytes[..5].copy_from_slice(b"solid");
        assert_eq!(bytes.len(), 134);
        let parsed = parse(&bytes, Path::new("t.stl")).unwrap();
        assert_eq!(parsed.mesh, mesh);
        let err = parse(&bytes[..120], Path::new("t.stl")).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("t.stl: byte 84: the file is truncated"),
            "{err}"
        );
    }

    #[test]
    fn facet_attribute_bytes_are_named_as_not_kept() {
        let mut bytes = vec![0u8; 80];
        bytes.extend_from_slice(&2u32.to_le_bytes());
        for colour in [[0u8, 0], [0x1f, 0x80]] {
            bytes.extend_from_slice(&[0u8; 12]);
            for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
                for c in p {
                    bytes.extend_from_slice(&c.to_le_bytes());
                }
            }
            bytes.extend_from_slice(&colour);
        }
        let parsed = parse(&bytes, Path::new("c.stl")).unwrap();
        assert!(parsed.kept.is_none());
        let items = parsed.unkept;
        assert!(items[0].contains("of 1 facets"), "{items:?}");
    }

    #[test]
    fn ascii_keywords_in_capitals() {
        let text = "SOLID X\r\n  FACET NORMAL 0 0 1\r\n    OUTER LOOP\r\n      VERTEX 0 0 0\r\n      \
                    VERTEX 1 0 0\r\n      VERTEX 0 1 0\r\n    ENDLOOP\r\n  ENDFACET\r\nENDSOLID X\r\n";
        let parsed = parse(text.as_bytes(), Path::new("a.stl")).unwrap();
        assert_eq!(parsed.mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(parsed.mesh.positions[1], [1.0, 0.0, 0.0]);
    }

    #[test]
    fn ascii_facets() {
        let text = "solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\nendsolid x\n";
        let parsed = parse(text.as_bytes(), Path::new("a.stl")).unwrap();
        assert_eq!(parsed.mesh.triangles, vec![[0, 1, 2]]);
        let bad = text.replace("vertex 1 0 0", "vertex 1 inf 0");
        let err = parse(bad.as_bytes(), Path::new("a.stl")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "a.stl: line 5: vertex 1 has an infinite coordinate"
        );
    }
}
