//! Feature edges: an edge with exactly two faces whose normals turn by more than the crease
//! angle, with its crease direction (the cross product of the two normals). Read per vertex,
//! from its faces ([`vertex_feature_edges`]) or, for a closed fan, from its ring's consecutive
//! face normals without reading a face ([`fan_feature_edges`]). Crease detection and the noise
//! estimate's scan ([`super::strength`]) both find them; they sit below both.

use crate::mesh::{Topology, TriMesh};
use glam::Vec3A;

/// A feature edge `[v, u]` (v < u) with its crease direction (unit, either sign).
pub(crate) type FeatureEdge = ([u32; 2], Vec3A);

/// Appends the feature edges `[v, u]` with u > v, ascending by u, with `normal(f)` a normal of face
/// f (of any length): the edges with exactly two faces whose normals' angle has its cosine below
/// `threshold` (the cosine of the crease angle). The faces of an edge v–u are among v's own, so no
/// other vertex's list is searched, and v's triangles are read once.
pub(crate) fn vertex_feature_edges(
    mesh: &TriMesh,
    topology: &Topology,
    v: u32,
    normal: impl Fn(u32) -> Vec3A,
    threshold: f32,
    edges: &mut Vec<FeatureEdge>,
) {
    let faces_v = topology.faces_of(v);
    // Every (u, i) with u > v a corner of v's i-th face (each face once per u), sorted: the
    // faces of an edge v–u are then side by side, in the order of v's list.
    let mut buffer = [(0u32, 0u32); 64];
    let mut heap = Vec::new();
    let pairs: &mut [(u32, u32)] = if 2 * faces_v.len() <= buffer.len() {
        let mut count = 0;
        for (i, &f) in faces_v.iter().enumerate() {
            let [a, b, c] = mesh.triangles[f as usize];
            // (Each face of v's list has v for a corner, so at most two others.)
            for (u, repeated) in [(a, false), (b, b == a), (c, c == a || c == b)] {
                if u > v && !repeated {
                    buffer[count] = (u, i as u32);
                    count += 1;
                }
            }
        }
        &mut buffer[..count]
    } else {
        for (i, &f) in faces_v.iter().enumerate() {
            let [a, b, c] = mesh.triangles[f as usize];
            for (u, repeated) in [(a, false), (b, b == a), (c, c == a || c == b)] {
                if u > v && !repeated {
                    heap.push((u, i as u32));
                }
            }
        }
        &mut heap
    };
    pairs.sort_unstable();
    // An edge with other than two faces is no feature edge.
    let mut rest = &*pairs;
    while let Some(&(u, i)) = rest.first() {
        let run = rest.iter().take_while(|&&(w, _)| w == u).count();
        if run == 2 {
            let j = rest[1].1;
            let (fi, fj) = (faces_v[i as usize], faces_v[j as usize]);
            if let Some(direction) = feature(normal(fi), normal(fj), threshold) {
                edges.push(([v, u], direction));
            }
        }
        rest = &rest[run..];
    }
}

/// [`vertex_feature_edges`] for a vertex with a closed fan, from its ring (`ring[k]` = x_k, at
/// most 64) and its faces' area normals (`faces[k]` = (x_(k−1) − x_v) × (x_k − x_v), the normal
/// of face (v, x_(k−1), x_k), which the noise estimate sums anyway): edge v–x_k lies on faces k
/// and k + 1, so no face is read.
pub(crate) fn fan_feature_edges(
    v: u32,
    ring: &[u32],
    faces: &[Vec3A],
    threshold: f32,
    edges: &mut Vec<FeatureEdge>,
) {
    let first = edges.len();
    edges.extend(
        fan_feature_neighbors(v, ring, faces, threshold)
            .map(|(u, [a, b])| ([v, u], a.cross(b).normalize_or_zero())),
    );
    edges[first..].sort_unstable_by_key(|&([_, u], _)| u);
}

/// The neighbours u > v of [`fan_feature_edges`] (in the ring's order), each with the normals of
/// its edge's two faces.
pub(crate) fn fan_feature_neighbors<'a>(
    v: u32,
    ring: &'a [u32],
    faces: &'a [Vec3A],
    threshold: f32,
) -> impl Iterator<Item = (u32, [Vec3A; 2])> + 'a {
    let n = ring.len();
    ring.iter().enumerate().filter_map(move |(k, &u)| {
        let pair = [faces[k], faces[(k + 1) % n]];
        (u > v && is_feature(pair[0], pair[1], threshold)).then_some((u, pair))
    })
}

/// The crease direction of an edge whose faces have the normals `na` and `nb` (of any length),
/// when it is a feature edge (the cosine of their angle below `threshold`; a face without a
/// normal makes none).
#[inline]
fn feature(na: Vec3A, nb: Vec3A, threshold: f32) -> Option<Vec3A> {
    is_feature(na, nb, threshold).then(|| na.cross(nb).normalize_or_zero())
}

/// Whether an edge whose faces have the normals `na` and `nb` is a feature edge ([`feature`]
/// without the direction).
#[inline]
fn is_feature(na: Vec3A, nb: Vec3A, threshold: f32) -> bool {
    let (la, lb) = (na.length(), nb.length());
    la > 0.0 && lb > 0.0 && (la * lb).is_finite() && na.dot(nb) < threshold * la * lb
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed fan of `n` faces around vertex 0 at the origin, folded by a right angle along
    /// the x axis: ring vertex k + 1 at the angle 2πk/n, the ring's first half in the plane
    /// z = 0 (y ≥ 0), its second half in the plane y = 0 (z < 0). Vertex 1 is (1, 0, 0) and
    /// vertex n/2 + 1 is (−1, 0, 0).
    fn folded_fan(n: usize) -> TriMesh {
        let mut positions = vec![[0.0f32; 3]];
        for k in 0..n {
            let (s, c) = (k as f32 / n as f32 * std::f32::consts::TAU).sin_cos();
            positions.push(if k <= n / 2 {
                [c, s.max(0.0), 0.0]
            } else {
                [c, 0.0, s]
            });
        }
        let triangles = (0..n as u32)
            .map(|k| [0, 1 + k, 1 + (k + 1) % n as u32])
            .collect();
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn a_folded_fan_has_its_two_fold_edges_for_feature_edges_with_few_faces_or_many() {
        // The faces of the half in z = 0 face +z, those of the other half −y: the two edges
        // along the fold turn by 90°, every other edge joins two faces of one plane. 8 faces are
        // read from the stack buffer, 40 from the heap.
        for n in [8, 40] {
            let mesh = folded_fan(n);
            let topology = Topology::build(&mesh);
            let normal = |f: u32| {
                let [a, b, c] =
                    mesh.triangles[f as usize].map(|v| Vec3A::from(mesh.positions[v as usize]));
                (b - a).cross(c - a)
            };
            let mut edges = Vec::new();
            let threshold = 30f32.to_radians().cos();
            vertex_feature_edges(&mesh, &topology, 0, normal, threshold, &mut edges);
            let found: Vec<[u32; 2]> = edges.iter().map(|e| e.0).collect();
            assert_eq!(found, [[0, 1], [0, n as u32 / 2 + 1]], "{n} faces");
            // The crease direction is the fold's, the x axis (the normals' cross product).
            for (_, direction) in &edges {
                assert!((direction.x.abs() - 1.0).abs() < 1e-5, "{direction}");
            }
        }
    }
}
