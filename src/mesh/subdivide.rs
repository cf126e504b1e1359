//! Loop subdivision (4:1 split with Loop's smoothing masks), used to make the large meshes the
//! benchmarks run on (twice on `bunny00` gives about 1.2M faces). Boundary edges and vertices use
//! the cubic B-spline curve masks, so open meshes keep their boundary curve.

use super::{Topology, TriMesh};
use std::collections::HashMap;

/// One level of Loop subdivision. New vertices (edge points) follow the original vertices, so the
/// first `mesh.vertex_count()` vertices of the result correspond to the input's.
pub fn subdivide_loop(mesh: &TriMesh) -> TriMesh {
    let topology = Topology::build(mesh);
    let n = mesh.vertex_count();
    let p = |v: u32| mesh.point(v);

    // Edge points, numbered in order of first appearance in the triangle list.
    let mut edge_index: HashMap<(u32, u32), u32> =
        HashMap::with_capacity(mesh.face_count() * 3 / 2 + 16);
    let mut edge_opposites: Vec<Vec<u32>> = Vec::new();
    let mut edge_ends: Vec<(u32, u32)> = Vec::new();
    let mut triangles = Vec::with_capacity(mesh.face_count() * 4);
    for t in &mesh.triangles {
        let mut mid = [0u32; 3];
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let key = (a.min(b), a.max(b));
            let next = (n + edge_ends.len()) as u32;
            let index = *edge_index.entry(key).or_insert_with(|| {
                edge_ends.push(key);
                edge_opposites.push(Vec::new());
                next
            });
            edge_opposites[index as usize - n].push(t[(i + 2) % 3]);
            mid[i] = index;
        }
        let [a, b, c] = *t;
        triangles.push([a, mid[0], mid[2]]);
        triangles.push([mid[0], b, mid[1]]);
        triangles.push([mid[2], mid[1], c]);
        triangles.push([mid[0], mid[1], mid[2]]);
    }

    let mut positions = Vec::with_capacity(n + edge_ends.len());
    for v in 0..n as u32 {
        let neighbors = topology.neighbors(v);
        let new = if topology.is_boundary_vertex(v) {
            // Neighbours along boundary edges (edges with one face).
            let ends: Vec<u32> = neighbors
                .iter()
                .copied()
                .filter(|&u| {
                    edge_index
                        .get(&(v.min(u), v.max(u)))
                        .is_some_and(|&e| edge_opposites[e as usize - n].len() == 1)
                })
                .collect();
            if ends.len() == 2 {
                p(v) * 0.75 + (p(ends[0]) + p(ends[1])) * 0.125
            } else {
                p(v)
            }
        } else if neighbors.is_empty() {
            p(v)
        } else {
            let k = neighbors.len() as f64;
            let beta = if neighbors.len() == 3 {
                3.0 / 16.0
            } else {
                3.0 / (8.0 * k)
            };
            let sum: glam::DVec3 = neighbors.iter().map(|&u| p(u)).sum();
            p(v) * (1.0 - k * beta) + sum * beta
        };
        positions.push(new.as_vec3().to_array());
    }
    for (e, &(a, b)) in edge_ends.iter().enumerate() {
        let opposites = &edge_opposites[e];
        let new = if opposites.len() == 2 {
            (p(a) + p(b)) * 0.375 + (p(opposites[0]) + p(opposites[1])) * 0.125
        } else {
            (p(a) + p(b)) * 0.5
        };
        positions.push(new.as_vec3().to_array());
    }
    TriMesh {
        positions,
        triangles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subdivided_octahedron_is_a_closed_sphere_with_four_times_the_faces() {
        let mesh = crate::mesh::fixtures::octahedron(1.0);
        let fine = subdivide_loop(&mesh);
        assert_eq!(fine.face_count(), 32);
        assert_eq!(fine.vertex_count(), 6 + 12);
        let topo = Topology::build(&fine);
        assert!(topo.is_closed() && topo.is_oriented_manifold());
        assert_eq!(topo.euler_characteristic(), 2);
        // Loop's masks pull the octahedron's corners inwards: 1 - 4 * 3/32 + 4 * 0 = 0.625 of the
        // way along the axis, by symmetry (the four neighbours sum to zero along that axis).
        assert!((fine.positions[0][0] - 0.625).abs() < 1e-6);
    }
}
