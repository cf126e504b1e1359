//! The kept glTF document as a [`Scene`] (see [`crate::io::scene`]), for saving in another
//! format: its parts, primitives, file vertices, materials and base colour textures.

use super::accessors::Layout;
use super::source::{attribute, index, name_of, GltfSource, PrimitiveRead};
use super::uri::{decode_base64, percent_decode};
use super::validate::IMAGE_FORMATS;
use crate::io::normals::dvec;
use crate::io::origin::Origin;
use crate::io::scene::{
    image_file_name, image_mime_type, Image, ImageData, Material, Part, Primitive, Scene,
    SceneVertex, TextureSampler, TextureTransform,
};
use crate::mesh::TriMesh;
use glam::{DMat3, DMat4};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

impl GltfSource {
    /// The document's parts, materials and file vertices, for saving in another format (see
    /// [`crate::io::scene`]): one part per node read (the node's name, and its mesh's name as the
    /// group), one primitive per glTF primitive, vertices and normals in world space, normals
    /// turned with their faces to `mesh`'s positions.
    pub(crate) fn scene(&self, origin: &Origin, mesh: &TriMesh) -> Scene {
        let mut scene = Scene {
            vertices: vec![SceneVertex::new(None, [0.0; 3]); origin.raw_vertices],
            material_less_is_gltf_default: true,
            ..Scene::default()
        };
        scene.materials = self.materials(origin, &mut scene.warnings);
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
            self.add_vertices(read, primitive, &positions, origin, &mut scene);
            let part = *part_of_node
                .entry(read.node)
                .or_insert_with(|| self.add_part(read, &mut scene.parts));
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

    /// The file vertices of one primitive read (`positions` its POSITION layout) in world space,
    /// with their UVs, colours and normals where it has them (a value that is not finite becomes
    /// zero, or white); the scene notes which it has.
    fn add_vertices(
        &self,
        read: &PrimitiveRead,
        primitive: &Value,
        positions: &Layout,
        origin: &Origin,
        scene: &mut Scene,
    ) {
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
            let local = self.read3(positions, k);
            let before = if identity {
                local
            } else {
                read.world
                    .transform_point3(dvec(local))
                    .as_vec3()
                    .to_array()
            };
            let mut vertex = SceneVertex::new(origin.welded(read.raw_start + k), before);
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
    }

    /// A new part for the node of `read`: named by the node (or `node<n>`), grouped by its
    /// mesh's name; returns its index.
    fn add_part(&self, read: &PrimitiveRead, parts: &mut Vec<Part>) -> usize {
        let mesh_name = name_of(&self.json, "meshes", read.mesh).map(String::from);
        let object = match read.node {
            Some(n) => Some(
                name_of(&self.json, "nodes", n).map_or_else(|| format!("node{n}"), String::from),
            ),
            None => mesh_name.clone(),
        };
        parts.push(Part {
            object,
            group: mesh_name,
            primitives: Vec::new(),
        });
        parts.len() - 1
    }

    /// Each material's name, base colour, metallic and roughness factors and base colour
    /// texture; what else a material has (other textures, extensions) is named in `warnings`.
    fn materials(&self, origin: &Origin, warnings: &mut Vec<String>) -> Vec<Material> {
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
                let texture_info = pbr.and_then(|p| p.get("baseColorTexture"));
                let texture_entry = texture_info
                    .and_then(|t| index(t, "index"))
                    .and_then(|t| self.array("textures").get(t));
                let transform_json = texture_info
                    .and_then(|t| t.get("extensions"))
                    .and_then(|e| e.get("KHR_texture_transform"));
                let texture_transform = transform_json.and_then(TextureTransform::from_gltf);
                let tex_coord = transform_json
                    .and_then(|t| index(t, "texCoord"))
                    .or_else(|| texture_info.and_then(|t| index(t, "texCoord")))
                    .unwrap_or(0) as u32;
                let sampler = texture_entry
                    .and_then(|t| index(t, "sampler"))
                    .and_then(|s| self.array("samplers").get(s))
                    .map_or_else(TextureSampler::default, TextureSampler::from_gltf);
                let texture = texture_entry
                    .and_then(|t| {
                        // Its own image (a PNG or JPEG) where it has one, which other tools read
                        // more widely; otherwise the one in another format (KTX2, WebP, ...).
                        index(t, "source").or_else(|| {
                            (IMAGE_FORMATS.iter())
                                .find_map(|e| index(t.get("extensions")?.get(e)?, "source"))
                        })
                    })
                    .and_then(|image| self.image(image, &name, origin, warnings));
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
                if tex_coord != 0 && texture.is_some() {
                    unkept.push(
                        "its base colour texture's own texture coordinates (TEXCOORD_0 is kept)",
                    );
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
                    sampler,
                    tex_coord,
                    texture_transform,
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
        origin: &Origin,
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
                let Ok(bytes) = decode_base64(data.as_bytes()) else {
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
            let Some(base) = &origin.base_dir else {
                return lost(format!(
                    "image {j} is the file {uri:?}, which cannot be found: the input was read from memory"
                ));
            };
            let file = percent_decode(uri).map(|relative| base.join(relative));
            return match file {
                Some(file) if crate::io::files::is_file(&file) => Some(Image {
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
}
