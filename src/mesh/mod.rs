//! The indexed triangle mesh and everything derived from its connectivity alone.
//!
//! - [`TriMesh`]: positions (f32, as files store them) and triangles (u32 indices).
//! - [`Topology`]: one-ring neighbours and vertex-to-face incidence in CSR form, ordered boundary
//!   loops, connected components, non-manifold edges and vertices, Euler characteristic and genus.
//! - [`weld`] and [`clean`]: merge vertices with identical positions, drop triangles that repeat a
//!   vertex and vertices no triangle uses, keeping the first-occurrence order of the input so that
//!   output files keep the input's vertex order.
//! - [`loose_triangles`]: triangles lying over a fan or hanging from a non-manifold edge, which
//!   the default fairing leaves out.
//! - `FanRings`: one-rings in fan order, and the face and vertex normals the gathers take
//!   from them and from the faces (`area_normal`).
//! - [`breadth_first_order`]: a locality order for the gather kernels, which keep their own
//!   internal numbering and map back on output.

mod clean;
mod fans;
#[cfg(test)]
pub(crate) mod fixtures;
mod normals;
mod orient;
mod overlay;
mod reorder;
pub mod shapes;
mod subdivide;
mod topology;

pub use clean::{clean, weld, CleanReport, WeldReport};
pub(crate) use clean::{
    clean_with_map_but_repeats, remove_triangles, repeats_among, weld_with_map, PositionHasher,
};
pub(crate) use fans::{split_into_vertex_blocks, FanRings, VERTEX_BLOCK};
pub(crate) use normals::{area_normal, unit_vertex_normals};
pub use orient::{orient_consistently, OrientReport};
pub use overlay::{loose_triangles, without_loose_triangles};
pub(crate) use reorder::morton_code;
pub use reorder::{breadth_first_order, inverse_permutation};
pub use subdivide::subdivide_loop;
pub use topology::{two_face_edges, ComponentInfo, Topology};

/// An indexed triangle mesh. Positions are stored in f32 (what every supported file format
/// holds); algorithms that need more precision compute in f64 internally.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    pub fn new(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            positions,
            triangles,
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn face_count(&self) -> usize {
        self.triangles.len()
    }

    /// Position of vertex `v` in f64.
    #[inline]
    pub fn point(&self, v: u32) -> glam::DVec3 {
        let p = self.positions[v as usize];
        glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
    }

    /// The three corners of triangle `t` in f64.
    #[inline]
    pub fn triangle_points(&self, t: usize) -> [glam::DVec3; 3] {
        let [a, b, c] = self.triangles[t];
        [self.point(a), self.point(b), self.point(c)]
    }

    /// Unnormalised normal of triangle `t` (twice its area in length), in f64.
    pub fn face_normal(&self, t: usize) -> glam::DVec3 {
        let [a, b, c] = self.triangle_points(t);
        (b - a).cross(c - a)
    }

    /// Area-weighted vertex normals (unit length; zero for isolated vertices), in f64.
    pub fn vertex_normals(&self) -> Vec<glam::DVec3> {
        let mut normals = vec![glam::DVec3::ZERO; self.positions.len()];
        for t in 0..self.triangles.len() {
            let n = self.face_normal(t);
            for &v in &self.triangles[t] {
                normals[v as usize] += n;
            }
        }
        for n in &mut normals {
            *n = n.normalize_or_zero();
        }
        normals
    }

    /// Index of the first vertex whose position is NaN or infinite, if any.
    pub fn first_non_finite_vertex(&self) -> Option<usize> {
        self.positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
    }
}
