//! The iteration kernel (a hot kernel: its functions stay long so the loops read whole): one
//! Jacobi iteration of section 3.2 as two parallel gather passes over the vertices, umbrella
//! means then averaged local solutions ([`Stencil::averaged_solutions`], with the normal
//! projection of the default variant), then the boundary curves of section 3.3; and the
//! workspace it runs in (loading positions, storing them back, re-imposing the constraints).

use super::ConstrainedFairing;
use crate::fairing::boundary::CurvePoint;
use crate::fairing::relaxation;
use crate::fairing::FairVariant;
use glam::{Vec3A, Vec3Swizzles};
use rayon::prelude::*;

/// Vertices per parallel work item: 256 and 512 are the fastest on meshes of 75k and 1.2M faces
/// (`docs/measurements.md`).
pub(super) const CHUNK: usize = 512;
/// How much of a move's tangential relaxation counts when a round reads whether it has settled
/// (the largest move, [`ConstrainedFairing::step`]): the normal move is the round's problem, and
/// it settles in a few iterations; the relaxation is a slow drift along the surface (a tenth of
/// the umbrella vector's tangential part per iteration) that the next rounds carry on, and at the
/// thin triangles, which get all of it, it kept every round of a finely sampled mesh at its 10
/// iterations for a few hundred vertices (`docs/measurements.md`, "A round ends once it has
/// settled").
pub(super) const RELAXATION_SETTLING: f32 = 0.1;

/// Evaluates `$body` with `$stencil` bound to `$fairing`'s one-ring stencil, whichever width its
/// weight index has (one monomorphised kernel per width).
macro_rules! with_stencil {
    ($fairing:expr, |$stencil:ident| $body:expr) => {
        match &$fairing.entry_weight_index {
            EntryWeightIndex::Narrow(index) => with_stencil!(@with $fairing, index, $stencil, $body),
            EntryWeightIndex::Wide(index) => with_stencil!(@with $fairing, index, $stencil, $body),
        }
    };
    (@with $fairing:expr, $index:ident, $stencil:ident, $body:expr) => {{
        let $stencil = Stencil {
            offsets: &$fairing.ring_offsets,
            ring: &$fairing.ring,
            index: $index,
            rows: &$fairing.entry_weights,
            self_weights: &$fairing.self_weights,
        };
        $body
    }};
}

/// Row indices into [`ConstrainedFairing::entry_weights`]: two bytes per entry unless the mesh
/// has more than 65536 distinct rows.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum EntryWeightIndex {
    Narrow(Vec<u16>),
    Wide(Vec<u32>),
}

impl EntryWeightIndex {
    fn bytes_per_entry(&self) -> usize {
        match self {
            EntryWeightIndex::Narrow(_) => 2,
            EntryWeightIndex::Wide(_) => 4,
        }
    }
}

/// The one-ring stencil the gather passes walk, with the entries' weight rows.
struct Stencil<'a, I> {
    offsets: &'a [u32],
    ring: &'a [u32],
    index: &'a [I],
    rows: &'a [[f32; 4]],
    self_weights: &'a [[f32; 3]],
}

#[derive(Clone, Debug, Default)]
pub(super) struct Workspace {
    current: Vec<Vec3A>,
    anchors: Vec<Vec3A>,
    anchor_terms: Vec<Vec3A>,
    position_and_mean: Vec<PositionAndMean>,
    curve_accumulator: Vec<([f64; 3], u32)>,
}

