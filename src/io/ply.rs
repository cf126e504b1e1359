//! Stanford PLY: our own parser for ASCII and binary (little and big endian) files; written as
//! binary little endian.
//!
//! Reading: the header is parsed into elements and properties; `vertex` must have scalar `x`, `y`
//! and `z` of any numeric type (doubles and integers are converted to f32; floats are taken bit for
//! bit); `face` must have a list property `vertex_indices` (or `vertex_index`, or its only list)
//! with any integer count and index type. Polygons are fan-triangulated; faces with fewer than
//! three corners are skipped with a warning. A file with no `face` element but a `tristrips`
//! one (older scans) is read as triangle strips (see `strips`). Other properties and elements
//! are skipped (binary lists are walked to find where the next row starts). A header line that
//! is no keyword, before the first element, is read as a comment with a warning.
//!
//! Robustness: every length is checked before it is read; a binary element of fixed row size is
//! checked against the remaining file size before anything is allocated, and preallocation of
//! variable-size elements is capped by what the remaining bytes could hold, so a header claiming
//! 4 billion faces cannot allocate 4 billion of anything. Errors name the line (header, ASCII) or
//! the byte offset and element (binary).
//!
//! Speed: binary vertex rows of fixed size are read with precomputed offsets; faces are read row by
//! row without per-face allocation. ASCII rows are one per line (what every writer produces).

use super::carry::{Gather, VertexAttributes};
use super::normals::{dvec, NormalTurns, SmoothGroups};
use super::origin::Origin;
use super::text::{lines, non_finite_kind, parse_f32, parse_f64, parse_i64, quote, tokens};
use super::{IoError, Parsed};
use crate::mesh::TriMesh;
use std::io::Write;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

#[derive(Debug)]
enum Property {
    Scalar {
        name: Vec<u8>,
        kind: Scalar,
    },
    List {
        name: Vec<u8>,
        count: Scalar,
        item: Scalar,
    },
}

impl Property {
    fn name(&self) -> &[u8] {
        match self {
            Property::Scalar { name, .. } | Property::List { name, .. } => name,
        }
    }
}

#[derive(Debug)]
struct Element {
    name: Vec<u8>,
    count: u64,
    properties: Vec<Property>,
}

impl Element {
    /// Row size when every property is a scalar.
    fn fixed_row_size(&self) -> Option<usize> {
        self.properties.iter().try_fold(0usize, |size, p| match p {
            Property::Scalar { kind, .. } => Some(size + kind.size()),
            Property::List { .. } => None,
        })
    }

