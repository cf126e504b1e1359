//! Reading a PLY's vertex and face rows, ASCII or binary (either endianness): parsers that read
//! row by row, each a state machine over the rows that reads best in one piece.

use super::header::{
    find_layout, parse_header, Element, Encoding, Header, Layout, Property, Scalar,
};
use crate::io::text::{lines, non_finite_kind, parse_f32, parse_f64, parse_i64, quote, tokens};
use crate::io::{IoError, Parsed};
use crate::mesh::TriMesh;
use std::path::Path;

pub(crate) fn parse(bytes: &[u8], path: &Path) -> Result<Parsed, IoError> {
    let header = parse_header(bytes, path)?;
    let layout = find_layout(&header, path)?;
    let vertex_count = header.elements[layout.vertex_element].count;
    if vertex_count > u32::MAX as u64 {
        return Err(IoError::invalid(
            path,
            format!(
                "the header declares {vertex_count} vertices, more than 32-bit indices can address"
            ),
        ));
    }
    let mut builder = Builder {
        mesh: TriMesh::default(),
        vertex_count: vertex_count as u32,
        short_faces: 0,
    };
    match header.encoding {
        Encoding::Ascii => read_ascii(bytes, path, &header, &layout, &mut builder)?,
        Encoding::LittleEndian => {
            read_binary::<false>(bytes, path, &header, &layout, &mut builder)?
        }
        Encoding::BigEndian => read_binary::<true>(bytes, path, &header, &layout, &mut builder)?,
    }
    if layout.face_element.is_none() || builder.mesh.triangles.is_empty() {
        return Err(IoError::invalid(
            path,
            format!(
                "no triangles: {} vertices and no face with 3 or more corners",
                builder.mesh.positions.len()
            ),
        ));
    }
    let mut parsed = Parsed::new(builder.mesh);
    if let Some((first, text)) = header.stray_lines.first() {
        let more = match header.stray_lines.len() {
            1 => String::new(),
            n => format!(" (and {} more such lines)", n - 1),
        };
        parsed.warnings.push(format!(
            "header line {first} ({}) is not a PLY keyword line: read as a comment{more}",
            quote(text.as_bytes())
        ));
    }
    if builder.short_faces > 0 {
        parsed
            .warnings
            .push(crate::io::text::short_faces_skipped(builder.short_faces));
    }
    Ok(parsed)
}

pub(super) struct Builder {
    mesh: TriMesh,
    vertex_count: u32,
    short_faces: usize,
}

impl Builder {
    /// Check a coordinate triple and add it.
    pub(super) fn vertex(&mut self, p: [f32; 3]) -> Result<(), String> {
        if let Some(bad) = p.iter().find(|c| !c.is_finite()) {
            return Err(format!(
                "vertex {} has {} coordinate",
                self.mesh.positions.len(),
                non_finite_kind(*bad)
            ));
        }
        self.mesh.positions.push(p);
        Ok(())
    }

    pub(super) fn index(&self, face: usize, value: i64) -> Result<u32, String> {
        match u32::try_from(value) {
            Ok(v) if v < self.vertex_count => Ok(v),
            _ => Err(format!(
                "face {face}: vertex index {value} is out of range (the file has {} vertices)",
                self.vertex_count
            )),
        }
    }
}

