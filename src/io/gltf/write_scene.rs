//! Writing a [`Scene`] (parts, materials, file vertices; see [`crate::io::scene`]) as a new glTF
//! document: the document is built as JSON values beside one binary buffer ([`Document`]), part
//! by part, then the materials, then written as a GLB or as a `.gltf` with its `.bin` and images.

use super::uri::percent_encode;
use super::write::{position_bounds, write_glb_container};
use crate::io::atomic;
use crate::io::scene::{
    image_mime_type, ImageData, Material, Part, PlacedImage, Primitive, Scene, SceneVertex,
};
use crate::io::IoError;
use crate::mesh::TriMesh;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::Path;

/// A glTF of `scene` (see [`crate::io::scene`]): per part a node (named by the part's object)
/// and a mesh (named by its group) with one primitive per material, each with its own POSITION,
/// NORMAL, TEXCOORD_0 and COLOR_0 (where the source had them) and u32 indices; a part with both
/// an object and a group name hangs under a node named by the object (an OBJ's `o` over its
/// `g`s); materials with pbrMetallicRoughness from the base colour, metallic, roughness and base
/// colour texture. A GLB embeds every image; a `.gltf` refers to image files beside it (copied
/// there, or written out when the source held them inside) and to `<stem>.bin`. Each primitive's
/// vertices follow `mesh`'s vertex order, so that a one-part, one-material file loads back as
/// `mesh` itself, vertex for vertex (several parts load back part by part).
pub(crate) fn write_scene(
    path: &Path,
    glb: bool,
    scene: &mut Scene,
    mesh: &TriMesh,
) -> Result<(), IoError> {
    scene.fill_missing_normals(mesh);
    let too_big = || IoError::Refused {
        path: path.to_owned(),
        message: "the mesh is too large for glTF (4 GiB)".into(),
    };
    let mut document = Document::default();
    let mut local = vec![u32::MAX; scene.vertices.len()];
    for part in &scene.parts {
        let mut primitives = Vec::new();
        for primitive in &part.primitives {
            primitives.push(document.add_primitive(scene, primitive, mesh, &mut local));
            if document.bin.len() > u32::MAX as usize - 1024 {
                return Err(too_big());
            }
        }
        document.add_part(part, primitives, scene.groups_under_objects);
    }
    // Images: embedded in a GLB; files beside a `.gltf`.
    let placed = if glb {
        Vec::new()
    } else {
        scene.place_images(path)
    };
    for (m, material) in scene.materials.iter().enumerate() {
        let placed = placed.get(m).and_then(Option::as_ref);
        document.add_material(material, glb.then_some(path), placed)?;
    }
    let (root, bin) = document.finish();
    write_files(path, glb, root, &bin, &placed)
}

/// A glTF document being built: its binary buffer and the JSON of its arrays.
#[derive(Default)]
struct Document {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    nodes: Vec<Value>,
    /// The nodes of the scene.
    roots: Vec<usize>,
    /// The node of each object name that has groups under it.
    parents: HashMap<String, usize>,
    images: Vec<Value>,
    /// The image of each file name (or image name, in a GLB).
    image_of: HashMap<String, usize>,
    textures: Vec<Value>,
    materials: Vec<Value>,
    /// Extensions the document uses (`extensionsUsed`): KHR_texture_transform where a base
    /// colour texture carried one.
    extensions_used: Vec<&'static str>,
}

/// Little-endian bytes of float vectors.
fn floats<const N: usize>(values: &[[f32; N]]) -> Vec<u8> {
    values
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect()
}

/// The file vertices of `primitive` in the order of the welded vertices they became (a vertex's
/// seam copies in file order), and its triangles' corners as indices into that order. Read back
/// and welded, a file with one part and one material gives the mesh's own vertex order, so the
/// vertex `i` that was saved is the vertex `i` that is loaded; in the order of first use (the
/// faces' order) the vertices would come back shuffled. `local` is all `u32::MAX` before and
/// after (scratch, one per file vertex).
fn vertex_order(scene: &Scene, primitive: &Primitive, local: &mut [u32]) -> (Vec<u32>, Vec<u32>) {
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
    (used, indices)
}

