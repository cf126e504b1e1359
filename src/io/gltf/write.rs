//! Writing a bare mesh as glTF: one buffer with positions, area-weighted unit vertex normals (a
//! vertex whose normal sums to zero takes an incident face's normal, or +Z), u32 indices and,
//! where given, per-vertex UVs and colours; one mesh, one node, one default scene. `.glb` is one
//! atomic write; `.gltf` writes `<stem>.bin` and the JSON, both staged as temporary files first
//! and renamed only when both are complete.

use super::uri::{encode_base64, percent_encode};
use crate::io::atomic;
use crate::io::carry::VertexAttributes;
use crate::io::normals::unit_vertex_normals;
use crate::io::IoError;
use crate::mesh::TriMesh;
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use std::io::Write;
use std::path::Path;

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
    let n = mesh.positions.len();
    let uvs = extra.uvs.as_ref().filter(|uvs| uvs.len() == n);
    let colours = extra.colours.as_ref().filter(|colours| colours.len() == n);
    let sizes = Sizes::of(mesh, uvs.is_some(), colours.is_some())?;
    let bin = buffer(mesh, uvs, colours, sizes.total);
    let mut root = json::Root::default();
    root.asset.generator = Some("fairmesh".into());
    let buffer = root.push(json::Buffer {
        byte_length: USize64(sizes.total as u64),
        name: None,
        uri,
        extensions: Default::default(),
        extras: Default::default(),
    });
    let primitive = add_primitive(&mut root, buffer, mesh, &sizes);
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

/// The byte lengths of the parts of a bare mesh's buffer, in their order: positions, normals,
/// indices, UVs and colours (where it has them).
struct Sizes {
    positions: usize,
    indices: usize,
    uvs: Option<usize>,
    colours: Option<usize>,
    total: usize,
}

impl Sizes {
    /// The sizes for `mesh`, or an error when the buffer would not fit a GLB (4 GiB).
    fn of(mesh: &TriMesh, uvs: bool, colours: bool) -> std::io::Result<Sizes> {
        let too_big =
            || std::io::Error::new(std::io::ErrorKind::InvalidInput, "mesh too large for glTF");
        let n = mesh.positions.len();
        let positions = n.checked_mul(12).ok_or_else(too_big)?;
        let indices = mesh.triangles.len().checked_mul(12).ok_or_else(too_big)?;
        let uvs = uvs.then(|| n * 8);
        let colours = colours.then(|| n * 16);
        let total = positions
            .checked_mul(2)
            .and_then(|b| b.checked_add(indices))
            .and_then(|b| b.checked_add(uvs.unwrap_or(0) + colours.unwrap_or(0)))
            .filter(|&t| t <= u32::MAX as usize - 1024)
            .ok_or_else(too_big)?;
        Ok(Sizes {
            positions,
            indices,
            uvs,
            colours,
            total,
        })
    }
}

