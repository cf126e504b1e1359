//! Texture coordinates that follow their vertices' slide along the surface in a written-back
//! document ([`crate::io::uv_follow`]), so that the texture stays where it was.

use super::accessors::{component_name, fits, Layout};
use super::buffers::Joined;
use super::positions::PositionEdit;
use super::source::{attribute, primitives, GltfSource};
use crate::io::origin::Origin;
use crate::io::SaveReport;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};

/// Move the texture coordinates (TEXCOORD_n) of every primitive whose positions moved so that
/// the texture stays where it was on the surface ([`crate::io::uv_follow`]), each accessor from the
/// triangles of the primitives that use it with one POSITION accessor. A glTF splits a vertex at
/// a UV seam into elements with the same position; those walk as the one welded vertex they are,
/// so a slide across the seam goes on in each side's own chart, as in an OBJ. Returns the
/// accessors written.
pub(super) fn follow_texture(
    gltf: &GltfSource,
    origin: &Origin,
    edits: &BTreeMap<usize, PositionEdit>,
    (joined, json, converted): (&mut Joined, &mut Value, &mut BTreeMap<usize, Layout>),
    report: &mut SaveReport,
) -> BTreeSet<usize> {
    let (uses, conflicting) = texture_uses(gltf, edits);
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
        let start = gltf.first_raw_start(p);
        let moved = followed(&read, edit, &triangles, |k| {
            start.and_then(|s| origin.welded(s + k))
        });
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
                crate::io::text::counted(outside, "coordinate", "coordinates"),
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

/// Texture coordinate accessor -> its position accessor and the triangles of its primitives.
type TextureUses = BTreeMap<usize, (usize, Vec<[u32; 3]>)>;

/// Per texture coordinate accessor of a primitive whose positions moved: its position accessor
/// and the triangles of its primitives; and the accessors used with more than one position
/// accessor (those cannot follow).
fn texture_uses(
    gltf: &GltfSource,
    edits: &BTreeMap<usize, PositionEdit>,
) -> (TextureUses, BTreeSet<usize>) {
    let mut uses: TextureUses = BTreeMap::new();
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
    (uses, conflicting)
}

/// The texture coordinates `read` (one per element of the position accessor `edit`) that
/// changed as they followed their vertices, with their elements. The elements' welded vertices
/// (`welded` of an element) are numbered in order of first appearance, with their positions
/// before and after (the elements of one welded vertex share them).
fn followed(
    read: &[[f32; 2]],
    edit: &PositionEdit,
    triangles: &[[u32; 3]],
    welded: impl Fn(usize) -> Option<usize>,
) -> Vec<(usize, [f32; 2])> {
    let uvs: Vec<[f64; 2]> = read.iter().map(|uv| uv.map(f64::from)).collect();
    let mut number: BTreeMap<usize, u32> = BTreeMap::new();
    let (mut before, mut after) = (Vec::new(), Vec::new());
    let vertex_of: Vec<usize> = (0..read.len())
        .map(|k| {
            // An element that became no welded vertex stands alone.
            let welded = welded(k).unwrap_or(usize::MAX - k);
            *number.entry(welded).or_insert_with(|| {
                before.push(edit.before[k]);
                after.push(edit.after[k].unwrap_or(edit.before[k]));
                before.len() as u32 - 1
            }) as usize
        })
        .collect();
    let corners: Vec<crate::io::uv_follow::UvTriangle> = triangles
        .iter()
        .map(|t| t.map(|k| [vertex_of[k as usize] as u32, k]))
        .collect();
    let followed = crate::io::uv_follow::follow(&before, &after, &corners, &uvs);
    (followed.moved.iter().enumerate())
        .filter_map(|(k, uv)| Some((k, uv.as_ref()?.map(|c| c as f32))))
        .filter(|(k, uv)| *uv != read[*k])
        .collect()
}
