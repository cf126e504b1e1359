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
//! A mask from a file (the CLI's `--mask`) is a vertex list read by
//! [`crate::io::read_vertex_list`] and mapped onto the loaded vertices by
//! [`crate::io::loaded_vertices`]; [`Mask::from_vertices`] makes it a mask.

use crate::mesh::Topology;
use std::collections::VecDeque;
use std::sync::Arc;

/// One weight in [0, 1] per vertex: 1 fair, 0 pinned (see the module docs). Cheap to clone.
#[derive(Clone, PartialEq)]
pub struct Mask {
    weights: Arc<[f32]>,
}

/// What is wrong with a mask.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MaskError {
    #[error("mask weight of vertex {vertex} is {value}; weights must be numbers from 0 to 1")]
    BadWeight { vertex: usize, value: f32 },
    #[error("the mask has {mask} weights but the mesh has {mesh} vertices")]
    WrongLength { mask: usize, mesh: usize },
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriMesh;

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
