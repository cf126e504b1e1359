//! Writing a PLY back with new positions: every byte as it was but the `x y z` of moved
//! vertices, their normals turned with their faces, and their texture coordinates following
//! their slide along the surface ([`crate::io::uv_follow`]).

use super::header::{find_layout, parse_header, Element, Encoding, Property, Scalar};
use super::read::{parse, read_f32};
use super::rows::{normal_properties, uv_properties, vertex_rows, vertex_triples, VertexRows};
use crate::io::normals::{dvec, NormalTurns, SmoothGroups};
use crate::io::origin::Origin;
use crate::io::text::{parse_f32, tokens};
use crate::mesh::TriMesh;
use std::io::Write;
use std::path::Path;

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
/// faces (see [`crate::io::normals`]), and texture coordinates (s t, u v or texture_u texture_v)
/// follow their vertex's slide along the surface ([`crate::io::uv_follow`]; each vertex row is its
/// own texture coordinate, so a seam's rows follow each in its own chart). Returns whether the
/// file has texture coordinates per vertex (which then followed).
pub(crate) fn write_back(
    out: &mut dyn Write,
    bytes: &[u8],
    origin: &Origin,
    mesh: &TriMesh,
) -> std::io::Result<bool> {
    let path = Path::new("");
    let header = parse_header(bytes, path).map_err(|e| invalid(&e.to_string()))?;
    let layout = find_layout(&header, path).map_err(|e| invalid(&e.to_string()))?;
    let rows = vertex_rows(bytes, &header, &layout)
        .ok_or_else(|| invalid("the vertex rows cannot be located"))?;
    let element = &header.elements[layout.vertex_element];
    let normal_props = normal_properties(element);

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
    let triangles = parsed
        .as_ref()
        .map(|parsed| parsed.mesh.triangles.as_slice());
    let triples = |props: [usize; 3]| vertex_triples(bytes, &header, &rows, element, props);
    let changes = RowChanges {
        before,
        after: &after,
        xyz: layout.xyz,
        normal_props,
        slotted: normal_props.zip(triangles).map(|(props, triangles)| {
            normal_slots(&triples(props), before, &after, triangles, origin)
        }),
        uv_props,
        followed: uv_props.zip(triangles).map(|((u, v), triangles)| {
            followed_uvs(&triples([u, v, v]), before, &after, triangles)
        }),
    };
    match rows {
        VertexRows::Binary { start, end, stride } => {
            let big = header.encoding == Encoding::BigEndian;
            let body = (start, end, stride);
            write_binary_rows(out, bytes, element, body, big, &changes)?
        }
        VertexRows::Ascii { first_row } => {
            let body = &bytes[header.body_start..];
            out.write_all(&bytes[..header.body_start])?;
            write_ascii_rows(out, body, first_row, element, &changes)?
        }
    }
    Ok(uv_props.is_some())
}

fn invalid(what: &str) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidData, what.to_string())
}

/// Each row's texture coordinate as read, and where it moves (`None`: it stays).
type FollowedUvs = (Vec<[f32; 2]>, Vec<Option<[f64; 2]>>);

/// Each row's texture coordinate as read (`read`, the first two of each triple), and where it
/// moves.
fn followed_uvs(
    read: &[[f32; 3]],
    before: &[[f32; 3]],
    after: &[[f32; 3]],
    triangles: &[[u32; 3]],
) -> FollowedUvs {
    let read: Vec<[f32; 2]> = read.iter().map(|t| [t[0], t[1]]).collect();
    let uvs: Vec<[f64; 2]> = read.iter().map(|t| t.map(f64::from)).collect();
    let triangles: Vec<crate::io::uv_follow::UvTriangle> =
        triangles.iter().map(|t| t.map(|v| [v, v])).collect();
    let moved = crate::io::uv_follow::follow(before, after, &triangles, &uvs).moved;
    (read, moved)
}

