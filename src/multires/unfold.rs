//! Not in the paper: the edges a multiresolution run leaves folded. Refining from a coarse level
//! places each split vertex from its coarse neighbours, and where a coarse level's fairing bent
//! a thin part or a sharp edge, a few of those placements fall on the wrong side of their
//! neighbours: two triangles then fold over their shared edge by more than a right angle (the
//! noisy bunny from its opening level 9: 18 such edges of 113k). The M0 pass that follows
//! ([`super::MultiresOptions::fair_finest`]) unfolds most, as constrained fairing does on M0,
//! but not all. So, last, every edge folded beyond 90° where M0 itself (the mesh the hierarchy
//! was built on) was not bent to within 5° of a right angle (a box's edges are features):
//!
//! 1. gets its two corners and the third corners of its two faces moved to the mean of their
//!    neighbours (Jacobi, a few sweeps), and those of edges still folded join them, until none
//!    is left or [`UNFOLD_PASSES`] have run. A crease vertex moves along its crease (to the mean
//!    of its two neighbours on it); corners and boundary vertices stay.
//! 2. What that cannot undo (a fold between crease corners, which stay, or one pressed in too
//!    deep: on the coarsely sampled noisy elephant, most of them) has the same four corners put
//!    back where M0 has them, where the edge was not folded, corners of creases included but not
//!    boundary vertices; they stay there, the passes of 1. run again around them, and this
//!    repeats up to [`FALLBACK_PASSES`] times.
//! 3. With the improved variant, M0's volume is given back before 1. and again after 2., as
//!    constrained fairing gives it back after a round: every vertex offset along its normal, one
//!    distance per connected part. (The paper's variant shows the paper's recipe, shrinkage
//!    and all.)
//!
//! A run with no such fold (most runs) changes nothing and pays one pass over the edges. Noisy
//! elephant from levels 3 / 5 / 7, edges folded that `fair`'s result does not fold: 31 / 72 /
//! 112 with 1. alone, 4 / 5 / 5 with 2. and 3. (`docs/measurements.md`, "Multiresolution
//! fairing").

use super::NONE;
use crate::fairing::creases::Creases;
use crate::fairing::volume::VolumeKeeper;
use crate::mesh::{Topology, TriMesh};
use glam::Vec3A;

/// What [`unfold`] reads of M0: its connectivity, its creases and, per vertex, its two
/// neighbours along its crease or boundary loop (`NONE` for others; empty when M0 has neither).
pub(super) struct Level<'a> {
    pub(super) mesh: &'a TriMesh,
    pub(super) topology: &'a Topology,
    pub(super) creases: Option<&'a Creases>,
    pub(super) loop_neighbors: &'a [[u32; 2]],
    /// Give M0's volume back (step 3 of the module docs): the improved variant, whose promise
    /// it is; the paper's variant shows the paper's recipe, shrinkage and all.
    pub(super) keep_volume: bool,
}

/// At most this many rounds of finding the folded edges and smoothing their corners.
pub const UNFOLD_PASSES: usize = 8;

/// At most this many times the corners of the folds left (and their neighbours) go back to M0.
const FALLBACK_PASSES: usize = 4;

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

