//! A PLY header: its format, elements and properties (a parser's state machine over the header
//! lines, which reads best in one piece), and the [`Layout`] of the vertex and face elements
//! the mesh is read from.

use crate::io::text::{lines, parse_i64, quote, tokens};
use crate::io::IoError;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
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
    pub(super) fn parse(name: &[u8]) -> Option<Scalar> {
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

    pub(super) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    pub(super) fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

#[derive(Debug)]
pub(super) enum Property {
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
    pub(super) fn name(&self) -> &[u8] {
        match self {
            Property::Scalar { name, .. } | Property::List { name, .. } => name,
        }
    }
}

#[derive(Debug)]
pub(super) struct Element {
    pub(super) name: Vec<u8>,
    pub(super) count: u64,
    pub(super) properties: Vec<Property>,
}

impl Element {
    /// Row size when every property is a scalar.
    pub(super) fn fixed_row_size(&self) -> Option<usize> {
        self.properties.iter().try_fold(0usize, |size, p| match p {
            Property::Scalar { kind, .. } => Some(size + kind.size()),
            Property::List { .. } => None,
        })
    }

    pub(super) fn label(&self) -> String {
        String::from_utf8_lossy(&self.name).into_owned()
    }
}

pub(super) struct Header {
    pub(super) encoding: Encoding,
    pub(super) elements: Vec<Element>,
    /// Byte offset where the body starts.
    pub(super) body_start: usize,
    /// Line number of the first body line (for ASCII).
    pub(super) body_line: usize,
    /// Lines before the first element that are no PLY keyword (old Blender exports write
    /// "Created by Blender3D 247 ..." there), read as comments: line number and text.
    pub(super) stray_lines: Vec<(usize, String)>,
}

/// Parses the header lines into the format, elements and properties, naming the line of any
/// error. A parser's state machine over the header lines, which reads best in one piece.
pub(super) fn parse_header(bytes: &[u8], path: &Path) -> Result<Header, IoError> {
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
pub(super) struct Layout {
    pub(super) vertex_element: usize,
    /// Property indices of x, y, z in the vertex element.
    pub(super) xyz: [usize; 3],
    /// The `face` element, or else a `tristrips` element (older scans, Stanford's tools).
    pub(super) face_element: Option<usize>,
    /// Property index of the index list in the face element.
    pub(super) face_list: usize,
    /// The face element is `tristrips`: each row is triangle strips, a negative index
    /// (-1) ending one strip and starting the next.
    pub(super) strips: bool,
}

pub(super) fn find_layout(header: &Header, path: &Path) -> Result<Layout, IoError> {
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
