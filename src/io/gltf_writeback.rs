//! Writing a glTF/GLB back with new positions and everything else as it was.
//!
//! What is kept: the whole JSON document (scenes, nodes with names, parents, TRS or matrix,
//! meshes, primitives, materials, textures, images, samplers, cameras, skins, animations, morph
//! targets, extensions and extras, in their order) and every byte of every buffer view, except the
//! elements of POSITION accessors whose vertex moved, the NORMAL and TANGENT elements whose faces
//! moved, and the POSITION accessors' `min`/`max`.
//!
//! How positions go back: the reader placed each primitive in world space through its node's
//! world transform; a moved vertex goes back to the primitive's own space through the inverse of
//! that transform (in f64). A vertex that did not move keeps its bytes. A mesh placed by two nodes
//! with different transforms has one set of vertices in the file: it is written as faired in its
//! first placement (scene order, depth first), and the save report says so.
//!
//! Normals and tangents turn with their faces, in the primitive's own space (see
//! [`super::source`]); a tangent's w (handedness) is kept. Morph target deltas are kept as they
//! are. Values are written in the accessor's own component type (floats, or normalized integers
//! under KHR_mesh_quantization); integer `min`/`max` are in the accessor's integer type, as the
//! specification asks. A normal or tangent written as integers takes, of the roundings of its
//! components down or up, one that keeps it of unit length within the validators' tolerance
//! (plain rounding does not, in 8 bits). A POSITION or TEXCOORD accessor in an integer type with
//! a value moved past the type's range (gltfpack quantizes over the values' bounding box, so a
//! vertex below the lowest, or a texture coordinate that follows its vertex past its chart's
//! edge, leaves the grid) is written as floats in a new buffer view instead of being clamped,
//! with a warning; its old buffer view stays, unused if nothing else reads it.
//!
//! Buffers: all buffers are joined into one (each starting at a multiple of 16 bytes, buffer views
//! moved accordingly), which becomes the GLB's BIN chunk or the `.gltf`'s `<stem>.bin`. Images
//! stored in buffer views or as data: URIs stay as they are. Images that are external files are
//! copied: into the GLB's binary chunk (a GLB is one self-contained file), or, for a `.gltf`
//! written to another folder, beside it (as `<stem>_<name>` if a different file of that name is
//! already there); a `.gltf` written beside its input refers to the same files.

use super::atomic;
use super::carry::{Gather, VertexAttributes};
use super::scene::{
    image_file_name, image_mime_type, Image, ImageData, Material, Part, Primitive, Scene,
    SceneVertex,
};
use super::source::{
    dvec, is_own_normal, NormalTurns, SaveReport, SlotSums, SmoothGroups, Source, Turn,
};
use super::{Format, IoError};
use crate::mesh::TriMesh;
use glam::{DMat3, DMat4, DVec3};
use rayon::prelude::*;
use serde_json::{json, Value};
use std::collections::{BTreeMap, BTreeSet};
use std::io::Write;
use std::path::{Path, PathBuf};

/// One primitive as the reader read it for one node: its POSITION accessor's elements became the
/// parser vertices `raw_start..raw_start + count`, placed by `world`.
#[derive(Clone, Debug)]
pub(crate) struct PrimitiveRead {
    pub accessor: usize,
    pub mesh: usize,
    /// The primitive's index in its mesh.
    pub primitive: usize,
    pub node: Option<usize>,
    pub raw_start: usize,
    pub count: usize,
    pub world: DMat4,
}

/// A glTF document as loaded: its JSON, its buffers and the primitive reads.
#[derive(Debug)]
pub(crate) struct GltfSource {
    pub json: Value,
    pub buffers: Vec<Vec<u8>>,
    pub reads: Vec<PrimitiveRead>,
}

/// The bytes behind one accessor: buffer, offset of element 0, stride, component type and size,
/// components per element, normalized, count.
#[derive(Clone, Copy, Debug)]
struct Layout {
    buffer: usize,
    start: usize,
    stride: usize,
    component: u64,
    size: usize,
    components: usize,
    normalized: bool,
    count: usize,
}

fn index(value: &Value, key: &str) -> Option<usize> {
    value
        .get(key)?
        .as_u64()
        .and_then(|v| usize::try_from(v).ok())
}

impl GltfSource {
    /// Where the first read of POSITION accessor `accessor` starts among the parser's vertices
    /// (its elements' welded vertices are `source.welded(start + k)`).
    fn first_raw_start(&self, accessor: usize) -> Option<usize> {
        self.reads
            .iter()
            .find(|read| read.accessor == accessor)
            .map(|read| read.raw_start)
    }

    fn array(&self, key: &str) -> &[Value] {
        self.json
            .get(key)
            .and_then(Value::as_array)
            .map_or(&[], Vec::as_slice)
    }

    /// The checked layout of accessor `a`, or why it cannot be used.
    fn layout(&self, a: usize) -> Result<Layout, String> {
        let accessor = self
            .array("accessors")
            .get(a)
            .ok_or_else(|| format!("accessor {a} does not exist"))?;
        if accessor.get("sparse").is_some() {
            return Err(format!("accessor {a} is sparse"));
        }
        let view_index = index(accessor, "bufferView")
            .ok_or_else(|| format!("accessor {a} has no buffer view"))?;
        let view = self
            .array("bufferViews")
            .get(view_index)
            .ok_or_else(|| format!("buffer view {view_index} does not exist"))?;
        let buffer = index(view, "buffer").unwrap_or(usize::MAX);
        let data = self
            .buffers
            .get(buffer)
            .ok_or_else(|| format!("buffer view {view_index}: its buffer does not exist"))?;
        let component = accessor
            .get("componentType")
            .and_then(Value::as_u64)
            .unwrap_or(0);
        let size = match component {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            5125 | 5126 => 4,
            other => return Err(format!("accessor {a}: component type {other}")),
        };
        let components = match accessor.get("type").and_then(Value::as_str) {
            Some("SCALAR") => 1,
            Some("VEC2") => 2,
            Some("VEC3") => 3,
            Some("VEC4") => 4,
            other => return Err(format!("accessor {a}: type {other:?}")),
        };
        let element = size * components;
        let stride = index(view, "byteStride").unwrap_or(element);
        let count = index(accessor, "count").unwrap_or(0);
        let view_start = index(view, "byteOffset").unwrap_or(0);
        let view_len = index(view, "byteLength").unwrap_or(0);
        let start = view_start
            .checked_add(index(accessor, "byteOffset").unwrap_or(0))
            .ok_or("offset overflows")?;
        let needed = match count {
            0 => 0,
            n => (n - 1)
                .checked_mul(stride)
                .and_then(|b| b.checked_add(element))
                .ok_or("size overflows")?,
        };
        let end = start.checked_add(needed).ok_or("size overflows")?;
        if stride < element || end > view_start.saturating_add(view_len) || end > data.len() {
            return Err(format!("accessor {a} runs past its buffer view"));
        }
        Ok(Layout {
            buffer,
            start,
            stride,
            component,
            size,
            components,
            normalized: accessor
                .get("normalized")
                .and_then(Value::as_bool)
                .unwrap_or(false),
            count,
        })
    }

    fn read(&self, layout: &Layout, element: usize, component: usize) -> f32 {
        let at = layout.start + element * layout.stride + component * layout.size;
        let bytes = &self.buffers[layout.buffer][at..at + layout.size];
        decode(layout, bytes)
    }

    fn read3(&self, layout: &Layout, element: usize) -> [f32; 3] {
        [0, 1, 2].map(|c| self.read(layout, element, c))
    }

    /// The first three components of every element ([`Self::read3`] of each), read straight
    /// from the bytes for plain floats.
    fn read3_all(&self, layout: &Layout) -> Vec<[f32; 3]> {
        if layout.component != FLOAT || layout.count == 0 {
            return (0..layout.count).map(|k| self.read3(layout, k)).collect();
        }
        let bytes = &self.buffers[layout.buffer][layout.start..];
        let float = |b: &[u8], c: usize| {
            f32::from_le_bytes([b[4 * c], b[4 * c + 1], b[4 * c + 2], b[4 * c + 3]])
        };
        (0..layout.count)
            .map(|k| {
                let b = &bytes[k * layout.stride..k * layout.stride + 12];
                [float(b, 0), float(b, 1), float(b, 2)]
            })
            .collect()
    }

