//! The glTF document as loaded ([`GltfSource`]: its JSON, its buffers and which accessor elements
//! became which vertices), and reading its accessors again from the JSON: for writing it back and
//! for carrying its UVs, colours and contents into another format.

use super::accessors::{decode, Layout, FLOAT};
use crate::io::carry::{Gather, VertexAttributes};
use crate::io::origin::Origin;
use glam::DMat4;
use serde_json::Value;

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

pub(super) fn index(value: &Value, key: &str) -> Option<usize> {
    value
        .get(key)?
        .as_u64()
        .and_then(|v| usize::try_from(v).ok())
}

impl GltfSource {
    /// Where the first read of POSITION accessor `accessor` starts among the parser's vertices
    /// (its elements' welded vertices are `origin.welded(start + k)`).
    pub(super) fn first_raw_start(&self, accessor: usize) -> Option<usize> {
        self.reads
            .iter()
            .find(|read| read.accessor == accessor)
            .map(|read| read.raw_start)
    }

    pub(super) fn array(&self, key: &str) -> &[Value] {
        self.json
            .get(key)
            .and_then(Value::as_array)
            .map_or(&[], Vec::as_slice)
    }

    /// The checked layout of accessor `a`, or why it cannot be used.
    pub(super) fn layout(&self, a: usize) -> Result<Layout, String> {
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

    pub(super) fn read(&self, layout: &Layout, element: usize, component: usize) -> f32 {
        let at = layout.start + element * layout.stride + component * layout.size;
        let bytes = &self.buffers[layout.buffer][at..at + layout.size];
        decode(layout, bytes)
    }

    pub(super) fn read3(&self, layout: &Layout, element: usize) -> [f32; 3] {
        [0, 1, 2].map(|c| self.read(layout, element, c))
    }

    /// The first three components of every element ([`Self::read3`] of each), read straight
    /// from the bytes for plain floats.
    pub(super) fn read3_all(&self, layout: &Layout) -> Vec<[f32; 3]> {
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
    pub(super) fn triangles(&self, primitive: &Value, vertex_count: usize) -> Vec<[u32; 3]> {
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
    pub(super) fn read_attribute(&self, read: &PrimitiveRead, name: &str) -> Option<Layout> {
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
    pub(crate) fn vertex_attributes(&self, origin: &Origin) -> VertexAttributes {
        let mut uvs = Gather::<2>::new(origin.welded_vertices, [0.0; 2]);
        let mut colours = Gather::<4>::new(origin.welded_vertices, [1.0; 4]);
        let (mut any_uv, mut any_colour) = (false, false);
        for read in &self.reads {
            let layout_of = |name: &str| self.read_attribute(read, name);
            if let Some(layout) = layout_of("TEXCOORD_0").filter(|l| l.components == 2) {
                any_uv = true;
                for k in 0..read.count {
                    let uv = [self.read(&layout, k, 0), self.read(&layout, k, 1)];
                    uvs.put(origin.welded(read.raw_start + k), uv);
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
                    colours.put(origin.welded(read.raw_start + k), [r, g, b, alpha]);
                }
            }
        }
        VertexAttributes::gathered(any_uv.then_some(uvs), any_colour.then_some(colours))
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

/// The `name` of element `index` of the top-level array `key`, if it has one.
pub(super) fn name_of<'a>(json: &'a Value, key: &str, index: usize) -> Option<&'a str> {
    json.get(key)?.get(index)?.get("name")?.as_str()
}

pub(super) fn primitives(json: &Value) -> impl Iterator<Item = &Value> {
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

pub(super) fn attribute(primitive: &Value, name: &str) -> Option<usize> {
    index(primitive.get("attributes")?, name)
}
