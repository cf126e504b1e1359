//! Stanford PLY: our own parser for ASCII and binary (little and big endian) files; written as
//! binary little endian.
//!
//! Reading: the header is parsed into elements and properties; `vertex` must have scalar `x`, `y`
//! and `z` of any numeric type (doubles and integers are converted to f32; floats are taken bit for
//! bit); `face` must have a list property `vertex_indices` (or `vertex_index`, or its only list)
//! with any integer count and index type. Polygons are fan-triangulated; faces with fewer than
//! three corners are skipped with a warning. Other properties and elements are skipped (binary
//! lists are walked to find where the next row starts).
//!
//! Robustness: every length is checked before it is read; a binary element of fixed row size is
//! checked against the remaining file size before anything is allocated, and preallocation of
//! variable-size elements is capped by what the remaining bytes could hold, so a header claiming
//! 4 billion faces cannot allocate 4 billion of anything. Errors name the line (header, ASCII) or
//! the byte offset and element (binary).
//!
//! Speed: binary vertex rows of fixed size are read with precomputed offsets; faces are read row by
//! row without per-face allocation. ASCII rows are one per line (what every writer produces).

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
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header, IoError> {
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
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
                });
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
    face_element: Option<usize>,
    /// Property index of the index list in the face element.
    face_list: usize,
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
    let face_element = header.elements.iter().position(|e| e.name == b"face");
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
    if builder.short_faces > 0 {
        parsed.warnings.push(format!(
            "{} faces with fewer than 3 corners were skipped",
            builder.short_faces
        ));
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
                    Property::List { .. } => {
                        let count_token = words.next().unwrap_or_default();
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
                                corners.push(builder.index(row as usize, value).map_err(&at)?);
                            }
                            fan(&corners, builder);
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
                                let index = builder
                                    .index(row as usize, value)
                                    .map_err(|m| IoError::at_byte(path, at, m))?;
                                corners.push(index);
                            }
                            fan(&corners, builder);
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
    let index_type = if mesh.positions.len() > i32::MAX as usize {
        "uint"
    } else {
        "int"
    };
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment written by fairmesh\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar {index_type} vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )?;
    let mut buffer = Vec::with_capacity(1 << 16);
    for p in &mesh.positions {
        for c in p {
            buffer.extend_from_slice(&c.to_le_bytes());
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

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_bytes(bytes: &[u8]) -> Result<Parsed, IoError> {
        parse(bytes, Path::new("t.ply"))
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