/// The binary buffer of a bare mesh (see [`Sizes`] for its layout).
fn buffer(
    mesh: &TriMesh,
    uvs: Option<&Vec<[f32; 2]>>,
    colours: Option<&Vec<[f32; 4]>>,
    total: usize,
) -> Vec<u8> {
    let mut bin = Vec::with_capacity(total);
    for p in &mesh.positions {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for p in &unit_vertex_normals(mesh) {
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
    bin
}

/// The per-axis minimum and maximum of `positions`.
pub(super) fn position_bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in positions {
        for axis in 0..3 {
            min[axis] = min[axis].min(p[axis]);
            max[axis] = max[axis].max(p[axis]);
        }
    }
    (min, max)
}

/// A buffer view of `buffer` with `target`.
fn view(
    buffer: json::Index<json::Buffer>,
    offset: usize,
    length: usize,
    target: json::buffer::Target,
) -> json::buffer::View {
    json::buffer::View {
        buffer,
        byte_length: USize64(length as u64),
        byte_offset: Some(USize64(offset as u64)),
        byte_stride: None,
        name: None,
        target: Some(Valid(target)),
        extensions: Default::default(),
        extras: Default::default(),
    }
}

/// An accessor of `count` elements in `view`, with `bounds` as its min and max.
fn accessor(
    view: json::Index<json::buffer::View>,
    count: usize,
    component: json::accessor::ComponentType,
    type_: json::accessor::Type,
    bounds: Option<([f32; 3], [f32; 3])>,
) -> json::Accessor {
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
}

/// The buffer views and accessors of a bare mesh's buffer (laid out as [`Sizes`] says) and its
/// one triangle primitive.
fn add_primitive(
    root: &mut json::Root,
    buffer: json::Index<json::Buffer>,
    mesh: &TriMesh,
    sizes: &Sizes,
) -> json::mesh::Primitive {
    use json::accessor::{ComponentType, Type};
    use json::buffer::Target;
    let n = mesh.positions.len();
    let p = sizes.positions;
    let position_view = root.push(view(buffer, 0, p, Target::ArrayBuffer));
    let normal_view = root.push(view(buffer, p, p, Target::ArrayBuffer));
    let index_view = root.push(view(
        buffer,
        2 * p,
        sizes.indices,
        Target::ElementArrayBuffer,
    ));
    let bounds = position_bounds(&mesh.positions);
    let positions = root.push(accessor(
        position_view,
        n,
        ComponentType::F32,
        Type::Vec3,
        Some(bounds),
    ));
    let normals = root.push(accessor(
        normal_view,
        n,
        ComponentType::F32,
        Type::Vec3,
        None,
    ));
    let indices = root.push(accessor(
        index_view,
        3 * mesh.triangles.len(),
        ComponentType::U32,
        Type::Scalar,
        None,
    ));
    let mut attributes: std::collections::BTreeMap<_, _> = [
        (Valid(json::mesh::Semantic::Positions), positions),
        (Valid(json::mesh::Semantic::Normals), normals),
    ]
    .into_iter()
    .collect();
    let mut offset = 2 * p + sizes.indices;
    for (length, semantic, type_) in [
        (sizes.uvs, json::mesh::Semantic::TexCoords(0), Type::Vec2),
        (sizes.colours, json::mesh::Semantic::Colors(0), Type::Vec4),
    ] {
        let Some(length) = length else {
            continue;
        };
        let view = root.push(view(buffer, offset, length, Target::ArrayBuffer));
        offset += length;
        let values = root.push(accessor(view, n, ComponentType::F32, type_, None));
        attributes.insert(Valid(semantic), values);
    }
    json::mesh::Primitive {
        attributes,
        extensions: Default::default(),
        extras: Default::default(),
        indices: Some(indices),
        material: None,
        mode: Valid(json::mesh::Mode::Triangles),
        targets: None,
    }
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
    let bin_path = crate::io::gltf_bin_path(path);
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

#[cfg(test)]
mod tests {
    use super::super::read::parse;
    use super::*;

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

    fn triangle_with_uvs() -> (TriMesh, VertexAttributes) {
        let mesh = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
        );
        let extra = VertexAttributes {
            uvs: Some(vec![[0.25, 0.0], [0.5, 0.25], [1.0, 0.75]]),
            ..Default::default()
        };
        (mesh, extra)
    }

    /// TEXCOORD_0 of the file's one primitive, read with the `gltf` crate's document and decoded
    /// by hand from the buffer: VEC2 of f32, little-endian, at the view's stride (8 when none).
    fn texcoords(document: &::gltf::Document, buffer: &[u8]) -> Option<Vec<[f32; 2]>> {
        let primitive = document.meshes().next()?.primitives().next()?;
        let accessor = primitive.get(&::gltf::Semantic::TexCoords(0))?;
        assert_eq!(accessor.data_type(), ::gltf::accessor::DataType::F32);
        assert_eq!(accessor.dimensions(), ::gltf::accessor::Dimensions::Vec2);
        let view = accessor.view()?;
        let stride = view.stride().unwrap_or(8);
        let start = view.offset() + accessor.offset();
        let float = |at: usize| f32::from_le_bytes(buffer[at..at + 4].try_into().unwrap());
        Some(
            (0..accessor.count())
                .map(|i| [float(start + i * stride), float(start + i * stride + 4)])
                .collect(),
        )
    }

    #[test]
    fn glb_with_uvs_holds_them_as_texcoord_0() {
        let (mesh, extra) = triangle_with_uvs();
        let mut bytes = Vec::new();
        write_glb_with(&mut bytes, &mesh, &extra).unwrap();
        let glb = ::gltf::Gltf::from_slice(&bytes).unwrap();
        let blob = glb.blob.as_deref().unwrap();
        // glTF counts v from the top row, as the library does: written unchanged.
        assert_eq!(texcoords(&glb.document, blob), extra.uvs);
    }

    #[test]
    fn gltf_with_uvs_holds_them_as_texcoord_0_in_its_bin() {
        let (mesh, extra) = triangle_with_uvs();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.gltf");
        write_gltf_with(&path, &mesh, &extra).unwrap();
        let document = ::gltf::Gltf::from_slice(&std::fs::read(&path).unwrap())
            .unwrap()
            .document;
        let bin = std::fs::read(dir.path().join("t.bin")).unwrap();
        assert_eq!(texcoords(&document, &bin), extra.uvs);
    }
}
