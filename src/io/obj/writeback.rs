//! Writing an OBJ back with new positions: every line as it was but the `v` lines of moved
//! vertices, the `vn` lines whose faces moved (turned with them) and the `vt` lines that follow
//! their vertices' slide along the surface ([`crate::io::uv_follow`]).

use super::line::{resolve, split_ending, vertex_of};
use crate::io::normals::{dvec, NormalTurns};
use crate::io::origin::Origin;
use crate::io::text::tokens;
use crate::mesh::TriMesh;
use std::io::Write;

/// Write the OBJ `source` back with `mesh`'s positions: every line but the `v` lines of moved
/// vertices, the `vn` lines of normals whose faces moved and the `vt` lines of texture
/// coordinates whose vertex slid comes back byte for byte. A moved vertex is written `v x y z`
/// (shortest round-trip floats; a w is folded in), followed by the line's vertex colour if it had
/// one. Normals turn with their faces (see [`crate::io::normals`]); texture coordinates follow their
/// vertex's slide along the surface, so that the texture stays where it was
/// ([`crate::io::uv_follow`]), written `vt u v` (f32 shortest round-trip, a w kept as written).
/// Returns how many texture coordinates several moved vertices share (those stay).
pub(crate) fn write_back(
    out: &mut dyn Write,
    bytes: &[u8],
    origin: &Origin,
    mesh: &TriMesh,
) -> std::io::Result<usize> {
    // The file's own positions (as the reader read them), and each vertex's new position.
    let (before, normal_count, uvs) = file_values(bytes, origin.raw_vertices);
    let after: Vec<[f32; 3]> = (0..before.len())
        .map(|k| origin.welded(k).map_or(before[k], |w| mesh.positions[w]))
        .collect();
    let moved = |k: usize| before[k] != after[k] && !before[k][0].is_nan();
    let any_moved = (0..before.len()).any(moved);
    // One pass over the faces: the normals' turns and the triangles the texture coordinates
    // follow on, each where the file has them.
    let mut turns = (normal_count > 0 && any_moved).then(|| NormalTurns::new(normal_count));
    let mut triangles = (!uvs.is_empty() && any_moved).then(Vec::new);
    if turns.is_some() || triangles.is_some() {
        let (mut normal_corners, mut uv_corners) = (Vec::new(), Vec::new());
        for_each_face(bytes, |face| {
            if let Some(turns) = &mut turns {
                add_turns(turns, face, &before, &after, &mut normal_corners);
            }
            if let Some(triangles) = &mut triangles {
                let counts = (before.len(), uvs.len());
                add_uv_triangles(triangles, face, counts, &mut uv_corners);
            }
        });
    }
    let followed =
        triangles.map(|triangles| crate::io::uv_follow::follow(&before, &after, &triangles, &uvs));
    let edits = LineEdits {
        before: &before,
        after: &after,
        turns: turns.as_ref(),
        uvs: &uvs,
        followed: followed.as_ref().map(|f| f.moved.as_slice()),
    };
    edits.write(out, bytes)?;
    Ok(followed.map_or(0, |f| f.shared))
}

/// The file's `v` positions (NaN where a line cannot be read), how many `vn` lines it has, and
/// its `vt` coordinates (NaN where unreadable).
fn file_values(bytes: &[u8], vertices: usize) -> (Vec<[f32; 3]>, usize, Vec<[f64; 2]>) {
    let mut before: Vec<[f32; 3]> = Vec::with_capacity(vertices);
    let mut normal_count = 0usize;
    let mut uvs: Vec<[f64; 2]> = Vec::new();
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => before.push(vertex_of(words).unwrap_or([f32::NAN; 3])),
            Some(b"vn") => normal_count += 1,
            Some(b"vt") => uvs.push(texture_coordinate_of(words).unwrap_or([f64::NAN; 2])),
            _ => {}
        }
    }
    (before, normal_count, uvs)
}

/// What changes in the lines: the positions before and after, the normals' turns, and the
/// texture coordinates as read and where they moved.
struct LineEdits<'a> {
    before: &'a [[f32; 3]],
    after: &'a [[f32; 3]],
    turns: Option<&'a NormalTurns>,
    uvs: &'a [[f64; 2]],
    followed: Option<&'a [Option<[f64; 2]>]>,
}

