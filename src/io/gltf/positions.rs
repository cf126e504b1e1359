//! The new positions of a written-back document's POSITION accessors: each moved vertex taken
//! back into its primitive's own space through the inverse of the world transform it was read
//! with (in f64); a vertex that did not move keeps its bytes.

use super::accessors::Layout;
use super::source::{name_of, GltfSource};
use crate::io::normals::dvec;
use crate::io::origin::Origin;
use crate::io::SaveReport;
use crate::mesh::TriMesh;
use glam::DMat4;
use rayon::prelude::*;
use serde_json::Value;
use std::collections::BTreeMap;

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
pub(super) fn node_label(json: &Value, node: Option<usize>) -> String {
    match node {
        None => "no node".into(),
        Some(n) => match name_of(json, "nodes", n) {
            Some(name) => format!("node {n} '{name}'"),
            None => format!("node {n}"),
        },
    }
}

/// "mesh 0 'ball'" or "mesh 0".
pub(super) fn mesh_label(json: &Value, mesh: usize) -> String {
    match name_of(json, "meshes", mesh) {
        Some(name) => format!("mesh {mesh} '{name}'"),
        None => format!("mesh {mesh}"),
    }
}

/// The new positions of every POSITION accessor with a moved vertex, from the first read of each
/// accessor; a later read that placed the same accessor differently is named in the report.
pub(super) fn position_edits(
    gltf: &GltfSource,
    origin: &Origin,
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
                let new = mesh.positions[origin.welded(read.raw_start + k)?];
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
