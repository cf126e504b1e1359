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

use super::atomic;
use super::carry::VertexAttributes;
use super::gltf_writeback::{GltfSource, PrimitiveRead};
use super::scene::{Scene, SceneVertex};
use super::source::SourceData;
use super::{IoError, Parsed};
use crate::mesh::TriMesh;
use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use ::gltf::Semantic;
use glam::{DMat4, DQuat, DVec3};
use gltf_json as json;
use std::borrow::Cow;
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

pub(crate) fn parse(bytes: &[u8], path: &Path, base_dir: Option<&Path>) -> Result<Parsed, IoError> {
    check_glb_header(bytes, path)?;
    let document = ::gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| older_gltf(bytes, path).unwrap_or_else(|| describe(e, path)))?;
    // (The document as plain JSON: the write-back keeps all of it, and `validate` reads the
    // extensions, which the `gltf` crate is built here without.)
    let json: serde_json::Value = json_text(bytes)
        .and_then(|text| serde_json::from_slice(text).ok())
        .ok_or_else(|| IoError::invalid(path, "the glTF JSON cannot be read again"))?;
    validate(document.as_json(), &json, path)?;
    let buffers = load_buffers(&document, path, base_dir)?;
    let mut reader = SceneReader {
        path,
        buffers: &buffers,
        mesh: TriMesh::default(),
        warnings: Vec::new(),
        skipped_points: 0,
        skipped_lines: 0,
        reads: Vec::new(),
    };
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    match scene {
        Some(scene) => reader.read_scene(&scene, document.nodes().len())?,
        None => {
            if document.meshes().len() > 0 {
                reader.warnings.push(
                    "the file has no scene: every mesh was read once, without transforms".into(),
                );
            }
            for mesh in document.meshes() {
                reader.read_mesh(&mesh, None, DMat4::IDENTITY)?;
            }
        }
    }
    let skipped = reader.skipped_points + reader.skipped_lines;
    if reader.mesh.triangles.is_empty() {
        let detail = if skipped > 0 {
            format!(
                ": the scene has only point and line primitives ({} point, {} line)",
                reader.skipped_points, reader.skipped_lines
            )
        } else {
            String::new()
        };
        return Err(IoError::invalid(path, format!("no triangles{detail}")));
    }
    if skipped > 0 {
        // "1 point primitive was skipped", "2 line primitives were skipped", or both.
        let parts: Vec<String> = [
            (reader.skipped_points, "point primitive", "point primitives"),
            (reader.skipped_lines, "line primitive", "line primitives"),
        ]
        .into_iter()
        .filter(|&(n, _, _)| n > 0)
        .map(|(n, one, many)| super::text::counted(n, one, many))
        .collect();
        let verb = if skipped == 1 { "was" } else { "were" };
        reader
            .warnings
            .push(format!("{} {verb} skipped", parts.join(" and ")));
    }
    let SceneReader {
        mesh,
        warnings,
        reads,
        ..
    } = reader;
    // Buffers read from elsewhere are owned already; the GLB's BIN chunk is taken, not copied.
    let owned: Vec<Option<Vec<u8>>> = buffers
        .into_iter()
        .map(|b| match b {
            Cow::Owned(data) => Some(data),
            Cow::Borrowed(_) => None,
        })
        .collect();
    let mut document = document;
    let mut blob = document.blob.take();
    let buffers = owned
        .into_iter()
        .map(|b| b.unwrap_or_else(|| blob.take().unwrap_or_default()))
        .collect();
    let source = GltfSource {
        json,
        buffers,
        reads,
    };
    Ok(Parsed {
        mesh,
        warnings,
        data: SourceData::Gltf(Box::new(source)),
    })
}

/// The JSON of a `.gltf` (the whole file) or of a GLB (its first chunk).
fn json_text(bytes: &[u8]) -> Option<&[u8]> {
    if !bytes.starts_with(b"glTF") {
        return Some(bytes);
    }
    let length = u32::from_le_bytes(bytes.get(12..16)?.try_into().ok()?) as usize;
    bytes.get(20..20usize.checked_add(length)?)
}

/// The GLB header's length, checked before the `gltf` crate sees it: gltf 1.4 subtracts the
/// header size from it unchecked (an overflow panic in debug builds, found by fuzzing).
fn check_glb_header(bytes: &[u8], path: &Path) -> Result<(), IoError> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let Some(declared) = bytes
        .get(8..12)
        .and_then(|b| b.try_into().ok())
        .map(u32::from_le_bytes)
    else {
        return Err(IoError::at_byte(
            path,
            0,
            format!(
                "GLB container: the file is truncated: the 12-byte header is cut off at {} bytes",
                bytes.len()
            ),
        ));
    };
    // Version 1 is glTF 1.0's container (KHR_binary_glTF), with another chunk layout.
    let version = u32::from_le_bytes(bytes[4..8].try_into().expect("4 bytes"));
    if version != 2 {
        return Err(IoError::at_byte(
            path,
            4,
            format!(
                "GLB container version {version}{}: fairmesh reads glTF 2.0 (GLB version 2); save \
                 the file again as glTF 2.0",
                if version == 1 { " (glTF 1.0)" } else { "" }
            ),
        ));
    }
    if declared < 12 {
        return Err(IoError::at_byte(
            path,
            8,
            format!("GLB container: the header declares a total length of {declared} bytes, less than the header itself"),
        ));
    }
    if declared as usize > bytes.len() {
        return Err(IoError::at_byte(
            path,
            8,
            format!(
                "GLB container: the file is truncated: the header declares {declared} bytes but the file has {}",
                bytes.len()
            ),
        ));
    }
    Ok(())
}

/// When glTF 2.0's JSON does not fit a file, whether it is a glTF 1.0 file (whose JSON holds
/// objects keyed by name where 2.0 has arrays): the error says so rather than where the first
/// array was not one.
fn older_gltf(bytes: &[u8], path: &Path) -> Option<IoError> {
    let json: serde_json::Value = serde_json::from_slice(json_text(bytes)?).ok()?;
    let version = json.get("asset")?.get("version")?.as_str()?;
    version.starts_with("1.").then(|| {
        IoError::at_element(
            path,
            "asset.version",
            format!(
                "glTF {version}: fairmesh reads glTF 2.0 (1.0 files are laid out differently); \
                 save the file again as glTF 2.0"
            ),
        )
    })
}

