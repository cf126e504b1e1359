//! Writing a bare mesh as glTF: one buffer with positions, area-weighted unit vertex normals (a
//! vertex whose normal sums to zero takes an incident face's normal, or +Z), u32 indices and,
//! where given, per-vertex UVs and colours; one mesh, one node, one default scene. `.glb` is one
//! atomic write; `.gltf` writes `<stem>.bin` and the JSON, both staged as temporary files first
//! and renamed only when both are complete.

use super::uri::{encode_base64, percent_encode};
use crate::io::atomic;
use crate::io::carry::VertexAttributes;
use crate::io::IoError;
use crate::mesh::TriMesh;
use glam::DVec3;
use gltf_json as json;
use std::io::Write;
use std::path::Path;

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