impl Document {
    /// Adds `bytes` as a buffer view (at a multiple of 4 bytes) with `target`; returns its index.
    fn add_view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut view =
            json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(view);
        self.views.len() - 1
    }

    /// Adds a vertex attribute accessor of 32-bit floats of `type_`, with `bytes` in a view of
    /// its own; `extra` holds more of the accessor's fields. Returns its index.
    fn add_floats(&mut self, bytes: &[u8], count: usize, type_: &str, extra: Value) -> usize {
        let view = self.add_view(bytes, Some(34962));
        let mut accessor =
            json!({"bufferView": view, "componentType": 5126, "count": count, "type": type_});
        if let (Some(accessor), Value::Object(extra)) = (accessor.as_object_mut(), extra) {
            accessor.extend(extra);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Adds one primitive's vertices (in [`vertex_order`]), attributes and indices; returns its
    /// JSON.
    fn add_primitive(
        &mut self,
        scene: &Scene,
        primitive: &Primitive,
        mesh: &TriMesh,
        local: &mut [u32],
    ) -> Value {
        let (used, indices) = vertex_order(scene, primitive, local);
        let vertices: Vec<&SceneVertex> =
            used.iter().map(|&v| &scene.vertices[v as usize]).collect();
        let positions: Vec<[f32; 3]> = vertices
            .iter()
            .map(|v| mesh.positions[v.welded as usize])
            .collect();
        let (min, max) = position_bounds(&positions);
        let count = positions.len();
        let mut attributes = serde_json::Map::new();
        let bounds = json!({"min": min, "max": max});
        let position = self.add_floats(&floats(&positions), count, "VEC3", bounds);
        attributes.insert("POSITION".into(), json!(position));
        let normals: Vec<[f32; 3]> = vertices.iter().map(|v| v.normal).collect();
        let normal = self.add_floats(&floats(&normals), count, "VEC3", json!({}));
        attributes.insert("NORMAL".into(), json!(normal));
        if scene.uvs {
            let uvs: Vec<[f32; 2]> = vertices.iter().map(|v| v.uv).collect();
            let uv = self.add_floats(&floats(&uvs), count, "VEC2", json!({}));
            attributes.insert("TEXCOORD_0".into(), json!(uv));
        }
        if scene.colours {
            let colours: Vec<[f32; 4]> = vertices.iter().map(|v| v.colour).collect();
            let colour = self.add_floats(&floats(&colours), count, "VEC4", json!({}));
            attributes.insert("COLOR_0".into(), json!(colour));
        }
        let index_bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.add_view(&index_bytes, Some(34963));
        self.accessors
            .push(json!({"bufferView": view, "componentType": 5125,
            "count": indices.len(), "type": "SCALAR"}));
        let mut out =
            json!({"attributes": attributes, "indices": self.accessors.len() - 1, "mode": 4});
        if let Some(m) = primitive.material {
            out["material"] = json!(m);
        }
        out
    }

    /// Adds a part's mesh (named by its group, else its object) and its node: named by the
    /// group under a node named by the object when `groups_under_objects` and it has both, else
    /// by its object or group, at the root.
    fn add_part(&mut self, part: &Part, primitives: Vec<Value>, groups_under_objects: bool) {
        let mut mesh_json = json!({ "primitives": primitives });
        if let Some(name) = part.group.as_ref().or(part.object.as_ref()) {
            mesh_json["name"] = json!(name);
        }
        self.meshes.push(mesh_json);
        let mut node = json!({ "mesh": self.meshes.len() - 1 });
        match (&part.object, &part.group) {
            (Some(object), Some(group)) if groups_under_objects => {
                node["name"] = json!(group);
                self.nodes.push(node);
                let child = self.nodes.len() - 1;
                let parent = match self.parents.get(object) {
                    Some(&parent) => parent,
                    None => {
                        self.nodes.push(json!({ "name": object, "children": [] }));
                        self.roots.push(self.nodes.len() - 1);
                        self.parents.insert(object.clone(), self.nodes.len() - 1);
                        self.nodes.len() - 1
                    }
                };
                if let Some(children) = self.nodes[parent]["children"].as_array_mut() {
                    children.push(json!(child));
                }
            }
            (name, other) => {
                if let Some(name) = name.as_ref().or(other.as_ref()) {
                    node["name"] = json!(name);
                }
                self.nodes.push(node);
                self.roots.push(self.nodes.len() - 1);
            }
        }
    }

    /// Adds a material with pbrMetallicRoughness and, when it has one, its base colour texture:
    /// the image embedded when `embed_for` (a GLB, the output path naming errors), else referred
    /// to by the file name it was `placed` under beside the `.gltf`. Materials with the same image
    /// share it.
    fn add_material(
        &mut self,
        material: &Material,
        embed_for: Option<&Path>,
        placed: Option<&PlacedImage>,
    ) -> Result<(), IoError> {
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
            let key = match (embed_for, placed) {
                (None, Some(placed)) => placed.uri_name.clone(),
                _ => image.name.clone(),
            };
            let index = match (self.image_of.get(&key), embed_for) {
                (Some(&index), _) => index,
                (None, Some(path)) => {
                    let bytes = image.data.bytes().map_err(|source| IoError::Read {
                        path: match &image.data {
                            ImageData::File(file) => file.clone(),
                            ImageData::Bytes(_) => path.to_owned(),
                        },
                        source,
                    })?;
                    let mime = image_mime_type(&bytes, Path::new(&image.name));
                    let view = self.add_view(&bytes, None);
                    self.images
                        .push(json!({"bufferView": view, "mimeType": mime, "name": image.name}));
                    self.images.len() - 1
                }
                (None, None) => {
                    self.images
                        .push(json!({"uri": percent_encode(&key), "name": image.name}));
                    self.images.len() - 1
                }
            };
            self.image_of.insert(key, index);
            self.textures.push(json!({ "source": index }));
            pbr["baseColorTexture"] = json!({ "index": self.textures.len() - 1 });
            // The texture transform as the source had it; only over TEXCOORD_0, the one set of
            // texture coordinates written (see `Scene::texture_transforms_carried`).
            if let Some(transform) = material.texture_transform.as_ref() {
                if material.tex_coord == 0 {
                    pbr["baseColorTexture"]["extensions"] =
                        json!({ "KHR_texture_transform": transform.json });
                    if !self.extensions_used.contains(&"KHR_texture_transform") {
                        self.extensions_used.push("KHR_texture_transform");
                    }
                }
            }
        }
        let mut out = json!({"name": material.name, "pbrMetallicRoughness": pbr});
        if a.clamp(0.0, 1.0) < 1.0 {
            out["alphaMode"] = json!("BLEND");
        }
        self.materials.push(out);
        Ok(())
    }

    /// The document's JSON (its materials, textures and images where it has any) and its binary
    /// buffer.
    fn finish(self) -> (Value, Vec<u8>) {
        let mut root = json!({
            "asset": {"version": "2.0", "generator": "fairmesh"},
            "scene": 0,
            "scenes": [{"nodes": self.roots}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{"byteLength": self.bin.len()}],
        });
        if !self.extensions_used.is_empty() {
            root["extensionsUsed"] = json!(self.extensions_used);
        }
        for (key, list) in [
            ("materials", self.materials),
            ("textures", self.textures),
            ("images", self.images),
        ] {
            if !list.is_empty() {
                root[key] = Value::Array(list);
            }
        }
        (root, self.bin)
    }
}

/// Writes the document: a GLB in one atomic write; a `.gltf` with `<stem>.bin` and the images
/// `placed` beside it that are to be written, all staged first and renamed into place only when
/// every one is complete.
fn write_files(
    path: &Path,
    glb: bool,
    mut root: Value,
    bin: &[u8],
    placed: &[Option<PlacedImage>],
) -> Result<(), IoError> {
    let fail = |source: std::io::Error| IoError::Write {
        path: path.to_owned(),
        source,
    };
    if glb {
        let text = serde_json::to_vec(&root).map_err(|e| fail(std::io::Error::other(e)))?;
        return atomic::write(path, |w| write_glb_container(w, text, bin));
    }
    let bin_path = crate::io::gltf_bin_path(path);
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
    staged.push(atomic::stage(&bin_path, |w| w.write_all(bin))?);
    staged.push(atomic::stage(path, |w| w.write_all(&text))?);
    for file in staged {
        file.commit()?;
    }
    Ok(())
}