    fn label(&self) -> String {
        String::from_utf8_lossy(&self.name).into_owned()
    }
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset where the body starts.
    body_start: usize,
    /// Line number of the first body line (for ASCII).
    body_line: usize,
    /// Lines before the first element that are no PLY keyword (old Blender exports write
    /// "Created by Blender3D 247 ..." there), read as comments: line number and text.
    stray_lines: Vec<(usize, String)>,
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header, IoError> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut stray_lines = Vec::new();
    let mut offset = 0usize;
    for (number, line) in lines(bytes) {
        // `lines` removed the '\n' (and maybe a '\r'): find where the next line starts.
        offset = offset.saturating_add(line.len());
        if bytes.get(offset) == Some(&b'\r') {
            offset += 1;
        }
        offset += 1;
        let at = |message: String| IoError::at_line(path, number, message);
        let mut words = tokens(line);
        let keyword = words.next();
        if number == 1 {
            if keyword != Some(b"ply") {
                return Err(at("not a PLY file: the first line must be \"ply\"".into()));
            }
            continue;
        }
        match keyword {
            Some(b"format") => {
                encoding = Some(match words.next() {
                    Some(b"ascii") => Encoding::Ascii,
                    Some(b"binary_little_endian") => Encoding::LittleEndian,
                    Some(b"binary_big_endian") => Encoding::BigEndian,
                    other => {
                        return Err(at(format!(
                            "unknown format {}",
                            quote(other.unwrap_or_default())
                        )))
                    }
                });
            }
            Some(b"comment") | Some(b"obj_info") | None => {}
            Some(b"element") => {
                let name = words.next().unwrap_or_default().to_vec();
                let count = words
                    .next()
                    .and_then(parse_i64)
                    .and_then(|c| u64::try_from(c).ok())
                    .ok_or_else(|| at("element needs a name and a non-negative count".into()))?;
                elements.push(Element {
                    name,
                    count,
                    properties: Vec::new(),
                });
            }
            Some(b"property") => {
                let Some(element) = elements.last_mut() else {
                    return Err(at("property before any element".into()));
                };
                let first = words.next().unwrap_or_default();
                let property = if first == b"list" {
                    let count = words.next().and_then(Scalar::parse);
                    let item = words.next().and_then(Scalar::parse);
                    let name = words.next();
                    match (count, item, name) {
                        (Some(count), Some(item), Some(name)) if count.is_integer() => {
                            Property::List {
                                name: name.to_vec(),
                                count,
                                item,
                            }
                        }
                        _ => {
                            return Err(at(
                                "expected \"property list <integer type> <type> <name>\"".into(),
                            ))
                        }
                    }
                } else {
                    match (Scalar::parse(first), words.next()) {
                        (Some(kind), Some(name)) => Property::Scalar {
                            name: name.to_vec(),
                            kind,
                        },
                        _ => {
                            return Err(at(format!(
                                "expected \"property <type> <name>\", unknown type {}",
                                quote(first)
                            )))
                        }
                    }
                };
                element.properties.push(property);
            }
            Some(b"end_header") => {
                let encoding =
                    encoding.ok_or_else(|| at("end_header before any format line".into()))?;
                return Ok(Header {
                    encoding,
                    elements,
                    body_start: offset.min(bytes.len()),
                    body_line: number + 1,
                    stray_lines,
                });
            }
            // Before the first element such a line cannot change how the body is laid out, so
            // it is read as a comment (with a warning); among the elements it might be a
            // misspelt element or property, and reading on could misplace every value.
            Some(_) if elements.is_empty() => {
                stray_lines.push((number, String::from_utf8_lossy(line).trim().to_string()));
            }
            Some(other) => {
                return Err(at(format!("unknown header keyword {}", quote(other))));
            }
        }
    }
    Err(IoError::invalid(
        path,
        "the header never ends: no end_header line",
    ))
}

/// Which properties of the vertex and face elements we use.
struct Layout {
    vertex_element: usize,
    /// Property indices of x, y, z in the vertex element.
    xyz: [usize; 3],
    /// The `face` element, or else a `tristrips` element (older scans, Stanford's tools).
    face_element: Option<usize>,
    /// Property index of the index list in the face element.
    face_list: usize,
    /// The face element is `tristrips`: each row is triangle strips, a negative index
    /// (-1) ending one strip and starting the next.
    strips: bool,
}

fn find_layout(header: &Header, path: &Path) -> Result<Layout, IoError> {
    let vertex_element = header
        .elements
        .iter()
        .position(|e| e.name == b"vertex")
        .ok_or_else(|| IoError::invalid(path, "the header declares no vertex element"))?;
    let vertex = &header.elements[vertex_element];
    let mut xyz = [0usize; 3];
    for (slot, axis) in xyz.iter_mut().zip([&b"x"[..], b"y", b"z"]) {
        *slot = vertex
            .properties
            .iter()
            .position(|p| matches!(p, Property::Scalar { name, .. } if name == axis))
            .ok_or_else(|| {
                IoError::invalid(
                    path,
                    format!(
                        "the vertex element has no scalar property {}",
                        String::from_utf8_lossy(axis)
                    ),
                )
            })?;
    }
    let face = header.elements.iter().position(|e| e.name == b"face");
    let tristrips = (header.elements.iter()).position(|e| e.name == b"tristrips" && e.count > 0);
    let strips = face.is_none() && tristrips.is_some();
    let face_element = face.or(tristrips);
    let mut face_list = 0;
    if let Some(f) = face_element {
        let face = &header.elements[f];
        let is_list = |p: &Property| matches!(p, Property::List { .. });
        let named = face.properties.iter().position(|p| {
            is_list(p) && (p.name() == b"vertex_indices" || p.name() == b"vertex_index")
        });
        let lists: Vec<usize> = (0..face.properties.len())
            .filter(|&i| is_list(&face.properties[i]))
            .collect();
        face_list = match (named, lists.as_slice()) {
            (Some(i), _) => i,
            (None, [only]) => *only,
            _ => {
                return Err(IoError::invalid(
                    path,
                    "the face element has no list property vertex_indices",
                ))
            }
        };
    }
    Ok(Layout {
        vertex_element,
        xyz,
        face_element,
        face_list,
        strips,
    })
}

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
            .push(super::text::short_faces_skipped(builder.short_faces));
    }
    Ok(parsed)
}

