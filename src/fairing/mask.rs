//! Masks: where fairing may change the mesh (the editor's painted region, the CLI's `--mask`).
//!
//! A [`Mask`] holds one weight in [0, 1] per (welded) vertex: 1 fairs the vertex fully, 0 pins it
//! where it is, and weights between blend: p = p⁰ + w·(p − p⁰), with p⁰ the input position and p
//! the faired one. A band of falling weights at the edge of the region ([`Mask::with_falloff`],
//! or the editor's soft brush) blends the fairing to nothing there, so no step shows.
//!
//! How each operator honours it (not part of the paper, which fairs every vertex alike):
//! - Constrained fairing ([`super::FairOptions::mask`]): weight-0 vertices are held as fixed
//!   boundary vertices are: they get no local solution, and the triangles touching them are not
//!   solved, so the painted region is faired with the pinned vertices as its boundary; then every
//!   vertex is blended by its weight.
//! - Multiresolution fairing ([`crate::multires::MultiresOptions::mask`]) and the baselines
//!   ([`super::fair_masked`]): the whole mesh is faired and the result blended per vertex. The
//!   levels of the hierarchy mix painted and unpainted vertices, so there is no honest pinning
//!   on them; the blend is what keeps the unpainted part.
//!
//! Either way a weight-0 vertex keeps its input position bit for bit. A mask whose length is not
//! the mesh's vertex count is a caller's mistake the fairing functions cannot report (they return
//! reports, not results): they then leave the mesh unchanged. [`Mask::check_fits`] says why.
//!
//! Vertex lists ([`read_vertex_list`]): a text file of 0-based vertex indices in the input file's
//! own vertex order, one a line; blank lines and `#` comments are allowed. Loading welds vertices
//! (an OBJ or glTF splits them at seams), so [`Mask::from_file_vertices`] translates the file's
//! indices to the loaded mesh's through [`crate::io::Source::loaded_vertex`].

use crate::io::Source;
use crate::mesh::Topology;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// One weight in [0, 1] per vertex: 1 fair, 0 pinned (see the module docs). Cheap to clone.
#[derive(Clone, PartialEq)]
pub struct Mask {
    weights: Arc<[f32]>,
}

/// What is wrong with a mask or a vertex list.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MaskError {
    #[error("mask weight of vertex {vertex} is {value}; weights must be numbers from 0 to 1")]
    BadWeight { vertex: usize, value: f32 },
    #[error("the mask has {mask} weights but the mesh has {mesh} vertices")]
    WrongLength { mask: usize, mesh: usize },
    #[error("{}: cannot read the vertex list: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}, line {line}: {message}", path.display())]
    Line {
        path: PathBuf,
        line: usize,
        message: String,
    },
}

impl std::fmt::Debug for Mask {
    // A mask of a big mesh has millions of weights: say what it holds, not every value.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Mask({} vertices, {} painted)",
            self.len(),
            self.painted_count()
        )
    }
}

impl Mask {
    /// A mask from per-vertex weights, each in [0, 1].
    pub fn new(weights: Vec<f32>) -> Result<Mask, MaskError> {
        if let Some((vertex, &value)) = weights
            .iter()
            .enumerate()
            .find(|(_, w)| !(0.0..=1.0).contains(*w))
        {
            return Err(MaskError::BadWeight { vertex, value });
        }
        Ok(Mask {
            weights: weights.into(),
        })
    }

    /// Weight 1 on `vertices`, 0 elsewhere, on a mesh of `vertex_count` vertices; indices at or
    /// beyond `vertex_count` are left out.
    pub fn from_vertices(vertex_count: usize, vertices: impl IntoIterator<Item = usize>) -> Mask {
        let mut weights = vec![0.0f32; vertex_count];
        for v in vertices {
            if let Some(w) = weights.get_mut(v) {
                *w = 1.0;
            }
        }
        Mask {
            weights: weights.into(),
        }
    }