    /// The indices of a primitive's triangles (strips and fans unrolled), in its own space;
    /// triangles with a corner past `vertex_count` are left out.
    fn triangles(&self, primitive: &Value, vertex_count: usize) -> Vec<[u32; 3]> {
        let mode = primitive.get("mode").and_then(Value::as_u64).unwrap_or(4);
        let in_range = |t: &[u32; 3]| t.iter().all(|&v| (v as usize) < vertex_count);
        let corners: Vec<u32> = match index(primitive, "indices") {
            Some(a) => match self.layout(a) {
                // A triangle list (nearly every file): read straight into triangles.
                Ok(layout) if layout.components == 1 && mode == 4 => {
                    let mut triangles = self.read_triangle_list(&layout);
                    triangles.retain(in_range);
                    return triangles;
                }
                Ok(layout) if layout.components == 1 => self.read_indices(&layout),
                _ => return Vec::new(),
            },
            None => (0..vertex_count.min(u32::MAX as usize) as u32).collect(),
        };
        let mut triangles = Vec::with_capacity(corners.len() / 3);
        match mode {
            4 => triangles.extend(corners.chunks_exact(3).map(|c| [c[0], c[1], c[2]])),
            5 => triangles.extend(corners.windows(3).enumerate().map(|(i, w)| {
                if i % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[0], w[2], w[1]]
                }
            })),
            6 => {
                if let Some((&first, rest)) = corners.split_first() {
                    triangles.extend(rest.windows(2).map(|w| [w[0], w[1], first]));
                }
            }
            _ => {}
        }
        triangles.retain(in_range);
        triangles
    }

    /// Every element of an index accessor (its layout checked), read straight from the bytes.
    fn read_indices(&self, layout: &Layout) -> Vec<u32> {
        let size = layout.size;
        let bytes = &self.buffers[layout.buffer][layout.start..];
        let elements = bytes
            .chunks(layout.stride)
            .take(layout.count)
            .map(|element| &element[..size]);
        match size {
            1 => elements.map(|b| b[0] as u32).collect(),
            2 => elements
                .map(|b| u16::from_le_bytes([b[0], b[1]]) as u32)
                .collect(),
            _ => elements
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect(),
        }
    }

    /// The triangles of an index accessor read as a triangle list (its layout checked; a last
    /// incomplete triple is left out), in one pass over the bytes.
    fn read_triangle_list(&self, layout: &Layout) -> Vec<[u32; 3]> {
        let (size, stride) = (layout.size, layout.stride);
        let bytes = &self.buffers[layout.buffer][layout.start..];
        let at = |k: usize| -> u32 {
            let b = &bytes[k * stride..k * stride + size];
            match size {
                1 => b[0] as u32,
                2 => u16::from_le_bytes([b[0], b[1]]) as u32,
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            }
        };
        if size == 4 && stride == 4 {
            // Tightly packed 32-bit indices: three words a triangle.
            return bytes[..layout.count / 3 * 12]
                .chunks_exact(12)
                .map(|b| {
                    let word = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
                    [word(0), word(4), word(8)]
                })
                .collect();
        }
        (0..layout.count / 3)
            .map(|t| [at(3 * t), at(3 * t + 1), at(3 * t + 2)])
            .collect()
    }

    /// The layout of a read primitive's attribute `name`, where it has one element per position.
    fn read_attribute(&self, read: &PrimitiveRead, name: &str) -> Option<Layout> {
        let primitive = self
            .array("meshes")
            .get(read.mesh)
            .and_then(|m| m.get("primitives"))
            .and_then(Value::as_array)?
            .iter()
            .find(|p| attribute(p, "POSITION") == Some(read.accessor))?;
        attribute(primitive, name)
            .and_then(|a| self.layout(a).ok())
            .filter(|l| l.count == read.count)
    }

    /// Whether a read primitive has TEXCOORD_0 (what makes [`Self::vertex_attributes`]' `uvs`
    /// `Some`), without reading it.
    pub(crate) fn has_texture_coordinates(&self) -> bool {
        self.reads.iter().any(|read| {
            self.read_attribute(read, "TEXCOORD_0")
                .is_some_and(|l| l.components == 2)
        })
    }

    /// TEXCOORD_0 and COLOR_0 per welded vertex, for saving in another format: each read
    /// primitive's elements go to the welded vertices its positions became.
    pub(crate) fn vertex_attributes(&self, source: &Source) -> VertexAttributes {
        let mut uvs = Gather::<2>::new(source.welded_vertices, [0.0; 2]);
        let mut colours = Gather::<4>::new(source.welded_vertices, [1.0; 4]);
        let (mut any_uv, mut any_colour) = (false, false);
        for read in &self.reads {
            let layout_of = |name: &str| self.read_attribute(read, name);
            if let Some(layout) = layout_of("TEXCOORD_0").filter(|l| l.components == 2) {
                any_uv = true;
                for k in 0..read.count {
                    let uv = [self.read(&layout, k, 0), self.read(&layout, k, 1)];
                    uvs.put(source.welded(read.raw_start + k), uv);
                }
            }
            if let Some(layout) = layout_of("COLOR_0").filter(|l| l.components >= 3) {
                any_colour = true;
                for k in 0..read.count {
                    let alpha = if layout.components == 4 {
                        self.read(&layout, k, 3)
                    } else {
                        1.0
                    };
                    let [r, g, b] = self.read3(&layout, k);
                    colours.put(source.welded(read.raw_start + k), [r, g, b, alpha]);
                }
            }
        }
        let mut out = VertexAttributes::default();
        if any_uv {
            let (values, merged) = uvs.finish();
            out.uvs = Some(values);
            out.uv_splits_merged = merged;
        }
        if any_colour {
            let (values, merged) = colours.finish();
            out.colours = Some(values);
            out.colour_splits_merged = merged;
        }
        out
    }

    /// The document's parts, materials and file vertices, for saving in another format (see
    /// [`super::scene`]): one part per node read (the node's name, and its mesh's name as the
    /// group), one primitive per glTF primitive, vertices and normals in world space, normals
    /// turned with their faces to `mesh`'s positions.
    pub(crate) fn scene(&self, source: &Source, mesh: &TriMesh) -> Scene {
        let mut scene = Scene {
            vertices: vec![SceneVertex::new(None, [0.0; 3]); source.raw_vertices],
            ..Scene::default()
        };
        scene.materials = self.materials(source, &mut scene.warnings);
        let mut part_of_node: BTreeMap<Option<usize>, usize> = BTreeMap::new();
        let meshes = self.array("meshes");
        for read in &self.reads {
            let Some(primitive) = meshes
                .get(read.mesh)
                .and_then(|m| m.get("primitives"))
                .and_then(|p| p.get(read.primitive))
            else {
                continue;
            };
            let Ok(positions) = self.layout(read.accessor) else {
                continue;
            };
            if positions.count != read.count
                || positions.components != 3
                || read.raw_start + read.count > scene.vertices.len()
            {
                continue;
            }
            let identity = read.world == DMat4::IDENTITY;
            let normal_matrix = DMat3::from_mat4(read.world).inverse().transpose();
            let layout_of = |name: &str| {
                attribute(primitive, name)
                    .and_then(|a| self.layout(a).ok())
                    .filter(|l| l.count == read.count)
            };
            let uvs = layout_of("TEXCOORD_0").filter(|l| l.components == 2);
            let colours = layout_of("COLOR_0").filter(|l| l.components >= 3);
            let normals = layout_of("NORMAL").filter(|l| l.components == 3);
            scene.uvs |= uvs.is_some();
            scene.colours |= colours.is_some();
            scene.normals |= normals.is_some();
            let finite = |values: &[f32]| values.iter().all(|c| c.is_finite());
            for k in 0..read.count {
                let local = self.read3(&positions, k);
                let before = if identity {
                    local
                } else {
                    read.world
                        .transform_point3(dvec(local))
                        .as_vec3()
                        .to_array()
                };
                let mut vertex = SceneVertex::new(source.welded(read.raw_start + k), before);
                if let Some(layout) = &uvs {
                    let uv = [self.read(layout, k, 0), self.read(layout, k, 1)];
                    vertex.uv = if finite(&uv) { uv } else { [0.0; 2] };
                }
                if let Some(layout) = &colours {
                    let [r, g, b] = self.read3(layout, k);
                    let a = if layout.components == 4 {
                        self.read(layout, k, 3)
                    } else {
                        1.0
                    };
                    let colour = [r, g, b, a];
                    vertex.colour = if finite(&colour) { colour } else { [1.0; 4] };
                }
                if let Some(layout) = &normals {
                    let n = self.read3(layout, k);
                    let n = if identity {
                        n
                    } else {
                        (normal_matrix * dvec(n))
                            .normalize_or_zero()
                            .as_vec3()
                            .to_array()
                    };
                    vertex.normal = if finite(&n) { n } else { [0.0; 3] };
                }
                scene.vertices[read.raw_start + k] = vertex;
            }
            let part = *part_of_node.entry(read.node).or_insert_with(|| {
                let mesh_name = name_of(&self.json, "meshes", read.mesh).map(String::from);
                let object = match read.node {
                    Some(n) => Some(
                        name_of(&self.json, "nodes", n)
                            .map_or_else(|| format!("node{n}"), String::from),
                    ),
                    None => mesh_name.clone(),
                };
                scene.parts.push(Part {
                    object,
                    group: mesh_name,
                    primitives: Vec::new(),
                });
                scene.parts.len() - 1
            });
            // A mirroring transform: the reader flipped the winding, and so does this.
            let flip = read.world.determinant() < 0.0;
            let triangles = self
                .triangles(primitive, read.count)
                .into_iter()
                .map(|t| {
                    let t = if flip { [t[0], t[2], t[1]] } else { t };
                    t.map(|v| (read.raw_start + v as usize) as u32)
                })
                .collect();
            scene.parts[part].primitives.push(Primitive {
                material: index(primitive, "material").filter(|&m| m < scene.materials.len()),
                triangles,
            });
        }
        scene.drop_degenerate();
        scene.assign_smooth_slots();
        scene.turn_normals(mesh);
        scene
    }

    /// Each material's name, base colour, metallic and roughness factors and base colour
    /// texture; what else a material has (other textures, extensions) is named in `warnings`.
    fn materials(&self, source: &Source, warnings: &mut Vec<String>) -> Vec<Material> {
        let mut others: Vec<String> = Vec::new();
        let materials = self
            .array("materials")
            .iter()
            .enumerate()
            .map(|(i, material)| {
                let name = material
                    .get("name")
                    .and_then(Value::as_str)
                    .map_or_else(|| format!("material{i}"), String::from);
                let pbr = material.get("pbrMetallicRoughness");
                let factor = |key: &str| {
                    pbr.and_then(|p| p.get(key))
                        .and_then(Value::as_f64)
                        .map_or(1.0, |v| v as f32)
                };
                let mut base_colour = [1.0f32; 4];
                if let Some(list) = pbr
                    .and_then(|p| p.get("baseColorFactor"))
                    .and_then(Value::as_array)
                {
                    for (c, value) in list.iter().take(4).enumerate() {
                        if let Some(value) = value.as_f64().filter(|v| v.is_finite()) {
                            base_colour[c] = value as f32;
                        }
                    }
                }
                let texture = pbr
                    .and_then(|p| p.get("baseColorTexture"))
                    .and_then(|t| index(t, "index"))
                    .and_then(|t| self.array("textures").get(t))
                    .and_then(|t| {
                        // Its own image (a PNG or JPEG) where it has one, which other tools read
                        // more widely; otherwise the one in another format (KTX2, WebP, ...).
                        index(t, "source").or_else(|| {
                            (super::gltf::IMAGE_FORMATS.iter())
                                .find_map(|e| index(t.get("extensions")?.get(e)?, "source"))
                        })
                    })
                    .and_then(|image| self.image(image, &name, source, warnings));
                let mut unkept: Vec<&str> = [
                    ("normalTexture", "normal map"),
                    ("occlusionTexture", "occlusion map"),
                    ("emissiveTexture", "emissive map"),
                    ("emissiveFactor", "emissive colour"),
                    ("extensions", "extensions"),
                ]
                .into_iter()
                .filter(|(key, _)| material.get(*key).is_some())
                .map(|(_, what)| what)
                .collect();
                if pbr.is_some_and(|p| p.get("metallicRoughnessTexture").is_some()) {
                    unkept.push("metallic-roughness map");
                }
                if !unkept.is_empty() {
                    others.push(format!("'{name}': {}", unkept.join(", ")));
                }
                Material {
                    name,
                    base_colour,
                    metallic: factor("metallicFactor"),
                    roughness: factor("roughnessFactor"),
                    texture,
                }
            })
            .collect();
        if !others.is_empty() {
            warnings.push(format!(
                "material properties beyond base colour, base colour texture, metallic and roughness ({})",
                others.join("; ")
            ));
        }
        materials
    }

    /// Image `j`: an external file beside the input, or the bytes of a data: URI or buffer
    /// view; `None` (named in `warnings`) when it cannot be had.
    fn image(
        &self,
        j: usize,
        material: &str,
        source: &Source,
        warnings: &mut Vec<String>,
    ) -> Option<Image> {
        let image = self.array("images").get(j)?;
        let fallback = format!("{material}_basecolor");
        let own_name = image
            .get("name")
            .and_then(Value::as_str)
            .unwrap_or(&fallback);
        let mut lost = |why: String| {
            warnings.push(format!("the texture of material '{material}' ({why})"));
            None
        };
        if let Some(uri) = image.get("uri").and_then(Value::as_str) {
            if let Some(rest) = uri.strip_prefix("data:") {
                let Some((header, data)) = rest.split_once(',') else {
                    return lost(format!("image {j}: a malformed data: URI"));
                };
                let Some(header) = header.strip_suffix(";base64") else {
                    return lost(format!("image {j}: a data: URI that is not base64"));
                };
                let Ok(bytes) = super::gltf::decode_base64(data.as_bytes()) else {
                    return lost(format!("image {j}: its data: URI is not valid base64"));
                };
                let mime = if header.starts_with("image/") {
                    header.to_string()
                } else {
                    image_mime_type(&bytes, Path::new("")).to_string()
                };
                return Some(Image {
                    name: image_file_name(own_name, &mime),
                    data: ImageData::Bytes(bytes),
                });
            }
            let Some(base) = &source.base_dir else {
                return lost(format!(
                    "image {j} is the file {uri:?}, which cannot be found: the input was read from memory"
                ));
            };
            let file = super::gltf::percent_decode(uri).map(|relative| base.join(relative));
            return match file {
                Some(file) if file.is_file() => Some(Image {
                    name: image_file_name(
                        &file.file_name().map_or_else(
                            || own_name.to_string(),
                            |n| n.to_string_lossy().into_owned(),
                        ),
                        image_mime_type(&[], &file),
                    ),
                    data: ImageData::File(file),
                }),
                _ => lost(format!("image {j}: {uri:?} is not beside the input")),
            };
        }
        let bytes = index(image, "bufferView")
            .and_then(|v| self.array("bufferViews").get(v))
            .and_then(|view| {
                let buffer = self.buffers.get(index(view, "buffer")?)?;
                let start = index(view, "byteOffset").unwrap_or(0);
                buffer
                    .get(start..start.checked_add(index(view, "byteLength")?)?)
                    .map(<[u8]>::to_vec)
            });
        let Some(bytes) = bytes else {
            return lost(format!("image {j}: its buffer view cannot be read"));
        };
        let mime = image
            .get("mimeType")
            .and_then(Value::as_str)
            .unwrap_or_else(|| image_mime_type(&bytes, Path::new("")))
            .to_string();
        Some(Image {
            name: image_file_name(own_name, &mime),
            data: ImageData::Bytes(bytes),
        })
    }

    /// What the document holds beyond positions and triangles, in plain words.
    pub(crate) fn contents(&self) -> Vec<String> {
        let names = |key: &str| -> Vec<String> {
            (0..self.array(key).len())
                .map(|i| match name_of(&self.json, key, i) {
                    Some(name) => format!("'{name}'"),
                    None => format!("#{i}"),
                })
                .collect()
        };
        let mut out = Vec::new();
        let nodes = names("nodes");
        if nodes.len() > 1 || self.array("nodes").iter().any(|n| n.get("name").is_some()) {
            out.push(format!(
                "the node tree ({} nodes: {})",
                nodes.len(),
                nodes.join(", ")
            ));
        }
        for (key, one, many) in [
            ("materials", "material", "materials"),
            ("textures", "texture", "textures"),
            ("cameras", "camera", "cameras"),
            ("skins", "skin", "skins"),
            ("animations", "animation", "animations"),
        ] {
            let list = names(key);
            if !list.is_empty() {
                let what = if list.len() == 1 { one } else { many };
                out.push(format!("{} {what} ({})", list.len(), list.join(", ")));
            }
        }
        let mut attributes: Vec<String> = Vec::new();
        let mut targets = 0;
        for primitive in primitives(&self.json) {
            if let Some(map) = primitive.get("attributes").and_then(Value::as_object) {
                for name in map.keys().filter(|n| *n != "POSITION") {
                    let plain = if name == "NORMAL" {
                        "normals".to_string()
                    } else if name == "TANGENT" {
                        "tangents".to_string()
                    } else if name.starts_with("TEXCOORD") {
                        format!("UVs ({name})")
                    } else if name.starts_with("COLOR") {
                        format!("vertex colours ({name})")
                    } else if name.starts_with("JOINTS") || name.starts_with("WEIGHTS") {
                        format!("skin weights ({name})")
                    } else {
                        name.clone()
                    };
                    if !attributes.contains(&plain) {
                        attributes.push(plain);
                    }
                }
            }
            targets += primitive
                .get("targets")
                .and_then(Value::as_array)
                .map_or(0, Vec::len);
        }
        out.extend(attributes);
        if targets > 0 {
            out.push(format!("{targets} morph targets"));
        }
        if let Some(used) = self.json.get("extensionsUsed").and_then(Value::as_array) {
            let used: Vec<&str> = used.iter().filter_map(Value::as_str).collect();
            if !used.is_empty() {
                out.push(format!("extensions {}", used.join(", ")));
            }
        }
        out
    }
}