struct Builder {
    mesh: TriMesh,
    vertex_count: u32,
    short_faces: usize,
}

impl Builder {
    /// Check a coordinate triple and add it.
    fn vertex(&mut self, p: [f32; 3]) -> Result<(), String> {
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

    fn index(&self, face: usize, value: i64) -> Result<u32, String> {
        match u32::try_from(value) {
            Ok(v) if v < self.vertex_count => Ok(v),
            _ => Err(format!(
                "face {face}: vertex index {value} is out of range (the file has {} vertices)",
                self.vertex_count
            )),
        }
    }
}

fn read_ascii(
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

fn ascii_coordinate(kind: Scalar, token: &[u8]) -> Option<f32> {
    match kind {
        Scalar::F32 => parse_f32(token),
        Scalar::F64 => parse_f64(token).map(|v| v as f32),
        _ => parse_i64(token).map(|v| v as f32),
    }
}

/// A `tristrips` row's negative index, which ends one strip and starts the next.
const STRIP_RESTART: u32 = u32::MAX;

/// The triangles of a `tristrips` row: in each strip (between restarts) the triangle at
/// position `i` is `(s[i], s[i+1], s[i+2])`, its two first corners swapped at odd `i` so that
/// all keep one orientation (as OpenGL draws strips). Triangles that repeat a corner only join
/// two strips, and are left out; so are strips of fewer than three corners.
fn strips(corners: &[u32], builder: &mut Builder) {
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

fn fan(corners: &[u32], builder: &mut Builder) {
    match corners {
        [first, rest @ ..] if rest.len() >= 2 => {
            for pair in rest.windows(2) {
                builder.mesh.triangles.push([*first, pair[0], pair[1]]);
            }
        }
        _ => builder.short_faces += 1,
    }
}

/// Read one scalar from the start of `bytes` (which has at least `kind.size()` bytes).
#[inline]
fn read_f64<const BIG: bool>(kind: Scalar, bytes: &[u8]) -> Option<f64> {
    macro_rules! get {
        ($t:ty, $n:literal) => {{
            let raw: [u8; $n] = bytes.get(..$n)?.try_into().ok()?;
            if BIG {
                <$t>::from_be_bytes(raw)
            } else {
                <$t>::from_le_bytes(raw)
            }
        }};
    }
    Some(match kind {
        Scalar::I8 => get!(i8, 1) as f64,
        Scalar::U8 => get!(u8, 1) as f64,
        Scalar::I16 => get!(i16, 2) as f64,
        Scalar::U16 => get!(u16, 2) as f64,
        Scalar::I32 => get!(i32, 4) as f64,
        Scalar::U32 => get!(u32, 4) as f64,
        Scalar::F32 => get!(f32, 4) as f64,
        Scalar::F64 => get!(f64, 8),
    })
}

#[inline]
fn read_f32<const BIG: bool>(kind: Scalar, bytes: &[u8]) -> Option<f32> {
    if kind == Scalar::F32 {
        let raw: [u8; 4] = bytes.get(..4)?.try_into().ok()?;
        return Some(if BIG {
            f32::from_be_bytes(raw)
        } else {
            f32::from_le_bytes(raw)
        });
    }
    read_f64::<BIG>(kind, bytes).map(|v| v as f32)
}

/// An integer property; float types are accepted when they hold a whole number.
#[inline]
fn read_int<const BIG: bool>(kind: Scalar, bytes: &[u8]) -> Option<i64> {
    macro_rules! get {
        ($t:ty, $n:literal) => {{
            let raw: [u8; $n] = bytes.get(..$n)?.try_into().ok()?;
            if BIG {
                <$t>::from_be_bytes(raw)
            } else {
                <$t>::from_le_bytes(raw)
            }
        }};
    }
    Some(match kind {
        Scalar::I8 => get!(i8, 1) as i64,
        Scalar::U8 => get!(u8, 1) as i64,
        Scalar::I16 => get!(i16, 2) as i64,
        Scalar::U16 => get!(u16, 2) as i64,
        Scalar::I32 => get!(i32, 4) as i64,
        Scalar::U32 => get!(u32, 4) as i64,
        Scalar::F32 | Scalar::F64 => {
            let v = read_f64::<BIG>(kind, bytes)?;
            if v.fract() != 0.0 || !(-9.0e15..=9.0e15).contains(&v) {
                return None;
            }
            v as i64
        }
    })
}

fn read_binary<const BIG: bool>(
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
fn read_vertex_rows<const BIG: bool>(
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
        for c in uvs.map_or(&[][..], |uvs| &uvs[v][..]) {
            buffer.extend_from_slice(&c.to_le_bytes());
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

/// Where the rows of the vertex element are, for writing a PLY back.
enum VertexRows {
    /// Binary rows of fixed size: the byte range of all of them and the row size.
    Binary {
        start: usize,
        end: usize,
        stride: usize,
    },
    /// ASCII: the 0-based index, among the body's non-empty lines, of the first vertex row.
    Ascii { first_row: usize },
}

/// The byte length of a binary element's rows starting at `pos` (rows with lists are walked).
fn binary_element_len<const BIG: bool>(
    bytes: &[u8],
    pos: usize,
    element: &Element,
) -> Option<usize> {
    if let Some(stride) = element.fixed_row_size() {
        return usize::try_from(element.count).ok()?.checked_mul(stride);
    }
    let mut at = pos;
    for _ in 0..element.count {
        for property in &element.properties {
            match property {
                Property::Scalar { kind, .. } => at = at.checked_add(kind.size())?,
                Property::List { count, item, .. } => {
                    let n = usize::try_from(read_int::<BIG>(*count, bytes.get(at..)?)?).ok()?;
                    at = at
                        .checked_add(count.size())?
                        .checked_add(n.checked_mul(item.size())?)?;
                }
            }
        }
    }
    (at <= bytes.len()).then_some(at - pos)
}

fn vertex_rows(bytes: &[u8], header: &Header, layout: &Layout) -> Option<VertexRows> {
    let before = &header.elements[..layout.vertex_element];
    match header.encoding {
        Encoding::Ascii => Some(VertexRows::Ascii {
            first_row: before
                .iter()
                .try_fold(0usize, |n, e| n.checked_add(usize::try_from(e.count).ok()?))?,
        }),
        encoding => {
            let mut pos = header.body_start;
            for element in before {
                pos += match encoding {
                    Encoding::BigEndian => binary_element_len::<true>(bytes, pos, element)?,
                    _ => binary_element_len::<false>(bytes, pos, element)?,
                };
            }
            let vertex = &header.elements[layout.vertex_element];
            let stride = vertex.fixed_row_size()?;
            let end = pos.checked_add(usize::try_from(vertex.count).ok()?.checked_mul(stride)?)?;
            (end <= bytes.len()).then_some(VertexRows::Binary {
                start: pos,
                end,
                stride,
            })
        }
    }
}

/// Whether a PLY file can be written back with new positions (its header reads and, in binary,
/// its vertex rows have a fixed size).
pub(crate) fn can_write_back(bytes: &[u8]) -> bool {
    let path = Path::new("");
    parse_header(bytes, path)
        .ok()
        .and_then(|header| {
            let layout = find_layout(&header, path).ok()?;
            vertex_rows(bytes, &header, &layout)
        })
        .is_some()
}

/// Property indices of nx, ny, nz when the vertex element has all three as scalars.
fn normal_properties(element: &Element) -> Option<[usize; 3]> {
    let find = |axis: &[u8]| {
        element
            .properties
            .iter()
            .position(|p| matches!(p, Property::Scalar { name, .. } if name == axis))
    };
    Some([find(b"nx")?, find(b"ny")?, find(b"nz")?])
}

/// The vertex properties that hold texture coordinates: s t, u v or texture_u texture_v.
fn uv_properties(element: &Element) -> Option<(usize, usize)> {
    let find = |name: &[u8]| {
        element
            .properties
            .iter()
            .position(|p| matches!(p, Property::Scalar { name: n, .. } if n == name))
    };
    [
        (b"s".as_slice(), b"t".as_slice()),
        (b"u", b"v"),
        (b"texture_u", b"texture_v"),
    ]
    .into_iter()
    .find_map(|(u, v)| Some((find(u)?, find(v)?)))
}

/// A value in a property's type and the file's byte order.
fn encode(kind: Scalar, big: bool, value: f32, out: &mut [u8]) {
    macro_rules! put {
        ($v:expr) => {{
            let v = $v;
            let raw = if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            };
            out[..raw.len()].copy_from_slice(&raw);
        }};
    }
    let whole = value.round() as f64;
    match kind {
        Scalar::F32 => put!(value),
        Scalar::F64 => put!(value as f64),
        Scalar::I8 => put!(whole.clamp(i8::MIN as f64, i8::MAX as f64) as i8),
        Scalar::U8 => put!(whole.clamp(0.0, u8::MAX as f64) as u8),
        Scalar::I16 => put!(whole.clamp(i16::MIN as f64, i16::MAX as f64) as i16),
        Scalar::U16 => put!(whole.clamp(0.0, u16::MAX as f64) as u16),
        Scalar::I32 => put!(whole.clamp(i32::MIN as f64, i32::MAX as f64) as i32),
        Scalar::U32 => put!(whole.clamp(0.0, u32::MAX as f64) as u32),
    }
}

/// A value as ASCII PLY text for a property's type.
fn ascii_value(kind: Scalar, value: f32) -> String {
    if kind.is_integer() {
        format!("{}", value.round() as i64)
    } else {
        format!("{value}")
    }
}

/// Write the PLY `source` back with `mesh`'s positions, in the file's own encoding: the header,
/// every other element and every other property come back byte for byte; x, y, z of moved
/// vertices are written in their declared types, nx, ny, nz (when present) turn with their
/// faces (see [`super::source`]), and texture coordinates (s t, u v or texture_u texture_v)
/// follow their vertex's slide along the surface ([`super::uv_follow`]; each vertex row is its
/// own texture coordinate, so a seam's rows follow each in its own chart). Returns whether the
/// file has texture coordinates per vertex (which then followed).
pub(crate) fn write_back(
    out: &mut dyn Write,
    bytes: &[u8],
    origin: &Origin,
    mesh: &TriMesh,
) -> std::io::Result<bool> {
    let invalid =
        |what: &str| std::io::Error::new(std::io::ErrorKind::InvalidData, what.to_string());
    let path = Path::new("");
    let header = parse_header(bytes, path).map_err(|e| invalid(&e.to_string()))?;
    let layout = find_layout(&header, path).map_err(|e| invalid(&e.to_string()))?;
    let rows = vertex_rows(bytes, &header, &layout)
        .ok_or_else(|| invalid("the vertex rows cannot be located"))?;
    let element = &header.elements[layout.vertex_element];
    let normal_props = normal_properties(element);
    let big = header.encoding == Encoding::BigEndian;

    // The file's positions, as the reader reads them.
    let before = &vertex_triples(bytes, &header, &rows, element, layout.xyz);
    let after: Vec<[f32; 3]> = (0..before.len())
        .map(|k| origin.welded(k).map_or(before[k], |w| mesh.positions[w]))
        .collect();
    let uv_props = uv_properties(element);
    // The faces, only needed to turn normals and move texture coordinates.
    let parsed = if (normal_props.is_some() || uv_props.is_some()) && before != &after {
        Some(parse(bytes, path).map_err(|e| invalid(&e.to_string()))?)
    } else {
        None
    };
    // Each row's texture coordinate as read, and where it moves.
    let followed = uv_props.zip(parsed.as_ref()).map(|((u, v), parsed)| {
        let read: Vec<[f32; 2]> = vertex_triples(bytes, &header, &rows, element, [u, v, v])
            .iter()
            .map(|t| [t[0], t[1]])
            .collect();
        let uvs: Vec<[f64; 2]> = read.iter().map(|t| t.map(f64::from)).collect();
        let triangles: Vec<super::uv_follow::UvTriangle> = parsed
            .mesh
            .triangles
            .iter()
            .map(|t| t.map(|v| [v, v]))
            .collect();
        let moved = super::uv_follow::follow(before, &after, &triangles, &uvs).moved;
        (read, moved)
    });
    // Per vertex: the area sums of its faces before and after; then slots (see `SmoothGroups`)
    // and the sums of each slot. Only when the file has normals.
    let slotted: Option<(Vec<usize>, NormalTurns)> =
        normal_props.zip(parsed.as_ref()).map(|(props, parsed)| {
            let values = vertex_triples(bytes, &header, &rows, element, props);
            let mut elements = NormalTurns::new(before.len());
            for t in &parsed.mesh.triangles {
                let corners = t.map(|v| v as usize);
                elements.add(
                    corners,
                    corners.map(|v| dvec(before[v])),
                    corners.map(|v| dvec(after[v])),
                );
            }
            let mut groups = SmoothGroups::default();
            let mut turns = NormalTurns::new(0);
            let slots = (0..before.len())
                .map(|k| {
                    let normal = values.get(k).copied().unwrap_or_default();
                    let slot = groups.slot_for(elements.area_before(k), origin.welded(k), normal);
                    turns.merge_slot(slot, &elements, k);
                    slot
                })
                .collect();
            (slots, turns)
        });
    // The properties to rewrite in a row: (property index, value).
    let changes = |k: usize, row_normal: &dyn Fn([usize; 3]) -> Option<[f32; 3]>| {
        let mut list: Vec<(usize, f32)> = Vec::new();
        if before[k] != after[k] && after[k].iter().all(|c| c.is_finite()) {
            list.extend(layout.xyz.iter().copied().zip(after[k]));
        }
        let turn = slotted
            .as_ref()
            .and_then(|(slots, turns)| turns.turn(slots[k]));
        if let (Some(props), Some(turn)) = (normal_props, turn) {
            if let Some(normal) = row_normal(props) {
                list.extend(props.iter().copied().zip(turn.normal(normal)));
            }
        }
        if let (Some((u, v)), Some((read, moved))) = (uv_props, &followed) {
            let uv = moved
                .get(k)
                .copied()
                .flatten()
                .map(|uv| uv.map(|c| c as f32));
            if let Some(uv) = uv.filter(|uv| Some(uv) != read.get(k)) {
                list.extend([(u, uv[0]), (v, uv[1])]);
            }
        }
        list
    };
    match rows {
        VertexRows::Binary { start, end, stride } => {
            let mut offsets = Vec::with_capacity(element.properties.len());
            let mut offset = 0;
            for property in &element.properties {
                let Property::Scalar { kind, .. } = property else {
                    return Err(invalid("the vertex rows have lists"));
                };
                offsets.push((offset, *kind));
                offset += kind.size();
            }
            let mut body = bytes[start..end].to_vec();
            for (k, row) in body.chunks_exact_mut(stride).enumerate().take(before.len()) {
                let read = |p: usize| {
                    let (at, kind) = offsets[p];
                    if big {
                        read_f32::<true>(kind, &row[at..])
                    } else {
                        read_f32::<false>(kind, &row[at..])
                    }
                };
                let normal =
                    |props: [usize; 3]| Some([read(props[0])?, read(props[1])?, read(props[2])?]);
                for (p, value) in changes(k, &normal) {
                    let (at, kind) = offsets[p];
                    encode(kind, big, value, &mut row[at..]);
                }
            }
            out.write_all(&bytes[..start])?;
            out.write_all(&body)?;
            out.write_all(&bytes[end..])?;
        }
        VertexRows::Ascii { first_row } => {
            out.write_all(&bytes[..header.body_start])?;
            let mut row = 0usize;
            for line in bytes[header.body_start..].split_inclusive(|&b| b == b'\n') {
                let text = line.strip_suffix(b"\n").unwrap_or(line);
                let text = text.strip_suffix(b"\r").unwrap_or(text);
                if tokens(text).next().is_none() {
                    out.write_all(line)?;
                    continue;
                }
                let k = row.wrapping_sub(first_row);
                row += 1;
                if k >= before.len() {
                    out.write_all(line)?;
                    continue;
                }
                let words: Vec<&[u8]> = tokens(text).collect();
                let read = |p: usize| words.get(p).and_then(|t| parse_f32(t));
                let normal =
                    |props: [usize; 3]| Some([read(props[0])?, read(props[1])?, read(props[2])?]);
                let list = changes(k, &normal);
                if list.is_empty() {
                    out.write_all(line)?;
                    continue;
                }
                let mut fields: Vec<String> = words
                    .iter()
                    .map(|w| String::from_utf8_lossy(w).into_owned())
                    .collect();
                for (p, value) in list {
                    if let (Some(field), Property::Scalar { kind, .. }) =
                        (fields.get_mut(p), &element.properties[p])
                    {
                        *field = ascii_value(*kind, value);
                    }
                }
                out.write_all(fields.join(" ").as_bytes())?;
                out.write_all(&line[text.len()..])?;
            }
        }
    }
    Ok(uv_props.is_some())
}

/// Three scalar properties (x y z, or nx ny nz) of every vertex row, read as the reader reads
/// coordinates (NaN where unreadable).
fn vertex_triples(
    bytes: &[u8],
    header: &Header,
    rows: &VertexRows,
    element: &Element,
    props: [usize; 3],
) -> Vec<[f32; 3]> {
    match *rows {
        VertexRows::Binary { start, end, stride } => {
            let mut offsets = [(0usize, Scalar::F32); 3];
            let mut offset = 0;
            for (p, property) in element.properties.iter().enumerate() {
                if let Property::Scalar { kind, .. } = property {
                    if let Some(axis) = props.iter().position(|&q| q == p) {
                        offsets[axis] = (offset, *kind);
                    }
                    offset += kind.size();
                }
            }
            let big = header.encoding == Encoding::BigEndian;
            bytes[start..end]
                .chunks_exact(stride)
                .map(|row| {
                    offsets.map(|(at, kind)| {
                        if big {
                            read_f32::<true>(kind, &row[at..])
                        } else {
                            read_f32::<false>(kind, &row[at..])
                        }
                        .unwrap_or(f32::NAN)
                    })
                })
                .collect()
        }
        VertexRows::Ascii { first_row } => lines(&bytes[header.body_start..])
            .map(|(_, line)| line)
            .filter(|line| tokens(line).next().is_some())
            .skip(first_row)
            .take(element.count as usize)
            .map(|line| {
                let words: Vec<&[u8]> = tokens(line).collect();
                props.map(|p| {
                    let kind = match element.properties.get(p) {
                        Some(Property::Scalar { kind, .. }) => *kind,
                        _ => Scalar::F32,
                    };
                    words
                        .get(p)
                        .and_then(|t| ascii_coordinate(kind, t))
                        .unwrap_or(f32::NAN)
                })
            })
            .collect(),
    }
}

/// Whether the PLY file's vertices have texture coordinates ([`uv_properties`]): what makes
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

/// The vertex colours (red green blue [alpha]) and UVs (s t, u v or texture_u texture_v) of a
/// PLY file, per welded vertex, for saving it in another format.
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
            gather.put(origin.welded(k), [uv[0], uv[1]]);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_bytes(bytes: &[u8]) -> Result<Parsed, IoError> {
        parse(bytes, Path::new("t.ply"))
    }

    /// A `tristrips` element (older scans) as triangles: one strip around a tetrahedron, a
    /// restart (-1), and a strip of two corners, which holds no triangle; ASCII and binary.
    #[test]
    fn reads_triangle_strips() {
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
    fn reads_ascii_with_extra_properties_and_polygons() {
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
    fn reads_big_endian_with_short_indices() {
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
    fn binary_round_trip_and_errors() {
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
