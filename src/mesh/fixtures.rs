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
