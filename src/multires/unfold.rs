//! Not in the paper: the edges a multiresolution run leaves folded. Refining from a coarse level
//! places each split vertex from its coarse neighbours, and where a coarse level's fairing bent
//! a thin part or a sharp edge, a few of those placements fall on the wrong side of their
//! neighbours: two triangles then fold over their shared edge by more than a right angle (the
//! noisy bunny from its opening level 9: 18 such edges of 113k). The M0 pass that follows
//! ([`super::MultiresOptions::fair_finest`]) unfolds most, as constrained fairing does on M0,
//! but not all. So, last, every edge folded beyond 90° where M0 itself (the mesh the hierarchy
//! was built on) was not bent to within 5° of a right angle (a box's edges are features) gets its two corners and the third corners of its two faces
//! moved to the mean of their neighbours (Jacobi, a few sweeps), and those of edges still folded
//! join them, until none is left or [`UNFOLD_PASSES`] have run. Only those vertices move (a few dozen), each by about the size
//! of its fold; a crease vertex moves along its crease (to the mean of its two neighbours on it),
//! corners and boundary vertices stay.

use super::NONE;
use crate::fairing::creases::Creases;
use crate::mesh::{Topology, TriMesh};
use glam::Vec3A;

/// What [`unfold`] reads of M0: its connectivity, its creases and, per vertex, its two
/// neighbours along its crease or boundary loop (`NONE` for others; empty when M0 has neither).
pub(super) struct Level<'a> {
    pub(super) mesh: &'a TriMesh,
    pub(super) topology: &'a Topology,
    pub(super) creases: Option<&'a Creases>,
    pub(super) loop_neighbors: &'a [[u32; 2]],
}

/// At most this many rounds of finding the folded edges and smoothing their corners.
pub const UNFOLD_PASSES: usize = 8;

/// Umbrella sweeps over the folded edges' corners in each pass.
const SWEEPS: usize = 3;

/// Whether each of `edges` folds beyond 90° with `positions` (its faces' normals more than a
/// right angle apart; a face with no area folds nothing).
pub(super) fn folded(positions: &[[f32; 3]], mesh: &TriMesh, edges: &[[u32; 4]]) -> Vec<bool> {
    bent_beyond(positions, mesh, edges, 0.0)
}

/// Whether each of `edges` bends to within [`RIGHT_ANGLE_MARGIN_DEGREES`] of a right angle or
/// beyond with `positions`: on M0, such an edge is a feature (a box's edges bend by exactly
/// 90°), which the unfolding leaves alone even when the levels bend it a little further.
pub(super) fn bent_to_right_angle(
    positions: &[[f32; 3]],
    mesh: &TriMesh,
    edges: &[[u32; 4]],
) -> Vec<bool> {
    let cosine = RIGHT_ANGLE_MARGIN_DEGREES.to_radians().sin();
    bent_beyond(positions, mesh, edges, cosine)
}

/// How close to a right angle an edge of M0 may bend and still be a feature ([`bent_to_right_angle`]).
pub const RIGHT_ANGLE_MARGIN_DEGREES: f32 = 5.0;

/// Whether the faces of each of `edges` have normals whose angle's cosine is below `cosine`.
fn bent_beyond(
    positions: &[[f32; 3]],
    mesh: &TriMesh,
    edges: &[[u32; 4]],
    cosine: f32,
) -> Vec<bool> {
    let normal = |f: u32| {
        let [a, b, c] =
            mesh.triangles[f as usize].map(|v| Vec3A::from_array(positions[v as usize]));
        (b - a).cross(c - a)
    };
    edges
        .iter()
        .map(|&[_, _, f, g]| {
            let (n, m) = (normal(f), normal(g));
            n.dot(m) < cosine * (n.length() * m.length())
        })
        .collect()
}

