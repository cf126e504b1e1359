//! Face and vertex normals in f32 SIMD points (`Vec3A`), for the gathers of the noise estimate,
//! the crease detection and the risk estimate: a face's area normal, every face's, and unit
//! vertex normals summed from the faces.

use super::{Topology, TriMesh};
use glam::Vec3A;
use rayon::prelude::*;

/// The area normal of face `f`, (x_b − x_a) × (x_c − x_a) (twice its area long), in f32.
#[inline]
pub(crate) fn area_normal(mesh: &TriMesh, f: u32) -> Vec3A {
    let [a, b, c] =
        mesh.triangles[f as usize].map(|v| Vec3A::from_array(mesh.positions[v as usize]));
    (b - a).cross(c - a)
}

/// Every face's area normal ([`area_normal`]), in parallel.
fn face_normals(mesh: &TriMesh) -> Vec<Vec3A> {
    (0..mesh.triangles.len() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .map(|f| area_normal(mesh, f))
        .collect()
}

/// Every vertex's unit normal, the sum of its faces' area normals (zero where that is zero), in
/// parallel.
pub(crate) fn unit_vertex_normals(mesh: &TriMesh, topology: &Topology) -> Vec<Vec3A> {
    let faces = face_normals(mesh);
    (0..mesh.positions.len() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .map(|v| {
            topology
                .faces_of(v)
                .iter()
                .map(|&f| faces[f as usize])
                .sum::<Vec3A>()
                .normalize_or_zero()
        })
        .collect()
}