fn decode(layout: &Layout, b: &[u8]) -> f32 {
    macro_rules! get {
        ($t:ty) => {
            <$t>::from_le_bytes(b.try_into().unwrap_or_default())
        };
    }
    let n = layout.normalized;
    match layout.component {
        5126 => get!(f32),
        5120 if n => (get!(i8) as f32 / 127.0).max(-1.0),
        5121 if n => get!(u8) as f32 / 255.0,
        5122 if n => (get!(i16) as f32 / 32767.0).max(-1.0),
        5123 if n => get!(u16) as f32 / 65535.0,
        5125 if n => (get!(u32) as f64 / u32::MAX as f64) as f32,
        5120 => get!(i8) as f32,
        5121 => get!(u8) as f32,
        5122 => get!(i16) as f32,
        5123 => get!(u16) as f32,
        _ => get!(u32) as f32,
    }
}

/// What a stored integer of an integer component type is multiplied by to give its value (1
/// unless normalized).
fn integer_scale(layout: &Layout) -> f64 {
    match (layout.normalized, layout.component) {
        (false, _) => 1.0,
        (true, 5120) => 127.0,
        (true, 5121) => 255.0,
        (true, 5122) => 32767.0,
        (true, 5123) => 65535.0,
        (true, _) => u32::MAX as f64,
    }
}