/// The corners of a folded edge that move: its two ends and its two faces' third corners (the
/// ones that move when the edge itself lies on a crease).
fn fold_corners(mesh: &TriMesh, &[a, b, f, g]: &[u32; 4]) -> [u32; 4] {
    let third = |face: u32| {
        let t = mesh.triangles[face as usize];
        t[0] ^ t[1] ^ t[2] ^ a ^ b
    };
    [a, b, third(f), third(g)]
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
        keep_volume,
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
    // Only when there is a fold to undo (most runs have none and pay one pass over the edges).
    if !folded(positions, mesh, edges)
        .iter()
        .zip(reference)
        .any(|(&now, &was)| now && !was)
    {
        return 0;
    }
    // M0's volume, given back before and after the unfolding as constrained fairing gives it
    // back after a round: every vertex offset along its normal, one distance per connected part.
    // Before, so that the levels' own drift (a coarse level's result can hold a percent more)
    // is not taken for folds and the offset after is small: one offset after alone folded a
    // third as many edges again on the noisy elephant. After, for what the means and the
    // vertices put back to M0 changed. (The improved variant only.)
    let mut keep = keep_volume.then(|| {
        (
            VolumeKeeper::new(mesh, topology, &[]),
            TriMesh::new(Vec::new(), mesh.triangles.clone()),
        )
    });
    let restore = |positions: &mut [[f32; 3]], keep: &mut Option<(VolumeKeeper, TriMesh)>| {
        if let Some((keeper, result)) = keep {
            result.positions = positions.to_vec();
            keeper.restore(result, topology, |_| false);
            positions.copy_from_slice(&result.positions);
        }
    };
    restore(positions, &mut keep);
    let mut moving = vec![false; positions.len()];
    let mut region: Vec<u32> = Vec::new();
    // The vertices put back to M0 (below), which stay there.
    let mut back = vec![false; positions.len()];
    let passes =
        |positions: &mut [[f32; 3]], region: &mut Vec<u32>, moving: &mut [bool], back: &[bool]| {
            for _ in 0..UNFOLD_PASSES {
                let now = folded(positions, mesh, edges);
                let mut grew = false;
                for ((edge, &folded), &was) in edges.iter().zip(&now).zip(reference) {
                    if !folded || was {
                        continue;
                    }
                    for v in fold_corners(mesh, edge) {
                        if !moving[v as usize] && !stays(v) {
                            moving[v as usize] = true;
                            region.push(v);
                            grew = true;
                        }
                    }
                }
                if !grew && !now.iter().zip(reference).any(|(&n, &r)| n && !r) {
                    return;
                }
                for _ in 0..SWEEPS {
                    let means: Vec<[f32; 3]> = region
                        .iter()
                        .map(|&v| {
                            if back[v as usize] {
                                return positions[v as usize];
                            }
                            if let Some([p, n]) = on_crease(v) {
                                let [p, n] =
                                    [p, n].map(|u| Vec3A::from_array(positions[u as usize]));
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
        };
    passes(positions, &mut region, &mut moving, &back);
    // What the neighbours' means cannot undo (a fold whose corners all stay, or one the levels
    // pressed in too deep): its corners, corners of creases among them, go back to where M0 has
    // them, where the edge was not folded, and the passes run again around them.
    for _ in 0..FALLBACK_PASSES {
        let still: Vec<u32> = folded(positions, mesh, edges)
            .iter()
            .zip(reference)
            .zip(edges)
            .filter(|((&now, &was), _)| now && !was)
            .flat_map(|(_, edge)| fold_corners(mesh, edge))
            .filter(|&v| !topology.is_boundary_vertex(v))
            .collect();
        if still.is_empty() {
            break;
        }
        for &v in &still {
            positions[v as usize] = mesh.positions[v as usize];
            back[v as usize] = true;
        }
        passes(positions, &mut region, &mut moving, &back);
    }
    restore(positions, &mut keep);
    let moved = |v: usize| moving[v] || back[v];
    (0..positions.len()).filter(|&v| moved(v)).count()
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
            keep_volume: true,
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
    fn a_fold_between_corners_that_stay_goes_back_to_m0() {
        // A cube's corner (a crease corner: it stays in the passes) pushed through the cube,
        // past the centre: the neighbours' means cannot unfold its edges, so its corners go back
        // to M0; nothing stays folded, the corner is where M0 has it (but for the volume's
        // offsets), and the volume is M0's.
        let mesh = crate::mesh::shapes::cuboid([1.0, 1.0, 1.0], 0.25);
        let topology = Topology::build(&mesh);
        let creases = crate::fairing::detect_creases(&mesh, &topology, &Default::default());
        let edges = two_face_edges(&mesh.triangles);
        let reference = bent_to_right_angle(&mesh.positions, &mesh, &edges);
        let sum = |p: &[f32; 3]| p[0] + p[1] + p[2];
        let corner = (0..mesh.positions.len())
            .max_by(|&a, &b| sum(&mesh.positions[a]).total_cmp(&sum(&mesh.positions[b])))
            .unwrap();
        let n = mesh.positions.len() as f32;
        let centre = mesh
            .positions
            .iter()
            .fold([0.0f32; 3], |s, p| [0, 1, 2].map(|i| s[i] + p[i] / n));
        let mut positions = mesh.positions.clone();
        positions[corner] = [0, 1, 2].map(|i| centre[i] - 0.3 * (positions[corner][i] - centre[i]));
        let new_folds = |positions: &[[f32; 3]]| {
            folded(positions, &mesh, &edges)
                .iter()
                .zip(&reference)
                .filter(|(&now, &was)| now && !was)
                .count()
        };
        assert!(new_folds(&positions) > 0, "the push folds edges");
        let level = Level {
            mesh: &mesh,
            topology: &topology,
            creases: Some(&creases),
            loop_neighbors: &[],
            keep_volume: true,
        };
        let moved = unfold(&mut positions, &level, &edges, &reference);
        assert!(moved >= 1);
        assert_eq!(new_folds(&positions), 0);
        // Back to M0 but for the volume's offsets (within a hundredth of the diagonal, where the
        // push moved it 1.3 diagonals).
        let off = (0..3).map(|i| (positions[corner][i] - mesh.positions[corner][i]).powi(2));
        assert!(
            off.sum::<f32>().sqrt() < 0.01 * 3f32.sqrt(),
            "{:?}",
            positions[corner]
        );
        let volume = |positions: &[[f32; 3]]| {
            crate::metrics::signed_volume(&TriMesh::new(positions.to_vec(), mesh.triangles.clone()))
        };
        assert!((volume(&positions) - volume(&mesh.positions)).abs() < 1e-5);
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
