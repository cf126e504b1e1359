//! Consistent orientation: flips triangles so that every two triangles sharing an edge traverse
//! it in opposite directions, component by component.
//!
//! Not in the paper, which assumes an oriented manifold. Scans and exports sometimes have patches
//! of flipped triangles; then volumes, normals and the fairing's normal projection mean nothing
//! there. Each connected component (through edges shared by exactly two triangles) is walked
//! breadth-first from its first triangle, and each triangle is given the orientation its
//! neighbour asks for; of the two consistent orientations of a component, the one that flips fewer
//! of its triangles is kept (a user's inward-facing part stays inward). A component where the walk
//! meets a contradiction (a Möbius strip) cannot be oriented: it is left as it was and counted.

use super::{Topology, TriMesh};
use std::collections::VecDeque;

/// What [`orient_consistently`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OrientReport {
    /// Triangles whose corner order was reversed.
    pub flipped_faces: usize,
    /// Components that had to be changed.
    pub reoriented_components: usize,
    /// Components that cannot be oriented (left as they were).
    pub non_orientable_components: usize,
}

/// Orients every component of `mesh` consistently (`topology` built from it; rebuild it after a
/// change: `flipped_faces > 0`).
pub fn orient_consistently(mesh: &mut TriMesh, topology: &Topology) -> OrientReport {
    let face_count = mesh.triangles.len();
    // +1: keep, -1: flip, 0: not reached yet.
    let mut sign = vec![0i8; face_count];
    let mut report = OrientReport::default();
    let mut queue = VecDeque::new();
    let direction = |t: &[u32; 3], a: u32, b: u32| -> i8 {
        let i = t.iter().position(|&c| c == a).expect("a is a corner");
        if t[(i + 1) % 3] == b {
            1
        } else {
            -1
        }
    };
    for seed in 0..face_count {
        if sign[seed] != 0 {
            continue;
        }
        sign[seed] = 1;
        queue.push_back(seed);
        let mut members = vec![seed];
        let mut contradiction = false;
        while let Some(f) = queue.pop_front() {
            let t = mesh.triangles[f];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let mut shared = topology
                    .faces_of(a)
                    .iter()
                    .map(|&g| g as usize)
                    .filter(|&g| g != f && mesh.triangles[g].contains(&b));
                let (Some(g), None) = (shared.next(), shared.next()) else {
                    continue; // boundary or non-manifold edge: no neighbour to agree with
                };
                let wanted = -sign[f] * direction(&t, a, b) * direction(&mesh.triangles[g], a, b);
                if sign[g] == 0 {
                    sign[g] = wanted;
                    members.push(g);
                    queue.push_back(g);
                } else if sign[g] != wanted {
                    contradiction = true;
                }
            }
        }
        if contradiction {
            report.non_orientable_components += 1;
            continue;
        }
        let flips = members.iter().filter(|&&f| sign[f] < 0).count();
        if flips == 0 || flips == members.len() {
            continue;
        }
        // Keep the orientation most of the component's triangles already have.
        let flip_negative = flips * 2 <= members.len();
        for &f in &members {
            if (sign[f] < 0) == flip_negative {
                mesh.triangles[f].swap(1, 2);
                report.flipped_faces += 1;
            }
        }
        report.reoriented_components += 1;
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::octahedron;

    #[test]
    fn flipped_faces_are_flipped_back_and_the_majority_orientation_is_kept() {
        let good = octahedron(1.0);
        let mut mesh = good.clone();
        mesh.triangles[2].swap(0, 1);
        mesh.triangles[5].swap(1, 2);
        let topology = Topology::build(&mesh);
        assert!(topology.inconsistent_edges > 0);
        let report = orient_consistently(&mut mesh, &topology);
        assert_eq!(report.flipped_faces, 2);
        assert_eq!(report.reoriented_components, 1);
        let topology = Topology::build(&mesh);
        assert_eq!(topology.inconsistent_edges, 0);
        assert!(crate::metrics::signed_volume(&mesh) > 0.0);

        // An inside-out octahedron with one face the other way stays inside out.
        let mut inverted = good.clone();
        for t in &mut inverted.triangles[1..] {
            t.swap(1, 2);
        }
        let topology = Topology::build(&inverted);
        let report = orient_consistently(&mut inverted, &topology);
        assert_eq!(report.flipped_faces, 1);
        assert!(crate::metrics::signed_volume(&inverted) < 0.0);
    }

    #[test]
    fn a_moebius_strip_is_left_alone_and_counted() {
        // A strip of 4 quads whose ends are glued with a half twist.
        let n = 4u32;
        let mut positions = Vec::new();
        for i in 0..n {
            let a = std::f32::consts::TAU * i as f32 / n as f32;
            positions.push([a.cos(), a.sin(), -0.2]);
            positions.push([a.cos(), a.sin(), 0.2]);
        }
        let mut triangles = Vec::new();
        for i in 0..n {
            let (b0, t0) = (2 * i, 2 * i + 1);
            let (b1, t1) = if i + 1 == n {
                (1, 0)
            } else {
                (2 * i + 2, 2 * i + 3)
            };
            triangles.push([b0, b1, t1]);
            triangles.push([b0, t1, t0]);
        }
        let mut mesh = TriMesh::new(positions, triangles);
        let before = mesh.clone();
        let topology = Topology::build(&mesh);
        let report = orient_consistently(&mut mesh, &topology);
        assert_eq!(report.non_orientable_components, 1);
        assert_eq!(mesh, before);
    }
}
