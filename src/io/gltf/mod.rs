//! glTF 2.0, JSON (`.gltf`) and binary (`.glb`): read with the `gltf` crate's document model and
//! our own bounds-checked accessor reading; written with `gltf-json`.
//!
//! Reading:
//! - The document is parsed and validated by `gltf` (JSON syntax errors give the line; schema
//!   errors the JSON path). Buffers come from the GLB BIN chunk, from base64 `data:` URIs (decoded
//!   here: the crate's `import` feature would pull in image decoders) or from files relative to
//!   the `.gltf` (not available from `load_from_bytes`).
//! - Every triangle primitive of every node of the default scene (or the first scene) is read,
//!   with the node's world transform (composed down the hierarchy in f64) applied; a transform with
//!   a negative determinant mirrors the mesh, so the triangles' winding is flipped back. Identity
//!   transforms are not applied at all, so untransformed positions stay bit-exact. If the file has
//!   no scene, every mesh is read once, untransformed, with a warning.
//! - Triangle strips and fans become triangles (glTF 2.0 spec, section 3.7.2.1); points and lines
//!   are skipped with a warning, or give an error if the file has no triangles at all.
//! - Accessors are read with every offset and length checked against the buffer view and buffer
//!   (the `gltf` crate's readers trust the file); positions may be float or (normalized) integers
//!   (KHR_mesh_quantization, which is read here: the `gltf` crate would refuse a file that
//!   requires it); indices u8/u16/u32. Sparse accessors are refused.
//! - Nodes must form a tree: a node reached twice (a cycle, or a shared child) is an error, which
//!   also bounds the work on hostile files.
//!
//! Writing: one buffer with positions, area-weighted unit vertex normals (a vertex whose normal
//! sums to zero takes an incident face's normal, or +Z) and u32 indices, three buffer views with
//! targets, position min/max, one mesh, one node, one default scene, asset.generator "fairmesh".
//! `.glb` is one atomic write; `.gltf` writes `<stem>.bin` and the JSON, both staged as temporary
//! files first and renamed only when both are complete.
//!
//! Writing back (`writeback.rs`): the document as loaded is kept ([`GltfSource`]) and written
//! again with the new positions, normals and texture coordinates.
//!
//! The files: `validate.rs` (what is refused before reading), `read.rs` and `read_accessors.rs`
//! (the scene into one triangle mesh), `source.rs` (the kept document and its accessors as JSON
//! values), `source_scene.rs` (the kept document as a [`crate::io::scene::Scene`] for writing
//! another format), `accessors.rs` (one accessor element's bytes: decoding, quantizing,
//! encoding), `buffers.rs` (the joined output buffer), `turn_normals.rs`, `writeback.rs`,
//! `images.rs` (images of a written-back document), `write.rs` (a bare mesh), `write_scene.rs`
//! (a scene with parts and materials) and `uri.rs` (base64 and percent coding).

mod accessors;
mod buffers;
mod images;
mod positions;
mod read;
mod read_accessors;
mod source;
mod source_scene;
mod texture;
mod turn_normals;
mod uri;
mod validate;
mod write;
mod write_scene;
mod writeback;

pub(crate) use read::parse;
pub(crate) use source::GltfSource;
pub(crate) use write::{
    write_glb, write_glb_with, write_gltf, write_gltf_embedded, write_gltf_with,
};
pub(crate) use write_scene::write_scene;
pub(crate) use writeback::write as write_back;