/// The least and greatest stored integer of an integer component type.
fn integer_range(layout: &Layout) -> (f64, f64) {
    match layout.component {
        5120 => (i8::MIN as f64, i8::MAX as f64),
        5121 => (0.0, u8::MAX as f64),
        5122 => (i16::MIN as f64, i16::MAX as f64),
        5123 => (0.0, u16::MAX as f64),
        _ => (0.0, u32::MAX as f64),
    }
}

/// The integer nearest `value` in an integer component type, before it is held to the type's
/// range.
fn unclamped(layout: &Layout, value: f32) -> f64 {
    (value as f64 * integer_scale(layout)).round()
}

/// The stored (integer) value for `value` in an integer component type.
fn quantize(layout: &Layout, value: f32) -> f64 {
    let (lo, hi) = integer_range(layout);
    unclamped(layout, value).clamp(lo, hi)
}

/// Whether `value` can be stored in the layout's component type without being clamped.
fn fits(layout: &Layout, value: f32) -> bool {
    let (lo, hi) = integer_range(layout);
    layout.component == FLOAT || (lo..=hi).contains(&unclamped(layout, value))
}

/// The stored integers for a direction (a normal, a tangent's first three components) in a
/// normalized integer type: of the roundings of each component down or up, one whose decoded
/// length is within [`LENGTH_TOLERANCE`] of the length it should have and whose direction is
/// nearest, or the one with the nearest length if none is. The length it should have is 1 for
/// a direction within 0.01 of it (a unit vector as integers store it: the file's own normal,
/// turned, keeps the few thousandths its integers were off), its own otherwise (a file that
/// stores longer or shorter vectors keeps them so). (Rounding each component to the nearest
/// integer leaves unit normals up to 0.007 off unit length in 8 bits, which glTF validators
/// reject: their tolerance is 0.00465.)
fn quantize_direction(layout: &Layout, direction: [f32; 3]) -> [f64; 3] {
    let scale = integer_scale(layout);
    let (lo, hi) = integer_range(layout);
    let wanted = DVec3::from(direction.map(f64::from));
    let length = match wanted.length() {
        unit if (unit - 1.0).abs() < 0.01 => 1.0,
        other => other,
    };
    let mut best = ([0.0; 3], (true, f64::INFINITY));
    for corner in 0..8 {
        let q: [f64; 3] = std::array::from_fn(|c| {
            let x = wanted[c] * scale;
            let q = if corner >> c & 1 == 0 {
                x.floor()
            } else {
                x.ceil()
            };
            q.clamp(lo, hi)
        });
        // As a reader decodes it (a signed -128 reads as -1, like -127).
        let decoded = DVec3::from(q.map(|q| (q / scale).max(-1.0)));
        let length_off = (decoded.length() - length).abs();
        let turn = 1.0 - decoded.normalize_or_zero().dot(wanted.normalize_or_zero());
        // Within the tolerance first (false orders before true), then the nearer direction; of
        // those outside it, the nearer length.
        let outside = length_off > LENGTH_TOLERANCE;
        let score = (outside, if outside { length_off } else { turn });
        if score < best.1 {
            best = (q, score);
        }
    }
    best.0
}

/// How far a direction written as integers may be from its own length (a normal's is 1; the
/// glTF validator accepts 0.00465).
const LENGTH_TOLERANCE: f64 = 0.004;

/// The component type of 32-bit floats.
const FLOAT: u64 = 5126;

fn encode(layout: &Layout, value: f32, out: &mut [u8]) {
    if layout.component == FLOAT {
        out.copy_from_slice(&value.to_le_bytes());
        return;
    }
    store(layout, quantize(layout, value), out);
}

/// Writes the stored integer `q` (already in the type's range) in the layout's component type.
fn store(layout: &Layout, q: f64, out: &mut [u8]) {
    match layout.component {
        5120 => out.copy_from_slice(&(q as i8).to_le_bytes()),
        5121 => out.copy_from_slice(&(q as u8).to_le_bytes()),
        5122 => out.copy_from_slice(&(q as i16).to_le_bytes()),
        5123 => out.copy_from_slice(&(q as u16).to_le_bytes()),
        _ => out.copy_from_slice(&(q as u32).to_le_bytes()),
    }
}

/// How the specification names a layout's component type, for messages.
fn component_name(layout: &Layout) -> String {
    let kind = match layout.component {
        5120 => "signed 8-bit",
        5121 => "unsigned 8-bit",
        5122 => "signed 16-bit",
        5123 => "unsigned 16-bit",
        5125 => "unsigned 32-bit",
        _ => "32-bit float",
    };
    if layout.normalized {
        format!("normalized {kind} integers")
    } else if layout.component == FLOAT {
        format!("{kind}s")
    } else {
        format!("{kind} integers")
    }
}

/// The new values of one POSITION accessor, in its own space; `None` where the vertex did not
/// move.
struct PositionEdit {
    layout: Layout,
    before: Vec<[f32; 3]>,
    after: Vec<Option<[f32; 3]>>,
    world: DMat4,
    node: Option<usize>,
    mesh: usize,
}

/// The `name` of element `index` of the top-level array `key`, if it has one.
fn name_of<'a>(json: &'a Value, key: &str, index: usize) -> Option<&'a str> {
    json.get(key)?.get(index)?.get("name")?.as_str()
}

/// "node 3 'arm'" or "node 3" (or "no node").
fn node_label(json: &Value, node: Option<usize>) -> String {
    match node {
        None => "no node".into(),
        Some(n) => match name_of(json, "nodes", n) {
            Some(name) => format!("node {n} '{name}'"),
            None => format!("node {n}"),
        },
    }
}

