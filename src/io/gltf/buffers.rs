//! The output buffer of a written-back document: every buffer joined into one, and writing an
//! accessor's elements into it (in place, or as floats in a new buffer view).

use super::accessors::{decode, encode, quantize_direction, store, Layout, FLOAT};
use super::source::index;
use serde_json::{json, Value};

/// All buffers joined into one, and where each of them starts in it.
pub(super) struct Joined {
    pub(super) bytes: Vec<u8>,
    /// Where each source buffer starts in `bytes`, and how many of its bytes were kept.
    pub(super) starts: Vec<(usize, usize)>,
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
    pub(super) fn bounds(&self, layout: &Layout) -> Option<(Vec<f64>, Vec<f64>)> {
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
    pub(super) fn put_direction(&mut self, layout: &Layout, k: usize, direction: &[f32; 3]) {
        if layout.component == FLOAT || !layout.normalized {
            return self.put(layout, k, direction);
        }
        let q = quantize_direction(layout, *direction);
        self.put_components(layout, k, 3, |c, out| store(layout, q[c], out));
    }

    /// Accessor `a` (of `layout`) rewritten as 32-bit floats: a new buffer view at the end of
    /// the bytes (at a multiple of 16 bytes) holding `values` (each element's components), which
    /// the accessor now points at; its old buffer view stays as it was. Returns the new layout.
    pub(super) fn as_floats(
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
    pub(super) fn put(&mut self, layout: &Layout, k: usize, values: &[f32]) {
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
pub(super) fn join_buffers(json: &mut Value, buffers: &[Vec<u8>]) -> Joined {
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

pub(super) fn set_buffer_length(json: &mut Value, length: usize) {
    if length == 0 {
        return;
    }
    match json.get_mut("buffers").and_then(|b| b.get_mut(0)) {
        Some(buffer) => buffer["byteLength"] = json!(length),
        None => json["buffers"] = json!([{ "byteLength": length }]),
    }
}
