//! The steps between two levels of multiresolution fairing (paper section 4.2 and the
//! Improved variant's corrections, see the parent module's docs): after a level's fairing, the
//! low-frequency part of its normal displacement taken back (Improved); then the refinement to
//! the next finer level, the split vertices placed at their rings' means, moved by one Kobbelt
//! step and (Improved) given back the volume their split added in the original geometry.

use super::{
    LevelData, MultiresVariant, MultiresWorkspace, HEIGHT_SMOOTHING_ROUNDS, NONE, PARALLEL_GRAIN,
    SHRINKAGE_SMOOTHING_ROUNDS,
};
use crate::hierarchy::Hierarchy;
use crate::mesh::Topology;
use glam::Vec3A;
use rayon::prelude::*;

/// Improved: removes the smooth part of the normal displacement the level's fairing made.
/// Noise removal is a high-frequency normal motion; shrinkage of curved and thin parts is a
/// coherent (low-frequency) one. The normal displacement `h_v = (x_v - x_v^before) . n_v` is
/// low-passed by two area-weighted 1-ring averages, and that part is taken back.
pub(super) fn remove_low_frequency_shrinkage(workspace: &mut MultiresWorkspace, level: usize) {
    let MultiresWorkspace {
        levels,
        positions,
        before_fairing,
        normals,
        normal_moves,
        smoothed_moves,
        ..
    } = workspace;
    let data = levels[level].as_ref().expect("prepared before fairing");
    let n = data.mesh.positions.len();
    normal_displacements(data, positions, before_fairing, normals, normal_moves);
    for _ in 0..SHRINKAGE_SMOOTHING_ROUNDS {
        low_pass_displacements(&data.topology, normal_moves, smoothed_moves);
        std::mem::swap(normal_moves, smoothed_moves);
    }
    let (moves, normals): (&[[f32; 2]], &[Vec3A]) = (normal_moves, normals);
    // Crease vertices and corners take the correction too: holding them loses volume from coarse
    // levels (CAD shapes, the elephant), and so does holding only the corners.
    positions[..n]
        .par_iter_mut()
        .with_min_len(PARALLEL_GRAIN)
        .enumerate()
        .for_each(|(v, p)| {
            let [weighted, area] = moves[v];
            if area > 0.0 {
                *p = (Vec3A::from_array(*p) - normals[v] * (weighted / area)).to_array();
            }
        });
}

/// Per vertex of the level (`data`), its unit area-weighted normal into `normals` and, into
/// `normal_moves`, its normal displacement from `before` to `positions` weighted by its area,
/// with that area (twice the area: Σ over the fan of (a − x) × (b − x), from the fan order
/// where the fan is closed, from the faces otherwise).
fn normal_displacements(
    data: &LevelData,
    positions: &[[f32; 3]],
    before: &[[f32; 3]],
    normals: &mut Vec<Vec3A>,
    normal_moves: &mut Vec<[f32; 2]>,
) {
    let n = data.mesh.positions.len();
    let topology = &data.topology;
    let triangles = &data.mesh.triangles;
    let (offsets, _) = topology.neighbor_csr();
    let fans = data
        .fans
        .as_ref()
        .expect("a faired level has its fan-ordered rings");
    let at = |v: u32| Vec3A::from_array(positions[v as usize]);
    (0..n)
        .into_par_iter()
        .with_min_len(PARALLEL_GRAIN)
        .map(|v| {
            let centre = at(v as u32);
            let mut normal = Vec3A::ZERO;
            if fans.closed_fan[v] {
                let fan = &fans.ring[offsets[v] as usize..offsets[v + 1] as usize];
                let mut previous = at(fan[fan.len() - 1]) - centre;
                for &u in fan {
                    let current = at(u) - centre;
                    normal += previous.cross(current);
                    previous = current;
                }
            } else {
                for &f in topology.faces_of(v as u32) {
                    let [a, b, c] = triangles[f as usize].map(at);
                    normal += (b - a).cross(c - a);
                }
            }
            let area = normal.length();
            let unit = if area > 0.0 && area.is_finite() {
                normal / area
            } else {
                Vec3A::ZERO
            };
            let moved = centre - Vec3A::from_array(before[v]);
            (unit, [moved.dot(unit) * area, area])
        })
        .unzip_into_vecs(normals, normal_moves);
}

/// One area-weighted 1-ring average of the weighted normal displacements `moves` (each with
/// its area) into `smoothed`.
fn low_pass_displacements(topology: &Topology, moves: &[[f32; 2]], smoothed: &mut Vec<[f32; 2]>) {
    (0..moves.len())
        .into_par_iter()
        .with_min_len(PARALLEL_GRAIN)
        .map(|v| {
            let mut sum = moves[v];
            for &u in topology.neighbors(v as u32) {
                let m = moves[u as usize];
                sum[0] += m[0];
                sum[1] += m[1];
            }
            let mean = if sum[1] > 0.0 { sum[0] / sum[1] } else { 0.0 };
            [mean * moves[v][1], moves[v][1]]
        })
        .collect_into_vec(smoothed);
}

