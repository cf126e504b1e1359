//! After parsing: welding bit-identical positions (seams), dropping degenerate and repeated
//! triangles and unused vertices, orienting and building the topology, with a warning for what
//! is non-manifold or inconsistently oriented.

use super::{LoadReport, Source};
use crate::mesh::{self, Topology, TriMesh};
use std::sync::Arc;

/// How a file is loaded.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Merge vertices with identical positions (seams in OBJ and glTF files, STL's unshared
    /// corners).
    pub weld: bool,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self { weld: true }
    }
}

/// A loaded, welded and cleaned mesh with its topology, and what it was read from.
#[derive(Clone, Debug)]
pub struct Loaded {
    pub mesh: TriMesh,
    pub topology: Topology,
    pub report: LoadReport,
    /// The file the mesh came from, kept so that [`super::save_with_source`] writes it back with only
    /// the positions (and what depends on them) changed.
    pub source: Arc<Source>,
}

/// Weld, clean and build the topology of a freshly parsed mesh. Indices must be in range and
/// positions finite (every parser checks both). Non-manifold and inconsistently oriented input
/// gets a warning in the report.
pub fn finish(mesh: TriMesh, options: &LoadOptions) -> Loaded {
    finish_with_map(mesh, options).0
}

/// [`finish`], also giving the map from the input's vertices to the welded ones (`u32::MAX` for
/// a dropped vertex), `None` when they are the same.
pub(super) fn finish_with_map(
    mut mesh: TriMesh,
    options: &LoadOptions,
) -> (Loaded, Option<Vec<u32>>) {
    let mut report = LoadReport::default();
    let mut map = None;
    if options.weld {
        let (welded, weld_map) = mesh::weld_with_map(&mut mesh);
        report.welded_vertices = welded.merged_vertices;
        map = weld_map;
    }
    let (mut cleaned, clean_map) = mesh::clean_with_map_but_repeats(&mut mesh);
    if let Some(clean_map) = clean_map {
        map = Some(match map {
            None => clean_map,
            Some(mut map) => {
                for v in &mut map {
                    *v = clean_map[*v as usize];
                }
                map
            }
        });
    }
    // Triangles that repeat an earlier one's corners: found from the topology, which is built
    // anyway (and built again only when some go).
    let mut topology = Topology::build(&mesh);
    let repeats = std::mem::take(&mut topology.repeated_triangles);
    if !repeats.is_empty() {
        mesh::remove_triangles(&mut mesh, &repeats);
        topology = Topology::build(&mesh);
    }
    cleaned.removed_repeated_faces = repeats.len();
    report.removed_degenerate_faces = cleaned.removed_degenerate_faces;
    report.removed_repeated_faces = cleaned.removed_repeated_faces;
    if cleaned.removed_repeated_faces > 0 {
        report.warnings.push(format!(
            "{} triangles had the same three corners as another triangle and were left out of \
             the smoothing (they would be pulled to a point); written back into its own format, \
             the file keeps them",
            cleaned.removed_repeated_faces
        ));
    }
    report.removed_unreferenced_vertices = cleaned.removed_unreferenced_vertices;
    orient(&mut mesh, &mut topology, &mut report.warnings);
    warn_about_topology(&topology, &mut report.warnings);
    let source = Arc::new(Source::plain(&mesh));
    (
        Loaded {
            mesh,
            topology,
            report,
            source,
        },
        map,
    )
}

/// Neighbouring triangles facing opposite ways: each component is oriented consistently (the
/// file itself keeps its own faces when it is written back; only positions change), with a
/// warning for what was flipped and what cannot be oriented.
fn orient(mesh: &mut TriMesh, topology: &mut Topology, warnings: &mut Vec<String>) {
    if topology.inconsistent_edges > 0 {
        let oriented = mesh::orient_consistently(mesh, topology);
        if oriented.flipped_faces > 0 {
            warnings.push(format!(
                "{} triangles faced the other way from their neighbours and were flipped, in {} \
                 part(s), so that volume and normals mean something",
                oriented.flipped_faces, oriented.reoriented_components
            ));
            *topology = Topology::build(mesh);
        }
        if oriented.non_orientable_components > 0 {
            warnings.push(format!(
                "{} part(s) cannot be oriented (like a Moebius strip): they are faired without \
                 keeping to their normals, and their volume means nothing",
                oriented.non_orientable_components
            ));
        }
    }
}

/// Warnings for non-manifold edges and vertices and inconsistently oriented edges.
fn warn_about_topology(topology: &Topology, warnings: &mut Vec<String>) {
    if !topology.non_manifold_edges.is_empty() {
        let [a, b] = topology.non_manifold_edges[0];
        warnings.push(format!(
            "{} non-manifold edges (used by more than two triangles), e.g. between vertices {a} and {b}",
            topology.non_manifold_edges.len()
        ));
    }
    if !topology.non_manifold_vertices.is_empty() {
        warnings.push(format!(
            "{} non-manifold vertices (their triangles do not form a single fan), e.g. vertex {}",
            topology.non_manifold_vertices.len(),
            topology.non_manifold_vertices[0]
        ));
    }
    if topology.inconsistent_edges > 0 {
        warnings.push(format!(
            "{} edges where neighbouring triangles have opposite orientations",
            topology.inconsistent_edges
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finish_warns_about_non_manifold_edges() {
        let mesh = crate::mesh::fixtures::three_triangles_on_one_edge();
        let loaded = finish(mesh, &LoadOptions::default());
        assert!(
            loaded
                .report
                .warnings
                .iter()
                .any(|w| w.contains("non-manifold edges")),
            "{:?}",
            loaded.report.warnings
        );
    }
}