impl Workspace {
    fn for_vertices(vertex_count: usize) -> Workspace {
        Workspace {
            current: vec![Vec3A::ZERO; vertex_count],
            anchors: vec![Vec3A::ZERO; vertex_count],
            anchor_terms: vec![Vec3A::ZERO; vertex_count],
            position_and_mean: vec![PositionAndMean::default(); vertex_count],
            curve_accumulator: Vec::new(),
        }
    }
}
impl ConstrainedFairing {
    /// Gives the tangential relaxation ([`Self::set_tangential_relaxation`]) only where it is
    /// needed ([`crate::fairing::relaxation`]): `everywhere` (0 to 1) of its weight at every
    /// vertex, and all of it at the vertices with a thin triangle among theirs (every one, or only
    /// the folded ones: `slivers`) in the current state (the positions of the last [`Self::load`];
    /// `relaxation::fan_sliver_share` of its fan). Holds until called again; `everywhere` 1 (or no
    /// state loaded yet) gives every vertex the whole weight again.
    pub fn relax_where_needed(&mut self, everywhere: f32, slivers: relaxation::Slivers) {
        let everywhere = if everywhere.is_nan() {
            1.0
        } else {
            everywhere.clamp(0.0, 1.0)
        };
        let x = &self.workspace.current;
        if everywhere >= 1.0 || x.len() != self.vertex_count() {
            self.relaxation_share = Vec::new();
            return;
        }
        let (offsets, ring, closed_fan) = (&self.ring_offsets, &self.ring, &self.closed_fan);
        let mut share = std::mem::take(&mut self.relaxation_share);
        share.resize(x.len(), 0.0);
        share
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(chunk, out)| {
                let start = chunk * CHUNK;
                for (i, share) in out.iter_mut().enumerate() {
                    let v = start + i;
                    let ring_v = &ring[offsets[v] as usize..offsets[v + 1] as usize];
                    *share = match ring_v.last() {
                        // Only a closed fan is projected (and relaxed), and it is in fan order.
                        Some(&last) if closed_fan[v] => {
                            let p = x[v];
                            everywhere.max(relaxation::fan_sliver_share(
                                x[last as usize] - p,
                                ring_v.iter().map(|&u| x[u as usize] - p),
                                slivers,
                            ))
                        }
                        _ => everywhere,
                    };
                }
            });
        self.relaxation_share = share;
    }

    /// Bytes one [`Self::step`] must stream from or to memory with this data layout, if every
    /// array is read once and gathered neighbours hit the cache: the floor for its run time is
    /// this divided by the machine's copy bandwidth (read + write bytes per second).
    pub fn streamed_bytes_per_iteration(&self) -> usize {
        let vertices = self.vertex_count();
        let entries = self.ring.len();
        let offsets = 4 * (vertices + 1);
        let point = 16 * vertices;
        let index = self.entry_weight_index.bytes_per_entry();
        // Pass 1: offsets, ring, 1/n, x; writes positions and means (counted twice:
        // write-allocate).
        let pass1 = offsets + 4 * entries + 4 * vertices + point + 4 * point;
        // Pass 2: offsets, ring, weight row indices, own weights, anchor terms, positions and
        // means (and, projected, the fan flags); writes the new positions.
        let flags = match self.variant {
            FairVariant::Paper => 0,
            FairVariant::Improved => vertices,
        };
        let pass2 = offsets + (4 + index) * entries + 12 * vertices + flags + 3 * point + 2 * point;
        pass1 + pass2
    }

    /// The run's buffers, allocated if [`Self::release_buffers`] freed them or none was loaded
    /// yet (then the state is all zeros until a load).
    fn buffers(&mut self) -> &mut Workspace {
        if self.workspace.current.len() != self.vertex_count() {
            self.workspace = Workspace::for_vertices(self.vertex_count());
        }
        &mut self.workspace
    }

    /// Takes `positions` (the mesh's numbering) as the current state and imposes the constraints
    /// on them (they become the anchors P⁰ of the next iterations).
    pub fn load(&mut self, positions: &[[f32; 3]]) {
        assert_eq!(
            positions.len(),
            self.vertex_count(),
            "positions do not fit this connectivity"
        );
        self.buffers();
        let order = &self.order;
        self.workspace
            .current
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(chunk, out)| {
                let start = chunk * CHUNK;
                for (state, &v) in out.iter_mut().zip(&order[start..]) {
                    *state = Vec3A::from_array(positions[v as usize]);
                }
            });
        self.reanchor();
    }

    /// Copies the current state into `positions` (the mesh's numbering); leaves them as they are
    /// when no state is held (before the first load, or after [`Self::release_buffers`]).
    pub fn store(&self, positions: &mut [[f32; 3]]) {
        let (current, internal) = (&self.workspace.current, &self.internal);
        if current.len() != internal.len() {
            return;
        }
        positions
            .par_chunks_mut(CHUNK)
            .zip(internal.par_chunks(CHUNK))
            .for_each(|(out, internal)| {
                for (p, &i) in out.iter_mut().zip(internal) {
                    *p = current[i as usize].to_array();
                }
            });
    }

    /// Moves every vertex that is not held (off the boundary, the creases and the mask's pins)
    /// `step` times as far from the anchors as the iterations since the last [`Self::load`] or
    /// [`Self::reanchor`] took it: a round's move extrapolated
    /// ([`crate::fairing::strength::DOUBLED_FROM_ROUND`]). Held vertices keep their iterations'
    /// positions (a boundary or crease curve's own move).
    pub fn extrapolate(&mut self, step: f32) {
        let (order, held) = (&self.order, &self.held);
        let ws = &mut self.workspace;
        if ws.current.len() != order.len() {
            return;
        }
        let anchors = &ws.anchors;
        ws.current
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(chunk, out)| {
                let start = chunk * CHUNK;
                for (i, state) in out.iter_mut().enumerate() {
                    let v = start + i;
                    if !held[order[v] as usize] {
                        let anchor = anchors[v];
                        *state = anchor + (*state - anchor) * step;
                    }
                }
            });
    }

    /// Re-imposes the constraints on the current state (the start of a new round).
    pub fn reanchor(&mut self) {
        self.buffers();
        let ws = &mut self.workspace;
        ws.anchors.copy_from_slice(&ws.current);
        with_stencil!(self, |stencil| stencil
            .anchor_terms(&ws.anchors, &mut ws.anchor_terms));
    }

    /// One Jacobi iteration of the current state (anchors from the last [`Self::load`] or
    /// [`Self::reanchor`]). Returns the largest vertex move, the tangential relaxation's part of
    /// a move counted at a tenth of its length (what a round's settling reads).
    pub fn step(&mut self) -> f64 {
        let project = self.variant == FairVariant::Improved;
        self.buffers();
        let ws = &mut self.workspace;
        let offsets = &self.ring_offsets;
        let ring = &self.ring;

        // Pass 1: umbrella means of the previous iterate, stored next to the positions so that
        // pass 2 gathers both with one access per neighbour.
        {
            let x: &[Vec3A] = &ws.current;
            let inverse_valence = &self.inverse_valence;
            ws.position_and_mean
                .par_chunks_mut(CHUNK)
                .enumerate()
                .for_each(|(chunk, pairs)| {
                    let start = chunk * CHUNK;
                    for (i, pair) in pairs.iter_mut().enumerate() {
                        let v = start + i;
                        let ring_v = &ring[offsets[v] as usize..offsets[v + 1] as usize];
                        *pair = PositionAndMean {
                            position: x[v],
                            mean: umbrella_mean(x, ring_v, inverse_valence[v]),
                        };
                    }
                });
        }

        // Pass 2: the averaged local solutions (the paper's update), projected on the normal
        // where the variant asks for it.
        let closed_fan = &self.closed_fan;
        let max_move_squared = if project {
            with_stencil!(self, |stencil| stencil.averaged_solutions::<true>(
                &ws.position_and_mean,
                &ws.anchor_terms,
                closed_fan,
                self.tangential,
                &self.relaxation_share,
                &mut ws.current
            ))
        } else {
            with_stencil!(self, |stencil| stencil.averaged_solutions::<false>(
                &ws.position_and_mean,
                &ws.anchor_terms,
                closed_fan,
                0.0,
                &[],
                &mut ws.current
            ))
        };
        let mut max_move = (max_move_squared as f64).sqrt();

        // The boundary curves, from the same previous iterate.
        if !self.curves.is_empty() {
            let curve_move = self.curves.constrained_step(
                &ws.position_and_mean,
                &ws.anchors,
                &mut ws.current,
                project,
                &mut ws.curve_accumulator,
            );
            max_move = max_move.max(curve_move);
        }
        max_move
    }
}