/// Required extensions fairmesh reads itself (the `gltf` crate, as built here, refuses them):
/// KHR_mesh_quantization only lets attributes be stored as integers, which the accessor reading
/// decodes (and the write-back encodes again); the others give a texture an image in another
/// format (KTX2, WebP, AVIF, DDS), and fairmesh never decodes images: it carries their bytes.
fn read_here(extension: &str) -> bool {
    extension == "KHR_mesh_quantization" || IMAGE_FORMATS.contains(&extension)
}

/// Texture extensions whose `source` names a texture's image in their format (the texture's own
/// `source`, when it has one, is a PNG or JPEG fallback).
pub(crate) const IMAGE_FORMATS: [&str; 4] = [
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_texture_avif",
    "MSFT_texture_dds",
];

/// A validation path `array[i]rest` (`textures[3].source`, `extensionsRequired[0] = "name"`) as
/// its top-level array, the index and the rest.
fn element(at: &str) -> Option<(&str, usize, &str)> {
    let (array, rest) = at.split_once('[')?;
    let (index, rest) = rest.split_once(']')?;
    Some((array, index.parse().ok()?, rest))
}

/// What a required extension that fairmesh cannot read holds, and what to do, for the error
/// that names it.
fn extension_content(name: &str) -> (&'static str, &'static str) {
    match name {
        "KHR_draco_mesh_compression" => (
            " (Draco-compressed geometry)",
            ": save the file again without mesh compression",
        ),
        "EXT_meshopt_compression" => (
            " (meshoptimizer-compressed buffers)",
            ": save the file again without compression",
        ),
        "KHR_technique_webgl" | "KHR_materials_common" => (" (glTF 1.0 materials)", ""),
        _ => ("", ""),
    }
}

