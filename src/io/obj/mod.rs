//! Wavefront OBJ: our own reader, written with `v` and `f` lines.
//!
//! Reading: `v x y z` (a fourth value is w and divides, six values are x y z r g b), `f` with
//! `v`, `v/vt`, `v//vn` or `v/vt/vn` corners, 1-based or negative (relative) indices, polygons
//! triangulated as fans from their first corner. Texture coordinates and normals are not needed
//! (fairing works on positions), so seams never split vertices; `l` polylines and `p` points are
//! skipped with a warning; everything else (`o`, `g`, `s`, `usemtl`, ...) is ignored.
//!
//! Why not tobj: tobj renumbers every object's vertices in the order its faces first use them,
//! so output files could not keep the input's vertex order (every other format does), and it
//! builds a `String` per line and a hash map per object, far above what parsing the lines
//! needs. This reader keeps the file's order and parses chunks of the file in parallel; indices are resolved after all chunks are read (negative ones relative
//! to the vertices before their line).
//!
//! Errors: the fast pass only says whether the file is good. When it is not, `read::locate` reads the
//! file again line by line to find the first line at fault and say what is wrong there, so every
//! message names the line.
//!
//! Writing: `v x y z` with Rust's shortest round-trip float formatting (`{}`), so every f32 reads
//!
//! The files: `read.rs` (the parallel reader and `locate`), `line.rs` (what the readers
//! of a kept file share: a line's words, a vertex, a corner's indices), `write.rs` (a bare mesh),
//! `attributes.rs` (what the file holds, per welded vertex and in plain words), `scene.rs` and
//! `materials.rs` (the file as a [`crate::io::scene::Scene`]), `write_scene.rs` and
//! `writeback.rs` (the file with new positions), `companions.rs` (its material libraries and
//! their images, copied beside a file written back into another folder).

mod attributes;
mod companions;
mod line;
mod materials;
mod read;
mod scene;
mod write;
mod write_scene;
mod writeback;

pub(crate) use attributes::{contents, has_texture_coordinates, vertex_attributes};
pub(crate) use companions::{companion_copies, stage_copies};
pub(crate) use read::parse;
pub(crate) use scene::scene;
pub(crate) use write::{write, write_with};
pub(crate) use write_scene::write_scene;
pub(crate) use writeback::write_back;