/// "mesh 0 'ball'" or "mesh 0".
fn mesh_label(json: &Value, mesh: usize) -> String {
    match name_of(json, "meshes", mesh) {
        Some(name) => format!("mesh {mesh} '{name}'"),
        None => format!("mesh {mesh}"),
    }
}

/// Write `gltf` back to `path` (GLB or `.gltf` + `.bin`) with `mesh`'s positions.
pub(crate) fn write(
    path: &Path,
    format: Format,
    gltf: &GltfSource,
    source: &Source,
    mesh: &TriMesh,
    report: &mut SaveReport,
) -> Result<(), IoError> {
    let fail = |message: String| IoError::Refused {
        path: path.to_owned(),
        message,
    };
    let mut edits = position_edits(gltf, source, mesh, report).map_err(&fail)?;
    let mut json = gltf.json.clone();
    // The buffers are copied once, into the joined output buffer, and edited there.
    let mut joined = join_buffers(&mut json, &gltf.buffers);
    // Normals turn from the file's own positions (read from `gltf`, never from `joined`), so the
    // order of these two steps does not matter.
    let mut changed = turn_normals(gltf, source, &edits, &mut joined, report);
    // Accessors rewritten as floats (see below), with their new layouts.
    let mut converted: BTreeMap<usize, Layout> = BTreeMap::new();
    changed.extend(follow_texture(
        gltf,
        source,
        &edits,
        (&mut joined, &mut json, &mut converted),
        report,
    ));
    report.texture_coordinates_follow = true;
    // Positions stored as integers (KHR_mesh_quantization) that moved past what their type can
    // hold (a vertex below the least stored value, as gltfpack quantizes from the bounding box)
    // would be clamped: such an accessor is written as floats instead, in a new buffer view
    // (its old one stays, as the rest of the buffer does).
    for (&a, edit) in &mut edits {
        let outside = (edit.after.iter().flatten())
            .filter(|p| !p.iter().all(|&c| fits(&edit.layout, c)))
            .count();
        if outside == 0 {
            continue;
        }
        let layout = joined.as_floats(&mut json, a, &edit.layout, |k| edit.before[k].to_vec());
        report.warnings.push(format!(
            "{}: {} moved past what its quantized positions ({}, KHR_mesh_quantization) can hold, so its positions are written as 32-bit floats",
            mesh_label(&gltf.json, edit.mesh),
            super::text::counted(outside, "vertex", "vertices"),
            component_name(&edit.layout),
        ));
        edit.layout = layout;
        converted.insert(a, layout);
    }
    for (&a, edit) in &edits {
        for (k, after) in edit.after.iter().enumerate() {
            if let Some(p) = after {
                joined.put(&edit.layout, k, p);
            }
        }
        changed.insert(a);
    }
    // Bounds of what changed: always for POSITION (the specification asks for them), for other
    // accessors where the file had them.
    for a in changed {
        let Some(accessor) = json.get_mut("accessors").and_then(|list| list.get_mut(a)) else {
            continue;
        };
        if !edits.contains_key(&a) && accessor.get("min").is_none() && accessor.get("max").is_none()
        {
            continue;
        }
        let Some(layout) = converted.get(&a).copied().or_else(|| gltf.layout(a).ok()) else {
            continue;
        };
        if let Some((min, max)) = joined.bounds(&layout) {
            accessor["min"] = json!(min);
            accessor["max"] = json!(max);
        }
    }
    let mut bin = joined.bytes;
    let images = external_images(&json, source, report);
    match format {
        Format::Glb => {
            embed_images(&mut json, &mut bin, images, report);
            atomic::write(path, |w| write_glb(w, &json, &bin))
        }
        _ => {
            let copies = place_image_files(&mut json, images, path);
            let bin_path = super::gltf_bin_path(path);
            let bin_name = bin_path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "mesh.bin".into());
            if let Some(buffer) = json.get_mut("buffers").and_then(|b| b.get_mut(0)) {
                buffer["uri"] = json!(super::gltf::percent_encode(&bin_name));
            }
            let text = serde_json::to_vec_pretty(&json).map_err(|e| IoError::Write {
                path: path.to_owned(),
                source: std::io::Error::other(e),
            })?;
            let staged_bin = (!bin.is_empty())
                .then(|| atomic::stage(&bin_path, |w| w.write_all(&bin)))
                .transpose()?;
            let mut staged_images = Vec::new();
            for (from, to) in &copies {
                let bytes = std::fs::read(from).map_err(|source| IoError::Read {
                    path: from.clone(),
                    source,
                })?;
                staged_images.push(atomic::stage(to, |w| w.write_all(&bytes))?);
            }
            let staged_json = atomic::stage(path, |w| w.write_all(&text))?;
            for staged in staged_images {
                staged.commit()?;
            }
            if let Some(staged) = staged_bin {
                staged.commit()?;
            }
            staged_json.commit()
        }
    }
}

/// The new positions of every POSITION accessor with a moved vertex, from the first read of each
/// accessor; a later read that placed the same accessor differently is named in the report.
fn position_edits(
    gltf: &GltfSource,
    source: &Source,
    mesh: &TriMesh,
    report: &mut SaveReport,
) -> Result<BTreeMap<usize, PositionEdit>, String> {
    let mut edits: BTreeMap<usize, PositionEdit> = BTreeMap::new();
    let mut other_placements: BTreeMap<usize, Vec<Option<usize>>> = BTreeMap::new();
    for read in &gltf.reads {
        if let Some(edit) = edits.get(&read.accessor) {
            if edit.world != read.world {
                other_placements
                    .entry(read.accessor)
                    .or_default()
                    .push(read.node);
            }
            continue;
        }
        let layout = gltf.layout(read.accessor)?;
        if layout.components != 3 || layout.count != read.count {
            return Err(format!(
                "accessor {} no longer matches what was read from it",
                read.accessor
            ));
        }
        let before = gltf.read3_all(&layout);
        let identity = read.world == DMat4::IDENTITY;
        let inverse = read.world.inverse();
        let invertible = identity || (read.world.determinant() != 0.0 && inverse.is_finite());
        if !invertible {
            report.warnings.push(format!(
                "{} is placed by {} with a transform that flattens it: its vertices were not moved",
                mesh_label(&gltf.json, read.mesh),
                node_label(&gltf.json, read.node)
            ));
        }
        let after = (0..layout.count)
            .into_par_iter()
            .map(|k| {
                let new = mesh.positions[source.welded(read.raw_start + k)?];
                let placed = if identity {
                    before[k]
                } else {
                    read.world
                        .transform_point3(dvec(before[k]))
                        .as_vec3()
                        .to_array()
                };
                if placed == new || !invertible {
                    return None;
                }
                let local = if identity {
                    new
                } else {
                    inverse.transform_point3(dvec(new)).as_vec3().to_array()
                };
                local.iter().all(|c| c.is_finite()).then_some(local)
            })
            .collect();
        edits.insert(
            read.accessor,
            PositionEdit {
                layout,
                before,
                after,
                world: read.world,
                node: read.node,
                mesh: read.mesh,
            },
        );
    }
    for (accessor, others) in other_placements {
        let edit = &edits[&accessor];
        let others: Vec<String> = others.iter().map(|&n| node_label(&gltf.json, n)).collect();
        report.warnings.push(format!(
            "{} is also placed by {} with another transform; the file holds its vertices once, so they are written as faired where {} places it (the first in the scene)",
            mesh_label(&gltf.json, edit.mesh),
            others.join(", "),
            node_label(&gltf.json, edit.node)
        ));
    }
    edits.retain(|_, edit| edit.after.iter().any(Option::is_some));
    Ok(edits)
}