impl LineEdits<'_> {
    /// Every line of `bytes` as it was, but the `v`, `vn` and `vt` lines that change.
    fn write(&self, out: &mut dyn Write, bytes: &[u8]) -> std::io::Result<()> {
        let (mut vertex, mut normal, mut texture_coordinate) = (0usize, 0usize, 0usize);
        for line in bytes.split_inclusive(|&b| b == b'\n') {
            let (text, ending) = split_ending(line);
            let mut words = tokens(text);
            let written = match words.next() {
                Some(b"v") => {
                    vertex += 1;
                    self.write_vertex(out, vertex - 1, words, ending)?
                }
                Some(b"vn") => {
                    normal += 1;
                    self.write_normal(out, normal - 1, words, ending)?
                }
                Some(b"vt") => {
                    texture_coordinate += 1;
                    self.write_texture_coordinate(out, texture_coordinate - 1, words, ending)?
                }
                _ => false,
            };
            if !written {
                out.write_all(line)?;
            }
        }
        Ok(())
    }

    /// Vertex `k`'s `v` line when it moved (a colour kept as written); whether it wrote one.
    fn write_vertex<'w>(
        &self,
        out: &mut dyn Write,
        k: usize,
        words: impl Iterator<Item = &'w [u8]>,
        ending: &[u8],
    ) -> std::io::Result<bool> {
        if self.before[k] == self.after[k] || self.before[k][0].is_nan() {
            return Ok(false);
        }
        let [x, y, z] = self.after[k];
        write!(out, "v {x} {y} {z}")?;
        let rest: Vec<&[u8]> = words.collect();
        if rest.len() == 6 {
            // x y z r g b: keep the colour as written.
            for colour in &rest[3..] {
                out.write_all(b" ")?;
                out.write_all(colour)?;
            }
        }
        out.write_all(ending)?;
        Ok(true)
    }

    /// Normal `k`'s `vn` line when it turns; whether it wrote one.
    fn write_normal<'w>(
        &self,
        out: &mut dyn Write,
        k: usize,
        words: impl Iterator<Item = &'w [u8]>,
        ending: &[u8],
    ) -> std::io::Result<bool> {
        let turn = self.turns.and_then(|t| t.turn(k));
        let (Some(turn), Some(n)) = (turn, vertex_of(words.take(3))) else {
            return Ok(false);
        };
        let [x, y, z] = turn.normal(n);
        write!(out, "vn {x} {y} {z}")?;
        out.write_all(ending)?;
        Ok(true)
    }

    /// Texture coordinate `k`'s `vt` line when it followed its vertex to another value (written
    /// as f32, what the reader reads; a w kept as written); whether it wrote one.
    fn write_texture_coordinate<'w>(
        &self,
        out: &mut dyn Write,
        k: usize,
        words: impl Iterator<Item = &'w [u8]>,
        ending: &[u8],
    ) -> std::io::Result<bool> {
        let uv = self.followed.and_then(|f| f.get(k).copied().flatten());
        let as_read = self.uvs[k].map(|c| c as f32);
        let written = uv.map(|uv| uv.map(|c| c as f32));
        let Some([u, v]) = written.filter(|&w| w != as_read) else {
            return Ok(false);
        };
        write!(out, "vt {u} {v}")?;
        for w in words.skip(2) {
            out.write_all(b" ")?;
            out.write_all(w)?;
        }
        out.write_all(ending)?;
        Ok(true)
    }
}

/// The (u, v) a `vt` line gives (a missing v reads 0, as the reader reads it); `None` if
/// unreadable.
fn texture_coordinate_of<'a>(mut words: impl Iterator<Item = &'a [u8]>) -> Option<[f64; 2]> {
    let u = crate::io::text::parse_f32(words.next()?)?;
    let v = words.next().map_or(Some(0.0), crate::io::text::parse_f32)?;
    Some([u as f64, v as f64])
}

/// Adds a face's triangles (a polygon as a fan from its first corner) of (vertex, texture
/// coordinate) corners, for [`crate::io::uv_follow::follow`]; a face with a corner that names no
/// vertex (of `counts.0`) is left out, a coordinate past `counts.1` is none.
fn add_uv_triangles(
    triangles: &mut Vec<crate::io::uv_follow::UvTriangle>,
    face: &[[Option<usize>; 3]],
    (vertex_count, uv_count): (usize, usize),
    corners: &mut Vec<[u32; 2]>,
) {
    corners.clear();
    for &[v, t, _] in face {
        match v {
            Some(v) if v < vertex_count => corners.push([
                v as u32,
                t.filter(|&t| t < uv_count)
                    .map_or(crate::io::uv_follow::NO_UV, |t| t as u32),
            ]),
            _ => return,
        }
    }
    for i in 1..corners.len().saturating_sub(1) {
        triangles.push([corners[0], corners[i], corners[i + 1]]);
    }
}

/// Adds a face to the turns of the `vn` normals: every corner `v//vn` or `v/vt/vn` adds the area
/// of its fan triangles to its normal (a face with a corner without both is left out).
fn add_turns(
    turns: &mut NormalTurns,
    face: &[[Option<usize>; 3]],
    before: &[[f32; 3]],
    after: &[[f32; 3]],
    corners: &mut Vec<(usize, usize)>,
) {
    corners.clear();
    for &[v, _, n] in face {
        match (v, n) {
            (Some(v), Some(n)) if v < before.len() => corners.push((v, n)),
            _ => return,
        }
    }
    for i in 1..corners.len().saturating_sub(1) {
        let fan = [corners[0], corners[i], corners[i + 1]];
        turns.add(
            fan.map(|(_, n)| n),
            fan.map(|(v, _)| dvec(before[v])),
            fan.map(|(v, _)| dvec(after[v])),
        );
    }
}

/// Calls `visit` with the corners of every `f` line: per corner its vertex, texture coordinate
/// and normal, as 0-based indices resolved against the items before the line (`None` where the
/// corner has none or names none).
fn for_each_face(bytes: &[u8], mut visit: impl FnMut(&[[Option<usize>; 3]])) {
    let (mut vertices, mut uvs, mut normals) = (0usize, 0usize, 0usize);
    let mut corners: Vec<[Option<usize>; 3]> = Vec::with_capacity(8);
    for line in bytes.split(|&b| b == b'\n') {
        let mut words = tokens(line);
        match words.next() {
            Some(b"v") => vertices += 1,
            Some(b"vt") => uvs += 1,
            Some(b"vn") => normals += 1,
            Some(b"f") => {
                corners.clear();
                for corner in words {
                    let mut parts = corner.split(|&b| b == b'/');
                    let mut index = |count: usize| {
                        parts
                            .next()
                            .filter(|t| !t.is_empty())
                            .and_then(|t| resolve(t, count))
                    };
                    corners.push([index(vertices), index(uvs), index(normals)]);
                }
                visit(&corners);
            }
            _ => {}
        }
    }
}
