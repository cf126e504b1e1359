//! Carrying a file's per-vertex data into another format (a coloured PLY scan saved as glTF, a
//! glTF scene saved as OBJ).
//!
//! The writers of another format write the welded mesh: one vertex per welded vertex. What the
//! source holds per file vertex (UVs, colours) is gathered onto the welded vertices
//! ([`VertexAttributes`]): each welded vertex takes the value of the first file vertex that
//! became it. Where file vertices that were welded into one had different values (a UV seam, a
//! colour border) the output cannot keep both, and the save report says how many vertices lost
//! their split. Normals are not carried but recomputed by the writers from the moved mesh.
//! Values that are not finite are never written: such a vertex gets zero. A vertex that had no
//! value (a part of a glTF scene with no COLOR_0 beside one with colours) gets white, or UV 0 0.
//! UVs are in the library's convention (`uv_convention.rs`) and follow their vertices' slide
//! along the surface ([`follow_slide`]), as the write-backs make them do.

use super::uv_follow::UvTriangle;
use crate::mesh::TriMesh;

/// Per welded vertex: UVs and RGBA colours (0..1), each present when the source had them.
#[derive(Debug, Default)]
pub struct VertexAttributes {
    pub uvs: Option<Vec<[f32; 2]>>,
    pub colours: Option<Vec<[f32; 4]>>,
    /// Welded vertices whose file vertices had different UVs / colours (the first was kept).
    pub uv_splits_merged: usize,
    pub colour_splits_merged: usize,
}

impl VertexAttributes {
    /// The UVs and colours gathered onto the welded vertices, each where the file had them.
    pub(crate) fn gathered(uvs: Option<Gather<2>>, colours: Option<Gather<4>>) -> Self {
        let mut out = VertexAttributes::default();
        if let Some(colours) = colours {
            let (values, merged) = colours.finish();
            out.colours = Some(values);
            out.colour_splits_merged = merged;
        }
        if let Some(uvs) = uvs {
            let (values, merged) = uvs.finish();
            out.uvs = Some(values);
            out.uv_splits_merged = merged;
        }
        out
    }

    /// What was carried, and what was lost doing so, in plain words.
    pub(crate) fn describe(&self) -> (Vec<&'static str>, Vec<String>) {
        let mut kept = Vec::new();
        let mut lost = Vec::new();
        if self.uvs.is_some() {
            kept.push("UVs");
            if self.uv_splits_merged > 0 {
                lost.push(format!(
                    "the UV seams at {} vertices (one vertex keeps one UV; the first was kept)",
                    self.uv_splits_merged
                ));
            }
        }
        if self.colours.is_some() {
            kept.push("vertex colours");
            if self.colour_splits_merged > 0 {
                lost.push(format!(
                    "the colour borders at {} vertices (one vertex keeps one colour; the first was kept)",
                    self.colour_splits_merged
                ));
            }
        }
        (kept, lost)
    }
}

/// Moves `uvs` (one per vertex of `mesh`, in the library's convention) so that the texture stays
/// where it was on the surface while the vertices moved from `before` to `mesh`'s positions
/// ([`super::uv_follow`]): each vertex's one UV walks over the faces around it. A vertex that did
/// not move keeps its UV exactly.
pub(crate) fn follow_slide(uvs: &mut [[f32; 2]], before: &[[f32; 3]], mesh: &TriMesh) {
    if uvs.len() != mesh.positions.len() || before.len() != uvs.len() || before == mesh.positions {
        return;
    }
    let triangles: Vec<UvTriangle> = (mesh.triangles.iter()).map(|t| t.map(|v| [v, v])).collect();
    let values: Vec<[f64; 2]> = uvs.iter().map(|uv| uv.map(f64::from)).collect();
    let followed = super::uv_follow::follow(before, &mesh.positions, &triangles, &values);
    for (uv, moved) in uvs.iter_mut().zip(followed.moved) {
        if let Some(moved) = moved {
            *uv = moved.map(|c| c as f32);
        }
    }
}

/// What an OBJ loses of vertex colours whose alpha is below 1 at `vertices` vertices (an OBJ
/// vertex colour is `r g b` alone); `None` when every colour is opaque.
pub(crate) fn alpha_lost_in_obj(vertices: usize) -> Option<String> {
    (vertices > 0).then(|| {
        format!(
            "the vertex colours' alpha at {vertices} vertices that are not opaque (an OBJ vertex colour is r g b alone)"
        )
    })
}

/// How many of `colours` are not opaque.
pub(crate) fn translucent(colours: &[[f32; 4]]) -> usize {
    colours.iter().filter(|c| c[3] < 1.0).count()
}

/// Gathers file-vertex values onto welded vertices, first value wins.
pub(crate) struct Gather<const N: usize> {
    values: Vec<[f32; N]>,
    set: Vec<bool>,
    merged: Vec<bool>,
}

impl<const N: usize> Gather<N> {
    /// For `welded_vertices` vertices; those that get no value keep `fallback` (white for
    /// colours, as glTF reads a primitive with no COLOR_0; zero for UVs).
    pub(crate) fn new(welded_vertices: usize, fallback: [f32; N]) -> Self {
        Gather {
            values: vec![fallback; welded_vertices],
            set: vec![false; welded_vertices],
            merged: vec![false; welded_vertices],
        }
    }

    /// File vertex value `value` for welded vertex `welded` (ignored when out of range).
    pub(crate) fn put(&mut self, welded: Option<usize>, value: [f32; N]) {
        let Some(w) = welded.filter(|&w| w < self.values.len()) else {
            return;
        };
        let value = if value.iter().all(|c| c.is_finite()) {
            value
        } else {
            [0.0; N]
        };
        if !self.set[w] {
            self.values[w] = value;
            self.set[w] = true;
        } else if self.values[w] != value {
            self.merged[w] = true;
        }
    }

    /// The values, and how many vertices had more than one.
    pub(crate) fn finish(self) -> (Vec<[f32; N]>, usize) {
        let merged = self.merged.iter().filter(|&&m| m).count();
        (self.values, merged)
    }
}
