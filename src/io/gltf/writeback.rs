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
//! [`crate::io::source`]); a tangent's w (handedness) is kept. Morph target deltas are kept as they
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

use super::accessors::{component_name, fits, Layout};
use super::buffers::{join_buffers, Joined};
use super::images::{embed_images, external_images, place_image_files};
use super::source::{attribute, name_of, primitives, GltfSource};
use super::turn_normals::turn_normals;
use super::uri::percent_encode;
use super::write::write_glb_container;
use crate::io::source::{dvec, SaveReport, Source};
use crate::io::{atomic, Format, IoError};
use crate::mesh::TriMesh;
use glam::DMat4;
use rayon::prelude::*;
use serde_json::{json, Value};
use std::collections::{BTreeMap, BTreeSet};
use std::io::Write;
use std::path::Path;

/// The new values of one POSITION accessor, in its own space; `None` where the vertex did not
/// move.
pub(super) struct PositionEdit {
    pub(super) layout: Layout,
    pub(super) before: Vec<[f32; 3]>,
    pub(super) after: Vec<Option<[f32; 3]>>,
    pub(super) world: DMat4,
    pub(super) node: Option<usize>,
    pub(super) mesh: usize,
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
            crate::io::text::counted(outside, "vertex", "vertices"),
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
            let bin_path = crate::io::gltf_bin_path(path);
            let bin_name = bin_path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "mesh.bin".into());
            if let Some(buffer) = json.get_mut("buffers").and_then(|b| b.get_mut(0)) {
                buffer["uri"] = json!(percent_encode(&bin_name));
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
/// the texture stays where it was on the surface ([`crate::io::uv_follow`]), each accessor from the
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
        let corners: Vec<crate::io::uv_follow::UvTriangle> = triangles
            .iter()
            .map(|t| t.map(|k| [vertex_of[k as usize] as u32, k]))
            .collect();
        let followed = crate::io::uv_follow::follow(&before, &after, &corners, &uvs);
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
fn write_glb(out: &mut dyn Write, json: &Value, bin: &[u8]) -> std::io::Result<()> {
    let text = serde_json::to_vec(json).map_err(std::io::Error::other)?;
    write_glb_container(out, text, bin)
}