/// Per vertex: the area sums of its faces before and after; then each normal's slot (see
/// `SmoothGroups`; `values` are the file's normals) and the sums of each slot.
fn normal_slots(
    values: &[[f32; 3]],
    before: &[[f32; 3]],
    after: &[[f32; 3]],
    triangles: &[[u32; 3]],
    origin: &Origin,
) -> (Vec<usize>, NormalTurns) {
    let mut elements = NormalTurns::new(before.len());
    for t in triangles {
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
}

/// What changes in the vertex rows: the positions before and after, the normals' slots and
/// turns, and the texture coordinates as read and where they move.
struct RowChanges<'a> {
    before: &'a [[f32; 3]],
    after: &'a [[f32; 3]],
    xyz: [usize; 3],
    normal_props: Option<[usize; 3]>,
    slotted: Option<(Vec<usize>, NormalTurns)>,
    uv_props: Option<(usize, usize)>,
    followed: Option<FollowedUvs>,
}

impl RowChanges<'_> {
    /// The properties to rewrite in row `k`: (property index, value); `row_normal` reads the
    /// row's normal from its properties.
    fn of_row(
        &self,
        k: usize,
        row_normal: &dyn Fn([usize; 3]) -> Option<[f32; 3]>,
    ) -> Vec<(usize, f32)> {
        let (before, after) = (self.before, self.after);
        let mut list: Vec<(usize, f32)> = Vec::new();
        if before[k] != after[k] && after[k].iter().all(|c| c.is_finite()) {
            list.extend(self.xyz.iter().copied().zip(after[k]));
        }
        let turn = self
            .slotted
            .as_ref()
            .and_then(|(slots, turns)| turns.turn(slots[k]));
        if let (Some(props), Some(turn)) = (self.normal_props, turn) {
            if let Some(normal) = row_normal(props) {
                list.extend(props.iter().copied().zip(turn.normal(normal)));
            }
        }
        if let (Some((u, v)), Some((read, moved))) = (self.uv_props, &self.followed) {
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
    }
}

/// The file with its binary vertex rows (`bytes[start..end]`, `stride` bytes each) changed.
fn write_binary_rows(
    out: &mut dyn Write,
    bytes: &[u8],
    element: &Element,
    (start, end, stride): (usize, usize, usize),
    big: bool,
    changes: &RowChanges,
) -> std::io::Result<()> {
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
    let count = changes.before.len();
    for (k, row) in body.chunks_exact_mut(stride).enumerate().take(count) {
        let read = |p: usize| {
            let (at, kind) = offsets[p];
            if big {
                read_f32::<true>(kind, &row[at..])
            } else {
                read_f32::<false>(kind, &row[at..])
            }
        };
        let normal = |props: [usize; 3]| Some([read(props[0])?, read(props[1])?, read(props[2])?]);
        for (p, value) in changes.of_row(k, &normal) {
            let (at, kind) = offsets[p];
            encode(kind, big, value, &mut row[at..]);
        }
    }
    out.write_all(&bytes[..start])?;
    out.write_all(&body)?;
    out.write_all(&bytes[end..])
}

/// The ASCII body (after the header) with its vertex rows (from row `first_row`) changed; other
/// lines as they were.
fn write_ascii_rows(
    out: &mut dyn Write,
    body: &[u8],
    first_row: usize,
    element: &Element,
    changes: &RowChanges,
) -> std::io::Result<()> {
    let mut row = 0usize;
    for line in body.split_inclusive(|&b| b == b'\n') {
        let text = line.strip_suffix(b"\n").unwrap_or(line);
        let text = text.strip_suffix(b"\r").unwrap_or(text);
        if tokens(text).next().is_none() {
            out.write_all(line)?;
            continue;
        }
        let k = row.wrapping_sub(first_row);
        row += 1;
        if k >= changes.before.len() {
            out.write_all(line)?;
            continue;
        }
        let words: Vec<&[u8]> = tokens(text).collect();
        let read = |p: usize| words.get(p).and_then(|t| parse_f32(t));
        let normal = |props: [usize; 3]| Some([read(props[0])?, read(props[1])?, read(props[2])?]);
        let list = changes.of_row(k, &normal);
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
    Ok(())
}