/// Moves the corners of the edges of `edges` folded in `positions` but not in `reference` (one
/// flag per edge, [`bent_to_right_angle`] of M0) to the mean of their neighbours, as the module
/// docs say.
/// Returns how many vertices moved.
pub(super) fn unfold(
    positions: &mut [[f32; 3]],
    level: &Level,
    edges: &[[u32; 4]],
    reference: &[bool],
) -> usize {
    let Level {
        mesh,
        topology,
        creases,
        loop_neighbors,
    } = *level;
    // A crease vertex moves along its crease (to the mean of its two neighbours on it); a corner
    // and a boundary vertex stay.
    let on_crease = |v: u32| {
        loop_neighbors
            .get(v as usize)
            .filter(|pair| pair[0] != NONE && pair[1] != NONE)
            .copied()
    };
    let stays = |v: u32| {
        topology.is_boundary_vertex(v)
            || (creases.is_some_and(|c| c.is_feature(v)) && on_crease(v).is_none())
    };
    let mut moving = vec![false; positions.len()];
    let mut region: Vec<u32> = Vec::new();
    for _ in 0..UNFOLD_PASSES {
        let now = folded(positions, mesh, edges);
        let mut grew = false;
        for ((edge, &folded), &was) in edges.iter().zip(&now).zip(reference) {
            if !folded || was {
                continue;
            }
            // The edge's corners and the two faces' third corners (the ones that move when the
            // edge itself lies on a crease).
            let [a, b, f, g] = *edge;
            let third = |face: u32| {
                let t = mesh.triangles[face as usize];
                t[0] ^ t[1] ^ t[2] ^ a ^ b
            };
            for v in [a, b, third(f), third(g)] {
                if !moving[v as usize] && !stays(v) {
                    moving[v as usize] = true;
                    region.push(v);
                    grew = true;
                }
            }
        }
        if !grew && !now.iter().zip(reference).any(|(&n, &r)| n && !r) {
            break;
        }
        for _ in 0..SWEEPS {
            let means: Vec<[f32; 3]> = region
                .iter()
                .map(|&v| {
                    if let Some([p, n]) = on_crease(v) {
                        let [p, n] = [p, n].map(|u| Vec3A::from_array(positions[u as usize]));
                        return ((p + n) * 0.5).to_array();
                    }
                    let ring = topology.neighbors(v);
                    let sum = ring.iter().fold(Vec3A::ZERO, |sum, &u| {
                        sum + Vec3A::from_array(positions[u as usize])
                    });
                    (sum / ring.len().max(1) as f32).to_array()
                })
                .collect();
            for (&v, mean) in region.iter().zip(means) {
                positions[v as usize] = mean;
            }
        }
    }
    region.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::grid;
    use crate::mesh::two_face_edges;

    fn level<'a>(mesh: &'a TriMesh, topology: &'a Topology) -> Level<'a> {
        Level {
            mesh,
            topology,
            creases: None,
            loop_neighbors: &[],
        }
    }

    #[test]
    fn a_vertex_pushed_through_its_neighbours_is_put_back_and_the_rest_stays() {
        // A flat grid (no fold) with one inner vertex moved far across its neighbours, in the
        // plane: its triangles flip over their edges.
        let mesh = grid(6);
        let topology = Topology::build(&mesh);
        let edges = two_face_edges(&mesh.triangles);
        let reference = folded(&mesh.positions, &mesh, &edges);
        assert!(reference.iter().all(|&f| !f), "the flat grid folds nothing");
        let v = 3 * 7 + 3;
        let mut positions = mesh.positions.clone();
        positions[v][0] += 1.6;
        let flipped = folded(&positions, &mesh, &edges);
        assert!(flipped.iter().any(|&f| f), "the push folds edges");
        let moved = unfold(&mut positions, &level(&mesh, &topology), &edges, &reference);
        assert!(folded(&positions, &mesh, &edges).iter().all(|&f| !f));
        assert!((1..=8).contains(&moved), "{moved} vertices moved");
        // The vertex is back near its place, the vertices away from the fold did not move.
        assert!((positions[v][0] - mesh.positions[v][0]).abs() < 0.5);
        for u in [0, 6, 42, 48] {
            assert_eq!(positions[u], mesh.positions[u], "corner {u}");
        }
    }

    #[test]
    fn folds_the_reference_has_are_kept() {
        // The same push, but taken as the reference: nothing is new, nothing moves.
        let mesh = grid(6);
        let topology = Topology::build(&mesh);
        let edges = two_face_edges(&mesh.triangles);
        let mut positions = mesh.positions.clone();
        positions[3 * 7 + 3][0] += 1.6;
        let reference = folded(&positions, &mesh, &edges);
        let before = positions.clone();
        assert_eq!(
            unfold(&mut positions, &level(&mesh, &topology), &edges, &reference),
            0
        );
        assert_eq!(positions, before);
    }
}