/// Reads the ASCII rows of every element (vertices, faces or strips, others skipped), one row a
/// line, naming the line of any error. A parser's loop over the rows, which reads best in one
/// piece.
pub(super) fn read_ascii(
    bytes: &[u8],
    path: &Path,
    header: &Header,
    layout: &Layout,
    builder: &mut Builder,
) -> Result<(), IoError> {
    let body = bytes.get(header.body_start..).unwrap_or_default();
    let mut rows = lines(body)
        .map(|(n, line)| (n + header.body_line - 1, line))
        .filter(|(_, line)| tokens(line).next().is_some());
    // Every row takes at least 2 bytes ("0\n"): a cap on preallocation.
    let capacity_cap = body.len() / 2;
    let mut last_line = header.body_line;
    for (e, element) in header.elements.iter().enumerate() {
        let is_vertex = e == layout.vertex_element;
        let is_face = Some(e) == layout.face_element;
        let cap = (element.count as usize).min(capacity_cap);
        if is_vertex {
            builder.mesh.positions.reserve(cap);
        } else if is_face {
            builder.mesh.triangles.reserve(cap);
        }
        for row in 0..element.count {
            let Some((number, line)) = rows.next() else {
                return Err(IoError::at_line(
                    path,
                    last_line,
                    format!(
                        "the file ends after {row} of {} {} rows",
                        element.count,
                        element.label()
                    ),
                ));
            };
            last_line = number;
            let at = |message: String| IoError::at_line(path, number, message);
            let mut words = tokens(line);
            let mut xyz = [0f32; 3];
            for (p, property) in element.properties.iter().enumerate() {
                match property {
                    Property::Scalar { kind, name } => {
                        let token = words.next().ok_or_else(|| {
                            at(format!(
                                "{} {row}: missing value for {}",
                                element.label(),
                                String::from_utf8_lossy(name)
                            ))
                        })?;
                        if is_vertex {
                            if let Some(axis) = layout.xyz.iter().position(|&i| i == p) {
                                xyz[axis] = ascii_coordinate(*kind, token).ok_or_else(|| {
                                    at(format!(
                                        "vertex {row}: cannot read coordinate {}",
                                        quote(token)
                                    ))
                                })?;
                            }
                        }
                    }
                    Property::List { name, .. } => {
                        let count_token = words.next().ok_or_else(|| {
                            at(format!(
                                "{} {row}: missing value for the list {}",
                                element.label(),
                                String::from_utf8_lossy(name)
                            ))
                        })?;
                        let count = parse_i64(count_token)
                            .and_then(|c| usize::try_from(c).ok())
                            .ok_or_else(|| {
                                at(format!(
                                    "{} {row}: cannot read list length {}",
                                    element.label(),
                                    quote(count_token)
                                ))
                            })?;
                        if is_face && p == layout.face_list {
                            let mut corners = Vec::with_capacity(count.min(64));
                            for _ in 0..count {
                                let token = words.next().ok_or_else(|| {
                                    at(format!("face {row}: fewer indices than its count {count}"))
                                })?;
                                let value = parse_i64(token).ok_or_else(|| {
                                    at(format!(
                                        "face {row}: cannot read vertex index {}",
                                        quote(token)
                                    ))
                                })?;
                                corners.push(if layout.strips && value < 0 {
                                    STRIP_RESTART
                                } else {
                                    builder.index(row as usize, value).map_err(&at)?
                                });
                            }
                            if layout.strips {
                                strips(&corners, builder);
                            } else {
                                fan(&corners, builder);
                            }
                        } else {
                            for _ in 0..count {
                                words.next().ok_or_else(|| {
                                    at(format!(
                                        "{} {row}: fewer list values than its count {count}",
                                        element.label()
                                    ))
                                })?;
                            }
                        }
                    }
                }
            }
            if is_vertex {
                builder.vertex(xyz).map_err(&at)?;
            }
        }
    }
    Ok(())
}

pub(super) fn ascii_coordinate(kind: Scalar, token: &[u8]) -> Option<f32> {
    match kind {
        Scalar::F32 => parse_f32(token),
        Scalar::F64 => parse_f64(token).map(|v| v as f32),
        _ => parse_i64(token).map(|v| v as f32),
    }
}

/// A `tristrips` row's negative index, which ends one strip and starts the next.
pub(super) const STRIP_RESTART: u32 = u32::MAX;

/// The triangles of a `tristrips` row: in each strip (between restarts) the triangle at
/// position `i` is `(s[i], s[i+1], s[i+2])`, its two first corners swapped at odd `i` so that
/// all keep one orientation (as OpenGL draws strips). Triangles that repeat a corner only join
/// two strips, and are left out; so are strips of fewer than three corners.
pub(super) fn strips(corners: &[u32], builder: &mut Builder) {
    for strip in corners.split(|&c| c == STRIP_RESTART) {
        for (i, t) in strip.windows(3).enumerate() {
            let [a, b, c] = [t[0], t[1], t[2]];
            if a != b && b != c && a != c {
                let triangle = if i % 2 == 0 { [a, b, c] } else { [b, a, c] };
                builder.mesh.triangles.push(triangle);
            }
        }
    }
}

pub(super) fn fan(corners: &[u32], builder: &mut Builder) {
    match corners {
        [first, rest @ ..] if rest.len() >= 2 => {
            for pair in rest.windows(2) {
                builder.mesh.triangles.push([*first, pair[0], pair[1]]);
            }
        }
        _ => builder.short_faces += 1,
    }
}