/// What `gltf::Gltf::from_slice` validates, after a check that its validation needs: gltf-json
/// 1.4 looks up every primitive's POSITION accessor by index without a bounds check (a panic,
/// found by fuzzing). A required extension fairmesh cannot read is named first: its data (a
/// Draco-compressed mesh's accessors have no buffer views) fails the other checks too, which
/// would otherwise be the error.
fn validate(root: &json::Root, plain: &serde_json::Value, path: &Path) -> Result<(), IoError> {
    use json::validation::{Checked, Validate};
    let mut unsupported = (root.extensions_required.iter().enumerate()).filter(|(_, name)| {
        !read_here(name) && !json::extensions::ENABLED_EXTENSIONS.contains(&name.as_str())
    });
    if let Some((i, name)) = unsupported.next() {
        let others = match unsupported.count() {
            0 => String::new(),
            n => format!(" ({n} more required extensions fairmesh cannot read)"),
        };
        let (content, advice) = extension_content(name);
        return Err(IoError::at_element(
            path,
            format!("extensionsRequired[{i}]"),
            format!(
                "the file needs the extension {name}{content}, which fairmesh does not \
                 support{others}{advice}"
            ),
        ));
    }
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(json::mesh::Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= root.accessors.len()) {
                return Err(IoError::at_element(
                    path,
                    format!("meshes[{m}].primitives[{p}].attributes.POSITION"),
                    format!(
                        "invalid glTF: accessor {} does not exist (the file has {})",
                        index.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, json::Path::new, &mut |where_, what| {
        let at = where_();
        // The `gltf` crate calls every required extension it does not handle unsupported,
        // including those read here.
        let handled = match (what, element(at.as_str())) {
            (json::validation::Error::Unsupported, Some(("extensionsRequired", i, _))) => {
                (root.extensions_required.get(i)).is_some_and(|name| read_here(name))
            }
            // A texture whose only image is in another format has it in its extension.
            (json::validation::Error::Missing, Some(("textures", t, ".source"))) => {
                (plain["textures"][t]["extensions"].as_object()).is_some_and(|extensions| {
                    (extensions.keys()).any(|name| IMAGE_FORMATS.contains(&name.as_str()))
                })
            }
            _ => false,
        };
        if !handled {
            errors.push((at, what))
        }
    });
    if errors.is_empty() {
        Ok(())
    } else {
        Err(describe(::gltf::Error::Validation(errors), path))
    }
}

fn describe(error: ::gltf::Error, path: &Path) -> IoError {
    match error {
        ::gltf::Error::Deserialize(e) if e.line() > 0 => IoError::at_line(
            path,
            e.line(),
            format!("invalid glTF JSON (column {}): {e}", e.column()),
        ),
        ::gltf::Error::Deserialize(e) => IoError::invalid(path, format!("invalid glTF JSON: {e}")),
        ::gltf::Error::Binary(e) => {
            IoError::at_element(path, "GLB container", format!("invalid GLB: {e}"))
        }
        ::gltf::Error::Validation(errors) => {
            let count = errors.len();
            match errors.into_iter().next() {
                Some((where_, what)) => IoError::at_element(
                    path,
                    where_.to_string(),
                    format!("invalid glTF: {what} ({count} problems in all)"),
                ),
                None => IoError::invalid(path, "invalid glTF"),
            }
        }
        other => IoError::invalid(path, format!("invalid glTF: {other}")),
    }
}

fn load_buffers<'a>(
    document: &'a ::gltf::Gltf,
    path: &Path,
    base_dir: Option<&Path>,
) -> Result<Vec<Cow<'a, [u8]>>, IoError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let label = format!("buffer {}", buffer.index());
        let at = |message: String| IoError::at_element(path, label.clone(), message);
        let data: Cow<[u8]> = match buffer.source() {
            ::gltf::buffer::Source::Bin => match document.blob.as_deref() {
                Some(blob) => Cow::Borrowed(blob),
                None => return Err(at("has no uri and the file has no GLB BIN chunk".into())),
            },
            ::gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let Some((_, payload)) = rest.split_once(";base64,") else {
                        return Err(at("only base64 data: URIs are supported".into()));
                    };
                    Cow::Owned(decode_base64(payload.as_bytes()).map_err(|offset| {
                        at(format!("bad base64 at character {offset} of its data URI"))
                    })?)
                } else {
                    let relative = percent_decode(uri)
                        .ok_or_else(|| at(format!("cannot decode the uri {uri:?}")))?;
                    if relative.contains("://") || Path::new(&relative).is_absolute() {
                        return Err(at(format!("the uri {uri:?} is not a relative file path")));
                    }
                    let Some(dir) = base_dir else {
                        return Err(at(format!(
                            "refers to the external file {uri:?}, which cannot be resolved when loading from memory"
                        )));
                    };
                    let file = dir.join(&relative);
                    Cow::Owned(
                        std::fs::read(&file)
                            .map_err(|e| at(format!("cannot read {}: {e}", file.display())))?,
                    )
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(at(format!(
                "has {} bytes but its byteLength is {}",
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// Standard base64 (RFC 4648), padding optional. On error, the offset of the bad character.
pub(crate) fn decode_base64(text: &[u8]) -> Result<Vec<u8>, usize> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    };
    let end = text.iter().rposition(|&c| c != b'=').map_or(0, |i| i + 1);
    if text.len() - end > 2 {
        return Err(end);
    }
    let mut out = Vec::with_capacity(end / 4 * 3 + 3);
    let mut bits = 0u32;
    let mut count = 0u32;
    for (offset, &c) in text[..end].iter().enumerate() {
        bits = (bits << 6) | value(c).ok_or(offset)?;
        count += 1;
        if count == 4 {
            out.extend_from_slice(&bits.to_be_bytes()[1..]);
            bits = 0;
            count = 0;
        }
    }
    match count {
        0 => {}
        2 => out.push((bits >> 4) as u8),
        3 => out.extend_from_slice(&((bits >> 2) as u16).to_be_bytes()),
        _ => return Err(end),
    }
    Ok(out)
}

/// Decode `%XX` escapes (UTF-8); `None` for a bad escape or invalid UTF-8.
pub(crate) fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Encode everything but unreserved characters, for a file name used as a URI.
pub(crate) fn percent_encode(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for b in name.bytes() {
        if b.is_ascii_alphanumeric() || b"-_.~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

struct SceneReader<'a> {
    path: &'a Path,
    buffers: &'a [Cow<'a, [u8]>],
    mesh: TriMesh,
    warnings: Vec<String>,
    skipped_points: usize,
    skipped_lines: usize,
    /// Which POSITION accessor elements became which parser vertices, for writing back.
    reads: Vec<PrimitiveRead>,
}

fn local_matrix(node: &::gltf::Node) -> DMat4 {
    match node.transform() {
        ::gltf::scene::Transform::Matrix { matrix } => {
            DMat4::from_cols_array_2d(&matrix.map(|col| col.map(f64::from)))
        }
        ::gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let [x, y, z, w] = rotation.map(f64::from);
            let q = DQuat::from_xyzw(x, y, z, w);
            let q = if q.length_squared() > 0.0 {
                q.normalize()
            } else {
                DQuat::IDENTITY
            };
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                q,
                DVec3::from_array(translation.map(f64::from)),
            )
        }
    }
}

impl SceneReader<'_> {
    fn read_scene(&mut self, scene: &::gltf::Scene, node_count: usize) -> Result<(), IoError> {
        let mut visited = vec![false; node_count];
        let mut stack: Vec<(::gltf::Node, DMat4)> =
            scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
        stack.reverse();
        while let Some((node, parent)) = stack.pop() {
            let seen = visited.get_mut(node.index()).ok_or_else(|| {
                IoError::at_element(
                    self.path,
                    format!("node {}", node.index()),
                    "does not exist",
                )
            })?;
            if *seen {
                return Err(IoError::at_element(
                    self.path,
                    format!("node {}", node.index()),
                    format!(
                        "is reached twice from scene {} (glTF nodes must form a tree)",
                        scene.index()
                    ),
                ));
            }
            *seen = true;
            let world = parent * local_matrix(&node);
            if let Some(mesh) = node.mesh() {
                self.read_mesh(&mesh, Some(node.index()), world)?;
            }
            let children: Vec<_> = node.children().collect();
            for child in children.into_iter().rev() {
                stack.push((child, world));
            }
        }
        Ok(())
    }

    fn read_mesh(
        &mut self,
        mesh: &::gltf::Mesh,
        node: Option<usize>,
        world: DMat4,
    ) -> Result<(), IoError> {
        for primitive in mesh.primitives() {
            let label = match node {
                Some(n) => format!(
                    "node {n}, mesh {}, primitive {}",
                    mesh.index(),
                    primitive.index()
                ),
                None => format!("mesh {}, primitive {}", mesh.index(), primitive.index()),
            };
            let at = |message: String| IoError::at_element(self.path, label.clone(), message);
            match primitive.mode() {
                Mode::Points => {
                    self.skipped_points += 1;
                    continue;
                }
                Mode::Lines | Mode::LineLoop | Mode::LineStrip => {
                    self.skipped_lines += 1;
                    continue;
                }
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => {}
            }
            let Some(position_accessor) = primitive.get(&Semantic::Positions) else {
                self.warnings
                    .push(format!("{label}: no POSITION attribute, skipped"));
                continue;
            };
            let mut positions = read_positions(&position_accessor, self.buffers).map_err(|m| {
                at(format!(
                    "POSITION accessor {}: {m}",
                    position_accessor.index()
                ))
            })?;
            if world != DMat4::IDENTITY {
                for p in &mut positions {
                    let q = world.transform_point3(DVec3::from_array(p.map(f64::from)));
                    *p = q.as_vec3().to_array();
                }
            }
            if let Some((v, _)) = positions
                .iter()
                .enumerate()
                .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
            {
                return Err(at(format!(
                    "vertex {v} has a NaN or infinite coordinate{}",
                    if world != DMat4::IDENTITY {
                        " (after the node's transform)"
                    } else {
                        ""
                    }
                )));
            }
            let vertex_count = positions.len();
            let corners: Vec<u32> = match primitive.indices() {
                Some(accessor) => {
                    let indices = read_indices(&accessor, self.buffers)
                        .map_err(|m| at(format!("index accessor {}: {m}", accessor.index())))?;
                    if let Some((k, i)) = indices
                        .iter()
                        .enumerate()
                        .find(|(_, &i)| i as usize >= vertex_count)
                    {
                        return Err(at(format!(
                            "index accessor {}, element {k}: index {i} is out of range (the POSITION accessor has {vertex_count} vertices)",
                            accessor.index()
                        )));
                    }
                    indices
                }
                None => {
                    let n = u32::try_from(vertex_count)
                        .map_err(|_| at("too many vertices for 32-bit indices".into()))?;
                    (0..n).collect()
                }
            };
            let base = u32::try_from(self.mesh.positions.len())
                .ok()
                .filter(|b| (*b as u64) + vertex_count as u64 <= u32::MAX as u64)
                .ok_or_else(|| at("too many vertices in all for 32-bit indices".into()))?;
            let flip = world.determinant() < 0.0;
            let before = self.mesh.triangles.len();
            let mut push = |t: [u32; 3]| {
                let t = if flip { [t[0], t[2], t[1]] } else { t };
                self.mesh.triangles.push(t.map(|v| v + base));
            };
            match primitive.mode() {
                Mode::TriangleStrip => {
                    for (i, w) in corners.windows(3).enumerate() {
                        push(if i % 2 == 0 {
                            [w[0], w[1], w[2]]
                        } else {
                            [w[0], w[2], w[1]]
                        });
                    }
                }
                Mode::TriangleFan => {
                    if let Some((&first, rest)) = corners.split_first() {
                        for w in rest.windows(2) {
                            push([w[0], w[1], first]);
                        }
                    }
                }
                _ => {
                    for c in corners.chunks_exact(3) {
                        push([c[0], c[1], c[2]]);
                    }
                    if !corners.len().is_multiple_of(3) {
                        self.warnings.push(format!(
                            "{label}: {} indices is not a multiple of 3; the last {} were ignored",
                            corners.len(),
                            corners.len() % 3
                        ));
                    }
                }
            }
            if self.mesh.triangles.len() > before {
                self.reads.push(PrimitiveRead {
                    accessor: position_accessor.index(),
                    mesh: mesh.index(),
                    primitive: primitive.index(),
                    node,
                    raw_start: base as usize,
                    count: positions.len(),
                    world,
                });
                self.mesh.positions.extend_from_slice(&positions);
            }
        }
        Ok(())
    }
}

/// The bytes of an accessor's elements, checked: `(data, stride, element size)`, `data` starting
/// at the first element and holding all `count` of them.
fn accessor_bytes<'a>(
    accessor: &::gltf::Accessor,
    buffers: &'a [Cow<'a, [u8]>],
) -> Result<(&'a [u8], usize, usize), String> {
    if accessor.sparse().is_some() {
        return Err("sparse accessors are not supported".into());
    }
    let view = accessor
        .view()
        .ok_or("has no bufferView (all zeros), which gives no usable geometry")?;
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or("its buffer does not exist")?;
    let element = accessor
        .data_type()
        .size()
        .checked_mul(accessor.dimensions().multiplicity())
        .ok_or("element size overflows")?;
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "buffer view {} has byteStride {stride}, less than the element size {element}",
            view.index()
        ));
    }
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&end| end <= buffer.len())
        .ok_or_else(|| {
            format!(
                "buffer view {} (bytes {}..+{}) runs past the end of buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                buffer.len()
            )
        })?;
    let view_bytes = buffer.get(view.offset()..view_end).unwrap_or_default();
    let count = accessor.count();
    let needed = match count {
        0 => 0,
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|b| b.checked_add(element))
            .and_then(|b| b.checked_add(accessor.offset()))
            .ok_or("its size overflows")?,
    };
    if needed > view_bytes.len() {
        return Err(format!(
            "{count} elements at byteOffset {} need {needed} bytes but buffer view {} has {}",
            accessor.offset(),
            view.index(),
            view_bytes.len()
        ));
    }
    let data = view_bytes
        .get(accessor.offset().min(needed)..needed)
        .unwrap_or_default();
    Ok((data, stride, element))
}