impl<I: Copy + Into<u32> + Sync> Stencil<'_, I> {
    /// The anchors' contribution to every vertex's update, constant within a round.
    fn anchor_terms(&self, anchors: &[Vec3A], terms: &mut [Vec3A]) {
        terms
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(chunk, out)| {
                let start = chunk * CHUNK;
                for (i, term) in out.iter_mut().enumerate() {
                    let v = start + i;
                    let mut sum = anchors[v] * self.self_weights[v][2];
                    let entries = self.offsets[v] as usize..self.offsets[v + 1] as usize;
                    for (&u, &row) in self.ring[entries.clone()].iter().zip(&self.index[entries]) {
                        sum += anchors[u as usize] * self.rows[row.into() as usize][2];
                    }
                    *term = sum;
                }
            });
    }

    /// Pass 2 of an iteration: x̃_v = anchor term + own terms + Σ (α·m_u + β·x_u) over the
    /// one-ring, into `next` (the iterate itself: pass 2 reads the previous positions from `pairs`,
    /// so no second position buffer is needed). With `PROJECT`, vertices with a closed fan keep
    /// only the part of the move x̃_v − x_v along the normal of their fan of umbrella means (centre
    /// m_v, ring m_u, gathered anyway for the update), plus `tangential` (times the vertex's
    /// `share` unless that is empty) of the tangential part of its umbrella vector. Returns the
    /// largest squared move, the relaxation's part counted at [`RELAXATION_SETTLING`].
    fn averaged_solutions<const PROJECT: bool>(
        &self,
        pairs: &[PositionAndMean],
        anchor_terms: &[Vec3A],
        closed_fan: &[bool],
        tangential: f32,
        share: &[f32],
        next: &mut [Vec3A],
    ) -> f32 {
        next.par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(chunk, out)| {
                let start = chunk * CHUNK;
                let mut max_squared = 0.0f32;
                for (i, new_position) in out.iter_mut().enumerate() {
                    let v = start + i;
                    let [wm, wx, _] = self.self_weights[v];
                    let PositionAndMean {
                        position: p,
                        mean: m,
                    } = pairs[v];
                    let mut sum = anchor_terms[v] + m * wm + p * wx;
                    let entries = self.offsets[v] as usize..self.offsets[v + 1] as usize;
                    let ring = &self.ring[entries.clone()];
                    // Fan normal Σ a_k × a_(k+1) of the relative points a = (x_u + m_u) −
                    // (x_v + m_v), twice the midpoints between the positions and their umbrella
                    // means. With w = Σ a_k ∘ a_(k+1).yzx − a_k.yzx ∘ a_(k+1) (lane products),
                    // the sum of cross products is w.yzx: one shuffle per entry instead of four.
                    let centre = p + m;
                    let mut w = Vec3A::ZERO;
                    let (mut previous, mut previous_yzx) = match ring.last() {
                        Some(&u) if PROJECT => {
                            let last = pairs[u as usize];
                            let a = last.position + last.mean - centre;
                            (a, a.yzx())
                        }
                        _ => (Vec3A::ZERO, Vec3A::ZERO),
                    };
                    for (&u, &row) in ring.iter().zip(&self.index[entries]) {
                        let [wm, wx, _, _] = self.rows[row.into() as usize];
                        let PositionAndMean {
                            position: xu,
                            mean: mu,
                        } = pairs[u as usize];
                        sum += mu * wm + xu * wx;
                        if PROJECT {
                            let current = xu + mu - centre;
                            let current_yzx = current.yzx();
                            w += previous * current_yzx - previous_yzx * current;
                            previous = current;
                            previous_yzx = current_yzx;
                        }
                    }
                    let normal = w.yzx();
                    let mut step = sum - p;
                    // What the move counts for the round's settling: all of it, but for the
                    // tangential relaxation, which counts a tenth.
                    let mut settling = None;
                    if PROJECT && closed_fan[v] {
                        let length_squared = normal.length_squared();
                        step = if length_squared > 0.0 && length_squared.is_finite() {
                            let along = normal * (normal.dot(step) / length_squared);
                            let tangential = share.get(v).map_or(tangential, |s| tangential * s);
                            if tangential > 0.0 {
                                let umbrella = m - p;
                                let across = normal * (normal.dot(umbrella) / length_squared);
                                let relaxing = (umbrella - across) * tangential;
                                settling = Some(along.length_squared().max(
                                    relaxing.length_squared()
                                        * (RELAXATION_SETTLING * RELAXATION_SETTLING),
                                ));
                                along + relaxing
                            } else {
                                along
                            }
                        } else {
                            Vec3A::ZERO
                        };
                    }
                    let squared = settling.unwrap_or_else(|| step.length_squared());
                    if squared > max_squared {
                        max_squared = squared;
                    }
                    *new_position = p + step;
                }
                max_squared
            })
            .reduce(|| 0.0f32, f32::max)
    }
}