    /// Weight 1 on the loaded vertices that the file's vertices `file_vertices` (0-based, in
    /// the file's order, as [`read_vertex_list`] gives them) became. `path` names the list in
    /// errors: an index beyond the file's vertices is an error naming its line.
    pub fn from_file_vertices(
        source: &Source,
        vertex_count: usize,
        file_vertices: &[(usize, usize)],
        path: &Path,
    ) -> Result<Mask, MaskError> {
        let file_count = source.file_vertex_count();
        let mut loaded = Vec::with_capacity(file_vertices.len());
        for &(line, index) in file_vertices {
            if index >= file_count {
                return Err(MaskError::Line {
                    path: path.to_owned(),
                    line,
                    message: format!(
                        "vertex {index} is out of range: the mesh file has {file_count} vertices \
                         (indices are 0-based)"
                    ),
                });
            }
            // A vertex no triangle uses was dropped on loading: nothing to fair there.
            loaded.extend(source.loaded_vertex(index));
        }
        Ok(Mask::from_vertices(vertex_count, loaded))
    }

    pub fn len(&self) -> usize {
        self.weights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    pub fn weights(&self) -> &[f32] {
        &self.weights
    }

    /// Vertex `v`'s weight (0 beyond the mask).
    pub fn weight(&self, v: usize) -> f32 {
        self.weights.get(v).copied().unwrap_or(0.0)
    }

    /// Vertices with a weight above 0 (those fairing may move).
    pub fn painted_count(&self) -> usize {
        self.weights.iter().filter(|&&w| w > 0.0).count()
    }

    /// Per vertex: whether its weight is 0 (it must not move).
    pub fn pinned_flags(&self) -> Vec<bool> {
        self.weights.iter().map(|&w| w <= 0.0).collect()
    }

    /// 1 − w for every vertex: the unpainted part becomes the painted one.
    #[must_use]
    pub fn inverted(&self) -> Mask {
        Mask {
            weights: self.weights.iter().map(|&w| 1.0 - w).collect(),
        }
    }

    /// Whether this mask can be used on a mesh of `vertex_count` vertices.
    pub fn check_fits(&self, vertex_count: usize) -> Result<(), MaskError> {
        if self.len() == vertex_count {
            Ok(())
        } else {
            Err(MaskError::WrongLength {
                mask: self.len(),
                mesh: vertex_count,
            })
        }
    }

    /// A soft edge `rings` one-rings wide: a painted vertex k rings in from the nearest unpainted
    /// one (k = 1 next to it) keeps at most k/(rings + 1) of its weight, so the fairing fades to
    /// nothing at the edge. Unpainted vertices stay unpainted. `topology` must be the mesh's.
    #[must_use]
    pub fn with_falloff(&self, topology: &Topology, rings: usize) -> Mask {
        if rings == 0 || self.len() != topology.vertex_count() {
            return self.clone();
        }
        // Breadth-first rings out of the unpainted region, `rings` deep.
        let mut depth = vec![u32::MAX; self.len()];
        let mut queue = VecDeque::new();
        for (v, &w) in self.weights.iter().enumerate() {
            if w <= 0.0 {
                depth[v] = 0;
                queue.push_back(v as u32);
            }
        }
        while let Some(v) = queue.pop_front() {
            let next = depth[v as usize] + 1;
            if next as usize > rings {
                continue;
            }
            for &u in topology.neighbors(v) {
                if depth[u as usize] == u32::MAX {
                    depth[u as usize] = next;
                    queue.push_back(u);
                }
            }
        }
        let weights = self
            .weights
            .iter()
            .zip(&depth)
            .map(|(&w, &d)| match d {
                u32::MAX => w,
                d => w.min(d as f32 / (rings + 1) as f32),
            })
            .collect();
        Mask { weights }
    }

    /// Blends faired `positions` back towards `original` by the weights: a weight-0 vertex gets
    /// its original position exactly, a weight-1 vertex keeps its faired one. Does nothing when
    /// the lengths differ.
    pub fn blend(&self, original: &[[f32; 3]], positions: &mut [[f32; 3]]) {
        if original.len() != self.len() || positions.len() != self.len() {
            return;
        }
        for ((p, &p0), &w) in positions.iter_mut().zip(original).zip(self.weights.iter()) {
            if w <= 0.0 {
                *p = p0;
            } else if w < 1.0 {
                *p = std::array::from_fn(|k| p0[k] + w * (p[k] - p0[k]));
            }
        }
    }
}

/// Parses a vertex list (see the module docs): (line number, 1-based; vertex index) per entry.
/// `path` names the list in errors.
pub fn parse_vertex_list(text: &str, path: &Path) -> Result<Vec<(usize, usize)>, MaskError> {
    let mut vertices = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let index = content.parse::<usize>().map_err(|_| MaskError::Line {
            path: path.to_owned(),
            line: number + 1,
            message: format!(
                "`{content}` is not a vertex index (expected one 0-based whole number a line)"
            ),
        })?;
        vertices.push((number + 1, index));
    }
    Ok(vertices)
}