fn component_f32(kind: DataType, normalized: bool, b: &[u8]) -> Option<f32> {
    macro_rules! get {
        ($t:ty, $n:literal) => {
            <$t>::from_le_bytes(b.get(..$n)?.try_into().ok()?)
        };
    }
    Some(match (kind, normalized) {
        (DataType::F32, _) => get!(f32, 4),
        (DataType::I8, true) => (get!(i8, 1) as f32 / 127.0).max(-1.0),
        (DataType::U8, true) => get!(u8, 1) as f32 / 255.0,
        (DataType::I16, true) => (get!(i16, 2) as f32 / 32767.0).max(-1.0),
        (DataType::U16, true) => get!(u16, 2) as f32 / 65535.0,
        (DataType::U32, true) => (get!(u32, 4) as f64 / u32::MAX as f64) as f32,
        (DataType::I8, false) => get!(i8, 1) as f32,
        (DataType::U8, false) => get!(u8, 1) as f32,
        (DataType::I16, false) => get!(i16, 2) as f32,
        (DataType::U16, false) => get!(u16, 2) as f32,
        (DataType::U32, false) => get!(u32, 4) as f32,
    })
}

fn read_positions(
    accessor: &::gltf::Accessor,
    buffers: &[Cow<[u8]>],
) -> Result<Vec<[f32; 3]>, String> {
    if accessor.dimensions() != Dimensions::Vec3 {
        return Err(format!(
            "type is {:?}, expected VEC3",
            accessor.dimensions()
        ));
    }
    let (data, stride, _) = accessor_bytes(accessor, buffers)?;
    let kind = accessor.data_type();
    let size = kind.size();
    let normalized = accessor.normalized();
    let mut positions = Vec::with_capacity(accessor.count());
    for k in 0..accessor.count() {
        let mut p = [0f32; 3];
        for (axis, c) in p.iter_mut().enumerate() {
            *c = data
                .get(k * stride + axis * size..)
                .and_then(|b| component_f32(kind, normalized, b))
                .ok_or_else(|| format!("element {k} is out of bounds"))?;
        }
        positions.push(p);
    }
    Ok(positions)
}