/// One `$t` from the first `$n` bytes of `$bytes`, big endian when `$big`; returns `None` from
/// the calling function when there are fewer bytes.
macro_rules! scalar_at {
    ($bytes:expr, $big:expr, $t:ty, $n:literal) => {{
        let raw: [u8; $n] = $bytes.get(..$n)?.try_into().ok()?;
        if $big {
            <$t>::from_be_bytes(raw)
        } else {
            <$t>::from_le_bytes(raw)
        }
    }};
}

/// Read one scalar from the start of `bytes` (which has at least `kind.size()` bytes).
#[inline]
pub(super) fn read_f64<const BIG: bool>(kind: Scalar, bytes: &[u8]) -> Option<f64> {
    Some(match kind {
        Scalar::I8 => scalar_at!(bytes, BIG, i8, 1) as f64,
        Scalar::U8 => scalar_at!(bytes, BIG, u8, 1) as f64,
        Scalar::I16 => scalar_at!(bytes, BIG, i16, 2) as f64,
        Scalar::U16 => scalar_at!(bytes, BIG, u16, 2) as f64,
        Scalar::I32 => scalar_at!(bytes, BIG, i32, 4) as f64,
        Scalar::U32 => scalar_at!(bytes, BIG, u32, 4) as f64,
        Scalar::F32 => scalar_at!(bytes, BIG, f32, 4) as f64,
        Scalar::F64 => scalar_at!(bytes, BIG, f64, 8),
    })
}

#[inline]
pub(super) fn read_f32<const BIG: bool>(kind: Scalar, bytes: &[u8]) -> Option<f32> {
    if kind == Scalar::F32 {
        return Some(scalar_at!(bytes, BIG, f32, 4));
    }
    read_f64::<BIG>(kind, bytes).map(|v| v as f32)
}

/// An integer property; float types are accepted when they hold a whole number.
#[inline]
pub(super) fn read_int<const BIG: bool>(kind: Scalar, bytes: &[u8]) -> Option<i64> {
    Some(match kind {
        Scalar::I8 => scalar_at!(bytes, BIG, i8, 1) as i64,
        Scalar::U8 => scalar_at!(bytes, BIG, u8, 1) as i64,
        Scalar::I16 => scalar_at!(bytes, BIG, i16, 2) as i64,
        Scalar::U16 => scalar_at!(bytes, BIG, u16, 2) as i64,
        Scalar::I32 => scalar_at!(bytes, BIG, i32, 4) as i64,
        Scalar::U32 => scalar_at!(bytes, BIG, u32, 4) as i64,
        Scalar::F32 | Scalar::F64 => {
            let v = read_f64::<BIG>(kind, bytes)?;
            if v.fract() != 0.0 || !(-9.0e15..=9.0e15).contains(&v) {
                return None;
            }
            v as i64
        }
    })
}

