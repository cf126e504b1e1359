//! Small hand-built meshes shared by the unit tests of every module.

use super::TriMesh;

/// The regular octahedron with corners at ±`scale` on each axis: closed, genus 0, outward
/// oriented, every vertex of valence 4.
pub(crate) fn octahedron(scale: f32) -> TriMesh {
    let s = scale;
    TriMesh::new(
        vec![
            [s, 0., 0.],
            [-s, 0., 0.],
            [0., s, 0.],
            [0., -s, 0.],
            [0., 0., s],
            [0., 0., -s],
        ],
        vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ],
    )
}

/// A flat grid of `n`×`n` squares of side 1 in the plane z = 0, each cut into two triangles
/// (valence 6 inside); vertex (x, y) is y·(n + 1) + x.
pub(crate) fn grid(n: usize) -> TriMesh {
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            positions.push([x as f32, y as f32, 0.0]);
        }
    }
    let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
    let mut triangles = Vec::new();
    for y in 0..n {
        for x in 0..n {
            triangles.push([at(x, y), at(x + 1, y), at(x + 1, y + 1)]);
            triangles.push([at(x, y), at(x + 1, y + 1), at(x, y + 1)]);
        }
    }
    TriMesh::new(positions, triangles)
}

/// Three triangles sharing the edge (0, 1): the smallest non-manifold mesh.
pub(crate) fn three_triangles_on_one_edge() -> TriMesh {
    TriMesh::new(
        vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [0., 1., 0.],
            [0., -1., 0.],
            [0., 0., 1.],
        ],
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
    )
}

/// A closed hexagonal bipyramid, outward oriented: apex 0 above the hexagon 1..=6 (vertex k at
/// angle (k − 1)·60°), apex 8 below, and vertex 7, above apex 0, used by no triangle; its twelve
/// triangles (apex 0's fan first: (0, k, k + 1)), then `extra`.
pub(crate) fn bipyramid_with(extra: &[[u32; 3]]) -> TriMesh {
    let mut positions = vec![[0.0, 0.0, 1.0]];
    for k in 0..6 {
        let a = k as f32 * std::f32::consts::PI / 3.0;
        positions.push([a.cos(), a.sin(), 0.0]);
    }
    positions.extend([[0.5, 0.5, 2.0], [0.0, 0.0, -1.0]]);
    let mut triangles: Vec<[u32; 3]> = (0..6u32)
        .map(|k| [0, k + 1, (k + 1) % 6 + 1])
        .chain((0..6u32).map(|k| [8, (k + 1) % 6 + 1, k + 1]))
        .collect();
    triangles.extend_from_slice(extra);
    TriMesh::new(positions, triangles)
}