fn read_indices(accessor: &::gltf::Accessor, buffers: &[Cow<[u8]>]) -> Result<Vec<u32>, String> {
    if accessor.dimensions() != Dimensions::Scalar {
        return Err(format!(
            "type is {:?}, expected SCALAR",
            accessor.dimensions()
        ));
    }
    let kind = accessor.data_type();
    if !matches!(kind, DataType::U8 | DataType::U16 | DataType::U32) {
        return Err(format!("component type {kind:?} is not an index type"));
    }
    let (data, stride, _) = accessor_bytes(accessor, buffers)?;
    let mut indices = Vec::with_capacity(accessor.count());
    for k in 0..accessor.count() {
        let b = data
            .get(k * stride..)
            .ok_or_else(|| format!("element {k} is out of bounds"))?;
        let index = match kind {
            DataType::U8 => b.first().map(|&x| x as u32),
            DataType::U16 => b.get(..2).map(|x| u16::from_le_bytes([x[0], x[1]]) as u32),
            _ => b
                .get(..4)
                .map(|x| u32::from_le_bytes([x[0], x[1], x[2], x[3]])),
        }
        .ok_or_else(|| format!("element {k} is out of bounds"))?;
        indices.push(index);
    }
    Ok(indices)
}

/// Area-weighted unit vertex normals in f32; never NaN (see the file's doc comment).
pub(crate) fn unit_vertex_normals(mesh: &TriMesh) -> Vec<[f32; 3]> {
    let mut sums = vec![DVec3::ZERO; mesh.positions.len()];
    let mut fallback = vec![DVec3::ZERO; mesh.positions.len()];
    for t in 0..mesh.triangles.len() {
        let n = mesh.face_normal(t);
        let unit = n.normalize_or_zero();
        for &v in &mesh.triangles[t] {
            sums[v as usize] += n;
            if fallback[v as usize] == DVec3::ZERO {
                fallback[v as usize] = unit;
            }
        }
    }
    sums.iter()
        .zip(&fallback)
        .map(|(sum, fallback)| {
            let n = sum.normalize_or_zero();
            let n = if n != DVec3::ZERO {
                n
            } else if *fallback != DVec3::ZERO {
                *fallback
            } else {
                DVec3::Z
            };
            n.as_vec3().to_array()
        })
        .collect()
}

/// The glTF document and its binary buffer for `mesh`. `uri` names the buffer file (`.gltf`),
/// or is `None` for the GLB BIN chunk.
fn build(mesh: &TriMesh, uri: Option<String>) -> std::io::Result<(json::Root, Vec<u8>)> {
    build_with(mesh, uri, &VertexAttributes::default())
}

