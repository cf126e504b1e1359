//! Reading a glTF scene into one triangle mesh: the document and its buffers, then every triangle
//! primitive of every node of the scene, placed by the node's world transform (see the folder's
//! doc comment for what is read and how).

use super::read_accessors::{read_indices, read_positions};
use super::source::{GltfSource, PrimitiveRead};
use super::uri::{decode_base64, percent_decode};
use super::validate::{check_glb_header, describe, json_text, older_gltf, validate};
use crate::io::{IoError, Parsed};
use crate::mesh::TriMesh;
use ::gltf::mesh::Mode;
use ::gltf::Semantic;
use glam::{DMat4, DQuat, DVec3};
use std::borrow::Cow;
use std::path::Path;

pub(crate) fn parse(
    bytes: &[u8],
    path: &Path,
    base_dir: Option<&Path>,
) -> Result<Parsed<GltfSource>, IoError> {
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
    reader.check_skipped()?;
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
        unkept: Vec::new(),
        kept: Some(source),
    })
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
                        crate::io::files::read(&file)
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

    /// The point and line primitives skipped, said in a warning; an error when nothing but
    /// them was read.
    fn check_skipped(&mut self) -> Result<(), IoError> {
        let skipped = self.skipped_points + self.skipped_lines;
        if self.mesh.triangles.is_empty() {
            let detail = if skipped > 0 {
                format!(
                    ": the scene has only point and line primitives ({} point, {} line)",
                    self.skipped_points, self.skipped_lines
                )
            } else {
                String::new()
            };
            return Err(IoError::invalid(self.path, format!("no triangles{detail}")));
        }
        if skipped > 0 {
            // "1 point primitive was skipped", "2 line primitives were skipped", or both.
            let parts: Vec<String> = [
                (self.skipped_points, "point primitive", "point primitives"),
                (self.skipped_lines, "line primitive", "line primitives"),
            ]
            .into_iter()
            .filter(|&(n, _, _)| n > 0)
            .map(|(n, one, many)| crate::io::text::counted(n, one, many))
            .collect();
            let verb = if skipped == 1 { "was" } else { "were" };
            self.warnings
                .push(format!("{} {verb} skipped", parts.join(" and ")));
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
            let positions = self.placed_positions(&position_accessor, world, &at)?;
            let corners = self.corners(&primitive, positions.len(), &at)?;
            let base = u32::try_from(self.mesh.positions.len())
                .ok()
                .filter(|b| (*b as u64) + positions.len() as u64 <= u32::MAX as u64)
                .ok_or_else(|| at("too many vertices in all for 32-bit indices".into()))?;
            let before = self.mesh.triangles.len();
            self.push_triangles(primitive.mode(), &corners, base, world, &label);
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

    /// A primitive's positions placed by `world`, every coordinate finite.
    fn placed_positions(
        &self,
        accessor: &::gltf::Accessor,
        world: DMat4,
        at: &impl Fn(String) -> IoError,
    ) -> Result<Vec<[f32; 3]>, IoError> {
        let mut positions = read_positions(accessor, self.buffers)
            .map_err(|m| at(format!("POSITION accessor {}: {m}", accessor.index())))?;
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
        Ok(positions)
    }

    /// A primitive's corners: its indices, each checked against its `vertex_count` vertices, or
    /// all its vertices in order when it has none.
    fn corners(
        &self,
        primitive: &::gltf::Primitive,
        vertex_count: usize,
        at: &impl Fn(String) -> IoError,
    ) -> Result<Vec<u32>, IoError> {
        let Some(accessor) = primitive.indices() else {
            let n = u32::try_from(vertex_count)
                .map_err(|_| at("too many vertices for 32-bit indices".into()))?;
            return Ok((0..n).collect());
        };
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
        Ok(indices)
    }

    /// The triangles of `corners` in `mode` (strips and fans unrolled; glTF 2.0 spec, section
    /// 3.7.2.1), their vertices counted from `base`, their winding flipped back under a
    /// mirroring `world` transform.
    fn push_triangles(
        &mut self,
        mode: Mode,
        corners: &[u32],
        base: u32,
        world: DMat4,
        label: &str,
    ) {
        let flip = world.determinant() < 0.0;
        let mut push = |t: [u32; 3]| {
            let t = if flip { [t[0], t[2], t[1]] } else { t };
            self.mesh.triangles.push(t.map(|v| v + base));
        };
        match mode {
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
    }
}
