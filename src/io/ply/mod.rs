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
//!
//! The files: `header.rs` (the header's elements and properties, and where `x y z` and the
//! faces are), `read.rs` (the ASCII and binary rows), `write.rs` (a bare mesh), `rows.rs` (where a
//! kept file's vertex rows and their properties are), `writeback.rs` (the file with new
//! positions) and `attributes.rs` (what the file holds, per welded vertex and in plain words).

mod attributes;
mod header;
mod read;
mod rows;
mod write;
mod writeback;

pub(crate) use attributes::{
    contents, has_face_texture_coordinates, has_texture_coordinates, vertex_attributes,
};
pub(crate) use read::parse;
pub(crate) use rows::can_write_back;
pub(crate) use write::{write, write_with};
pub(crate) use writeback::write_back;