/// The document and binary buffer of a bare mesh, with TEXCOORD_0 and COLOR_0 where `extra`
/// has them (one value per vertex of `mesh`; ignored otherwise).
fn build_with(
    mesh: &TriMesh,
    uri: Option<String>,
    extra: &VertexAttributes,
) -> std::io::Result<(json::Root, Vec<u8>)> {
    use json::validation::{Checked::Valid, USize64};
    let too_big =
        || std::io::Error::new(std::io::ErrorKind::InvalidInput, "mesh too large for glTF");
    let n = mesh.positions.len();
    let m = mesh.triangles.len();
    let normals = unit_vertex_normals(mesh);
    let positions_len = n.checked_mul(12).ok_or_else(too_big)?;
    let indices_len = m.checked_mul(12).ok_or_else(too_big)?;
    let uvs = extra.uvs.as_ref().filter(|uvs| uvs.len() == n);
    let colours = extra.colours.as_ref().filter(|colours| colours.len() == n);
    let uvs_len = if uvs.is_some() { n * 8 } else { 0 };
    let colours_len = if colours.is_some() { n * 16 } else { 0 };
    let total = positions_len
        .checked_mul(2)
        .and_then(|b| b.checked_add(indices_len))
        .and_then(|b| b.checked_add(uvs_len + colours_len))
        .filter(|&t| t <= u32::MAX as usize - 1024)
        .ok_or_else(too_big)?;
    let mut bin = Vec::with_capacity(total);
    for p in &mesh.positions {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for p in &normals {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        for v in t {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    for value in uvs.into_iter().flatten().flatten() {
        bin.extend_from_slice(&value.to_le_bytes());
    }
    for value in colours.into_iter().flatten().flatten() {
        bin.extend_from_slice(&value.to_le_bytes());
    }
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in &mesh.positions {
        for axis in 0..3 {
            min[axis] = min[axis].min(p[axis]);
            max[axis] = max[axis].max(p[axis]);
        }
    }

    let mut root = json::Root::default();
    root.asset.generator = Some("fairmesh".into());
    let buffer = root.push(json::Buffer {
        byte_length: USize64(total as u64),
        name: None,
        uri,
        extensions: Default::default(),
        extras: Default::default(),
    });
    let view = |offset: usize, length: usize, target: json::buffer::Target| json::buffer::View {
        buffer,
        byte_length: USize64(length as u64),
        byte_offset: Some(USize64(offset as u64)),
        byte_stride: None,
        name: None,
        target: Some(Valid(target)),
        extensions: Default::default(),
        extras: Default::default(),
    };
    let position_view = view(0, positions_len, json::buffer::Target::ArrayBuffer);
    let normal_view = view(
        positions_len,
        positions_len,
        json::buffer::Target::ArrayBuffer,
    );
    let index_view = view(
        2 * positions_len,
        indices_len,
        json::buffer::Target::ElementArrayBuffer,
    );
    let position_view = root.push(position_view);
    let normal_view = root.push(normal_view);
    let index_view = root.push(index_view);
    let accessor = |view, count: usize, component, type_, bounds: Option<([f32; 3], [f32; 3])>| {
        json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(count as u64),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: Default::default(),
            extras: Default::default(),
            type_: Valid(type_),
            min: bounds.map(|(lo, _)| json::Value::from(lo.to_vec())),
            max: bounds.map(|(_, hi)| json::Value::from(hi.to_vec())),
            name: None,
            normalized: false,
            sparse: None,
        }
    };
    let positions = root.push(accessor(
        position_view,
        n,
        json::accessor::ComponentType::F32,
        json::accessor::Type::Vec3,
        Some((min, max)),
    ));
    let normals = root.push(accessor(
        normal_view,
        n,
        json::accessor::ComponentType::F32,
        json::accessor::Type::Vec3,
        None,
    ));
    let indices = root.push(accessor(
        index_view,
        3 * m,
        json::accessor::ComponentType::U32,
        json::accessor::Type::Scalar,
        None,
    ));
    let mut attributes: std::collections::BTreeMap<_, _> = [
        (Valid(json::mesh::Semantic::Positions), positions),
        (Valid(json::mesh::Semantic::Normals), normals),
    ]
    .into_iter()
    .collect();
    let mut offset = 2 * positions_len + indices_len;
    for (present, length, semantic, type_) in [
        (
            uvs.is_some(),
            uvs_len,
            json::mesh::Semantic::TexCoords(0),
            json::accessor::Type::Vec2,
        ),
        (
            colours.is_some(),
            colours_len,
            json::mesh::Semantic::Colors(0),
            json::accessor::Type::Vec4,
        ),
    ] {
        if !present {
            continue;
        }
        let view = root.push(view(offset, length, json::buffer::Target::ArrayBuffer));
        offset += length;
        let values = root.push(accessor(
            view,
            n,
            json::accessor::ComponentType::F32,
            type_,
            None,
        ));
        attributes.insert(Valid(semantic), values);
    }
    let primitive = json::mesh::Primitive {
        attributes,
        extensions: Default::default(),
        extras: Default::default(),
        indices: Some(indices),
        material: None,
        mode: Valid(json::mesh::Mode::Triangles),
        targets: None,
    };
    let mesh_index = root.push(json::Mesh {
        extensions: Default::default(),
        extras: Default::default(),
        name: None,
        primitives: vec![primitive],
        weights: None,
    });
    let node = root.push(json::Node {
        mesh: Some(mesh_index),
        ..Default::default()
    });
    let scene = root.push(json::Scene {
        extensions: Default::default(),
        extras: Default::default(),
        name: None,
        nodes: vec![node],
    });
    root.scene = Some(scene);
    Ok((root, bin))
}

pub(crate) fn write_glb(out: &mut dyn Write, mesh: &TriMesh) -> std::io::Result<()> {
    write_glb_with(out, mesh, &VertexAttributes::default())
}

/// A GLB of `mesh` with the per-vertex UVs and colours of `extra`.
pub(crate) fn write_glb_with(
    out: &mut dyn Write,
    mesh: &TriMesh,
    extra: &VertexAttributes,
) -> std::io::Result<()> {
    let (root, bin) = build_with(mesh, None, extra)?;
    let json_bytes = json::serialize::to_vec(&root).map_err(std::io::Error::other)?;
    write_glb_container(out, json_bytes, &bin)
}

/// A GLB container: the header, the JSON chunk (padded with spaces) and, when `bin` is not empty,
/// the BIN chunk (padded with zeros).
pub(crate) fn write_glb_container(
    out: &mut dyn Write,
    mut json_bytes: Vec<u8>,
    bin: &[u8],
) -> std::io::Result<()> {
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let padded_bin = bin.len().div_ceil(4) * 4;
    let bin_chunk = if bin.is_empty() { 0 } else { 8 + padded_bin };
    let total = u32::try_from(12 + 8 + json_bytes.len() + bin_chunk).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "GLB files hold at most 4 GiB",
        )
    })?;
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&total.to_le_bytes())?;
    out.write_all(&(json_bytes.len() as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(&json_bytes)?;
    if !bin.is_empty() {
        out.write_all(&(padded_bin as u32).to_le_bytes())?;
        out.write_all(b"BIN\0")?;
        out.write_all(bin)?;
        out.write_all(&[0u8; 3][..padded_bin - bin.len()])?;
    }
    Ok(())
}

/// A `.gltf` with its buffer embedded as a base64 data: URI, for writers that are not files.
pub(crate) fn write_gltf_embedded(out: &mut dyn Write, mesh: &TriMesh) -> std::io::Result<()> {
    let (mut root, bin) = build(mesh, None)?;
    if let Some(buffer) = root.buffers.first_mut() {
        buffer.uri = Some(format!(
            "data:application/octet-stream;base64,{}",
            encode_base64(&bin)
        ));
    }
    let json_bytes = json::serialize::to_vec_pretty(&root).map_err(std::io::Error::other)?;
    out.write_all(&json_bytes)
}

/// Standard base64 (RFC 4648) with padding.
fn encode_base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let bits = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for (i, shift) in [18, 12, 6, 0].into_iter().enumerate() {
            if i <= chunk.len() {
                out.push(ALPHABET[(bits >> shift & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Write `path` (.gltf) and `<stem>.bin` beside it: both are staged, then renamed into place.
pub(crate) fn write_gltf(path: &Path, mesh: &TriMesh) -> Result<(), IoError> {
    write_gltf_with(path, mesh, &VertexAttributes::default())
}

/// [`write_gltf`] with the per-vertex UVs and colours of `extra`.
pub(crate) fn write_gltf_with(
    path: &Path,
    mesh: &TriMesh,
    extra: &VertexAttributes,
) -> Result<(), IoError> {
    let bin_path = super::gltf_bin_path(path);
    let bin_name = bin_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh.bin".into());
    let (root, bin) =
        build_with(mesh, Some(percent_encode(&bin_name)), extra).map_err(|source| {
            IoError::Write {
                path: path.to_owned(),
                source,
            }
        })?;
    let json_bytes = json::serialize::to_vec_pretty(&root).map_err(|e| IoError::Write {
        path: path.to_owned(),
        source: std::io::Error::other(e),
    })?;
    let staged_bin = atomic::stage(&bin_path, |w| w.write_all(&bin))?;
    let staged_json = atomic::stage(path, |w| w.write_all(&json_bytes))?;
    staged_bin.commit()?;
    staged_json.commit()
}

/// A glTF of `scene` (see [`super::scene`]): per part a node (named by the part's object) and a
/// mesh (named by its group) with one primitive per material, each with its own POSITION,
/// NORMAL, TEXCOORD_0 and COLOR_0 (where the source had them) and u32 indices; a part with both
/// an object and a group name hangs under a node named by the object (an OBJ's `o` over its `g`s);
/// materials with pbrMetallicRoughness from the base colour, metallic, roughness and base colour
/// texture. A GLB embeds every image; a `.gltf` refers to image files beside it (copied there,
/// or written out when the source held them inside) and to `<stem>.bin`. Each primitive's
/// vertices follow `mesh`'s vertex order, so that a one-part, one-material file loads back as
/// `mesh` itself, vertex for vertex (several parts load back part by part).
pub(crate) fn write_scene(
    path: &Path,
    glb: bool,
    scene: &mut Scene,
    mesh: &TriMesh,
) -> Result<(), IoError> {
    use serde_json::{json, Value};
    scene.fill_missing_normals(mesh);
    let too_big = || IoError::Refused {
        path: path.to_owned(),
        message: "the mesh is too large for glTF (4 GiB)".into(),
    };
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let mut add_view = |bin: &mut Vec<u8>, bytes: &[u8], target: Option<u32>| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let mut view = json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()});
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        bin.extend_from_slice(bytes);
        views.push(view);
        views.len() - 1
    };
    fn floats<const N: usize>(values: &[[f32; N]]) -> Vec<u8> {
        values
            .iter()
            .flatten()
            .flat_map(|c| c.to_le_bytes())
            .collect()
    }
    let mut meshes: Vec<Value> = Vec::new();
    let mut nodes: Vec<Value> = Vec::new();
    let mut roots: Vec<usize> = Vec::new();
    let mut parents: HashMap<String, usize> = HashMap::new();
    let mut local = vec![u32::MAX; scene.vertices.len()];
    for part in &scene.parts {
        let mut primitives = Vec::new();
        for primitive in &part.primitives {
            // The primitive's file vertices in the order of the welded vertices they became (a
            // vertex's seam copies in file order): read back and welded, a file with one part and
            // one material gives the mesh's own vertex order, so the vertex `i` that was saved
            // is the vertex `i` that is loaded. In the order of first use (the faces' order) the
            // vertices would come back shuffled.
            let mut used: Vec<u32> = Vec::new();
            for &v in primitive.triangles.iter().flatten() {
                let slot = &mut local[v as usize];
                if *slot == u32::MAX {
                    *slot = 0;
                    used.push(v);
                }
            }
            used.sort_unstable_by_key(|&v| (scene.vertices[v as usize].welded, v));
            for (k, &v) in used.iter().enumerate() {
                local[v as usize] = k as u32;
            }
            let indices: Vec<u32> = primitive
                .triangles
                .iter()
                .flatten()
                .map(|&v| local[v as usize])
                .collect();
            for &v in &used {
                local[v as usize] = u32::MAX;
            }
            let vertices: Vec<&SceneVertex> =
                used.iter().map(|&v| &scene.vertices[v as usize]).collect();
            let positions: Vec<[f32; 3]> = vertices
                .iter()
                .map(|v| mesh.positions[v.welded as usize])
                .collect();
            let mut min = [f32::INFINITY; 3];
            let mut max = [f32::NEG_INFINITY; 3];
            for p in &positions {
                for axis in 0..3 {
                    min[axis] = min[axis].min(p[axis]);
                    max[axis] = max[axis].max(p[axis]);
                }
            }
            let count = positions.len();
            let view = add_view(&mut bin, &floats(&positions), Some(34962));
            accessors.push(
                json!({"bufferView": view, "componentType": 5126, "count": count,
                "type": "VEC3", "min": min, "max": max}),
            );
            let mut attributes = serde_json::Map::new();
            attributes.insert("POSITION".into(), json!(accessors.len() - 1));
            let normals: Vec<[f32; 3]> = vertices.iter().map(|v| v.normal).collect();
            let view = add_view(&mut bin, &floats(&normals), Some(34962));
            accessors.push(
                json!({"bufferView": view, "componentType": 5126, "count": count, "type": "VEC3"}),
            );
            attributes.insert("NORMAL".into(), json!(accessors.len() - 1));
            if scene.uvs {
                let uvs: Vec<[f32; 2]> = vertices.iter().map(|v| v.uv).collect();
                let view = add_view(&mut bin, &floats(&uvs), Some(34962));
                accessors.push(json!({"bufferView": view, "componentType": 5126,
                    "count": count, "type": "VEC2"}));
                attributes.insert("TEXCOORD_0".into(), json!(accessors.len() - 1));
            }
            if scene.colours {
                let colours: Vec<[f32; 4]> = vertices.iter().map(|v| v.colour).collect();
                let view = add_view(&mut bin, &floats(&colours), Some(34962));
                accessors.push(json!({"bufferView": view, "componentType": 5126,
                    "count": count, "type": "VEC4"}));
                attributes.insert("COLOR_0".into(), json!(accessors.len() - 1));
            }
            let index_bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
            let view = add_view(&mut bin, &index_bytes, Some(34963));
            accessors.push(json!({"bufferView": view, "componentType": 5125,
                "count": indices.len(), "type": "SCALAR"}));
            let mut out =
                json!({"attributes": attributes, "indices": accessors.len() - 1, "mode": 4});
            if let Some(m) = primitive.material {
                out["material"] = json!(m);
            }
            primitives.push(out);
            if bin.len() > u32::MAX as usize - 1024 {
                return Err(too_big());
            }
        }
        let mut mesh_json = json!({ "primitives": primitives });
        if let Some(name) = part.group.as_ref().or(part.object.as_ref()) {
            mesh_json["name"] = json!(name);
        }
        meshes.push(mesh_json);
        let mut node = json!({ "mesh": meshes.len() - 1 });
        match (&part.object, &part.group) {
            (Some(object), Some(group)) if scene.groups_under_objects => {
                node["name"] = json!(group);
                nodes.push(node);
                let child = nodes.len() - 1;
                let parent = *parents.entry(object.clone()).or_insert_with(|| {
                    nodes.push(json!({ "name": object, "children": [] }));
                    roots.push(nodes.len() - 1);
                    nodes.len() - 1
                });
                if let Some(children) = nodes[parent]["children"].as_array_mut() {
                    children.push(json!(child));
                }
            }
            (name, other) => {
                if let Some(name) = name.as_ref().or(other.as_ref()) {
                    node["name"] = json!(name);
                }
                nodes.push(node);
                roots.push(nodes.len() - 1);
            }
        }
    }
    // Images: embedded in a GLB; files beside a `.gltf`.
    let placed = if glb {
        Vec::new()
    } else {
        scene.place_images(path)
    };
    let mut images: Vec<Value> = Vec::new();
    let mut image_of: HashMap<String, usize> = HashMap::new();
    let mut textures: Vec<Value> = Vec::new();
    let mut materials: Vec<Value> = Vec::new();
    for (m, material) in scene.materials.iter().enumerate() {
        // As written in the source (0.8, not 0.800000011920929): the shortest f32 text.
        let number = |v: f32| {
            let v = v.clamp(0.0, 1.0);
            v.to_string().parse::<f64>().unwrap_or(v as f64)
        };
        let [r, g, b, a] = material.base_colour;
        let mut pbr = json!({
            "baseColorFactor": [number(r), number(g), number(b), number(a)],
            "metallicFactor": number(material.metallic),
            "roughnessFactor": number(material.roughness),
        });
        if let Some(image) = &material.texture {
            let key = if glb {
                image.name.clone()
            } else {
                placed
                    .get(m)
                    .and_then(Option::as_ref)
                    .map_or_else(|| image.name.clone(), |p| p.uri_name.clone())
            };
            let index = match image_of.get(&key) {
                Some(&index) => Some(index),
                None if glb => {
                    let bytes = image.data.bytes().map_err(|source| IoError::Read {
                        path: match &image.data {
                            super::scene::ImageData::File(file) => file.clone(),
                            super::scene::ImageData::Bytes(_) => path.to_owned(),
                        },
                        source,
                    })?;
                    let mime = super::scene::image_mime_type(&bytes, Path::new(&image.name));
                    let view = add_view(&mut bin, &bytes, None);
                    images.push(json!({"bufferView": view, "mimeType": mime, "name": image.name}));
                    Some(images.len() - 1)
                }
                None => {
                    images.push(json!({"uri": percent_encode(&key), "name": image.name}));
                    Some(images.len() - 1)
                }
            };
            if let Some(index) = index {
                image_of.insert(key, index);
                textures.push(json!({ "source": index }));
                pbr["baseColorTexture"] = json!({ "index": textures.len() - 1 });
            }
        }
        let mut out = json!({"name": material.name, "pbrMetallicRoughness": pbr});
        if a.clamp(0.0, 1.0) < 1.0 {
            out["alphaMode"] = json!("BLEND");
        }
        materials.push(out);
    }
    let mut root = json!({
        "asset": {"version": "2.0", "generator": "fairmesh"},
        "scene": 0,
        "scenes": [{"nodes": roots}],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    for (key, list) in [
        ("materials", materials),
        ("textures", textures),
        ("images", images),
    ] {
        if !list.is_empty() {
            root[key] = Value::Array(list);
        }
    }
    let fail = |source: std::io::Error| IoError::Write {
        path: path.to_owned(),
        source,
    };
    if glb {
        let text = serde_json::to_vec(&root).map_err(|e| fail(std::io::Error::other(e)))?;
        return atomic::write(path, |w| write_glb_container(w, text, &bin));
    }
    let bin_path = super::gltf_bin_path(path);
    let bin_name = bin_path
        .file_name()
        .map_or_else(|| "mesh.bin".into(), |n| n.to_string_lossy().into_owned());
    root["buffers"][0]["uri"] = json!(percent_encode(&bin_name));
    let text = serde_json::to_vec_pretty(&root).map_err(|e| fail(std::io::Error::other(e)))?;
    let mut staged = Vec::new();
    for (target, data) in placed.iter().flatten().filter_map(|p| p.write.as_ref()) {
        let bytes = data.bytes().map_err(|source| IoError::Read {
            path: target.clone(),
            source,
        })?;
        staged.push(atomic::stage(target, |w| w.write_all(&bytes))?);
    }
    staged.push(atomic::stage(&bin_path, |w| w.write_all(&bin))?);
    staged.push(atomic::stage(path, |w| w.write_all(&text))?);
    for file in staged {
        file.commit()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_with_and_without_padding() {
        assert_eq!(decode_base64(b"aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64(b"aGVsbG8").unwrap(), b"hello");
        assert_eq!(decode_base64(b"aGk=").unwrap(), b"hi");
        assert_eq!(decode_base64(b"").unwrap(), b"");
        assert_eq!(decode_base64(b"aG!k"), Err(2));
        assert!(decode_base64(b"a").is_err());
    }

    #[test]
    fn base64_round_trips() {
        for text in [
            &b""[..],
            b"h",
            b"hi",
            b"hel",
            b"hello world",
            &[0, 255, 128, 7],
        ] {
            assert_eq!(decode_base64(encode_base64(text).as_bytes()).unwrap(), text);
        }
        assert_eq!(encode_base64(b"hello"), "aGVsbG8=");
    }

    #[test]
    fn percent_coding_round_trips() {
        assert_eq!(percent_encode("my mesh.bin"), "my%20mesh.bin");
        assert_eq!(percent_decode("my%20mesh.bin").unwrap(), "my mesh.bin");
        assert!(percent_decode("bad%2").is_none());
    }

    #[test]
    fn normals_are_unit_and_never_nan() {
        // A degenerate triangle (all corners equal) and two opposite faces sharing a vertex set.
        let mesh = TriMesh::new(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [5., 5., 5.]],
            vec![[0, 1, 2], [0, 2, 1], [3, 3, 3]],
        );
        for n in unit_vertex_normals(&mesh) {
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((length - 1.0).abs() < 1e-6, "{n:?}");
        }
    }

    #[test]
    fn glb_round_trip_is_bit_exact() {
        let mesh = TriMesh::new(
            vec![[0.1, 0.2, 0.3], [1.0, -0.0, 0.0], [0.0, 1.0, 1e-20]],
            vec![[0, 1, 2]],
        );
        let mut bytes = Vec::new();
        write_glb(&mut bytes, &mesh).unwrap();
        let parsed = parse(&bytes, Path::new("t.glb"), None).unwrap();
        assert_eq!(parsed.mesh, mesh);
    }
}