/// Refines the working positions from level `finer + 1` to `finer`: places the split vertices
/// at their rings' means, moves them by one Kobbelt step and (Improved) gives back the volume
/// each split added in the original geometry.
pub(super) fn refine_positions(
    hierarchy: &Hierarchy,
    workspace: &mut MultiresWorkspace,
    finer: usize,
    variant: MultiresVariant,
) {
    let coarse_count = hierarchy.level_info(finer + 1).vertices;
    let fine_count = hierarchy.level_info(finer).vertices;
    let MultiresWorkspace {
        levels,
        positions,
        laplacians,
        displacements,
        heights,
        height_sums,
        ..
    } = workspace;
    let data = levels[finer].as_ref().expect("prepared before refining");
    let rings = Rings {
        topology: &data.topology,
        loops: &data.loop_neighbors,
    };
    positions.resize(fine_count, [0.0; 3]);
    place_at_ring_means(positions, coarse_count, rings);
    kobbelt_step(positions, coarse_count, rings, laplacians, displacements);
    if variant == MultiresVariant::Paper {
        return;
    }
    // Improved: restore the volume each split added in the original geometry, low-passed.
    split_heights(hierarchy, data, positions, coarse_count, heights);
    for _ in 0..HEIGHT_SMOOTHING_ROUNDS {
        low_pass_heights(
            heights,
            height_sums,
            rings.topology,
            coarse_count,
            fine_count,
        );
    }
    positions[coarse_count..]
        .par_iter_mut()
        .zip(heights.par_iter())
        .for_each(|(p, &(normal, height, _, bound))| {
            let height = height.clamp(-bound, bound);
            *p = (Vec3A::from_array(*p) + normal * height as f32).to_array()
        });
}

/// A level's one-rings as refining reads them: a vertex on a boundary loop or a crease has its
/// two loop neighbours for a ring, any other its topology's one-ring.
#[derive(Clone, Copy)]
struct Rings<'a> {
    topology: &'a Topology,
    /// [`LevelData::loop_neighbors`].
    loops: &'a [[u32; 2]],
}

impl Rings<'_> {
    fn on_loop(&self, v: usize) -> bool {
        !self.loops.is_empty() && self.loops[v][0] != NONE
    }
}

/// Places every split vertex (those from `coarse_count` on) at the 1-ring mean (loop midpoint on
/// the boundary). Split vertices of one level are never adjacent, so their neighbours all come
/// before them and have positions.
fn place_at_ring_means(positions: &mut [[f32; 3]], coarse_count: usize, rings: Rings) {
    let (coarse, fine) = positions.split_at_mut(coarse_count);
    let coarse: &[[f32; 3]] = coarse;
    let at = |v: u32| Vec3A::from_array(coarse[v as usize]);
    fine.par_iter_mut()
        .with_min_len(PARALLEL_GRAIN)
        .enumerate()
        .for_each(|(i, p)| {
            let v = coarse_count + i;
            let x = if rings.on_loop(v) {
                let [a, b] = rings.loops[v];
                (at(a) + at(b)) * 0.5
            } else {
                let ring = rings.topology.neighbors(v as u32);
                ring.iter().map(|&u| at(u)).sum::<Vec3A>() / ring.len().max(1) as f32
            };
            *p = x.to_array();
        });
}

/// One Kobbelt step for all split vertices, from the placed positions, applied together: the
/// umbrella Laplacian of every vertex first (a split vertex needs its neighbours'), then the
/// steps.
fn kobbelt_step(
    positions: &mut [[f32; 3]],
    coarse_count: usize,
    rings: Rings,
    laplacians: &mut Vec<Vec3A>,
    displacements: &mut Vec<Vec3A>,
) {
    let fine_count = positions.len();
    let Rings { topology, loops } = rings;
    {
        let placed: &[[f32; 3]] = positions;
        let at = |v: u32| Vec3A::from_array(placed[v as usize]);
        (0..fine_count)
            .into_par_iter()
            .with_min_len(PARALLEL_GRAIN)
            .map(|v| {
                if rings.on_loop(v) {
                    let [a, b] = loops[v];
                    (at(a) + at(b)) * 0.5 - at(v as u32)
                } else {
                    let ring = topology.neighbors(v as u32);
                    let sum: Vec3A = ring.iter().map(|&u| at(u)).sum();
                    sum / ring.len().max(1) as f32 - at(v as u32)
                }
            })
            .collect_into_vec(laplacians);
    }
    let laplacians: &[Vec3A] = laplacians;
    (coarse_count..fine_count)
        .into_par_iter()
        .with_min_len(PARALLEL_GRAIN)
        .map(|v| {
            let own = laplacians[v];
            let (sum, inverse_valences, n) = if rings.on_loop(v) {
                let [a, b] = loops[v];
                (laplacians[a as usize] + laplacians[b as usize], 1.0, 2.0)
            } else {
                let ring = topology.neighbors(v as u32);
                let mut sum = Vec3A::ZERO;
                let mut inverse_valences = 0.0;
                for &u in ring {
                    sum += laplacians[u as usize];
                    inverse_valences += 1.0 / topology.valence(u) as f32;
                }
                (sum, inverse_valences, ring.len() as f32)
            };
            let l2 = sum / n - own;
            let nu = 1.0 + inverse_valences / n;
            -l2 / nu
        })
        .collect_into_vec(displacements);
    positions[coarse_count..]
        .par_iter_mut()
        .zip(displacements.par_iter())
        .for_each(|(p, d)| *p = (Vec3A::from_array(*p) + *d).to_array());
}