/// The boundary curves read the previous iterate from the pairs pass 1 wrote.
impl CurvePoint for PositionAndMean {
    #[inline]
    fn xyz(&self) -> [f32; 3] {
        self.position.to_array()
    }
    #[inline]
    fn from_xyz(p: [f32; 3]) -> Self {
        PositionAndMean {
            position: Vec3A::from_array(p),
            mean: Vec3A::ZERO,
        }
    }
}

impl CurvePoint for Vec3A {
    #[inline]
    fn xyz(&self) -> [f32; 3] {
        self.to_array()
    }
    #[inline]
    fn from_xyz(p: [f32; 3]) -> Self {
        Vec3A::from_array(p)
    }
}

/// A vertex's position and umbrella mean side by side (32 bytes, one half cache line). Points
/// are `Vec3A`: three lanes padded to 16 bytes, so the kernels load and combine whole points
/// with single SSE instructions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
struct PositionAndMean {
    position: Vec3A,
    mean: Vec3A,
}

#[inline]
fn umbrella_mean(x: &[Vec3A], ring: &[u32], inverse_valence: f32) -> Vec3A {
    // Two sums (even and odd entries) halve the chain of dependent additions.
    let (mut even, mut odd) = (Vec3A::ZERO, Vec3A::ZERO);
    let mut pairs = ring.chunks_exact(2);
    for pair in &mut pairs {
        even += x[pair[0] as usize];
        odd += x[pair[1] as usize];
    }
    if let [u] = pairs.remainder() {
        even += x[*u as usize];
    }
    (even + odd) * inverse_valence
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fairing::constrained::{LocalOperator, Matrix3};
    use crate::fairing::{BoundaryMode, FairOptions};
    use crate::mesh::fixtures::irregular_sphere;
    use crate::mesh::{Topology, TriMesh};

    /// The paper's pseudocode, literally (scatter over triangles, f64), for comparison.
    fn reference_iteration(
        mesh: &TriMesh,
        topology: &Topology,
        anchors: &[[f32; 3]],
    ) -> Vec<[f64; 3]> {
        let point = |p: [f32; 3]| p.map(|x| x as f64);
        let mut sums = vec![[0.0f64; 3]; mesh.positions.len()];
        let mut counts = vec![0usize; mesh.positions.len()];
        for t in &mesh.triangles {
            if t.iter().any(|&c| topology.is_boundary_vertex(c)) {
                continue;
            }
            let n = t.map(|c| topology.valence(c));
            let op = LocalOperator::umbrella(n).unwrap();
            let q: Matrix3 = std::array::from_fn(|r| {
                let mut q = [0.0; 3];
                for &u in topology.neighbors(t[r]) {
                    if !t.contains(&u) {
                        let p = point(mesh.positions[u as usize]);
                        for (qk, pk) in q.iter_mut().zip(p) {
                            *qk += pk / n[r] as f64;
                        }
                    }
                }
                q
            });
            let c: [f64; 3] =
                std::array::from_fn(|k| t.iter().map(|&v| anchors[v as usize][k] as f64).sum());
            let p = op.solve(&q, c);
            for r in 0..3 {
                for k in 0..3 {
                    sums[t[r] as usize][k] += p[r][k];
                }
                counts[t[r] as usize] += 1;
            }
        }
        sums.iter()
            .zip(&counts)
            .enumerate()
            .map(|(v, (s, &n))| {
                if n == 0 {
                    point(mesh.positions[v])
                } else {
                    s.map(|x| x / n as f64)
                }
            })
            .collect()
    }

    #[test]
    fn fast_iteration_equals_the_papers_pseudocode() {
        let mut mesh = irregular_sphere();
        let topology = Topology::build(&mesh);
        assert!(topology.is_closed());
        let anchors = mesh.positions.clone();
        let mut fairing =
            ConstrainedFairing::new(&mesh, &topology, FairVariant::Paper, BoundaryMode::Curve);
        fairing.load(&anchors);
        for iteration in 0..5 {
            let expected = reference_iteration(&mesh, &topology, &anchors);
            fairing.step();
            fairing.store(&mut mesh.positions);
            for (v, (got, want)) in mesh.positions.iter().zip(&expected).enumerate() {
                for k in 0..3 {
                    assert!(
                        (got[k] as f64 - want[k]).abs() < 1e-5,
                        "iteration {iteration}, vertex {v}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn an_extrapolated_round_moves_the_free_vertices_its_step_times_as_far_and_the_held_ones_not() {
        // A noisy cube with its creases held: free vertices on the faces, held ones on the edges.
        let clean = crate::mesh::shapes::cuboid([1.0, 1.0, 1.0], 0.1);
        let topology = Topology::build(&clean);
        let creases = crate::fairing::creases::detect_creases(
            &clean,
            &topology,
            &crate::fairing::creases::CreaseOptions::default(),
        );
        let mut noisy = clean.clone();
        crate::noise::add_noise(&mut noisy, &Default::default());
        let start = noisy.positions.clone();
        let options = FairOptions {
            rounds: 1,
            ..Default::default()
        };
        let mut fairing = ConstrainedFairing::with_creases(
            &noisy,
            &topology,
            FairVariant::Improved,
            BoundaryMode::Curve,
            &creases,
        );
        let mut report = Default::default();
        let mut plain = start.clone();
        fairing.load(&plain);
        fairing.run_round(&options, &mut report);
        fairing.store(&mut plain);
        let mut doubled = start.clone();
        fairing.load(&doubled);
        fairing.run_round(&options, &mut report);
        fairing.extrapolate(2.0);
        fairing.store(&mut doubled);
        let (mut free, mut held) = (0, 0);
        for v in 0..start.len() {
            if creases.is_feature(v as u32) {
                held += 1;
                assert_eq!(doubled[v], plain[v], "held vertex {v}");
            } else {
                free += 1;
                for k in 0..3 {
                    let twice = start[v][k] + 2.0 * (plain[v][k] - start[v][k]);
                    assert!((doubled[v][k] - twice).abs() < 1e-6, "free vertex {v}");
                }
            }
        }
        assert!(free > 0 && held > 0, "{free} free, {held} held");
        assert_ne!(doubled, plain);
    }

    #[test]
    fn the_tangential_relaxation_counts_a_tenth_toward_settling() {
        // A flat grid with its inner vertices jittered within the plane: the normal move is
        // nil, the relaxation evens the triangles out along the plane.
        let mut mesh = crate::mesh::fixtures::grid(8);
        for (v, p) in mesh.positions.iter_mut().enumerate() {
            let jitter = ((v * 37) % 11) as f32 * 0.004 - 0.02;
            p[0] += jitter;
            p[1] -= 0.5 * jitter;
        }
        assert!(mesh.positions.iter().all(|p| p[2] == 0.0), "a flat grid");
        let topology = Topology::build(&mesh);
        let mut fairing =
            ConstrainedFairing::new(&mesh, &topology, FairVariant::Improved, BoundaryMode::Fixed);
        fairing.set_tangential_relaxation(1.0);
        fairing.load(&mesh.positions);
        let reported = fairing.step();
        let mut after = mesh.positions.clone();
        fairing.store(&mut after);
        let moved = after
            .iter()
            .zip(&mesh.positions)
            .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>().sqrt())
            .fold(0.0f32, f32::max) as f64;
        assert!(moved > 1e-3, "the relaxation moved the vertices ({moved})");
        let expected = moved * RELAXATION_SETTLING as f64;
        assert!(
            (reported - expected).abs() <= 1e-3 * expected,
            "reported {reported}, moved {moved}"
        );
    }

    #[test]
    fn a_run_after_the_buffers_were_released_is_the_run_with_them_kept() {
        let mesh = irregular_sphere();
        let topology = Topology::build(&mesh);
        let noisy: Vec<[f32; 3]> = mesh
            .positions
            .iter()
            .enumerate()
            .map(|(v, p)| {
                let bump = ((v * 37) % 11) as f32 * 0.01 - 0.05;
                [p[0] + bump, p[1] - 0.5 * bump, p[2] + 0.3 * bump]
            })
            .collect();
        for variant in [FairVariant::Paper, FairVariant::Improved] {
            let options = FairOptions {
                iterations: 4,
                rounds: 2,
                variant,
                ..Default::default()
            };
            let mut kept = ConstrainedFairing::new(&mesh, &topology, variant, BoundaryMode::Curve);
            let mut released = kept.clone();
            let (mut a, mut b) = (noisy.clone(), noisy.clone());
            kept.run(&mut a, &options);
            released.run(&mut b, &options);
            released.release_buffers();
            assert!(released.workspace.current.is_empty());
            // No state is held: storing leaves the positions as they are.
            let mut untouched = noisy.clone();
            released.store(&mut untouched);
            assert_eq!(untouched, noisy);
            // The second run starts from other positions than the first one ended with.
            let (mut a2, mut b2) = (noisy.clone(), noisy.clone());
            a2.reverse();
            b2.reverse();
            kept.run(&mut a2, &options);
            released.run(&mut b2, &options);
            assert_eq!(a2, b2);
            assert_ne!(a2, a);
        }
    }
}
