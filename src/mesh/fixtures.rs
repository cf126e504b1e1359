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

/// A flat grid of `n`×`n` squares of side 1 ([`super::shapes::grid`]).
pub(crate) fn grid(n: usize) -> TriMesh {
    super::shapes::grid(n)
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

/// Small deterministic generator (xorshift) so the tests need no seeds from outside.
pub(crate) struct Rng(pub(crate) u64);
impl Rng {
    pub(crate) fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// A small irregular closed mesh: an octahedron subdivided irregularly, with bumps.
pub(crate) fn irregular_sphere() -> TriMesh {
    let TriMesh {
        mut positions,
        mut triangles,
    } = crate::mesh::fixtures::octahedron(1.0);
    // Split some faces at their centre (1-to-3) to make valences irregular.
    let mut rng = Rng(12345);
    for round in 0..3 {
        let count = triangles.len();
        for f in (0..count).filter(|f| (f + round) % 2 == 0) {
            let [a, b, c] = triangles[f];
            let centre: [f32; 3] = std::array::from_fn(|k| {
                (positions[a as usize][k] + positions[b as usize][k] + positions[c as usize][k])
                    / 3.0
            });
            let length = centre.iter().map(|x| x * x).sum::<f32>().sqrt();
            let bump = 1.0 + 0.1 * rng.range(-1.0, 1.0) as f32;
            positions.push(centre.map(|x| x / length * bump));
            let m = positions.len() as u32 - 1;
            triangles[f] = [a, b, m];
            triangles.push([b, c, m]);
            triangles.push([c, a, m]);
        }
    }
    TriMesh::new(positions, triangles)
}