/// Move the texture coordinates (TEXCOORD_n) of every primitive whose positions moved so that
/// the texture stays where it was on the surface ([`super::uv_follow`]), each accessor from the
/// triangles of the primitives that use it with one POSITION accessor. A glTF splits a vertex at
/// a UV seam into elements with the same position; those walk as the one welded vertex they are,
/// so a slide across the seam goes on in each side's own chart, as in an OBJ. Returns the
/// accessors written.
fn follow_texture(
    gltf: &GltfSource,
    source: &Source,
    edits: &BTreeMap<usize, PositionEdit>,
    (joined, json, converted): (&mut Joined, &mut Value, &mut BTreeMap<usize, Layout>),
    report: &mut SaveReport,
) -> BTreeSet<usize> {
    // Texture coordinate accessor -> its position accessor and the triangles of its primitives.
    let mut uses: BTreeMap<usize, (usize, Vec<[u32; 3]>)> = BTreeMap::new();
    let mut conflicting = BTreeSet::new();
    for primitive in primitives(&gltf.json) {
        let Some(p) = attribute(primitive, "POSITION").filter(|p| edits.contains_key(p)) else {
            continue;
        };
        let Some(attributes) = primitive.get("attributes").and_then(Value::as_object) else {
            continue;
        };
        for (name, accessor) in attributes {
            let Some(t) = accessor.as_u64().map(|t| t as usize) else {
                continue;
            };
            if !name.starts_with("TEXCOORD_") {
                continue;
            }
            let triangles = gltf.triangles(primitive, edits[&p].layout.count);
            match uses.get_mut(&t) {
                Some((q, list)) if *q == p => list.extend(triangles),
                Some(_) => {
                    conflicting.insert(t);
                }
                None => {
                    uses.insert(t, (p, triangles));
                }
            }
        }
    }
    let mut changed = BTreeSet::new();
    for (t, (p, triangles)) in uses {
        let edit = &edits[&p];
        let layout = match gltf.layout(t) {
            Ok(layout)
                if !conflicting.contains(&t)
                    && layout.components == 2
                    && layout.count == edit.layout.count =>
            {
                layout
            }
            _ => {
                report.warnings.push(format!(
                    "texture coordinate accessor {t} does not match one set of positions: its \
                     texture coordinates stay with their vertices (the texture slides with them)"
                ));
                continue;
            }
        };
        let read: Vec<[f32; 2]> = (0..layout.count)
            .map(|k| [gltf.read(&layout, k, 0), gltf.read(&layout, k, 1)])
            .collect();
        let uvs: Vec<[f64; 2]> = read.iter().map(|uv| uv.map(f64::from)).collect();
        // The elements' welded vertices, numbered in order of first appearance, with their
        // positions before and after (the elements of one welded vertex share them).
        let start = gltf.first_raw_start(p);
        let mut number: BTreeMap<usize, u32> = BTreeMap::new();
        let (mut before, mut after) = (Vec::new(), Vec::new());
        let vertex_of: Vec<usize> = (0..layout.count)
            .map(|k| {
                // An element that became no welded vertex stands alone.
                let welded = start
                    .and_then(|s| source.welded(s + k))
                    .unwrap_or(usize::MAX - k);
                *number.entry(welded).or_insert_with(|| {
                    before.push(edit.before[k]);
                    after.push(edit.after[k].unwrap_or(edit.before[k]));
                    before.len() as u32 - 1
                }) as usize
            })
            .collect();
        let corners: Vec<super::uv_follow::UvTriangle> = triangles
            .iter()
            .map(|t| t.map(|k| [vertex_of[k as usize] as u32, k]))
            .collect();
        let followed = super::uv_follow::follow(&before, &after, &corners, &uvs);
        let moved: Vec<(usize, [f32; 2])> = (followed.moved.iter().enumerate())
            .filter_map(|(k, uv)| Some((k, uv.as_ref()?.map(|c| c as f32))))
            .filter(|(k, uv)| *uv != read[*k])
            .collect();
        // Stored as integers (KHR_mesh_quantization, over the coordinates' bounding box as
        // gltfpack stores them), a coordinate that followed its vertex past the range would be
        // clamped (a few on most moved seams): the accessor is written as floats instead.
        let outside = (moved.iter())
            .filter(|(_, uv)| !uv.iter().all(|&c| fits(&layout, c)))
            .count();
        let layout = if outside > 0 {
            report.warnings.push(format!(
                "texture coordinate accessor {t}: {} followed past what its quantized type ({}, \
                 KHR_mesh_quantization) can hold, so its texture coordinates are written as \
                 32-bit floats",
                super::text::counted(outside, "coordinate", "coordinates"),
                component_name(&layout),
            ));
            let floats = joined.as_floats(json, t, &layout, |k| read[k].to_vec());
            converted.insert(t, floats);
            floats
        } else {
            layout
        };
        for (k, uv) in moved {
            joined.put(&layout, k, &uv);
            changed.insert(t);
        }
    }
    changed
}

fn primitives(json: &Value) -> impl Iterator<Item = &Value> {
    json.get("meshes")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .flat_map(|mesh| {
            mesh.get("primitives")
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
        })
}

fn attribute(primitive: &Value, name: &str) -> Option<usize> {
    index(primitive.get("attributes")?, name)
}

/// Turn the NORMAL (and TANGENT) elements of every primitive whose faces moved. Normals of all
/// accessors share slots by welded vertex and value ([`SmoothGroups`]), so a smooth normal split
/// at a UV seam or between two primitives stays smooth.
fn turn_normals(
    gltf: &GltfSource,
    source: &Source,
    edits: &BTreeMap<usize, PositionEdit>,
    joined: &mut Joined,
    report: &mut SaveReport,
) -> BTreeSet<usize> {
    let touched: BTreeSet<usize> = primitives(&gltf.json)
        .filter(|p| attribute(p, "POSITION").is_some_and(|a| edits.contains_key(&a)))
        .filter_map(|p| attribute(p, "NORMAL"))
        .collect();
    // Normal accessor -> its layout, its primitives' triangles with their position accessor, and
    // its tangent accessors.
    type Uses = Vec<(usize, Layout, Vec<[u32; 3]>)>;
    let mut normals: BTreeMap<usize, (Layout, Uses, BTreeSet<usize>)> = BTreeMap::new();
    for primitive in primitives(&gltf.json) {
        let (Some(p), Some(n)) = (
            attribute(primitive, "POSITION"),
            attribute(primitive, "NORMAL"),
        ) else {
            continue;
        };
        if !touched.contains(&n) {
            continue;
        }
        let (Ok(layout), Ok(positions)) = (gltf.layout(n), gltf.layout(p)) else {
            report.warnings.push(format!(
                "normal accessor {n} cannot be read: its normals were not turned"
            ));
            continue;
        };
        if layout.components != 3 || layout.count != positions.count {
            report.warnings.push(format!(
                "normal accessor {n} does not match its positions: its normals were not turned"
            ));
            continue;
        }
        let (_, uses, tangents) = normals
            .entry(n)
            .or_insert_with(|| (layout, Vec::new(), BTreeSet::new()));
        uses.push((p, positions, gltf.triangles(primitive, positions.count)));
        if let Some(t) = attribute(primitive, "TANGENT") {
            tangents.insert(t);
        }
    }
    // Per element: the area sums of its faces before and after, block by block in parallel
    // (`block_sums`: each element adds its faces in the order of the triangles, as a serial pass
    // would). A normal that is its own faces' normal turns with its own sums, worked out in the
    // same block; the others (`SmoothGroups`) share the sums of their slot, gathered in `shared`
    // in the order of the elements and turned once every accessor has added to them.
    let mut groups = SmoothGroups::default();
    let mut shared = NormalTurns::new(0);
    let mut slotted: Vec<Slotted> = Vec::new();
    for (&n, (layout, uses, tangents)) in &normals {
        let faces: Vec<FaceUse> = uses
            .iter()
            .map(|(p, positions, triangles)| match edits.get(p) {
                Some(edit) => FaceUse::new(triangles, &edit.before, Some(&edit.after)),
                None => FaceUse::new(triangles, &gltf.read3_all(positions), None),
            })
            .collect();
        let values = gltf.read3_all(layout);
        let keep_turns = !tangents.is_empty();
        let blocks = block_sums(&faces, layout.count, |first, sums| {
            let mut block = BlockTurns::default();
            for (k, sums) in (first..).zip(sums) {
                let turn = if is_own_normal(sums.area_before(), values[k]) {
                    sums.alone().turn()
                } else {
                    block.shared.push((k, *sums));
                    None
                };
                block.normals.push(turn.map(|turn| turn.normal(values[k])));
                if keep_turns {
                    block.turns.push(turn);
                }
            }
            block
        });
        let start = gltf.first_raw_start(uses[0].0);
        let mut slots = Vec::new();
        for &(k, sums) in blocks.iter().flat_map(|block| &block.shared) {
            let welded = start.and_then(|s| source.welded(s + k));
            let slot = groups.slot(welded, values[k]);
            shared.merge_sums(slot, sums);
            slots.push((k, slot));
        }
        slotted.push(Slotted {
            accessor: n,
            layout,
            values,
            blocks,
            slots,
            tangents,
        });
    }
    let mut changed = BTreeSet::new();
    for normal in slotted {
        let layout = normal.layout;
        let shared_turns: Vec<(usize, Option<Turn>)> = normal
            .slots
            .iter()
            .map(|&(k, slot)| (k, shared.turn(slot)))
            .collect();
        let mut any = false;
        let own = normal.blocks.iter().flat_map(|block| &block.normals);
        for (k, value) in own.enumerate() {
            if let Some(value) = value {
                joined.put_direction(layout, k, value);
                any = true;
            }
        }
        for &(k, turn) in &shared_turns {
            if let Some(turn) = turn {
                joined.put_direction(layout, k, &turn.normal(normal.values[k]));
                any = true;
            }
        }
        if any {
            changed.insert(normal.accessor);
        }
        for &t in normal.tangents {
            match gltf.layout(t) {
                Ok(tangent) if tangent.components == 4 && tangent.count == layout.count => {
                    let own = normal.blocks.iter().flat_map(|block| &block.turns);
                    let turns = own.copied().enumerate().chain(shared_turns.iter().copied());
                    for (k, turn) in turns {
                        if let Some(turn) = turn {
                            let direction = turn.direction(gltf.read3(&tangent, k));
                            joined.put_direction(&tangent, k, &direction);
                        }
                    }
                    if any {
                        changed.insert(t);
                    }
                }
                _ => report.warnings.push(format!(
                    "tangent accessor {t} does not match its normals: its tangents were not turned"
                )),
            }
        }
    }
    changed
}