/// Reads the binary rows of every element (vertices, faces or strips, others walked over),
/// naming the byte offset and element of any error. A parser's loop over the rows, which reads
/// best in one piece.
pub(super) fn read_binary<const BIG: bool>(
    bytes: &[u8],
    path: &Path,
    header: &Header,
    layout: &Layout,
    builder: &mut Builder,
) -> Result<(), IoError> {
    let mut pos = header.body_start;
    let end = bytes.len();
    for (e, element) in header.elements.iter().enumerate() {
        let is_vertex = e == layout.vertex_element;
        let is_face = Some(e) == layout.face_element;
        let remaining = end - pos;
        if let Some(stride) = element.fixed_row_size() {
            let needed = (element.count as u128) * (stride as u128);
            if needed > remaining as u128 {
                let complete = remaining / stride.max(1);
                return Err(IoError::at_byte(
                    path,
                    pos + complete * stride,
                    format!(
                        "the file is truncated: {} {complete} of {} is cut off (rows of {stride} bytes, {remaining} bytes left)",
                        element.label(),
                        element.count
                    ),
                ));
            }
            let rows_len = needed as usize; // <= remaining
            let rows = bytes.get(pos..pos + rows_len).unwrap_or_default();
            if is_vertex && stride > 0 {
                read_vertex_rows::<BIG>(rows, stride, element, layout, builder).map_err(
                    |(row, message)| IoError::at_byte(path, pos + row * stride, message),
                )?;
            }
            pos += rows_len;
            continue;
        }
        // Rows with lists: walk them one by one. Each row holds at least one count.
        let min_row = element
            .properties
            .iter()
            .map(|p| match p {
                Property::Scalar { kind, .. } => kind.size(),
                Property::List { count, .. } => count.size(),
            })
            .sum::<usize>()
            .max(1);
        let cap = (element.count as usize).min(remaining / min_row);
        if is_vertex {
            builder.mesh.positions.reserve(cap);
        } else if is_face {
            builder.mesh.triangles.reserve(cap);
        }
        let mut corners: Vec<u32> = Vec::new();
        for row in 0..element.count {
            let row_start = pos;
            let cut = |at: usize| {
                IoError::at_byte(
                    path,
                    at,
                    format!(
                        "the file is truncated: {} {row} of {} is cut off",
                        element.label(),
                        element.count
                    ),
                )
            };
            let mut xyz = [0f32; 3];
            for (p, property) in element.properties.iter().enumerate() {
                match property {
                    Property::Scalar { kind, .. } => {
                        let value = bytes.get(pos..).unwrap_or_default();
                        if value.len() < kind.size() {
                            return Err(cut(pos));
                        }
                        if is_vertex {
                            if let Some(axis) = layout.xyz.iter().position(|&i| i == p) {
                                xyz[axis] =
                                    read_f32::<BIG>(*kind, value).ok_or_else(|| cut(pos))?;
                            }
                        }
                        pos += kind.size();
                    }
                    Property::List { count, item, .. } => {
                        let count_bytes = bytes.get(pos..).unwrap_or_default();
                        if count_bytes.len() < count.size() {
                            return Err(cut(pos));
                        }
                        let n = read_int::<BIG>(*count, count_bytes)
                            .and_then(|n| usize::try_from(n).ok())
                            .ok_or_else(|| {
                                IoError::at_byte(
                                    path,
                                    pos,
                                    format!("{} {row}: negative list length", element.label()),
                                )
                            })?;
                        pos += count.size();
                        let list_len = n.saturating_mul(item.size());
                        if list_len > end - pos {
                            return Err(cut(pos));
                        }
                        if is_face && p == layout.face_list {
                            corners.clear();
                            for k in 0..n {
                                let at = pos + k * item.size();
                                let value = bytes
                                    .get(at..)
                                    .and_then(|b| read_int::<BIG>(*item, b))
                                    .ok_or_else(|| {
                                        IoError::at_byte(
                                            path,
                                            at,
                                            format!(
                                                "face {row}: vertex index is not a whole number"
                                            ),
                                        )
                                    })?;
                                let index = if layout.strips && value < 0 {
                                    STRIP_RESTART
                                } else {
                                    builder
                                        .index(row as usize, value)
                                        .map_err(|m| IoError::at_byte(path, at, m))?
                                };
                                corners.push(index);
                            }
                            if layout.strips {
                                strips(&corners, builder);
                            } else {
                                fan(&corners, builder);
                            }
                        }
                        pos += list_len;
                    }
                }
            }
            if is_vertex {
                builder
                    .vertex(xyz)
                    .map_err(|m| IoError::at_byte(path, row_start, m))?;
            }
        }
    }
    Ok(())
}