/// Reads and parses the vertex list at `path` ([`parse_vertex_list`]).
pub fn read_vertex_list(path: &Path) -> Result<Vec<(usize, usize)>, MaskError> {
    let bytes = std::fs::read(path).map_err(|source| MaskError::Read {
        path: path.to_owned(),
        source,
    })?;
    let text = String::from_utf8(bytes).map_err(|e| MaskError::Line {
        path: path.to_owned(),
        line: 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count(),
        message: "the line is not text (UTF-8)".into(),
    })?;
    parse_vertex_list(&text, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriMesh;

    #[test]
    fn vertex_lists_skip_comments_and_name_the_bad_line() {
        let path = Path::new("region.txt");
        let list = parse_vertex_list("# painted\n3\n\n 7  # tip\n0\n", path).unwrap();
        assert_eq!(list, vec![(2, 3), (4, 7), (5, 0)]);
        let error = parse_vertex_list("1\n2\nseven\n", path).unwrap_err();
        let message = error.to_string();
        assert!(message.starts_with("region.txt, line 3:"), "{message}");
        assert!(message.contains("`seven`"), "{message}");
        assert!(parse_vertex_list("-1\n", path).is_err());
    }

    #[test]
    fn weights_outside_zero_to_one_are_refused() {
        assert!(Mask::new(vec![0.0, 0.5, 1.0]).is_ok());
        for bad in [f32::NAN, -0.1, 1.5, f32::INFINITY] {
            let error = Mask::new(vec![0.0, bad]).unwrap_err();
            assert!(matches!(error, MaskError::BadWeight { vertex: 1, .. }));
        }
        let mask = Mask::from_vertices(3, [0, 9]);
        assert_eq!(mask.weights(), &[1.0, 0.0, 0.0]);
        assert!(mask.check_fits(4).is_err());
        assert_eq!(mask.inverted().weights(), &[0.0, 1.0, 1.0]);
    }

    #[test]
    fn blend_keeps_pinned_vertices_exactly_and_scales_the_rest() {
        let mask = Mask::new(vec![0.0, 0.5, 1.0]).unwrap();
        let original = [[0.1f32, 0.2, 0.3]; 3];
        let mut positions = [[1.0f32, 1.0, 1.0]; 3];
        mask.blend(&original, &mut positions);
        assert_eq!(positions[0], original[0]);
        assert!((positions[1][0] - 0.55).abs() < 1e-6);
        assert_eq!(positions[2], [1.0, 1.0, 1.0]);
    }

    #[test]
    fn falloff_fades_towards_the_unpainted_region() {
        // A strip of triangles 0-1-2-...-7: vertex v is next to v+1 and v+2.
        let positions = (0..8).map(|i| [i as f32, (i % 2) as f32, 0.0]).collect();
        let triangles = (0..6u32).map(|i| [i, i + 1, i + 2]).collect();
        let mesh = TriMesh::new(positions, triangles);
        let topology = Topology::build(&mesh);
        let mask = Mask::from_vertices(8, 0..6).with_falloff(&topology, 2);
        let w = mask.weights();
        assert_eq!(w[6], 0.0);
        assert_eq!(w[7], 0.0);
        // 4 and 5 touch 6 or 7 (one ring in), 2 and 3 two rings in, 0 and 1 beyond the band.
        assert!((w[5] - 1.0 / 3.0).abs() < 1e-6 && (w[4] - 1.0 / 3.0).abs() < 1e-6);
        assert!((w[3] - 2.0 / 3.0).abs() < 1e-6 && (w[2] - 2.0 / 3.0).abs() < 1e-6);
        assert_eq!(w[1], 1.0);
        assert_eq!(w[0], 1.0);
    }
}