/// One block of a normal accessor's elements after [`block_sums`]: per element, the turned
/// normal when it turns with its own faces (`None` when it stays, or shares a slot), the turn
/// itself when the accessor has tangents, and the elements that share a slot with their sums.
#[derive(Default)]
struct BlockTurns {
    normals: Vec<Option<[f32; 3]>>,
    turns: Vec<Option<Turn>>,
    shared: Vec<(usize, SlotSums)>,
}

/// One normal accessor ready to turn: its values, its blocks, and the slot of each element that
/// shares one.
struct Slotted<'a> {
    accessor: usize,
    layout: &'a Layout,
    values: Vec<[f32; 3]>,
    blocks: Vec<BlockTurns>,
    slots: Vec<(usize, usize)>,
    tangents: &'a BTreeSet<usize>,
}

/// The triangles of one primitive that uses a normal accessor, with its positions before and
/// after (`None`: they did not move).
struct FaceUse<'a> {
    triangles: &'a [[u32; 3]],
    /// Per vertex of the primitive, its position before and after, side by side (one place to
    /// read per corner).
    points: Vec<[[f32; 3]; 2]>,
}

impl<'a> FaceUse<'a> {
    fn new(
        triangles: &'a [[u32; 3]],
        before: &[[f32; 3]],
        after: Option<&[Option<[f32; 3]>]>,
    ) -> FaceUse<'a> {
        let points = match after {
            Some(after) => before
                .par_iter()
                .zip(after)
                .with_min_len(4096)
                .map(|(&b, a)| [b, a.unwrap_or(b)])
                .collect(),
            None => before
                .par_iter()
                .with_min_len(4096)
                .map(|&b| [b, b])
                .collect(),
        };
        FaceUse { triangles, points }
    }

    fn corners(&self, t: [u32; 3]) -> ([DVec3; 3], [DVec3; 3]) {
        let points = t.map(|v| self.points[v as usize]);
        (points.map(|p| dvec(p[0])), points.map(|p| dvec(p[1])))
    }
}

/// Per block of a normal accessor's elements (`count` of them; one block per thread),
/// `finish(first element, the block's area sums)`, the blocks worked out in parallel and
/// returned in order. Each element's sums are those of the faces that use it, before and after,
/// added in the order of the uses and their triangles (a face using it twice adds twice), exactly
/// as one serial pass adds them: the same bits for any number of threads. Each block's task goes
/// through all the triangles and adds those with a corner in its block (a triangle across two
/// blocks is worked out in both).
fn block_sums<R: Send>(
    uses: &[FaceUse],
    count: usize,
    finish: impl Fn(usize, &[SlotSums]) -> R + Sync,
) -> Vec<R> {
    let threads = rayon::current_num_threads().max(1);
    let triangles: usize = uses.iter().map(|u| u.triangles.len()).sum();
    let block = if threads == 1 || triangles < 100_000 {
        count.max(1)
    } else {
        count.div_ceil(threads).max(1)
    };
    (0..count.div_ceil(block))
        .into_par_iter()
        .map(|b| {
            let first = b * block;
            let len = block.min(count - first);
            let mut sums = vec![SlotSums::default(); len];
            let ours = |v: u32| (v as usize).wrapping_sub(first) < len;
            for u in uses {
                for &t in u.triangles {
                    if !t.iter().any(|&v| ours(v)) {
                        continue;
                    }
                    let (before, after) = u.corners(t);
                    let add = SlotSums::of_triangle(before, after);
                    for v in t {
                        if ours(v) {
                            sums[v as usize - first].merge(add);
                        }
                    }
                }
            }
            finish(first, &sums)
        })
        .collect()
}

/// All buffers joined into one, and where each of them starts in it.
struct Joined {
    bytes: Vec<u8>,
    /// Where each source buffer starts in `bytes`, and how many of its bytes were kept.
    starts: Vec<(usize, usize)>,
}

impl Joined {
    /// Where byte `at` of buffer `buffer` (as a layout of the source sees it) is in the joined
    /// bytes, for `len` bytes; `None` past the end (a buffer longer than it declared).
    fn range(&self, buffer: usize, at: usize, len: usize) -> Option<std::ops::Range<usize>> {
        let &(start, kept) = self.starts.get(buffer)?;
        (at + len <= kept).then_some(start + at..start + at + len)
    }

    /// Per-component minimum and maximum of an accessor's stored values (integers for integer
    /// types, as the specification asks, not the normalized values); `None` when it is empty.
    fn bounds(&self, layout: &Layout) -> Option<(Vec<f64>, Vec<f64>)> {
        if layout.count == 0 {
            return None;
        }
        let raw = Layout {
            normalized: false,
            ..*layout
        };
        let mut min = vec![f64::INFINITY; layout.components];
        let mut max = vec![f64::NEG_INFINITY; layout.components];
        for k in 0..layout.count {
            for c in 0..layout.components {
                let at = layout.start + k * layout.stride + c * layout.size;
                let Some(range) = self.range(layout.buffer, at, layout.size) else {
                    continue;
                };
                let bytes = &self.bytes[range];
                let value = if layout.component == FLOAT {
                    f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f64
                } else {
                    decode(&raw, bytes) as f64
                };
                min[c] = min[c].min(value);
                max[c] = max[c].max(value);
            }
        }
        min.iter().all(|m| m.is_finite()).then_some((min, max))
    }

    /// Write the direction of element `k` (a normal, or a tangent's first three components):
    /// as [`Self::put`] does, but a normalized integer type gets the rounding that keeps it a
    /// unit vector ([`quantize_direction`]).
    fn put_direction(&mut self, layout: &Layout, k: usize, direction: &[f32; 3]) {
        if layout.component == FLOAT || !layout.normalized {
            return self.put(layout, k, direction);
        }
        let q = quantize_direction(layout, *direction);
        self.put_components(layout, k, 3, |c, out| store(layout, q[c], out));
    }

    /// Accessor `a` (of `layout`) rewritten as 32-bit floats: a new buffer view at the end of
    /// the bytes (at a multiple of 16 bytes) holding `values` (each element's components), which
    /// the accessor now points at; its old buffer view stays as it was. Returns the new layout.
    fn as_floats(
        &mut self,
        json: &mut Value,
        a: usize,
        layout: &Layout,
        values: impl Fn(usize) -> Vec<f32>,
    ) -> Layout {
        while !self.bytes.len().is_multiple_of(16) {
            self.bytes.push(0);
        }
        let start = self.bytes.len();
        let length = 4 * layout.components * layout.count;
        self.bytes.resize(start + length, 0);
        self.starts.push((start, length));
        let floats = Layout {
            buffer: self.starts.len() - 1,
            start: 0,
            stride: 4 * layout.components,
            component: FLOAT,
            size: 4,
            normalized: false,
            ..*layout
        };
        for k in 0..layout.count {
            self.put(&floats, k, &values(k));
        }
        let views = &mut json["bufferViews"];
        if !views.is_array() {
            *views = json!([]);
        }
        let views = views.as_array_mut().expect("made an array above");
        // (A vertex attribute's buffer view.)
        views
            .push(json!({"buffer": 0, "byteOffset": start, "byteLength": length, "target": 34962}));
        let view = views.len() - 1;
        set_buffer_length(json, self.bytes.len());
        if let Some(accessor) = json["accessors"][a].as_object_mut() {
            accessor.remove("byteOffset");
            accessor.remove("normalized");
            accessor.insert("bufferView".into(), json!(view));
            accessor.insert("componentType".into(), json!(FLOAT));
        }
        floats
    }

