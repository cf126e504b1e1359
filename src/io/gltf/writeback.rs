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
use super::positions::{mesh_label, position_edits, PositionEdit};
use super::source::GltfSource;
use super::texture::follow_texture;
use super::turn_normals::turn_normals;
use super::uri::percent_encode;
use super::write::write_glb_container;
use crate::io::origin::Origin;
use crate::io::SaveReport;
use crate::io::{atomic, Format, IoError};
use crate::mesh::TriMesh;
use serde_json::{json, Value};
use std::collections::{BTreeMap, BTreeSet};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Write `gltf` back to `path` (GLB or `.gltf` + `.bin`) with `mesh`'s positions.
pub(crate) fn write(
    path: &Path,
    format: Format,
    gltf: &GltfSource,
    origin: &Origin,
    mesh: &TriMesh,
    report: &mut SaveReport,
) -> Result<(), IoError> {
    let fail = |message: String| IoError::Refused {
        path: path.to_owned(),
        message,
    };
    let mut edits = position_edits(gltf, origin, mesh, report).map_err(&fail)?;
    let mut json = gltf.json.clone();
    // The buffers are copied once, into the joined output buffer, and edited there.
    let mut joined = join_buffers(&mut json, &gltf.buffers);
    // Normals turn from the file's own positions (read from `gltf`, never from `joined`), so the
    // order of these two steps does not matter.
    let mut changed = turn_normals(gltf, origin, &edits, &mut joined, report);
    // Accessors rewritten as floats (see `positions_as_floats`), with their new layouts.
    let mut converted: BTreeMap<usize, Layout> = BTreeMap::new();
    changed.extend(follow_texture(
        gltf,
        origin,
        &edits,
        (&mut joined, &mut json, &mut converted),
        report,
    ));
    report.texture_coordinates_follow = true;
    positions_as_floats(
        gltf,
        &mut edits,
        (&mut joined, &mut json, &mut converted),
        report,
    );
    for (&a, edit) in &edits {
        for (k, after) in edit.after.iter().enumerate() {
            if let Some(p) = after {
                joined.put(&edit.layout, k, p);
            }
        }
        changed.insert(a);
    }
    update_bounds(gltf, &edits, &converted, &joined, changed, &mut json);
    let mut bin = joined.bytes;
    let images = external_images(&json, origin, report);
    match format {
        Format::Glb => {
            embed_images(&mut json, &mut bin, images, report);
            atomic::write(path, |w| write_glb(w, &json, &bin))
        }
        _ => write_gltf_files(path, json, &bin, images),
    }
}

/// Positions stored as integers (KHR_mesh_quantization) that moved past what their type can
/// hold (a vertex below the least stored value, as gltfpack quantizes from the bounding box)
/// would be clamped: such an accessor is written as floats instead, in a new buffer view (its
/// old one stays, as the rest of the buffer does), and is named in the report.
fn positions_as_floats(
    gltf: &GltfSource,
    edits: &mut BTreeMap<usize, PositionEdit>,
    (joined, json, converted): (&mut Joined, &mut Value, &mut BTreeMap<usize, Layout>),
    report: &mut SaveReport,
) {
    for (&a, edit) in edits {
        let outside = (edit.after.iter().flatten())
            .filter(|p| !p.iter().all(|&c| fits(&edit.layout, c)))
            .count();
        if outside == 0 {
            continue;
        }
        let layout = joined.as_floats(json, a, &edit.layout, |k| edit.before[k].to_vec());
        report.warnings.push(format!(
            "{}: {} moved past what its quantized positions ({}, KHR_mesh_quantization) can hold, so its positions are written as 32-bit floats",
            mesh_label(&gltf.json, edit.mesh),
            crate::io::text::counted(outside, "vertex", "vertices"),
            component_name(&edit.layout),
        ));
        edit.layout = layout;
        converted.insert(a, layout);
    }
}

/// The `min`/`max` of the accessors that `changed`: always for POSITION (the specification asks
/// for them), for other accessors where the file had them.
fn update_bounds(
    gltf: &GltfSource,
    edits: &BTreeMap<usize, PositionEdit>,
    converted: &BTreeMap<usize, Layout>,
    joined: &Joined,
    changed: BTreeSet<usize>,
    json: &mut Value,
) {
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
}

/// A written-back `.gltf`: the JSON, `<stem>.bin` (when there are buffers) and the copies of
/// its external images, all staged first and renamed into place only when every one is
/// complete.
fn write_gltf_files(
    path: &Path,
    mut json: Value,
    bin: &[u8],
    images: Vec<(usize, PathBuf)>,
) -> Result<(), IoError> {
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
        .then(|| atomic::stage(&bin_path, |w| w.write_all(bin)))
        .transpose()?;
    let mut staged_images = Vec::new();
    for (from, to) in &copies {
        staged_images.push(atomic::stage_copy(from, to)?);
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

fn write_glb(out: &mut dyn Write, json: &Value, bin: &[u8]) -> std::io::Result<()> {
    let text = serde_json::to_vec(json).map_err(std::io::Error::other)?;
    write_glb_container(out, text, bin)
}
