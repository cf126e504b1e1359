//! Keeping each part's volume over many rounds of constrained fairing (the default's volume
//! correction, [`super::FairOptions::keep_volume`]).
//!
//! Not in the paper. One round of the paper's fairing keeps every triangle's barycentre near its
//! anchor, so it changes the volume little; but the default runs several rounds, each re-anchored
//! where the last one ended, and on coarsely sampled or thin parts each round loses a little
//! (the elephant of `tests/data` lost 1.1 % over 6 rounds, and it got further from its clean
//! surface round after round). After every round this takes the loss back with one number per
//! connected part: every vertex that may move is offset along its normal by the same distance δ,
//! chosen so that the part encloses the volume it enclosed before fairing (δ = ΔV / A, the
//! volume's derivative under a uniform normal offset being about the area; two Newton steps).
//! Being a single number per part, it carries no detail of the noise back, unlike a correction
//! that varies over the surface (a low-passed per-vertex correction was tried and kept too much
//! noise: `docs/measurements.md`).
//!
//! An open part has no inside; its "volume" here is that of the cone from its centroid (taken
//! before fairing) to its surface, which a uniform inward drift of the surface lowers just the
//! same. Vertices that must not move (boundary vertices, crease corners, vertices a mask pins)
//! are left out of both the offset and the derivative.

use crate::mesh::{Topology, TriMesh};
use glam::DVec3;
use rayon::prelude::*;

/// Faces per block of the sums (a fixed block size keeps the sums the same for any number of
/// threads).
const BLOCK: usize = 4096;

/// Offset steps per restore (see [`VolumeKeeper::restore`]).
const NEWTON_STEPS: usize = 2;

/// The volume of each connected part of a mesh before fairing, and which vertices may be offset.
#[derive(Clone, Debug)]
pub struct VolumeKeeper {
    /// Connected part of each face.
    face_part: Vec<u32>,
    /// Connected part of each vertex (`Topology::component_of_vertex`).
    vertex_part: Vec<u32>,
    /// Per part: the apex of its cone volume and the volume to keep.
    apex: Vec<DVec3>,
    target: Vec<f64>,
    /// Vertices that may be offset.
    movable: Vec<bool>,
}

impl VolumeKeeper {
    /// Records the volume of each connected part of `mesh`; `fixed[v]` (when given for every
    /// vertex) marks vertices that must not move. Boundary vertices never move.
    pub fn new(mesh: &TriMesh, topology: &Topology, fixed: &[bool]) -> Self {
        let n = mesh.positions.len();
        // The topology's connected components (an isolated vertex is a part of its own, with
        // no face and nothing to move).
        let vertex_part = topology.component_of_vertex.clone();
        let parts = topology.components.len();
        let face_part: Vec<u32> = mesh
            .triangles
            .iter()
            .map(|t| vertex_part[t[0] as usize])
            .collect();
        let mut sum = vec![DVec3::ZERO; parts];
        let mut count = vec![0usize; parts];
        for (v, &p) in vertex_part.iter().enumerate() {
            sum[p as usize] += mesh.point(v as u32);
            count[p as usize] += 1;
        }
        let apex: Vec<DVec3> = sum
            .iter()
            .zip(&count)
            .map(|(s, &c)| *s / c.max(1) as f64)
            .collect();
        let movable = (0..n)
            .map(|v| {
                !topology.faces_of(v as u32).is_empty()
                    && !topology.is_boundary_vertex(v as u32)
                    && !fixed.get(v).copied().unwrap_or(false)
            })
            .collect();
        let mut keeper = VolumeKeeper {
            face_part,
            vertex_part,
            apex,
            target: Vec::new(),
            movable,
        };
        keeper.target = keeper.volumes(mesh);
        keeper
    }

    /// Number of connected parts.
    pub fn parts(&self) -> usize {
        self.apex.len()
    }

    /// The cone volume of each part about its apex (for a closed part, its enclosed volume).
    fn volumes(&self, mesh: &TriMesh) -> Vec<f64> {
        let parts = self.parts();
        let blocks: Vec<Vec<f64>> = mesh
            .triangles
            .par_chunks(BLOCK)
            .zip(self.face_part.par_chunks(BLOCK))
            .map(|(faces, owners)| {
                let mut sums = vec![0.0; parts];
                for (t, &p) in faces.iter().zip(owners) {
                    let apex = self.apex[p as usize];
                    let [a, b, c] = t.map(|v| mesh.point(v) - apex);
                    sums[p as usize] += a.dot(b.cross(c)) / 6.0;
                }
                sums
            })
            .collect();
        let mut total = vec![0.0; parts];
        for block in blocks {
            for (t, s) in total.iter_mut().zip(block) {
                *t += s;
            }
        }
        total
    }

