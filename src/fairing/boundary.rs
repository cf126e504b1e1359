//! Boundary curves (paper section 3.3): each boundary loop is faired as a closed curve.
//!
//! Interpretations (see the repository's `docs/paper.md`):
//! - The curve Laplacian of loop vertex p_i uses its two loop neighbours with weights ½, not its
//!   mesh neighbours.
//! - Each boundary edge (p_{i−1}, p_i), with loop neighbours p_{i−2} and p_{i+1}, solves the curve
//!   version of eq (7): minimise |L(p_{i−1})|² + |L(p_i)|² with p_{i−1} + p_i held at its anchor:
//!   `[p_{i−1}; p_i] = [[2/3, 1/3], [1/3, 2/3]]·[p_{i−2}; p_{i+1}] + [d; d]`,
//!   `d = ½[(p⁰_{i−1} + p⁰_i) − (p_{i−2} + p_{i+1})]`. Every loop vertex lies on two boundary
//!   edges and takes the mean of its two estimates. Anchors p⁰ are the positions at the start of
//!   the round, like the surface's.
//! - The curve step reads the previous iterate, like the surface step of the same iteration.
//! - A vertex on several loops (a pinch) takes the mean over all its estimates. Loops shorter than
//!   three vertices are left alone.
//! - The normal-projected variant keeps only the part of each boundary move orthogonal to the
//!   loop's tangent (p_{i+1} − p_{i−1}), the curve's analogue of the surface's normal projection.

/// A missing stencil entry (beyond the end of an open chain).
const NONE: u32 = u32::MAX;

/// A point type the curve operator reads and writes: plain `[f32; 3]` or a padded layout.
pub trait CurvePoint: Copy {
    fn xyz(&self) -> [f32; 3];
    fn from_xyz(p: [f32; 3]) -> Self;
}

impl CurvePoint for [f32; 3] {
    #[inline]
    fn xyz(&self) -> [f32; 3] {
        *self
    }
    #[inline]
    fn from_xyz(p: [f32; 3]) -> Self {
        p
    }
}

/// The boundary loops of a mesh, flattened for the curve operators.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BoundaryCurves {
    /// Every loop occurrence of a boundary vertex: `[p_{i−2}, p_{i−1}, p_i, p_{i+1}, p_{i+2}]`
    /// (`NONE` beyond the end of an open chain).
    stencils: Vec<[u32; 5]>,
    /// For each stencil, the index of its vertex in `vertices`.
    slot_of_stencil: Vec<u32>,
    /// The distinct boundary vertices, in order of first appearance.
    vertices: Vec<u32>,
}

impl BoundaryCurves {
    pub fn new(boundary_loops: &[Vec<u32>], vertex_count: usize) -> Self {
        let mut slot_of_vertex = vec![u32::MAX; vertex_count];
        let mut curves = BoundaryCurves::default();
        for boundary_loop in boundary_loops {
            let len = boundary_loop.len();
            if len < 3 {
                continue;
            }
            for i in 0..len {
                let at = |offset: isize| {
                    boundary_loop[(i as isize + offset).rem_euclid(len as isize) as usize]
                };
                let v = at(0);
                if slot_of_vertex[v as usize] == u32::MAX {
                    slot_of_vertex[v as usize] = curves.vertices.len() as u32;
                    curves.vertices.push(v);
                }
                curves.stencils.push([at(-2), at(-1), v, at(1), at(2)]);
                curves.slot_of_stencil.push(slot_of_vertex[v as usize]);
            }
        }
        curves
    }

    /// Closed loops as in [`Self::new`] and open chains whose two ends stay fixed (crease chains
    /// between corners, boundary loops cut at corners). A chain vertex takes the estimates of
    /// those of its two edges whose outer neighbours exist (an edge next to an end has none
    /// beyond the end); a chain of two edges has no such edge and stays as it is.
    pub fn with_open_chains(
        closed_loops: &[Vec<u32>],
        open_chains: &[Vec<u32>],
        vertex_count: usize,
    ) -> Self {
        let mut curves = Self::new(closed_loops, vertex_count);
        let mut slot_of_vertex = vec![u32::MAX; vertex_count];
        for (slot, &v) in curves.vertices.iter().enumerate() {
            slot_of_vertex[v as usize] = slot as u32;
        }
        for chain in open_chains {
            let n = chain.len();
            for i in 1..n.saturating_sub(1) {
                let at = |offset: isize| {
                    let k = i as isize + offset;
                    if (0..n as isize).contains(&k) {
                        chain[k as usize]
                    } else {
                        NONE
                    }
                };
                let stencil = [at(-2), at(-1), at(0), at(1), at(2)];
                if stencil[0] == NONE && stencil[4] == NONE {
                    continue;
                }
                let v = stencil[2];
                if slot_of_vertex[v as usize] == u32::MAX {
                    slot_of_vertex[v as usize] = curves.vertices.len() as u32;
                    curves.vertices.push(v);
                }
                curves.stencils.push(stencil);
                curves.slot_of_stencil.push(slot_of_vertex[v as usize]);
            }
        }
        curves
    }