    /// Write the first components of element `k` (as many as `values` holds).
    fn put(&mut self, layout: &Layout, k: usize, values: &[f32]) {
        if layout.component == FLOAT {
            let at = layout.start + k * layout.stride;
            if let Some(range) = self.range(layout.buffer, at, 4 * values.len()) {
                let out = &mut self.bytes[range];
                for (c, value) in values.iter().enumerate() {
                    out[4 * c..4 * c + 4].copy_from_slice(&value.to_le_bytes());
                }
                return;
            }
        }
        self.put_components(layout, k, values.len(), |c, out| {
            encode(layout, values[c], out)
        });
    }

    /// Calls `write` with the bytes of each of the first `components` components of element
    /// `k` (those inside the buffer).
    fn put_components(
        &mut self,
        layout: &Layout,
        k: usize,
        components: usize,
        write: impl Fn(usize, &mut [u8]),
    ) {
        for c in 0..components {
            let at = layout.start + k * layout.stride + c * layout.size;
            if let Some(range) = self.range(layout.buffer, at, layout.size) {
                write(c, &mut self.bytes[range]);
            }
        }
    }
}

/// Join every buffer into one (each starting at a multiple of 16 bytes, cut to its declared
/// length) and point the buffer views at it.
fn join_buffers(json: &mut Value, buffers: &[Vec<u8>]) -> Joined {
    let declared: Vec<usize> = json
        .get("buffers")
        .and_then(Value::as_array)
        .map(|list| {
            list.iter()
                .map(|b| index(b, "byteLength").unwrap_or(0))
                .collect()
        })
        .unwrap_or_default();
    let mut bin = Vec::with_capacity(buffers.iter().map(|b| b.len() + 16).sum());
    let mut starts = Vec::with_capacity(buffers.len());
    for (b, data) in buffers.iter().enumerate() {
        while bin.len() % 16 != 0 {
            bin.push(0);
        }
        let length = declared
            .get(b)
            .copied()
            .unwrap_or(data.len())
            .min(data.len());
        starts.push((bin.len(), length));
        bin.extend_from_slice(&data[..length]);
    }
    if let Some(views) = json.get_mut("bufferViews").and_then(Value::as_array_mut) {
        for view in views {
            let buffer = index(view, "buffer").unwrap_or(0);
            let offset = index(view, "byteOffset").unwrap_or(0);
            let start = starts.get(buffer).map_or(0, |&(start, _)| start);
            view["buffer"] = json!(0);
            if start + offset > 0 {
                view["byteOffset"] = json!(start + offset);
            }
        }
    }
    if let Some(root) = json.as_object_mut() {
        if buffers.is_empty() {
            root.remove("buffers");
        } else {
            let mut joined = serde_json::Map::new();
            if let Some(name) = root
                .get("buffers")
                .and_then(|b| b.get(0))
                .and_then(|b| b.get("name"))
            {
                joined.insert("name".into(), name.clone());
            }
            joined.insert("byteLength".into(), json!(bin.len()));
            root.insert("buffers".into(), json!([joined]));
        }
    }
    Joined { bytes: bin, starts }
}

/// The external image files of the document (`uri` that is not a data: URI), resolved against
/// the input's folder; those that cannot be found are named in the report and left as they are.
fn external_images(
    json: &Value,
    source: &Source,
    report: &mut SaveReport,
) -> Vec<(usize, PathBuf)> {
    let mut found = Vec::new();
    let images = json.get("images").and_then(Value::as_array);
    for (i, image) in images.into_iter().flatten().enumerate() {
        let Some(uri) = image.get("uri").and_then(Value::as_str) else {
            continue;
        };
        if uri.starts_with("data:") {
            continue;
        }
        let Some(base) = &source.base_dir else {
            report.warnings.push(format!(
                "image {i} refers to the file {uri:?}, which cannot be found (the input was read from memory): the reference is kept as it was"
            ));
            continue;
        };
        let file = super::gltf::percent_decode(uri).map(|relative| base.join(relative));
        match file {
            Some(file) if file.is_file() => found.push((i, file)),
            _ => report.warnings.push(format!(
                "image {i} refers to {uri:?}, which is not beside the input: the reference is kept as it was"
            )),
        }
    }
    found
}

/// A GLB is self-contained: external images are copied into its binary chunk, each in a buffer
/// view of its own.
fn embed_images(
    json: &mut Value,
    bin: &mut Vec<u8>,
    images: Vec<(usize, PathBuf)>,
    report: &mut SaveReport,
) {
    for (i, file) in images {
        let bytes = match std::fs::read(&file) {
            Ok(bytes) => bytes,
            Err(e) => {
                report.warnings.push(format!(
                    "image {i} ({}) cannot be read ({e}): the reference is kept as it was",
                    file.display()
                ));
                continue;
            }
        };
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let view = json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()});
        bin.extend_from_slice(&bytes);
        let Some(root) = json.as_object_mut() else {
            return;
        };
        let views = root
            .entry("bufferViews")
            .or_insert_with(|| json!([]))
            .as_array_mut();
        let Some(views) = views else { return };
        views.push(view);
        let view_index = views.len() - 1;
        if let Some(image) = root.get_mut("images").and_then(|list| list.get_mut(i)) {
            if let Some(image) = image.as_object_mut() {
                image.remove("uri");
                image.insert("bufferView".into(), json!(view_index));
                if !image.contains_key("mimeType") {
                    image.insert("mimeType".into(), json!(image_mime_type(&bytes, &file)));
                }
            }
        }
    }
    set_buffer_length(json, bin.len());
}

fn set_buffer_length(json: &mut Value, length: usize) {
    if length == 0 {
        return;
    }
    match json.get_mut("buffers").and_then(|b| b.get_mut(0)) {
        Some(buffer) => buffer["byteLength"] = json!(length),
        None => json["buffers"] = json!([{ "byteLength": length }]),
    }
}

/// A `.gltf` keeps its images as files beside it: those not already in the output's folder are
/// copied there (as `<output stem>_<name>` when another file of that name is there) and the
/// copies to make are returned; those in the same folder are referenced as they were.
fn place_image_files(
    json: &mut Value,
    images: Vec<(usize, PathBuf)>,
    output: &Path,
) -> Vec<(PathBuf, PathBuf)> {
    let (out_dir, stem) = super::folder_and_stem(output);
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    let mut copies: Vec<(PathBuf, PathBuf)> = Vec::new();
    for (i, file) in images {
        if file.parent().is_some_and(|dir| same(dir, &out_dir)) {
            continue;
        }
        let name = file.file_name().map_or_else(
            || format!("image{i}.png"),
            |n| n.to_string_lossy().into_owned(),
        );
        let mut target = out_dir.join(&name);
        let taken = |target: &Path| {
            copies
                .iter()
                .any(|(from, to)| to == target && *from != file)
                || (target.exists() && std::fs::read(target).ok() != std::fs::read(&file).ok())
        };
        if taken(&target) {
            target = out_dir.join(format!("{stem}_{name}"));
        }
        let uri_name = target
            .file_name()
            .map_or_else(|| name.clone(), |n| n.to_string_lossy().into_owned());
        if let Some(image) = json.get_mut("images").and_then(|list| list.get_mut(i)) {
            image["uri"] = json!(super::gltf::percent_encode(&uri_name));
        }
        if !copies.iter().any(|(_, to)| *to == target) {
            copies.push((file, target));
        }
    }
    copies
}

fn write_glb(out: &mut dyn Write, json: &Value, bin: &[u8]) -> std::io::Result<()> {
    let text = serde_json::to_vec(json).map_err(std::io::Error::other)?;
    super::gltf::write_glb_container(out, text, bin)
}
