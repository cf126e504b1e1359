//! Writing a [`Scene`] (parts, materials, file vertices; see [`crate::io::scene`]) as a new glTF
//! document.

use super::uri::percent_encode;
use super::write::write_glb_container;
use crate::io::atomic;
use crate::io::scene::{Scene, SceneVertex};
use crate::io::IoError;
use crate::mesh::TriMesh;
use std::collections::HashMap;

use std::path::Path;

/// A glTF of `scene` (see [`crate::io::scene`]): per part a node (named by the part's object) and a
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
                            crate::io::scene::ImageData::File(file) => file.clone(),
                            crate::io::scene::ImageData::Bytes(_) => path.to_owned(),
                        },
                        source,
                    })?;
                    let mime = crate::io::scene::image_mime_type(&bytes, Path::new(&image.name));
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
    staged.push(atomic::stage(&bin_path, |w| w.write_all(&bin))?);
    staged.push(atomic::stage(path, |w| w.write_all(&text))?);
    for file in staged {
        file.commit()?;
    }
    Ok(())
}