/// Vertex rows of fixed size: x, y, z at precomputed offsets. Errors give the row.
pub(super) fn read_vertex_rows<const BIG: bool>(
    rows: &[u8],
    stride: usize,
    element: &Element,
    layout: &Layout,
    builder: &mut Builder,
) -> Result<(), (usize, String)> {
    let mut offsets = [0usize; 3];
    let mut kinds = [Scalar::F32; 3];
    for axis in 0..3 {
        let mut offset = 0;
        for (p, property) in element.properties.iter().enumerate() {
            if let Property::Scalar { kind, .. } = property {
                if p == layout.xyz[axis] {
                    offsets[axis] = offset;
                    kinds[axis] = *kind;
                    break;
                }
                offset += kind.size();
            }
        }
    }
    builder.mesh.positions.reserve(rows.len() / stride);
    for (row, chunk) in rows.chunks_exact(stride).enumerate() {
        let mut p = [0f32; 3];
        for axis in 0..3 {
            p[axis] = chunk
                .get(offsets[axis]..)
                .and_then(|b| read_f32::<BIG>(kinds[axis], b))
                .unwrap_or(f32::NAN);
        }
        builder.vertex(p).map_err(|m| (row, m))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::write::write;
    use super::*;

    pub(super) fn parse_bytes(bytes: &[u8]) -> Result<Parsed, IoError> {
        parse(bytes, Path::new("t.ply"))
    }

    /// A `tristrips` element (older scans) as triangles: one strip around a tetrahedron, a
    /// restart (-1), and a strip of two corners, which holds no triangle; ASCII and binary.
    #[test]
    pub(super) fn reads_triangle_strips() {
        let header = |format: &str| {
            format!(
                "ply\nformat {format} 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
                 property float z\nelement tristrips 1\nproperty list int int vertex_indices\n\
                 end_header\n"
            )
        };
        let strip: [i32; 9] = [0, 1, 2, 3, 0, 1, -1, 3, 2];
        let points = [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
        let ascii = format!(
            "{}0 0 0\n1 0 0\n0 1 0\n0 0 1\n9 {}\n",
            header("ascii"),
            strip.map(|i| i.to_string()).join(" ")
        );
        let mut binary = header("binary_little_endian").into_bytes();
        binary.extend(points.iter().flatten().flat_map(|c| c.to_le_bytes()));
        binary.extend(9i32.to_le_bytes());
        binary.extend(strip.iter().flat_map(|i| i.to_le_bytes()));
        for bytes in [ascii.into_bytes(), binary] {
            let parsed = parse_bytes(&bytes).unwrap();
            assert_eq!(parsed.mesh.positions, points.to_vec());
            // Even positions as they come, odd ones with their first two corners swapped.
            assert_eq!(
                parsed.mesh.triangles,
                vec![[0, 1, 2], [2, 1, 3], [2, 3, 0], [0, 3, 1]]
            );
            assert!(parsed.warnings.is_empty(), "{:?}", parsed.warnings);
        }
    }

    #[test]
    pub(super) fn reads_ascii_with_extra_properties_and_polygons() {
        let text = "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\nproperty double x\n\
                    property float nx\nproperty float y\nproperty int z\nelement edge 1\n\
                    property int a\nproperty int b\nelement face 1\nproperty uchar flags\n\
                    property list ushort uint vertex_indices\nend_header\n\
                    0 9 0 0\n1 9 0 0\n1 9 1 0\n0 9 1 0\n0 1\n7 4 0 1 2 3\n";
        let parsed = parse_bytes(text.as_bytes()).unwrap();
        assert_eq!(
            parsed.mesh.positions,
            vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]]
        );
        assert_eq!(parsed.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    pub(super) fn reads_big_endian_with_short_indices() {
        let mut bytes = b"ply\r\nformat binary_big_endian 1.0\r\nelement vertex 3\r\n\
            property float x\r\nproperty float y\r\nproperty float z\r\nelement face 1\r\n\
            property list uchar short vertex_indices\r\nend_header\r\n"
            .to_vec();
        for v in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.5]] {
            for c in v {
                bytes.extend_from_slice(&c.to_be_bytes());
            }
        }
        bytes.push(3);
        for i in [0i16, 1, 2] {
            bytes.extend_from_slice(&i.to_be_bytes());
        }
        let parsed = parse_bytes(&bytes).unwrap();
        assert_eq!(parsed.mesh.positions[2], [0., 1., 0.5]);
        assert_eq!(parsed.mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    pub(super) fn binary_round_trip_and_errors() {
        let mesh = TriMesh::new(
            vec![[0.1, 0.2, 0.3], [1.0, 0.0, -0.0], [0.0, 1e-38, 3.0]],
            vec![[0, 1, 2]],
        );
        let mut bytes = Vec::new();
        write(&mut bytes, &mesh).unwrap();
        assert_eq!(parse_bytes(&bytes).unwrap().mesh, mesh);

        let err = parse_bytes(&bytes[..bytes.len() - 3]).unwrap_err();
        assert!(err.to_string().contains("truncated"), "{err}");
        assert!(err.to_string().contains("face 0"), "{err}");

        let body = bytes
            .windows(11)
            .position(|w| w == b"end_header\n")
            .unwrap()
            + 11;
        let header = String::from_utf8(bytes[..body].to_vec()).unwrap();
        let mut huge = header
            .replace("element vertex 3", "element vertex 4000000000")
            .into_bytes();
        huge.extend_from_slice(&bytes[body..]);
        let err = parse_bytes(&huge).unwrap_err();
        assert!(err.to_string().starts_with("t.ply: byte "), "{err}");
    }
}