    /// Offsets the movable vertices of each part along their normals so that the part's volume
    /// is again what it was when `self` was made (two Newton steps with the normals of the
    /// positions given: what is left is of second order in the offset, a small fraction of an
    /// edge length);
    /// vertices for which
    /// `held` is true stay too (crease corners). `topology` is the mesh's. Returns the largest
    /// offset applied.
    pub fn restore(
        &self,
        mesh: &mut TriMesh,
        topology: &Topology,
        held: impl Fn(usize) -> bool + Sync,
    ) -> f64 {
        let parts = self.parts();
        let moves = |v: usize| self.movable[v] && !held(v);
        // Each face's normal N_f (twice its area in length), once; then each movable vertex's
        // normal (area-weighted) and its share of the volume's derivative.
        let face_normals: Vec<DVec3> = (0..mesh.triangles.len())
            .into_par_iter()
            .map(|f| mesh.face_normal(f))
            .collect();
        let normals: Vec<(DVec3, f64)> = (0..mesh.positions.len())
            .into_par_iter()
            .map(|v| {
                if !moves(v) {
                    return (DVec3::ZERO, 0.0);
                }
                let sum: DVec3 = topology
                    .faces_of(v as u32)
                    .iter()
                    .map(|&f| face_normals[f as usize])
                    .sum();
                let length = sum.length();
                if length > 0.0 && length.is_finite() {
                    // |Σ N_f| / 6 is the volume's derivative for a move of v along its normal
                    // (the gradient of the volume at v is Σ N_f / 6 over its closed fan).
                    (sum / length, length / 6.0)
                } else {
                    (DVec3::ZERO, 0.0)
                }
            })
            .collect();
        drop(face_normals);
        let area_blocks: Vec<Vec<f64>> = normals
            .par_chunks(BLOCK)
            .enumerate()
            .map(|(block, chunk)| {
                let mut sums = vec![0.0; parts];
                for (i, (_, area)) in chunk.iter().enumerate() {
                    let part = self.vertex_part[block * BLOCK + i];
                    if *area > 0.0 {
                        sums[part as usize] += area;
                    }
                }
                sums
            })
            .collect();
        let mut area = vec![0.0; parts];
        for block in area_blocks {
            for (a, s) in area.iter_mut().zip(block) {
                *a += s;
            }
        }
        // Newton steps with the derivative taken once (Σ over the vertices of |Σ N_f| / 6: the
        // area on a smooth surface, a little less along sharp edges); the second step takes up
        // what is left to second order in the offset.
        let mut total = vec![0.0; parts];
        for _ in 0..NEWTON_STEPS {
            let volumes = self.volumes(mesh);
            let offsets: Vec<f64> = (0..parts)
                .map(|p| {
                    let delta = (self.target[p] - volumes[p]) / area[p];
                    if area[p] > 0.0 && delta.is_finite() {
                        delta
                    } else {
                        0.0
                    }
                })
                .collect();
            mesh.positions
                .par_iter_mut()
                .zip(&normals)
                .zip(&self.vertex_part)
                .for_each(|((position, (normal, area)), &part)| {
                    if *area > 0.0 {
                        let moved =
                            DVec3::from(position.map(f64::from)) + *normal * offsets[part as usize];
                        *position = moved.as_vec3().to_array();
                    }
                });
            for (t, d) in total.iter_mut().zip(&offsets) {
                *t += d;
            }
        }
        total.iter().fold(0.0, |m, d| m.max(d.abs()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::metrics::signed_volume;

    #[test]
    fn a_shrunk_part_gets_its_volume_back_and_a_second_part_keeps_its_own() {
        let cube = shapes::cuboid([1.0, 1.0, 1.0], 0.1);
        // Two cubes, the second moved away: two parts.
        let mut mesh = cube.clone();
        let offset = cube.positions.len() as u32;
        mesh.positions
            .extend(cube.positions.iter().map(|p| [p[0] + 3.0, p[1], p[2]]));
        mesh.triangles
            .extend(cube.triangles.iter().map(|t| t.map(|v| v + offset)));
        let topology = Topology::build(&mesh);
        let keeper = VolumeKeeper::new(&mesh, &topology, &[]);
        assert_eq!(keeper.parts(), 2);
        let before = signed_volume(&mesh);
        // Shrink the first cube only, by 1 % about its centre (3 % of its volume: more than a
        // round of fairing loses, 0.2 % at most in the measurements).
        for p in &mut mesh.positions[..offset as usize] {
            *p = p.map(|c| 0.5 + (c - 0.5) * 0.99);
        }
        let second: Vec<[f32; 3]> = mesh.positions[offset as usize..].to_vec();
        keeper.restore(&mut mesh, &topology, |_| false);
        let after = signed_volume(&mesh);
        assert!(
            ((after - before) / before).abs() < 1e-4,
            "volume {after} after restoring, {before} before"
        );
        // The second cube did not change, so it did not move.
        assert_eq!(&mesh.positions[offset as usize..], &second[..]);
    }

    #[test]
    fn fixed_vertices_stay_and_the_others_make_up_the_volume() {
        let mut mesh = shapes::cuboid([1.0, 1.0, 1.0], 0.1);
        let topology = Topology::build(&mesh);
        let fixed: Vec<bool> = (0..mesh.positions.len()).map(|v| v % 3 == 0).collect();
        let keeper = VolumeKeeper::new(&mesh, &topology, &fixed);
        let before = signed_volume(&mesh);
        let original = mesh.positions.clone();
        for p in &mut mesh.positions {
            *p = p.map(|c| 0.5 + (c - 0.5) * 0.98);
        }
        let shrunk = mesh.positions.clone();
        keeper.restore(&mut mesh, &topology, |_| false);
        for v in (0..mesh.positions.len()).filter(|v| fixed[*v]) {
            assert_eq!(mesh.positions[v], shrunk[v], "fixed vertex {v} moved");
        }
        let after = signed_volume(&mesh);
        assert!(
            ((after - before) / before).abs() < 1e-3,
            "{after} vs {before}"
        );
        assert_ne!(mesh.positions, original);
    }
}