/// Improved: per split vertex (from `coarse_count` on), the unit normal of its ring's fan
/// around its collapse target, the height along it that gives back the volume the split added
/// in the original geometry, that fan's area (the height's weight) and the most height it may
/// take.
fn split_heights(
    hierarchy: &Hierarchy,
    data: &LevelData,
    positions: &[[f32; 3]],
    coarse_count: usize,
    heights: &mut Vec<(Vec3A, f64, f64, f64)>,
) {
    let triangles = &data.mesh.triangles;
    let (face_offsets, vertex_faces) = data.topology.face_csr();
    let at = |v: u32| Vec3A::from_array(positions[v as usize]);
    (coarse_count..positions.len())
        .into_par_iter()
        .with_min_len(PARALLEL_GRAIN)
        .map(|v| {
            let Some(k) = hierarchy.collapse_target(v as u32) else {
                return (Vec3A::ZERO, 0.0, 0.0, 0.0);
            };
            let (xv, xk) = (at(v as u32), at(k));
            let mut area = Vec3A::ZERO;
            // The longest edge at `v` now (every neighbour is some face's `a`, or on an open
            // fan the last face's `b`).
            let mut spoke_squared = 0f32;
            for &f in &vertex_faces[face_offsets[v] as usize..face_offsets[v + 1] as usize] {
                let t = triangles[f as usize];
                let (a, b) = if t[0] == v as u32 {
                    (t[1], t[2])
                } else if t[1] == v as u32 {
                    (t[2], t[0])
                } else {
                    (t[0], t[1])
                };
                let (xa, xb) = (at(a), at(b));
                spoke_squared = spoke_squared
                    .max(xa.distance_squared(xv))
                    .max(xb.distance_squared(xv));
                if a != k && b != k {
                    area += (xa - xk).cross(xb - xk);
                }
            }
            let weight = area.length();
            if weight <= 0.0 || !weight.is_finite() {
                return (Vec3A::ZERO, 0.0, 0.0, 0.0);
            }
            let normal = area / weight;
            let current = area.dot(xv - xk) as f64;
            let weight = weight as f64;
            let height = (hierarchy.six_split_volume(v as u32) as f64 - current) / weight;
            // The most height a split may take (after the low-pass): twice its longest edge
            // now. Where the fairing has shrunk its ring to a sliver (a spike's base on a
            // noisy scan), the volume over that sliver asks for a tower. (A bound by its height
            // in M0 would need a second position array to read.)
            let bound = 2.0 * spoke_squared.sqrt() as f64;
            (normal, height, weight, bound)
        })
        .collect_into_vec(heights);
}

/// One two-ring average of the split heights, weighted by their areas: per vertex of the finer
/// level (`fine_count`), the weighted heights of its adjacent split vertices (a gather over the
/// sorted one-ring: the same sums, in the same order, as scattering from the split vertices),
/// then per split vertex the mean over its ring of those sums.
fn low_pass_heights(
    heights: &mut [(Vec3A, f64, f64, f64)],
    height_sums: &mut Vec<[f64; 2]>,
    topology: &Topology,
    coarse_count: usize,
    fine_count: usize,
) {
    {
        let heights: &[(Vec3A, f64, f64, f64)] = heights;
        (0..fine_count)
            .into_par_iter()
            .with_min_len(PARALLEL_GRAIN)
            .map(|u| {
                let mut sum = [0.0; 2];
                for &v in topology.neighbors(u as u32) {
                    if let Some(&(_, height, weight, _)) =
                        (v as usize).checked_sub(coarse_count).map(|i| &heights[i])
                    {
                        sum[0] += height * weight;
                        sum[1] += weight;
                    }
                }
                sum
            })
            .collect_into_vec(height_sums);
    }
    let sums: &[[f64; 2]] = height_sums;
    heights
        .par_iter_mut()
        .with_min_len(PARALLEL_GRAIN)
        .enumerate()
        .for_each(|(i, entry)| {
            let mut sum = [0.0; 2];
            for &u in topology.neighbors((coarse_count + i) as u32) {
                let s = sums[u as usize];
                sum[0] += s[0];
                sum[1] += s[1];
            }
            if sum[1] > 0.0 {
                entry.1 = sum[0] / sum[1];
            }
        });
}
