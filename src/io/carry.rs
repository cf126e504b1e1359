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