    /// The distinct vertices the curve operators move.
    pub fn vertices(&self) -> &[u32] {
        &self.vertices
    }

    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// The loop neighbours (previous, next) of every loop occurrence, with its vertex: used by the
    /// baselines' curve Laplacian.
    pub fn loop_neighbors(&self) -> impl Iterator<Item = (u32, u32, u32)> + '_ {
        self.stencils.iter().map(|s| (s[2], s[1], s[3]))
    }

    /// One constrained curve step (section 3.3): reads `previous` and `anchors`, writes the
    /// boundary vertices of `next`. `accumulator` is a reusable buffer. Returns the largest move.
    pub fn constrained_step<P: CurvePoint, Q: CurvePoint>(
        &self,
        previous: &[Q],
        anchors: &[P],
        next: &mut [P],
        normal_projected: bool,
        accumulator: &mut Vec<([f64; 3], u32)>,
    ) -> f64 {
        accumulator.clear();
        accumulator.resize(self.vertices.len(), ([0.0; 3], 0));
        for (stencil, &slot) in self.stencils.iter().zip(&self.slot_of_stencil) {
            // An open chain's stencil lacks p_{i−2} or p_{i+2} next to its ends: that edge's
            // estimate is left out.
            let (has_before2, has_after2) = (stencil[0] != NONE, stencil[4] != NONE);
            let [before2, before, v, after, after2] = stencil.map(|u| match u {
                NONE => [0.0; 3],
                u => point(&previous[u as usize]),
            });
            let anchor_before = point(&anchors[stencil[1] as usize]);
            let anchor_v = point(&anchors[stencil[2] as usize]);
            let anchor_after = point(&anchors[stencil[3] as usize]);
            let mut estimate = [0.0; 3];
            for c in 0..3 {
                // Edge (p_{i−1}, p_i): p_i is its second vertex.
                let d_before = 0.5 * ((anchor_before[c] + anchor_v[c]) - (before2[c] + after[c]));
                let from_before = before2[c] / 3.0 + 2.0 * after[c] / 3.0 + d_before;
                // Edge (p_i, p_{i+1}): p_i is its first vertex.
                let d_after = 0.5 * ((anchor_v[c] + anchor_after[c]) - (before[c] + after2[c]));
                let from_after = 2.0 * before[c] / 3.0 + after2[c] / 3.0 + d_after;
                estimate[c] = match (has_before2, has_after2) {
                    (true, true) => 0.5 * (from_before + from_after),
                    (true, false) => from_before,
                    _ => from_after,
                };
            }
            let mut step = [estimate[0] - v[0], estimate[1] - v[1], estimate[2] - v[2]];
            if normal_projected {
                let tangent = [
                    after[0] - before[0],
                    after[1] - before[1],
                    after[2] - before[2],
                ];
                let length_squared = dot(tangent, tangent);
                if length_squared > 0.0 {
                    let along = dot(step, tangent) / length_squared;
                    for c in 0..3 {
                        step[c] -= along * tangent[c];
                    }
                }
            }
            let entry = &mut accumulator[slot as usize];
            for (sum, s) in entry.0.iter_mut().zip(step) {
                *sum += s;
            }
            entry.1 += 1;
        }
        let mut max_move: f64 = 0.0;
        for (&v, (step_sum, count)) in self.vertices.iter().zip(accumulator.iter()) {
            let old = point(&previous[v as usize]);
            let inv = 1.0 / *count as f64;
            let step = step_sum.map(|s| s * inv);
            max_move = max_move.max(dot(step, step).sqrt());
            next[v as usize] = P::from_xyz([
                (old[0] + step[0]) as f32,
                (old[1] + step[1]) as f32,
                (old[2] + step[2]) as f32,
            ]);
        }
        max_move
    }
}

#[inline]
fn point(p: &impl CurvePoint) -> [f64; 3] {
    p.xyz().map(|c| c as f64)
}

#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn polygon(n: usize, radius: f64) -> Vec<[f32; 3]> {
        (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                [(radius * a.cos()) as f32, (radius * a.sin()) as f32, 0.0]
            })
            .collect()
    }

    #[test]
    fn straight_evenly_spaced_line_is_a_fixed_point() {
        // A loop whose middle part is a straight evenly spaced line: those vertices must not move.
        let positions: Vec<[f32; 3]> = (0..8)
            .map(|i| [i as f32, 0.0, 0.0])
            .chain([[7.0, 5.0, 0.0], [0.0, 5.0, 0.0]])
            .collect();
        let loop_vertices: Vec<u32> = (0..10).collect();
        let curves = BoundaryCurves::new(&[loop_vertices], positions.len());
        let mut next = positions.clone();
        curves.constrained_step(&positions, &positions, &mut next, false, &mut Vec::new());
        for i in 2..6 {
            assert_eq!(next[i], positions[i], "vertex {i}");
        }
    }

    #[test]
    fn regular_polygon_keeps_its_perimeter_nearly() {
        // A regular polygon is not a fixed point (the curve Laplacian is not zero on a circle),
        // but the constraints keep it from shrinking like the plain curve Laplacian would.
        let positions = polygon(64, 1.0);
        let curves = BoundaryCurves::new(&[(0..64).collect()], 64);
        let mut current = positions.clone();
        let mut next = positions.clone();
        for _ in 0..50 {
            curves.constrained_step(&current, &positions, &mut next, false, &mut Vec::new());
            std::mem::swap(&mut current, &mut next);
        }
        for p in &current {
            let r = ((p[0] as f64).powi(2) + (p[1] as f64).powi(2)).sqrt();
            assert!((r - 1.0).abs() < 1e-3, "radius {r}");
        }
    }
}
