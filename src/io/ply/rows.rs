//! Where a kept PLY file's vertex rows are, and which of their properties hold normals and
//! texture coordinates: what writing it back and carrying its attributes read.

use super::header::{
    find_layout, parse_header, Element, Encoding, Header, Layout, Property, Scalar,
};
use super::read::{ascii_coordinate, read_f32, read_int};
use crate::io::text::{lines, tokens};
use std::path::Path;

/// Where the rows of the vertex element are, for writing a PLY back.
pub(super) enum VertexRows {
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
pub(super) fn binary_element_len<const BIG: bool>(
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

pub(super) fn vertex_rows(bytes: &[u8], header: &Header, layout: &Layout) -> Option<VertexRows> {
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
pub(super) fn normal_properties(element: &Element) -> Option<[usize; 3]> {
    let find = |axis: &[u8]| {
        element
            .properties
            .iter()
            .position(|p| matches!(p, Property::Scalar { name, .. } if name == axis))
    };
    Some([find(b"nx")?, find(b"ny")?, find(b"nz")?])
}

/// The vertex properties that hold texture coordinates: s t, u v or texture_u texture_v.
pub(super) fn uv_properties(element: &Element) -> Option<(usize, usize)> {
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

/// Three scalar properties (x y z, or nx ny nz) of every vertex row, read as the reader reads
/// coordinates (NaN where unreadable).
pub(super) fn vertex_triples(
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
