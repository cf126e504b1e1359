//! Constrained fairing (paper section 3.2): the local least-squares problem (6) of every interior
//! triangle, solved in closed form (eq 7), averaged per vertex, iterated Jacobi-style.
//!
//! Interpretations (the repository's `docs/paper.md` gives the whole reading this follows):
//! - Weights ω_ij = 1/n_i with n_i the number of distinct one-ring neighbours. For triangle
//!   ⟨i, j, k⟩ the local energy is ‖AP − Q‖² with A = I − (ω between the three corners) and
//!   q_i = Σ ω_ij x_j over the n_i − 2 neighbours of i that are not corners of the triangle.
//! - Eq (7) read as a matrix product, P = A⁻¹Q + A⁻¹A⁻ᵀBᵀ(C − BA⁻¹Q)/‖BA⁻¹‖², B = [1 1 1],
//!   C = BP⁰. It is precomputed as P = G·Q + h·C with G = A⁻¹ − A⁻¹A⁻ᵀBᵀBA⁻¹/‖BA⁻¹‖² and
//!   h = A⁻¹A⁻ᵀBᵀ/‖BA⁻¹‖² ([`LocalOperator`]). A depends on the valence triple only, so G and h
//!   are computed once per distinct triple.
//! - "Interior triangle" = none of its corners is a boundary vertex (and every corner has valence
//!   three or more, so that A is invertible). Only interior triangles are solved.
//! - Not in the paper: a triangle with exactly one corner on a crease (the default variant's
//!   sharp edges, [`super::creases`]) is solved too, with that corner held where it is: its two
//!   other corners minimise the same energy ‖AP − Q‖² with their own midpoint kept
//!   (P_a + P_b = P⁰_a + P⁰_b), while the crease corner moves along its curve. Writing P_a = s and
//!   P_b = K − s with K = P⁰_a + P⁰_b, the residual is d·s + e with d = A_a − A_b (columns of A)
//!   and e = A_b·K + A_h·x_h − Q, so s = −dᵀe / dᵀd ([`held_corner_weights`]). Left unsolved, as
//!   the paper leaves the boundary's triangles, they left every vertex beside a crease with
//!   fewer solutions to average, and on coarse scans (where crease vertices are many) a third of
//!   the vertices with one or two and some with none, so the noise stayed there
//!   (`docs/measurements.md`, "Triangles beside a crease solved"). Keeping the triangle's own
//!   centroid instead (the free pair making up for the crease corner's move along its curve)
//!   pushed the pair against that move: the open mushroom's rim folded. The boundary's triangles
//!   stay unsolved, as the paper has them.
//! - Jacobi: every local solve of one iteration reads the previous iterate. The new position of a
//!   vertex is the mean of its triangles' solutions; a vertex with no solution (all its triangles
//!   touch the boundary, or it is unreferenced) keeps its position (the paper's pseudocode would
//!   send it to the origin). Boundary vertices are moved by the curve operator of section 3.3
//!   ([`super::boundary`]) in the same iteration, or kept ([`BoundaryMode::Fixed`]).
//! - Anchors P⁰ are the positions at the start of each round; a round re-imposes the constraints
//!   on the current positions ("imposing and relaxing the centre constraints by turns").
//!
//! # How it is computed
//! Write m_u for the umbrella mean (1/n_u)·Σ_{w∈S(u)} x_w. For triangle t with corners c and
//! vertex v at row r, q_c = m_c − (x_a + x_b)/n_c, so v's solution is
//! Σ_c G_rc·m_c + Σ_c (G_rc/n_c − Σ_c' G_rc'/n_c')·x_c + h_r·C_t: a linear combination of the
//! umbrella means and positions of v's closed one-ring, plus the anchors' contribution, which is
//! constant within a round. Averaging over v's triangles keeps that form, so the precomputation
//! folds everything into one weight row (α, β, anchor weight) per one-ring entry, and an iteration
//! is two gather passes over vertices, both parallel (rayon) with no scatter and no atomics:
//! 1. umbrella means m, reading the previous iterate;
//! 2. x̃ = anchor term + Σ (α·m_u + β·x_u) over the closed one-ring; the normal-projected variant
//!    then keeps x + n·(n·(x̃ − x)) (see below); then the boundary curves.
//!
//! # The normal of the normal-projected variant
//! The projection keeps the volume best when n is the volume gradient along the move, i.e. the
//! fan normal at the midpoint of the path. Pass 2 has, for every one-ring neighbour, its position
//! and umbrella mean (gathered for the update anyway), but not its new position, so it takes the
//! fan of the midpoints between the positions and their umbrella means, (x_u + m_u)/2: the
//! neighbours' own moves approximated by a Laplacian step. Of the candidates measured (the fans of
//! the updated positions, of the positions and of the means; `docs/measurements.md`) it keeps the
//! volume about as well as the best and needs no third gather pass.
//!
//! # Speed
//! - Locality: vertices are renumbered breadth-first over the one-rings (neighbours close in
//!   memory), then sorted by valence within blocks of `VALENCE_SORTED_BLOCK` (the gather loops'
//!   exits become predictable); [`ConstrainedFairing::load`] and [`ConstrainedFairing::store`]
//!   map between the mesh's numbering and this one.
//! - Bytes: weight rows are deduplicated (a mesh has a few hundred distinct rows) and each entry
//!   holds a 2-byte row index; points are `Vec3A` (16 bytes, one SSE register); a vertex's position
//!   and umbrella mean sit side by side so pass 2 reads both with one gather.
//! - Fan normals: Σ a_k × a_(k+1) = (Σ a_k ∘ a_(k+1).yzx − a_k.yzx ∘ a_(k+1)).yzx, one shuffle
//!   per entry instead of four.
//!
//! Every vertex is computed by the same sequence of operations whatever the thread count, so the
//! output is bit-identical for any rayon pool. Positions, means and weights are f32 (weights are
//! computed in f64 and rounded): the operator is a contraction towards its fixed point, so rounding
//! does not accumulate; the tests check volume to 1e-4 relative and equivariance to f32 accuracy.

use super::boundary::BoundaryCurves;
use super::creases::{
    detect_creases_cached, detect_creases_with_estimate, CreaseOptions, Creases, FaceRingCache,
    FeatureClass,
};
use super::relaxation::{self, read_tangential_noise};
use super::strength::{
    normal_filtering_for, read_noise, RoundRisk, CLEAN_NOISE, MAX_AUTO_ROUNDS, RISK_MIN_FALL,
    RISK_PATIENCE,
};
use super::volume::VolumeKeeper;
use super::{BoundaryMode, FairOptions, FairReport, FairVariant, Relaxation, Strength};
use crate::mesh::{breadth_first_order, inverse_permutation, PositionHasher, Topology, TriMesh};
use glam::{Vec3A, Vec3Swizzles};
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::BuildHasherDefault;

/// A 3×3 matrix, rows first.
pub type Matrix3 = [[f64; 3]; 3];

/// Eq (7) in precomputed form for one local matrix A: P = G·Q + h·C, where P and Q hold one row
/// per triangle corner and C = BP⁰ is the sum of the corners' anchors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalOperator {
    pub g: Matrix3,
    pub h: [f64; 3],
}

impl LocalOperator {
    /// The operator for an invertible local matrix `a` and B = [1 1 1]; `None` when `a` is
    /// singular or BA⁻¹ vanishes.
    pub fn from_matrix(a: &Matrix3) -> Option<Self> {
        let inverse = invert3(a)?;
        // w = (BA⁻¹)ᵀ: the column sums of A⁻¹.
        let w: [f64; 3] = std::array::from_fn(|c| inverse[0][c] + inverse[1][c] + inverse[2][c]);
        let norm_squared = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        if !(norm_squared > 0.0 && norm_squared.is_finite()) {
            return None;
        }
        // A⁻¹A⁻ᵀBᵀ = A⁻¹w.
        let h: [f64; 3] = std::array::from_fn(|r| {
            (inverse[r][0] * w[0] + inverse[r][1] * w[1] + inverse[r][2] * w[2]) / norm_squared
        });
        let g = std::array::from_fn(|r| std::array::from_fn(|c| inverse[r][c] - h[r] * w[c]));
        Some(LocalOperator { g, h })
    }

    /// The operator for the paper's uniform weights and the corners' valences.
    pub fn umbrella(valences: [usize; 3]) -> Option<Self> {
        if valences.iter().any(|&n| n < 3) {
            return None;
        }
        Self::from_matrix(&umbrella_local_matrix(valences))
    }

    /// P = G·Q + h·C; `q` and the result have one row per corner, one column per coordinate.
    pub fn solve(&self, q: &Matrix3, c: [f64; 3]) -> Matrix3 {
        std::array::from_fn(|r| {
            std::array::from_fn(|k| {
                self.g[r][0] * q[0][k]
                    + self.g[r][1] * q[1][k]
                    + self.g[r][2] * q[2][k]
                    + self.h[r] * c[k]
            })
        })
    }
}

/// A of section 3.2 for uniform weights: 1 on the diagonal, −1/n_r off it in row r.
pub fn umbrella_local_matrix(valences: [usize; 3]) -> Matrix3 {
    std::array::from_fn(|r| {
        std::array::from_fn(|c| {
            if r == c {
                1.0
            } else {
                -1.0 / valences[r] as f64
            }
        })
    })
}

/// Inverse by the adjugate; `None` when (nearly) singular.
pub fn invert3(a: &Matrix3) -> Option<Matrix3> {
    let cofactor = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]
    };
    let det = a[0][0] * cofactor(0, 0) + a[0][1] * cofactor(0, 1) + a[0][2] * cofactor(0, 2);
    let scale = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    // Negated on purpose: a NaN determinant (or scale) must count as singular too.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(det.abs() > 1e-12 * scale * scale * scale) {
        return None;
    }
    Some(std::array::from_fn(|r| {
        std::array::from_fn(|c| cofactor(c, r) / det)
    }))
}

/// Valences below this index a dense table of local operators; larger ones are computed on the fly.
const TABLE_VALENCE: usize = 32;
/// Vertices per parallel work item: 256 and 512 were the fastest on meshes of 75k and 1.2M faces
/// (`docs/measurements.md`).
const CHUNK: usize = 512;
/// The locality order is sorted by valence within blocks of this many vertices, so that the
/// gather loops run the same trip count many times in a row and their exits are predicted (about
/// 40% less CPU time per iteration on a mesh of mixed valences; blocks of 64 to 512 measured
/// alike, see `docs/measurements.md`). Neighbours stay within a block of each other.
const VALENCE_SORTED_BLOCK: usize = 256;

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

/// Precomputed constrained fairing for one mesh connectivity, with its workspace buffers (from
/// the first run on, until [`Self::release_buffers`]): build it once, then run it on as many
/// position sets (of that connectivity) as wanted.
///
/// Internally the vertices are renumbered in a breadth-first locality order
/// ([`crate::mesh::breadth_first_order`]) so that every gather reads neighbours that sit close in
/// memory; [`Self::load`] and [`Self::store`] map to and from the mesh's own numbering.
#[derive(Clone, Debug)]
pub struct ConstrainedFairing {
    /// The vertices (mesh numbering) that bound the surface patches: boundary, crease and pinned
    /// vertices. They get no local solution and their triangles are not solved, but for those
    /// with one crease corner and no other held one ([`triangle_solve`]).
    held: Vec<bool>,
    variant: FairVariant,
    boundary: BoundaryMode,
    /// Internal vertex i is the mesh's vertex `order[i]`.
    order: Vec<u32>,
    /// The mesh's vertex v is internal vertex `internal[v]` (the inverse of `order`).
    internal: Vec<u32>,
    /// One-ring of each vertex (internal numbering): in fan order (faces (v, ring[k], ring[k+1]))
    /// when the vertex has a closed, consistently oriented fan, otherwise the topology's sorted
    /// neighbours.
    ring_offsets: Vec<u32>,
    ring: Vec<u32>,
    /// Per one-ring entry: which row of `entry_weights` holds its weights.
    entry_weight_index: EntryWeightIndex,
    /// The distinct weight rows of the one-ring entries: weights of the neighbour's umbrella mean,
    /// its position and its anchor (fourth lane unused). The weights depend only on the valences
    /// around an entry, so a mesh has few distinct rows (`bunny00`: 512 for 226k entries; a
    /// Loop-subdivided mesh: about 20), and a row index is a third of the bytes of the row.
    entry_weights: Vec<[f32; 4]>,
    /// Per vertex: weights of its own umbrella mean, position and anchor.
    self_weights: Vec<[f32; 3]>,
    /// 1/n_v (0 for unreferenced vertices).
    inverse_valence: Vec<f32>,
    /// Whether `ring` is a closed fan, so the vertex normal can be taken from it.
    closed_fan: Vec<bool>,
    curves: BoundaryCurves,
    /// Normal-projected only: the weight of the tangential relaxation added to each move (0: none;
    /// see [`Self::set_tangential_relaxation`]).
    tangential: f32,
    /// Per vertex (internal numbering), the share of `tangential` it gets; empty: all of it,
    /// everywhere ([`Self::relax_where_needed`]).
    relaxation_share: Vec<f32>,
    /// Number of vertices that get at least one local solution.
    solved_vertices: usize,
    workspace: Workspace,
}

/// Row indices into [`ConstrainedFairing::entry_weights`]: two bytes per entry unless the mesh
/// has more than 65536 distinct rows.
#[derive(Clone, Debug, PartialEq)]
enum EntryWeightIndex {
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

/// What an operator's set-up computes from the connectivity alone: the locality order (internal
/// vertex i is the mesh's vertex `order[i]`; `internal` is its inverse) and the one-rings in it
/// (`offsets`, `ring`, relabelled).
struct Layout {
    order: Vec<u32>,
    internal: Vec<u32>,
    offsets: Vec<u32>,
    ring: Vec<u32>,
}

impl Layout {
    /// From the one-rings in the mesh's numbering (`ring_offsets`, `ring`): a breadth-first
    /// order, its blocks sorted by valence.
    fn new(ring_offsets: &[u32], ring: &[u32]) -> Layout {
        let vertex_count = ring_offsets.len() - 1;
        let mut order = breadth_first_order(ring_offsets, ring);
        for block in order.chunks_mut(VALENCE_SORTED_BLOCK) {
            block.sort_by_key(|&v| ring_offsets[v as usize + 1] - ring_offsets[v as usize]);
        }
        let internal = inverse_permutation(&order);
        let mut offsets = Vec::with_capacity(vertex_count + 1);
        offsets.push(0u32);
        for &v in &order {
            let v = v as usize;
            let end = offsets[offsets.len() - 1] + ring_offsets[v + 1] - ring_offsets[v];
            offsets.push(end);
        }
        let internal_ring = entries_in_order(&order, &offsets, ring_offsets, ring, |u| {
            internal[u as usize]
        });
        Layout {
            order,
            internal,
            offsets,
            ring: internal_ring,
        }
    }
}

/// One value per one-ring entry (`values`, laid out by `ring_offsets` in the mesh's numbering)
/// moved with its vertex into the internal order (`order`, laid out by `offsets`), in parallel
/// over blocks of vertices, each passed through `map`.
fn entries_in_order(
    order: &[u32],
    offsets: &[u32],
    ring_offsets: &[u32],
    values: &[u32],
    map: impl Fn(u32) -> u32 + Sync,
) -> Vec<u32> {
    let mut out = vec![0u32; values.len()];
    split_into_vertex_blocks(&mut out, offsets)
        .into_par_iter()
        .for_each(|(first, block)| {
            let base = offsets[first] as usize;
            let last = (first + VERTEX_BLOCK).min(order.len());
            for (i, &v) in order[first..last].iter().enumerate() {
                let slots =
                    offsets[first + i] as usize - base..offsets[first + i + 1] as usize - base;
                let entries =
                    ring_offsets[v as usize] as usize..ring_offsets[v as usize + 1] as usize;
                for (out, &value) in block[slots].iter_mut().zip(&values[entries]) {
                    *out = map(value);
                }
            }
        });
    out
}

#[derive(Clone, Debug, Default)]
struct Workspace {
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
    /// Precomputes the operator for `mesh`'s connectivity (`topology` must be built from it).
    pub fn new(
        mesh: &TriMesh,
        topology: &Topology,
        variant: FairVariant,
        boundary: BoundaryMode,
    ) -> Self {
        let fans = FanRings::new(&mesh.triangles, topology);
        Self::with_fans(mesh, topology, &fans, variant, boundary, None, &[])
    }

    /// [`Self::new`] with sharp creases kept: the surface on either side of a crease is faired
    /// with the crease as its boundary, the crease chains are faired as curves (section 3.3's
    /// edge-centre constraints, open chains between fixed ends), corners stay in place
    /// ([`super::creases`]).
    pub fn with_creases(
        mesh: &TriMesh,
        topology: &Topology,
        variant: FairVariant,
        boundary: BoundaryMode,
        creases: &Creases,
    ) -> Self {
        let fans = FanRings::new(&mesh.triangles, topology);
        Self::with_fans(mesh, topology, &fans, variant, boundary, Some(creases), &[])
    }

    /// [`Self::new`] for a caller that already has the mesh's fan-ordered one-rings; `creases`
    /// kept as in [`Self::with_creases`]; the vertices flagged in `pinned` (empty: none) held
    /// where they are, like fixed boundary vertices ([`super::mask`]).
    pub(crate) fn with_fans(
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        variant: FairVariant,
        boundary: BoundaryMode,
        creases: Option<&Creases>,
        pinned: &[bool],
    ) -> Self {
        Self::set_up(
            mesh, topology, fans, variant, boundary, creases, pinned, None,
        )
    }

    /// This operator set up again for other `creases` on the same connectivity (`mesh`,
    /// `topology` and `fans` those it was built from; the same variant, boundary mode, pinned
    /// vertices and tangential relaxation): the same operator as [`Self::with_fans`] would give
    /// (every entry's weights, the own weights, the fans and curves bit for bit; only the
    /// numbering of the distinct weight rows may differ). Constrained fairing sets its operator
    /// up again whenever the creases found before a round changed.
    ///
    /// Only the vertices whose held status changed (a crease vertex that is one no more, or a
    /// new one) and their neighbours have other weights: a vertex's weights depend on which of
    /// its triangles are solved, and that on its triangles' corners. Those are gathered again
    /// and their rows looked up in (or added to) the distinct rows; the curves are made again.
    /// When more than an eighth of the vertices changed, the set-up runs whole instead (still
    /// keeping the locality order and the one-rings renumbered in it).
    pub(crate) fn for_other_creases(
        self,
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        creases: Option<&Creases>,
        pinned: &[bool],
    ) -> Self {
        self.for_other_creases_within(mesh, topology, fans, creases, pinned, 8)
    }

    /// [`Self::for_other_creases`], updating in place while at most 1/`fraction` of the vertices
    /// changed (0: never; the tests take both ways).
    fn for_other_creases_within(
        mut self,
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        creases: Option<&Creases>,
        pinned: &[bool],
        fraction: usize,
    ) -> Self {
        let creases = creases.filter(|c| !c.is_empty());
        let held = held_flags(topology, creases, pinned);
        let changed: Vec<u32> = (0..held.len() as u32)
            .filter(|&v| held[v as usize] != self.held[v as usize])
            .collect();
        if fraction == 0 || changed.len() * fraction > held.len() {
            let (variant, boundary, tangential) = (self.variant, self.boundary, self.tangential);
            let layout = Layout {
                order: self.order,
                internal: self.internal,
                offsets: self.ring_offsets,
                ring: self.ring,
            };
            let mut fairing = Self::set_up(
                mesh,
                topology,
                fans,
                variant,
                boundary,
                creases,
                pinned,
                Some(layout),
            );
            fairing.tangential = tangential;
            return fairing;
        }
        let mut affected: Vec<u32> = changed
            .iter()
            .flat_map(|&v| std::iter::once(v).chain(topology.neighbors(v).iter().copied()))
            .collect();
        affected.sort_unstable();
        affected.dedup();
        let (ring_offsets, _) = topology.neighbor_csr();
        let triangles = &mesh.triangles;
        // A vertex's rows and whether it is solved, with the triangles solved as `held` says.
        let gather = |v: usize, held: &[bool], rows: &mut Vec<[f32; 4]>, own: &mut [f32; 3]| {
            let ring_v = &fans.ring[ring_offsets[v] as usize..ring_offsets[v + 1] as usize];
            rows.resize(ring_v.len(), [0.0; 4]);
            let operator = |f: u32| {
                let t = &triangles[f as usize];
                let valences = t.map(|c| topology.valence(c));
                match triangle_solve(t, held, topology, pinned)? {
                    None => Some(corner_weights(valences)),
                    // v itself, when it is the held corner, gets no solution from the triangle.
                    Some(h) => (t[h] as usize != v).then(|| held_corner_weights(valences, h)),
                }
            };
            let mut solved = false;
            gather_rows(
                v,
                ring_v,
                topology,
                triangles,
                operator,
                rows,
                own,
                &mut solved,
            );
            solved
        };
        let mut row_of: RowMap = self
            .entry_weights
            .iter()
            .enumerate()
            .map(|(i, row)| (row_key(row), i as u32))
            .collect();
        let (mut rows, mut own) = (Vec::new(), [0.0f32; 3]);
        for &v in &affected {
            let v = v as usize;
            let was_solved = gather(v, &self.held, &mut rows, &mut own);
            let solved = gather(v, &held, &mut rows, &mut own);
            self.solved_vertices =
                self.solved_vertices + usize::from(solved) - usize::from(was_solved);
            let i = self.internal[v] as usize;
            self.self_weights[i] = own;
            self.closed_fan[i] = fans.closed_fan[v] && solved;
            let first = self.ring_offsets[i] as usize;
            for (k, row) in rows.iter().enumerate() {
                let index = *row_of.entry(row_key(row)).or_insert_with(|| {
                    self.entry_weights.push(*row);
                    (self.entry_weights.len() - 1) as u32
                });
                if let EntryWeightIndex::Narrow(narrow) = &self.entry_weight_index {
                    if index > u32::from(u16::MAX) {
                        let wide = narrow.iter().map(|&i| u32::from(i)).collect();
                        self.entry_weight_index = EntryWeightIndex::Wide(wide);
                    }
                }
                match &mut self.entry_weight_index {
                    EntryWeightIndex::Narrow(narrow) => narrow[first + k] = index as u16,
                    EntryWeightIndex::Wide(wide) => wide[first + k] = index,
                }
            }
        }
        self.curves = fairing_curves(topology, self.boundary, creases, &self.internal);
        self.held = held;
        self
    }

    #[allow(clippy::too_many_arguments)]
    fn set_up(
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        variant: FairVariant,
        boundary: BoundaryMode,
        creases: Option<&Creases>,
        pinned: &[bool],
        layout: Option<Layout>,
    ) -> Self {
        let vertex_count = mesh.positions.len();
        let triangles = &mesh.triangles;
        // Crease vertices and corners, and pinned vertices, bound the surface patches like
        // boundary vertices do: they get no local solution and their triangles are not solved,
        // but for those with a single crease corner, solved with it held ([`triangle_solve`]).
        let creases = creases.filter(|c| !c.is_empty());
        let held = held_flags(topology, creases, pinned);

        let ring_offsets = topology.neighbor_csr().0.to_vec();
        let (ring, closed) = (&fans.ring, &fans.closed_fan);

        let valence = |v: u32| topology.valence(v);

        // Local operators of the valence triples that occur, in a dense table, and each triangle's
        // slot in it (u32::MAX: not solved), found once per triangle rather than once per
        // corner. Triples with a valence beyond the table get an operator of their own, and so
        // do the (few) triangles solved with a crease corner held, per triple and held corner.
        let table_index = |n: [usize; 3]| (n[0] * TABLE_VALENCE + n[1]) * TABLE_VALENCE + n[2];
        let triangle_valences: Vec<Option<([usize; 3], Option<usize>)>> = triangles
            .par_iter()
            .map(|t| triangle_solve(t, &held, topology, pinned).map(|h| (t.map(valence), h)))
            .collect();
        let mut table_slot = vec![u32::MAX; TABLE_VALENCE * TABLE_VALENCE * TABLE_VALENCE];
        let mut held_corner_slot: HashMap<([usize; 3], usize), u32> = HashMap::new();
        // Per operator, the weights corner r's solution gives corner c's umbrella mean, position
        // and anchor: G_rc, G_rc/n_c − Σ_c' G_rc'/n_c' and h_r (see "How it is computed"); and
        // which corner it holds (3: none).
        let mut operators: Vec<[[[f64; 3]; 3]; 3]> = Vec::new();
        let mut operator_held: Vec<u8> = Vec::new();
        let mut operator_slot = |(n, held_at): ([usize; 3], Option<usize>)| -> u32 {
            if let Some(h) = held_at {
                return *held_corner_slot.entry((n, h)).or_insert_with(|| {
                    operators.push(held_corner_weights(n, h));
                    operator_held.push(h as u8);
                    (operators.len() - 1) as u32
                });
            }
            let in_table = n.iter().all(|&k| k < TABLE_VALENCE);
            if in_table && table_slot[table_index(n)] != u32::MAX {
                return table_slot[table_index(n)];
            }
            let slot = operators.len() as u32;
            operators.push(corner_weights(n));
            operator_held.push(3);
            if in_table {
                table_slot[table_index(n)] = slot;
            }
            slot
        };
        let triangle_operator: Vec<u32> = triangle_valences
            .iter()
            .map(|n| n.map_or(u32::MAX, &mut operator_slot))
            .collect();
        drop(triangle_valences);

        // Per vertex, gather the weights of its triangles' solutions (f64, then rounded), one row
        // (mean, position, anchor, 0) per one-ring entry.
        let mut self_weights = vec![[0.0f32; 3]; vertex_count];
        let mut solved = vec![false; vertex_count];
        let gather = |v: usize,
                      ring_weights_v: &mut [[f32; 4]],
                      own_out: &mut [f32; 3],
                      solved_out: &mut bool| {
            let ring_v = &ring[ring_offsets[v] as usize..ring_offsets[v + 1] as usize];
            let operator = |f: u32| {
                let slot = triangle_operator[f as usize];
                // v itself, when it is the held corner, gets no solution from the triangle.
                (slot != u32::MAX
                    && triangles[f as usize].get(operator_held[slot as usize] as usize)
                        != Some(&(v as u32)))
                .then(|| &operators[slot as usize])
            };
            gather_rows(
                v,
                ring_v,
                topology,
                triangles,
                operator,
                ring_weights_v,
                own_out,
                solved_out,
            );
        };
        // In blocks of vertices, each block's rows deduplicated as soon as they are gathered:
        // the 16-byte rows of the whole mesh are never held at once (on the 1.2M-face mesh they
        // were 58 MB at the set-up's peak); only a 4-byte index per entry and the few distinct
        // rows. The rows are a function of the valences around the vertex, so they repeat.
        let blocks: Vec<(Vec<u32>, Vec<[f32; 4]>)> = self_weights
            .par_chunks_mut(VERTEX_BLOCK)
            .zip(solved.par_chunks_mut(VERTEX_BLOCK))
            .enumerate()
            .map(|(b, (own_block, solved_block))| {
                let first = b * VERTEX_BLOCK;
                let base = ring_offsets[first] as usize;
                let end = ring_offsets[first + own_block.len()] as usize;
                let mut rows = vec![[0.0f32; 4]; end - base];
                for (i, (own_out, solved_out)) in own_block
                    .iter_mut()
                    .zip(solved_block.iter_mut())
                    .enumerate()
                {
                    let v = first + i;
                    let entries =
                        ring_offsets[v] as usize - base..ring_offsets[v + 1] as usize - base;
                    gather(v, &mut rows[entries], own_out, solved_out);
                }
                deduplicate_chunk(&rows)
            })
            .collect();
        let (mesh_rows, mesh_index) = join_deduplicated(blocks);
        let solved_vertices = solved.iter().filter(|&&s| s).count();

        // Renumber for locality: internal vertex i is `order[i]`; every per-vertex array is
        // permuted and every one-ring entry moved with its vertex (its fan order and weights kept)
        // and relabelled. (Given a layout, the order and the relabelled rings are those.)
        let layout = layout.unwrap_or_else(|| Layout::new(&ring_offsets, ring));
        debug_assert_eq!(layout.order.len(), vertex_count);
        debug_assert_eq!(layout.ring.len(), ring.len());
        let Layout {
            order,
            internal,
            offsets: internal_offsets,
            ring: internal_ring,
        } = layout;
        // Only the rows' 4-byte index is permuted (permuting the 16-byte rows and then
        // deduplicating them held two copies of every entry's row at once). The distinct rows
        // are then renumbered in order of first use in the internal order, as deduplicating the
        // permuted rows numbers them, so the operator is the same bit for bit and its table is
        // read in order.
        let internal_index =
            entries_in_order(&order, &internal_offsets, &ring_offsets, &mesh_index, |i| i);
        drop(mesh_index);
        let (entry_weights, entry_weight_index) = renumber_by_first_use(&mesh_rows, internal_index);
        drop(mesh_rows);
        let self_weights = order.iter().map(|&v| self_weights[v as usize]).collect();
        // A vertex with no local solution keeps its position: it gets neither the projection nor
        // the tangential relaxation (corners of creases, vertices whose triangles all touch the
        // boundary).
        let closed_fan = order
            .iter()
            .map(|&v| closed[v as usize] && solved[v as usize])
            .collect();
        let inverse_valence = order
            .iter()
            .map(|&v| match topology.valence(v) {
                0 => 0.0,
                n => 1.0 / n as f32,
            })
            .collect();
        let curves = fairing_curves(topology, boundary, creases, &internal);
        ConstrainedFairing {
            held,
            variant,
            boundary,
            order,
            internal,
            ring_offsets: internal_offsets,
            ring: internal_ring,
            entry_weight_index,
            entry_weights,
            self_weights,
            inverse_valence,
            closed_fan,
            curves,
            tangential: 0.0,
            relaxation_share: Vec::new(),
            solved_vertices,
            // Allocated by the first load.
            workspace: Workspace::default(),
        }
    }

    /// Normal-projected variant: also move every vertex with a closed fan by `weight` times the
    /// tangential part of its umbrella vector, each iteration (0, the initial value: not at all).
    /// Noise that moved vertices along the surface (every scanner's noise has some) leaves
    /// triangles jittered and skewed that the normal motion alone cannot even out; this evens
    /// them out while keeping the vertices on the surface (a tangential move changes the volume
    /// only to second order). The paper's variant ignores it.
    pub fn set_tangential_relaxation(&mut self, weight: f32) {
        self.tangential = if weight.is_finite() {
            weight.clamp(0.0, 1.0)
        } else {
            0.0
        };
    }

    /// Gives the tangential relaxation ([`Self::set_tangential_relaxation`]) only where it is
    /// needed ([`super::relaxation`]): `everywhere` (0 to 1) of its weight at every vertex, and all
    /// of it at the vertices with a thin triangle among theirs (every one, or only the folded ones:
    /// `slivers`) in the current state (the positions of the last [`Self::load`];
    /// [`super::relaxation::fan_sliver_share`] of its fan). Holds until called again;
    /// `everywhere` 1 (or no state loaded yet) gives every vertex the whole weight again.
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

    pub fn variant(&self) -> FairVariant {
        self.variant
    }

    pub fn boundary(&self) -> BoundaryMode {
        self.boundary
    }

    pub fn vertex_count(&self) -> usize {
        self.self_weights.len()
    }

    /// Vertices that get at least one local solution (the others keep their positions, boundary
    /// vertices aside).
    pub fn solved_vertices(&self) -> usize {
        self.solved_vertices
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
            FairVariant::NormalProjected => vertices,
        };
        let pass2 = offsets + (4 + index) * entries + 12 * vertices + flags + 3 * point + 2 * point;
        pass1 + pass2
    }

    /// Runs `options.rounds` rounds of up to `options.iterations` iterations on `positions`
    /// (which must have this connectivity's vertex count). `options.variant` and
    /// `options.boundary` are those given to [`ConstrainedFairing::new`].
    pub fn run(&mut self, positions: &mut [[f32; 3]], options: &FairOptions) -> FairReport {
        self.load(positions);
        let mut report = FairReport::default();
        for round in 0..options.rounds {
            if round > 0 {
                self.reanchor();
            }
            self.run_round(options, &mut report);
        }
        self.store(positions);
        report
    }

    /// Up to `options.iterations` iterations from the current anchors (one round), counted in
    /// `report`.
    pub fn run_round(&mut self, options: &FairOptions, report: &mut FairReport) {
        for _ in 0..options.iterations {
            report.max_move = self.step();
            report.iterations_run += 1;
            if report.max_move < options.tolerance {
                break;
            }
        }
        report.rounds_run += 1;
    }

    /// Frees the buffers a run works in (80 bytes per vertex: the current state, the anchors and
    /// their terms, the positions with their umbrella means); the next [`Self::load`] allocates
    /// them again. For a caller that keeps many operators and runs one at a time (the editor
    /// keeps one per level of the hierarchy, and these buffers were over half of their memory).
    pub fn release_buffers(&mut self) {
        self.workspace = Workspace::default();
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

    /// Re-imposes the constraints on the current state (the start of a new round).
    pub fn reanchor(&mut self) {
        self.buffers();
        let ws = &mut self.workspace;
        ws.anchors.copy_from_slice(&ws.current);
        with_stencil!(self, |stencil| stencil
            .anchor_terms(&ws.anchors, &mut ws.anchor_terms));
    }

    /// One Jacobi iteration of the current state (anchors from the last [`Self::load`] or
    /// [`Self::reanchor`]). Returns the largest vertex move.
    pub fn step(&mut self) -> f64 {
        let project = self.variant == FairVariant::NormalProjected;
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
    /// one-ring, into `next` (the iterate itself: pass 2 reads the previous positions from
    /// `pairs`, so no second position buffer is needed). With `PROJECT`, vertices with a closed fan keep only the part of
    /// the move x̃_v − x_v along the normal of their fan of umbrella means (centre m_v, ring m_u,
    /// gathered anyway for the update), plus `tangential` (times the vertex's `share` unless that
    /// is empty) of the tangential part of its umbrella vector. Returns the largest squared move.
    #[allow(clippy::too_many_arguments)]
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
                    if PROJECT && closed_fan[v] {
                        let length_squared = normal.length_squared();
                        step = if length_squared > 0.0 && length_squared.is_finite() {
                            let along = normal * (normal.dot(step) / length_squared);
                            let tangential = share.get(v).map_or(tangential, |s| tangential * s);
                            if tangential > 0.0 {
                                let umbrella = m - p;
                                let across = normal * (normal.dot(umbrella) / length_squared);
                                along + (umbrella - across) * tangential
                            } else {
                                along
                            }
                        } else {
                            Vec3A::ZERO
                        };
                    }
                    let squared = step.length_squared();
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

/// The vertices (mesh numbering) that bound the surface patches like boundary vertices do: the
/// boundary's, the creases' (their vertices and corners) and the pinned ones.
fn held_flags(topology: &Topology, creases: Option<&Creases>, pinned: &[bool]) -> Vec<bool> {
    let on_boundary = topology.boundary_flags();
    if creases.is_none() && pinned.is_empty() {
        return on_boundary.to_vec();
    }
    (0..on_boundary.len())
        .into_par_iter()
        .with_min_len(VERTEX_BLOCK)
        .map(|v| {
            on_boundary[v]
                || creases.is_some_and(|c| c.is_feature(v as u32))
                || pinned.get(v).copied().unwrap_or(false)
        })
        .collect()
}

/// How triangle `t` gets a local solution: `Some(None)` with every corner free (none held:
/// `held` flags the boundary, crease and pinned vertices), `Some(Some(h))` with corner h held
/// where it is (see the module docs: the one held corner, held by a crease, not by the boundary,
/// which the paper leaves unsolved, nor pinned), `None` for no solution (two or three corners
/// held, or the one held by the boundary or pinned). Only a triangle whose corners are distinct
/// and of valence three or more (so that A is invertible) is solved.
fn triangle_solve(
    t: &[u32; 3],
    held: &[bool],
    topology: &Topology,
    pinned: &[bool],
) -> Option<Option<usize>> {
    let distinct = t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    if !distinct || t.iter().any(|&c| topology.valence(c) < 3) {
        return None;
    }
    let mut held_at = (0..3).filter(|&k| held[t[k] as usize]);
    match (held_at.next(), held_at.next()) {
        (None, _) => Some(None),
        (Some(h), None) => {
            let c = t[h];
            let by_crease = !topology.is_boundary_vertex(c)
                && !pinned.get(c as usize).copied().unwrap_or(false);
            by_crease.then_some(Some(h))
        }
        _ => None,
    }
}

/// [`corner_weights`] for a triangle solved with corner `held` held where it is (see the module
/// docs): per free corner r, the weights its solution gives each corner c's umbrella mean,
/// position and anchor (the held corner's rows are zero). Built as coefficient vectors over
/// (m_0, m_1, m_2, x_0, x_1, x_2, anchor_0, anchor_1, anchor_2).
fn held_corner_weights(n: [usize; 3], held: usize) -> [[[f64; 3]; 3]; 3] {
    type Coefficients = [f64; 9];
    let unit = |i: usize| -> Coefficients { std::array::from_fn(|k| f64::from(u8::from(k == i))) };
    let plus = |a: Coefficients, b: Coefficients, scale: f64| -> Coefficients {
        std::array::from_fn(|k| a[k] + scale * b[k])
    };
    let a_matrix = umbrella_local_matrix(n);
    // q_r = m_r − Σ_{c ≠ r} x_c / n_r.
    let q: [Coefficients; 3] = std::array::from_fn(|r| {
        (0..3)
            .filter(|&c| c != r)
            .fold(unit(r), |q, c| plus(q, unit(3 + c), -1.0 / n[r] as f64))
    });
    let (a, b) = match held {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    // The free pair's anchors sum: P_a + P_b = K.
    let k = plus(unit(6 + a), unit(6 + b), 1.0);
    let d: [f64; 3] = std::array::from_fn(|r| a_matrix[r][a] - a_matrix[r][b]);
    let e: [Coefficients; 3] = std::array::from_fn(|r| {
        let e = plus([0.0; 9], k, a_matrix[r][b]);
        let e = plus(e, unit(3 + held), a_matrix[r][held]);
        plus(e, q[r], -1.0)
    });
    let d_squared: f64 = d.iter().map(|x| x * x).sum();
    let p_a = (0..3).fold([0.0; 9], |s, r| plus(s, e[r], -d[r] / d_squared));
    let p_b = plus(k, p_a, -1.0);
    let mut weights = [[[0.0; 3]; 3]; 3];
    for (r, p) in [(a, p_a), (b, p_b)] {
        weights[r] = std::array::from_fn(|c| [p[c], p[3 + c], p[6 + c]]);
    }
    weights
}

/// For the valence triple `n` of a triangle's corners: per corner r, the weights its local
/// solution gives each corner c's umbrella mean, position and anchor (G_rc,
/// G_rc/n_c − Σ_c' G_rc'/n_c', h_r; see "How it is computed").
fn corner_weights(n: [usize; 3]) -> [[[f64; 3]; 3]; 3] {
    let op = LocalOperator::umbrella(n).expect("valences are at least 3");
    std::array::from_fn(|r| {
        let k_sum: f64 = (0..3).map(|c| op.g[r][c] / n[c] as f64).sum();
        std::array::from_fn(|c| [op.g[r][c], op.g[r][c] / n[c] as f64 - k_sum, op.h[r]])
    })
}

/// Vertex `v`'s weights: the mean of its solved triangles' corner weights (f64, then rounded),
/// one row (mean, position, anchor, 0) per entry of its one-ring `ring_v` into
/// `ring_weights_v`, its own into `own_out`; `operator(f)` gives face f's corner weights, `None`
/// for a face that is not solved. A vertex with no solved face keeps its position (own weights
/// (0, 1, 0), ring weights 0) and `solved_out` stays false.
#[allow(clippy::too_many_arguments)]
fn gather_rows<W>(
    v: usize,
    ring_v: &[u32],
    topology: &Topology,
    triangles: &[[u32; 3]],
    operator: impl Fn(u32) -> Option<W>,
    ring_weights_v: &mut [[f32; 4]],
    own_out: &mut [f32; 3],
    solved_out: &mut bool,
) where
    W: std::borrow::Borrow<[[[f64; 3]; 3]; 3]>,
{
    let mut own = [0.0f64; 3];
    let mut stack_entries = [[0.0f64; 3]; 64];
    let mut heap_entries = Vec::new();
    let entries: &mut [[f64; 3]] = if ring_v.len() <= 64 {
        &mut stack_entries[..ring_v.len()]
    } else {
        heap_entries.resize(ring_v.len(), [0.0f64; 3]);
        &mut heap_entries
    };
    let mut count = 0usize;
    for &f in topology.faces_of(v as u32) {
        let Some(weights_of) = operator(f) else {
            continue;
        };
        count += 1;
        let t = &triangles[f as usize];
        let r = t
            .iter()
            .position(|&c| c as usize == v)
            .expect("v is a corner");
        for (c, weights) in weights_of.borrow()[r].iter().enumerate() {
            let slot = if t[c] as usize == v {
                &mut own
            } else {
                let at = ring_v
                    .iter()
                    .position(|&u| u == t[c])
                    .expect("a triangle's corners are one-ring neighbours");
                &mut entries[at]
            };
            for k in 0..3 {
                slot[k] += weights[k];
            }
        }
    }
    *solved_out = false;
    if count == 0 {
        // No local solution: the vertex keeps its position (ring weights stay 0).
        *own_out = [0.0, 1.0, 0.0];
        ring_weights_v.fill([0.0; 4]);
        return;
    }
    let inv = 1.0 / count as f64;
    *own_out = own.map(|w| (w * inv) as f32);
    for (out, e) in ring_weights_v.iter_mut().zip(entries.iter()) {
        *out = [
            (e[0] * inv) as f32,
            (e[1] * inv) as f32,
            (e[2] * inv) as f32,
            0.0,
        ];
    }
    *solved_out = true;
}

/// The curves the curve operator moves (internal numbering): the boundary loops (when they are
/// faired), cut into open chains at crease corners, and the crease chains.
fn fairing_curves(
    topology: &Topology,
    boundary: BoundaryMode,
    creases: Option<&Creases>,
    internal: &[u32],
) -> BoundaryCurves {
    let mut closed: Vec<Vec<u32>> = Vec::new();
    let mut open: Vec<Vec<u32>> = Vec::new();
    let is_corner = |v: u32| creases.is_some_and(|c| c.class[v as usize] == FeatureClass::Corner);
    if boundary == BoundaryMode::Curve {
        for boundary_loop in &topology.boundary_loops {
            match boundary_loop.iter().position(|&v| is_corner(v)) {
                None => closed.push(boundary_loop.clone()),
                Some(first) => {
                    // Rotate so the loop starts at a corner, then cut at every corner.
                    let n = boundary_loop.len();
                    let mut chain = vec![boundary_loop[first]];
                    for k in 1..=n {
                        let v = boundary_loop[(first + k) % n];
                        chain.push(v);
                        if is_corner(v) {
                            open.push(std::mem::replace(&mut chain, vec![v]));
                        }
                    }
                }
            }
        }
    }
    if let Some(creases) = creases {
        for chain in &creases.chains {
            if chain.closed {
                closed.push(chain.vertices.clone());
            } else {
                open.push(chain.vertices.clone());
            }
        }
    }
    let relabel = |curves: Vec<Vec<u32>>| -> Vec<Vec<u32>> {
        curves
            .into_iter()
            .map(|c| c.iter().map(|&v| internal[v as usize]).collect())
            .collect()
    };
    BoundaryCurves::with_open_chains(&relabel(closed), &relabel(open), internal.len())
}

type RowMap = HashMap<[u32; 3], u32, BuildHasherDefault<PositionHasher>>;

/// A weight row's key: its three weights, bit for bit (the fourth lane is always 0).
fn row_key(row: &[f32; 4]) -> [u32; 3] {
    [row[0].to_bits(), row[1].to_bits(), row[2].to_bits()]
}

/// One chunk of rows deduplicated against a table of its own: each row's index among the
/// chunk's distinct rows, and those rows in order of first appearance.
fn deduplicate_chunk(rows: &[[f32; 4]]) -> (Vec<u32>, Vec<[f32; 4]>) {
    let mut distinct = Vec::new();
    let mut slot = RowMap::default();
    let index = rows
        .iter()
        .map(|row| {
            *slot.entry(row_key(row)).or_insert_with(|| {
                distinct.push(*row);
                (distinct.len() - 1) as u32
            })
        })
        .collect();
    (index, distinct)
}

/// Consecutive chunks deduplicated by [`deduplicate_chunk`], joined: the distinct rows of them
/// all, numbered in chunk order (which is the order of first appearance over the whole
/// sequence), and every row's index among them, in order.
fn join_deduplicated(mut local: Vec<(Vec<u32>, Vec<[f32; 4]>)>) -> (Vec<[f32; 4]>, Vec<u32>) {
    let mut distinct: Vec<[f32; 4]> = Vec::new();
    let mut slot = RowMap::default();
    let global_of_local: Vec<Vec<u32>> = local
        .iter()
        .map(|(_, rows)| {
            rows.iter()
                .map(|row| {
                    *slot.entry(row_key(row)).or_insert_with(|| {
                        distinct.push(*row);
                        (distinct.len() - 1) as u32
                    })
                })
                .collect()
        })
        .collect();
    local
        .par_iter_mut()
        .zip(&global_of_local)
        .for_each(|((index, _), global)| {
            for i in index.iter_mut() {
                *i = global[*i as usize];
            }
        });
    let index = local.into_iter().flat_map(|(index, _)| index).collect();
    (distinct, index)
}

/// Two-byte indices where the rows allow.
fn narrowed(distinct: usize, index: Vec<u32>) -> EntryWeightIndex {
    if distinct <= 1 << 16 {
        EntryWeightIndex::Narrow(index.into_par_iter().map(|i| i as u16).collect())
    } else {
        EntryWeightIndex::Wide(index)
    }
}

/// The distinct rows of `rows` (compared bit for bit) in order of first appearance, and each
/// row's index among them. Chunks are deduplicated in parallel against small local tables, then
/// their distinct rows are numbered in chunk order, which is the order of first appearance.
#[cfg(test)]
fn deduplicate_rows(rows: &[[f32; 4]]) -> (Vec<[f32; 4]>, EntryWeightIndex) {
    const ROWS_PER_CHUNK: usize = 1 << 16;
    let local = rows
        .par_chunks(ROWS_PER_CHUNK)
        .map(deduplicate_chunk)
        .collect();
    let (distinct, index) = join_deduplicated(local);
    let index = narrowed(distinct.len(), index);
    (distinct, index)
}

/// The rows `rows` (distinct) renumbered in order of their first use in `index`, with `index`
/// rewritten to the new numbers: what [`deduplicate_rows`] gives for the rows `index` picks, in
/// that order, without making those rows (2 or 4 bytes per entry instead of 16).
fn renumber_by_first_use(
    rows: &[[f32; 4]],
    mut index: Vec<u32>,
) -> (Vec<[f32; 4]>, EntryWeightIndex) {
    let mut new_of_old = vec![u32::MAX; rows.len()];
    let mut renumbered = Vec::new();
    for i in index.iter_mut() {
        let slot = &mut new_of_old[*i as usize];
        if *slot == u32::MAX {
            *slot = renumbered.len() as u32;
            renumbered.push(rows[*i as usize]);
        }
        *i = *slot;
    }
    let index = narrowed(renumbered.len(), index);
    (renumbered, index)
}

/// The boundary curves read the previous iterate from the pairs pass 1 wrote.
impl super::boundary::CurvePoint for PositionAndMean {
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

impl super::boundary::CurvePoint for Vec3A {
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

/// Every vertex's one-ring, in fan order where possible, sharing the topology's one-ring CSR
/// offsets (a closed fan has as many entries as the vertex has neighbours).
pub(crate) struct FanRings {
    /// For a vertex with a closed, consistently oriented fan, its neighbours in fan order (faces
    /// (v, ring[k], ring[k+1])); otherwise the topology's sorted neighbours.
    pub ring: Vec<u32>,
    pub closed_fan: Vec<bool>,
}

impl FanRings {
    pub fn new(triangles: &[[u32; 3]], topology: &Topology) -> Self {
        let (offsets, neighbors) = topology.neighbor_csr();
        let is_boundary = topology.boundary_flags();
        let mut ring = vec![0u32; neighbors.len()];
        let mut closed = vec![false; offsets.len().saturating_sub(1)];
        split_into_vertex_blocks(&mut ring, offsets)
            .into_par_iter()
            .zip(closed.par_chunks_mut(VERTEX_BLOCK))
            .for_each(|((first, block), closed_block)| {
                let base = offsets[first] as usize;
                for (i, closed_v) in closed_block.iter_mut().enumerate() {
                    let v = first + i;
                    let ring_v =
                        &mut block[offsets[v] as usize - base..offsets[v + 1] as usize - base];
                    let v = v as u32;
                    *closed_v =
                        !is_boundary[v as usize] && closed_fan(v, topology, triangles, ring_v);
                    if !*closed_v {
                        ring_v.copy_from_slice(topology.neighbors(v));
                    }
                }
            });
        FanRings {
            ring,
            closed_fan: closed,
        }
    }
}

/// Writes v's neighbours in fan order (faces (v, fan[k], fan[k+1])) into `fan` when v has a closed,
/// consistently oriented fan with as many faces as neighbours; returns whether it does.
fn closed_fan(v: u32, topology: &Topology, triangles: &[[u32; 3]], fan: &mut [u32]) -> bool {
    let faces = topology.faces_of(v);
    if faces.len() < 3 || faces.len() != topology.valence(v) || faces.len() > 64 {
        return false;
    }
    // Each face as the directed edge opposite v: (next after v, next after that).
    let mut edge_buffer = [(0u32, 0u32); 64];
    let edges = &mut edge_buffer[..faces.len()];
    for (edge, &f) in edges.iter_mut().zip(faces) {
        let t = triangles[f as usize];
        let Some(r) = t.iter().position(|&c| c == v) else {
            return false;
        };
        *edge = (t[(r + 1) % 3], t[(r + 2) % 3]);
    }
    let mut used = [false; 64];
    let (first, mut current) = edges[0];
    used[0] = true;
    fan[0] = first;
    let mut len = 1;
    while current != first {
        if len == fan.len() {
            return false;
        }
        fan[len] = current;
        len += 1;
        let Some(next) = (0..edges.len()).find(|&e| !used[e] && edges[e].0 == current) else {
            return false;
        };
        used[next] = true;
        current = edges[next].1;
    }
    len == faces.len() && used[..edges.len()].iter().all(|&u| u)
}

/// Vertices per block of [`split_into_vertex_blocks`] and of the operator's gather (each
/// block's weight rows are deduplicated as soon as they are made).
const VERTEX_BLOCK: usize = 4096;

/// `data`, a CSR array with `offsets`, cut at every [`VERTEX_BLOCK`]-th vertex: (the block's first
/// vertex, its entries `offsets[first]..offsets[first + VERTEX_BLOCK]`), for parallel passes that
/// write every vertex's slice (a slice per vertex cost 16 bytes a vertex, allocated and filled
/// on one thread before the pass).
fn split_into_vertex_blocks<'a, T>(
    data: &'a mut [T],
    offsets: &[u32],
) -> Vec<(usize, &'a mut [T])> {
    let vertices = offsets.len().saturating_sub(1);
    let mut blocks = Vec::with_capacity(vertices.div_ceil(VERTEX_BLOCK));
    let mut rest = data;
    for first in (0..vertices).step_by(VERTEX_BLOCK) {
        let last = (first + VERTEX_BLOCK).min(vertices);
        let (head, tail) =
            std::mem::take(&mut rest).split_at_mut((offsets[last] - offsets[first]) as usize);
        blocks.push((first, head));
        rest = tail;
    }
    blocks
}

/// Once two detections in a row found the creases unchanged (or settled, see
/// [`CREASE_SETTLED`]), [`fair_constrained`] finds them again only in every this many rounds.
const CREASE_RECHECK_ROUNDS: usize = 4;

/// A detection whose feature edges differ from the last in at most one edge in this many (the
/// two sets' symmetric difference against the larger) counts as unchanged for
/// [`CREASE_RECHECK_ROUNDS`].
const CREASE_SETTLED: usize = 20;

/// How many edges are in one of `a` and `b` but not the other (each a set of edges).
fn edges_changed(a: &[[u32; 2]], b: &[[u32; 2]]) -> usize {
    let sorted = |edges: &[[u32; 2]]| {
        let mut edges = edges.to_vec();
        edges.sort_unstable();
        edges
    };
    let (a, b) = (sorted(a), sorted(b));
    let (mut i, mut j, mut changed) = (0, 0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => (changed, i) = (changed + 1, i + 1),
            std::cmp::Ordering::Greater => (changed, j) = (changed + 1, j + 1),
            std::cmp::Ordering::Equal => (i, j) = (i + 1, j + 1),
        }
    }
    changed + (a.len() - i) + (b.len() - j)
}

/// Constrained fairing of `mesh` in place (sections 3.2 and 3.3); `topology` must be built from
/// `mesh`. Precomputes the operator (see [`ConstrainedFairing`] to reuse it) and runs
/// `options.rounds` rounds of up to `options.iterations` iterations each.
///
/// ```
/// use fairmesh::fairing::{fair_constrained, FairOptions};
/// use fairmesh::metrics::signed_volume;
/// use fairmesh::noise::{add_noise, NoiseOptions};
///
/// let loaded = fairmesh::bundled::load_bunny(&Default::default())?;
/// let (mut mesh, topology) = (loaded.mesh, loaded.topology);
/// add_noise(&mut mesh, &NoiseOptions::default());
/// let noisy = mesh.clone();
///
/// let options = FairOptions::default().with_rounds(3);
/// let report = fair_constrained(&mut mesh, &topology, &options);
/// assert!(report.iterations_run > 0);
/// // Smoother: the vertices moved, by less than the noise's size.
/// let moved = mesh.positions.iter().zip(&noisy.positions).filter(|(a, b)| a != b).count();
/// assert!(moved > mesh.vertex_count() / 2);
/// // And without shrinkage: the volume stays within 0.1%.
/// let change = signed_volume(&mesh) / signed_volume(&noisy) - 1.0;
/// assert!(change.abs() < 1e-3, "{change}");
/// # Ok::<(), fairmesh::io::IoError>(())
/// ```
pub fn fair_constrained(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &FairOptions,
) -> FairReport {
    if options.iterations == 0 || mesh.positions.is_empty() {
        return FairReport::default();
    }
    if options.strength == Strength::Fixed && options.rounds == 0 {
        return FairReport::default();
    }
    // A mask that does not fit, or pins everything: nothing may move.
    if let Some(mask) = &options.mask {
        if mask.check_fits(mesh.positions.len()).is_err() || mask.painted_count() == 0 {
            return FairReport::default();
        }
    }
    // A non-manifold scan is faired as the surface it stands for: without the triangles its
    // reconstruction left lying loose at its non-manifold edges (overlays on a fan, fins), which
    // made their corners boundary vertices on chains no boundary curve runs through, and so
    // held them with their noise (`crate::mesh::loose_triangles`). Same vertices, nothing
    // renumbered; a corner only loose triangles use (a fin's tip) stays where it is.
    // On the noisy Stanford dragon (vrip) the vertices at non-manifold edges went from twice
    // the others' distance to the clean surface to about theirs (`docs/measurements.md`).
    if options.variant == FairVariant::NormalProjected && !topology.non_manifold_edges.is_empty() {
        if let Some((loose, mut kept, kept_topology)) =
            crate::mesh::without_loose_triangles(mesh, topology)
        {
            // The volume kept is the file's, loose triangles included: they follow their
            // corners, and their own (cone) volume changes with them; one more uniform offset
            // takes that back (about a thousandth of an edge length on the dragon, which moved
            // the volume by 0.04 % without it).
            let pinned = options
                .mask
                .as_ref()
                .map(|mask| mask.pinned_flags())
                .unwrap_or_default();
            let volume = options
                .keep_volume
                .then(|| VolumeKeeper::new(mesh, topology, &pinned));
            let mut report = fair_constrained(&mut kept, &kept_topology, options);
            mesh.positions = kept.positions;
            if let Some(volume) = volume.filter(|_| report.rounds_run > 0) {
                volume.restore(mesh, topology, |v| pinned.get(v).copied().unwrap_or(false));
            }
            report.loose_triangles += loose.len();
            return report;
        }
    }
    let original = options.mask.as_ref().map(|_| mesh.positions.clone());
    let pinned = options
        .mask
        .as_ref()
        .map(|mask| mask.pinned_flags())
        .unwrap_or_default();
    let report = if options.strength == Strength::Fixed && options.rounds >= LOCAL_ORDER_ROUNDS {
        in_local_order(
            mesh,
            topology,
            options,
            &pinned,
            |mesh, topology, options, pinned| {
                decide_and_fair(mesh, topology, options, pinned, false)
            },
        )
    } else {
        decide_and_fair(mesh, topology, options, &pinned, true)
    };
    // The operator held the pinned vertices; the blend fades the rest by their weights (and
    // puts back pinned boundary vertices, which the boundary curves may have moved).
    if let (Some(mask), Some(original)) = (&options.mask, &original) {
        mask.blend(original, &mut mesh.positions);
    }
    report
}

/// Rounds from which a run in the locality order pays for making it (see [`in_local_order`]).
const LOCAL_ORDER_ROUNDS: usize = 3;

/// Runs `fair` on a copy of `mesh` whose vertices are numbered breadth-first over the one-rings
/// and whose faces are sorted by their lowest corner, then puts the faired positions back in the
/// mesh's numbering. Every per-vertex pass of a round outside the operator (the crease detection
/// and the noise estimate over the fans, the volume correction's normals, the risk's normals)
/// gathers its neighbours' data; in a file's own order (a scan's, a subdivided mesh's) those sit
/// megabytes apart, here a few breadth-first fronts apart. On the noisy 1.2M-face bunny, whose
/// file order is poor, the whole default `fair` went from 23.3 to 19.9 s for ~0.2 s of
/// reordering and a second topology (`docs/measurements.md`). The operator renumbers its own vertices the same
/// way, so its iterations are unchanged. What `options` number by vertex (the file's hard edges)
/// is renumbered too; `pinned` stands for the mask, which `fair` does not see.
fn in_local_order(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &FairOptions,
    pinned: &[bool],
    fair: impl FnOnce(&mut TriMesh, &Topology, &FairOptions, &[bool]) -> FairReport,
) -> FairReport {
    let (offsets, neighbors) = topology.neighbor_csr();
    let order = breadth_first_order(offsets, neighbors);
    let position = inverse_permutation(&order);
    let positions: Vec<[f32; 3]> = order
        .par_iter()
        .map(|&v| mesh.positions[v as usize])
        .collect();
    // Faces relabelled (corners in their own order, so the winding stays), then placed by their
    // lowest corner with a stable counting sort.
    let relabelled: Vec<[u32; 3]> = mesh
        .triangles
        .par_iter()
        .map(|t| t.map(|v| position[v as usize]))
        .collect();
    let lowest = |t: &[u32; 3]| t[0].min(t[1]).min(t[2]) as usize;
    let mut start = vec![0u32; positions.len() + 1];
    for t in &relabelled {
        start[lowest(t) + 1] += 1;
    }
    for v in 0..positions.len() {
        start[v + 1] += start[v];
    }
    let mut triangles = vec![[0u32; 3]; relabelled.len()];
    for t in relabelled {
        let slot = &mut start[lowest(&t)];
        triangles[*slot as usize] = t;
        *slot += 1;
    }
    let mut local = TriMesh::new(positions, triangles);
    let local_topology = Topology::build(&local);
    let local_pinned: Vec<bool> = if pinned.is_empty() {
        Vec::new()
    } else {
        order.iter().map(|&v| pinned[v as usize]).collect()
    };
    let mut local_options = options.clone();
    local_options.mask = None;
    if let Some(creases) = &mut local_options.creases {
        let edges: Vec<[u32; 2]> = creases
            .file_edges
            .iter()
            .map(
                |&[a, b]| match (position.get(a as usize), position.get(b as usize)) {
                    (Some(&pa), Some(&pb)) if a < b => [pa.min(pb), pa.max(pb)],
                    // Edges the detection leaves out (a reversed pair, a vertex out of range) are
                    // passed on as they are, to be left out there too.
                    _ => [a, b],
                },
            )
            .collect();
        creases.file_edges = edges.into();
    }
    let report = fair(&mut local, &local_topology, &local_options, &local_pinned);
    for (&v, p) in order.iter().zip(&local.positions) {
        mesh.positions[v as usize] = *p;
    }
    report
}

/// The noise estimate, the decision to fair at all (automatic strength leaves a clean mesh as it
/// is), the first creases, then the rounds. With `may_reorder`, automatic strength on a noisy
/// mesh runs its rounds in the locality order ([`in_local_order`]).
fn decide_and_fair(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &FairOptions,
    pinned: &[bool],
    may_reorder: bool,
) -> FairReport {
    // The fan-ordered one-rings the operator is built from serve the noise estimate and the
    // crease detection first (`read_noise`, `detect_creases_with_estimate`).
    let fans = FanRings::new(&mesh.triangles, topology);
    // The noise estimate decides the strength (automatic) and how much the normals are filtered
    // before creases are detected (raw normals of a noisy mesh make creases of the noise).
    // Automatic strength fairs only a noisy mesh, so its creases are always found on filtered
    // normals; a fixed strength finds the estimate and the faces' own feature edges in one
    // gather, and skips the filter when the mesh is clean.
    // Without `may_reorder` the mesh is already the locality-ordered copy (`in_local_order`):
    // the filter keeps its face order (the same normals bit for bit, its lists built in about
    // half the time).
    let mut face_rings = if may_reorder {
        FaceRingCache::default()
    } else {
        FaceRingCache::in_mesh_order()
    };
    let started = std::time::Instant::now();
    // Automatic strength reads, in the same gather, which vertices lie on sharp edges.
    let (estimate, found, reading) = match (&options.creases, options.strength) {
        (Some(crease_options), Strength::Fixed) => {
            let (estimate, creases) = detect_creases_with_estimate(
                mesh,
                topology,
                &fans,
                crease_options,
                &mut face_rings,
                true,
            );
            (estimate, Some(creases), None)
        }
        (_, Strength::Auto) => {
            let angle = options
                .creases
                .as_ref()
                .map_or(CreaseOptions::default().angle_degrees, |c| c.angle_degrees);
            let reading = read_noise(mesh, topology, &fans, angle);
            (reading.noise(topology), None, Some(reading))
        }
        (None, _) => (None, None, None),
    };
    // Automatic strength: a clean mesh is left as it is, and so is one that reads noisy only
    // because of its sharp edges (a coarse CAD part: most of its vertices lie on or beside an
    // edge, and those make the median read noise; away from the edges it reads clean).
    let clean_away_from_edges = || {
        reading
            .as_ref()
            .and_then(|reading| reading.away_from_edges(topology))
            .is_some_and(|away| away <= CLEAN_NOISE)
    };
    let auto_noise = match options.strength {
        Strength::Auto => match estimate {
            Some(noise) if noise > CLEAN_NOISE && !clean_away_from_edges() => Some(noise),
            _ => {
                return FairReport {
                    noise_estimate: estimate,
                    detection_ms: milliseconds(started),
                    ..FairReport::default()
                }
            }
        },
        _ => None,
    };
    drop(reading);
    let decided_ms = milliseconds(started);
    let rounds = Rounds {
        estimate,
        auto_noise,
        pinned,
    };
    let mut report = if may_reorder && auto_noise.is_some() {
        drop(fans);
        in_local_order(
            mesh,
            topology,
            options,
            pinned,
            |mesh, topology, options, pinned| {
                let fans = FanRings::new(&mesh.triangles, topology);
                fair_rounds(
                    mesh,
                    topology,
                    fans,
                    (None, FaceRingCache::in_mesh_order()),
                    options,
                    Rounds { pinned, ..rounds },
                )
            },
        )
    } else {
        fair_rounds(mesh, topology, fans, (found, face_rings), options, rounds)
    };
    report.detection_ms += decided_ms;
    report
}

/// Milliseconds since `start`.
fn milliseconds(start: std::time::Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

/// What [`fair_rounds`] takes from the decision to fair.
#[derive(Clone, Copy)]
struct Rounds<'a> {
    /// The input's noise estimate (reported, and setting the first detection's filtering).
    estimate: Option<f64>,
    /// Automatic strength: the noise estimate of the input that is faired; `None` for a fixed
    /// strength.
    auto_noise: Option<f64>,
    /// Vertices a mask pins (empty: none).
    pinned: &'a [bool],
}

/// The rounds of [`fair_constrained`], after the decision to fair: `fans` are `mesh`'s,
/// `found` the creases found with the noise estimate (a fixed strength), if any, with the faces
/// around each face if that detection filtered the normals.
fn fair_rounds(
    mesh: &mut TriMesh,
    topology: &Topology,
    fans: FanRings,
    (found, mut face_rings): (Option<Creases>, FaceRingCache),
    options: &FairOptions,
    rounds: Rounds,
) -> FairReport {
    let Rounds {
        estimate,
        auto_noise,
        pinned,
    } = rounds;
    // Creases are found again before every round (every CREASE_RECHECK_ROUNDS-th once they stop
    // changing): the noise left after a round makes fewer false creases, and a crease found on
    // the noisy input may turn out to be noise (`docs/measurements.md`). The normals are filtered
    // as much as the current noise asks for: the first time as the input's estimate says, later
    // as the estimate made in the same gather as the faces' own feature edges says
    // (`detect_creases_with_estimate`; once the noise is gone, that gather is the detection).
    let started = std::time::Instant::now();
    let mut creases = found.or_else(|| {
        options.creases.as_ref().map(|crease_options| {
            let mut crease_options = crease_options.clone();
            crease_options.normal_filtering = crease_options
                .normal_filtering
                .max(estimate.map_or(0, normal_filtering_for));
            detect_creases_cached(mesh, topology, &crease_options, &mut face_rings)
        })
    });
    let first_detection_ms = milliseconds(started);
    let max_rounds = match auto_noise {
        Some(_) => MAX_AUTO_ROUNDS,
        None => options.rounds,
    };
    let redetect = options.creases.is_some() && max_rounds > 1;
    let build = |mesh: &TriMesh, creases: Option<&Creases>, fans: &FanRings| {
        let mut fairing = ConstrainedFairing::with_fans(
            mesh,
            topology,
            fans,
            options.variant,
            options.boundary,
            creases,
            pinned,
        );
        fairing.set_tangential_relaxation(options.tangential_relaxation as f32);
        fairing
    };
    let mut fairing = build(mesh, creases.as_ref(), &fans);
    // The relaxation where it is needed: the share every vertex gets, from how much of the
    // input's noise lies along its surface ([`relaxation`]); the slivers' before every round.
    let started = std::time::Instant::now();
    let tangential_noise = (options.variant == FairVariant::NormalProjected
        && options.tangential_relaxation > 0.0
        && options.relaxation == Relaxation::WhereNeeded)
        .then(|| read_tangential_noise(mesh, topology, &fans));
    let mut everywhere =
        tangential_noise.map(|reading| relaxation::everywhere_share(reading, estimate));
    // Without creases the surface is taken for a smooth one, whose thin triangles may lie along a
    // bend: only the folded ones are relaxed ([`relaxation::Slivers`]).
    let slivers = match options.creases {
        Some(_) => relaxation::Slivers::All,
        None => relaxation::Slivers::Folded,
    };
    let reading_ms = milliseconds(started);
    // The fans serve the later rounds only to find the creases again (and estimate the noise
    // that sets the filtering for it) and to read the noise along the surface again while the
    // relaxation acts everywhere: otherwise they are freed before the iterations (the peak,
    // while the operator is set up from them, stays: 277 MB for `fair --rounds 3 --no-creases`
    // on 1.2M faces either way).
    let fans = (redetect || everywhere.is_some_and(|share| share > 0.0)).then_some(fans);
    let volume = options
        .keep_volume
        .then(|| VolumeKeeper::new(mesh, topology, pinned));
    let mut report = FairReport {
        detection_ms: first_detection_ms + reading_ms,
        tangential_noise: tangential_noise.flatten(),
        ..FairReport::default()
    };
    // Automatic strength: round by round while the estimated risk of the result falls (see
    // [`super::strength`]): a copy of the input, moved a little along its normals, goes through
    // the same rounds, and the mesh goes back to the last round that lowered the risk clearly
    // (RISK_MIN_FALL).
    let mut risk = auto_noise.map(|noise| {
        // σ is read away from the first detection's creases and the boundary.
        let held = held_flags(topology, creases.as_ref(), &[]);
        RoundRisk::new(
            mesh,
            topology,
            crate::metrics::mean_edge_length(mesh),
            noise,
            &held,
        )
    });
    // The last round kept (see RISK_MIN_FALL): its number, its risk, its positions and crease
    // count.
    let mut kept_round: Option<(usize, f64)> = None;
    let mut kept_positions = Vec::new();
    let mut kept_creases = 0;
    let mut first_fall = 0.0;
    let mut before_restore = Vec::new();
    let mut copy_report = FairReport::default();
    // Detections in a row that found the creases already kept (or changed in a few edges in
    // CREASE_SETTLED): from two on, the creases are found again only every
    // CREASE_RECHECK_ROUNDS rounds (once the noise is gone they change little: on the noisy
    // 1.2M-face bunny the later detections change 0-4 of ~75 edges; counting those as settled
    // took the run from 29 detections to 20, 8.6 % less time, the same mean distance).
    let mut unchanged = 0usize;
    // Whether a detection has read the mesh clean (its estimate asked for no filtering): the
    // rounds only smooth it further, so the later ones find the faces' own feature edges without
    // estimating again (on the noisy 1.2M-face bunny the estimates fell from 0.047 after the
    // first round to 0.001; the estimate's share of a detection is ~4 of 15 ms).
    let mut read_clean = false;
    let detect_in = |round: usize, unchanged: usize| {
        redetect && (unchanged < 2 || round.is_multiple_of(CREASE_RECHECK_ROUNDS))
    };
    for round in 0..max_rounds {
        if let (true, Some(fans), Some(crease_options)) = (
            round > 0 && detect_in(round, unchanged),
            &fans,
            &options.creases,
        ) {
            let started = std::time::Instant::now();
            let (noise, found) = detect_creases_with_estimate(
                mesh,
                topology,
                fans,
                crease_options,
                &mut face_rings,
                !read_clean,
            );
            report.detection_ms += milliseconds(started);
            read_clean |= noise.is_some_and(|noise| normal_filtering_for(noise) == 0);
            let found = Some(found);
            fn edges(creases: &Option<Creases>) -> &[[u32; 2]] {
                creases.as_ref().map_or(&[], |c| &c.edges)
            }
            let (before, after) = (edges(&creases), edges(&found));
            if before != after {
                // A change of a few edges in twenty counts as settled: the crease set is taken
                // all the same, but the detections thin out.
                let settled =
                    CREASE_SETTLED * edges_changed(before, after) <= before.len().max(after.len());
                creases = found;
                unchanged = if settled { unchanged + 1 } else { 0 };
                fairing = fairing.for_other_creases(mesh, topology, fans, creases.as_ref(), pinned);
            } else {
                unchanged += 1;
            }
        }
        let held = creases.as_ref().map(|c| c.class.as_slice()).unwrap_or(&[]);
        let corner = |v: usize| held.get(v) == Some(&FeatureClass::Corner);
        // Imposes the constraints on the positions this round starts from.
        fairing.load(&mesh.positions);
        if let Some(share) = &mut everywhere {
            // Once the noise along the surface is gone (the mesh reads as even as a relaxed one),
            // the relaxation keeps to the thin triangles (`relaxation::still_needed_share`).
            if round > 0 && *share > 0.0 {
                if let Some(fans) = &fans {
                    let started = std::time::Instant::now();
                    let reading = read_tangential_noise(mesh, topology, fans);
                    *share = share.min(relaxation::still_needed_share(reading));
                    report.detection_ms += milliseconds(started);
                }
            }
            // From the mesh's state: the risk's copy is faired with the same shares.
            fairing.relax_where_needed(*share, slivers);
        }
        fairing.run_round(options, &mut report);
        fairing.store(&mut mesh.positions);
        if let Some(volume) = &volume {
            if risk.is_some() {
                before_restore.clone_from(&mesh.positions);
            }
            volume.restore(mesh, topology, corner);
        }
        if let Some((risk, copy)) = &mut risk {
            // The copy's round, with the same operator (and creases) as the mesh's.
            fairing.load(copy);
            fairing.run_round(options, &mut copy_report);
            fairing.store(copy);
            // The volume correction offsets every vertex by one distance per part along its
            // normal; the copy takes the mesh's offsets (what its own correction would give, but
            // for a change of the distance that sums a part's volume change, of order 1/N per
            // vertex against the local response the risk reads).
            if volume.is_some() {
                copy.par_chunks_mut(CHUNK)
                    .zip(mesh.positions.par_chunks(CHUNK))
                    .zip(before_restore.par_chunks(CHUNK))
                    .for_each(|((copy, after), before)| {
                        for ((c, a), b) in copy.iter_mut().zip(after).zip(before) {
                            for k in 0..3 {
                                c[k] += a[k] - b[k];
                            }
                        }
                    });
            }
            let now = risk.read(mesh, topology, copy);
            report.risk_by_round.push(now);
            let edges = creases.as_ref().map_or(0, |c| c.edges.len());
            // A round is kept when it lowers the risk below the last kept round's by
            // RISK_MIN_FALL of what the second round lowered it by (the falls after a kept round
            // add up until they pass that); the rounds stop RISK_PATIENCE rounds after the last
            // kept one.
            if round == 1 {
                if let Some((_, first)) = kept_round {
                    first_fall = (first - now).max(0.0);
                }
            }
            if kept_round.is_none_or(|(_, kept_risk)| now < kept_risk - RISK_MIN_FALL * first_fall)
            {
                kept_round = Some((round, now));
                kept_positions.clone_from(&mesh.positions);
                kept_creases = edges;
            } else if now.is_nan() {
                break;
            }
            if kept_round.is_some_and(|(kept, _)| round - kept >= RISK_PATIENCE) {
                break;
            }
        }
    }
    let mut crease_edges = creases.map_or(0, |c| c.edges.len());
    if let Some((round, _)) = kept_round {
        if round + 1 != report.rounds_run {
            mesh.positions = kept_positions;
            report.rounds_run = round + 1;
            crease_edges = kept_creases;
        }
    }
    report.noise_estimate = estimate;
    report.crease_edges = crease_edges;
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small deterministic generator (xorshift) so the tests need no seeds from outside.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
    }

    /// Solves the dense system `m·x = rhs` by Gaussian elimination with partial pivoting.
    #[allow(clippy::needless_range_loop)] // rows and columns by index read like the textbook
    fn gauss_solve<const N: usize>(mut m: [[f64; N]; N], mut rhs: [f64; N]) -> [f64; N] {
        for col in 0..N {
            let pivot = (col..N)
                .max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))
                .unwrap();
            m.swap(col, pivot);
            rhs.swap(col, pivot);
            for row in col + 1..N {
                let factor = m[row][col] / m[col][col];
                for k in col..N {
                    m[row][k] -= factor * m[col][k];
                }
                rhs[row] -= factor * rhs[col];
            }
        }
        let mut x = [0.0; N];
        for row in (0..N).rev() {
            let tail: f64 = (row + 1..N).map(|k| m[row][k] * x[k]).sum();
            x[row] = (rhs[row] - tail) / m[row][row];
        }
        x
    }

    /// The KKT system of min ‖AP − Q‖² s.t. BP = C, one coordinate:
    /// [2AᵀA Bᵀ; B 0]·[P; λ] = [2AᵀQ; C].
    fn kkt_solve(a: &Matrix3, q: [f64; 3], c: f64) -> [f64; 3] {
        let mut m = [[0.0; 4]; 4];
        let mut rhs = [0.0; 4];
        for r in 0..3 {
            for s in 0..3 {
                m[r][s] = 2.0 * (0..3).map(|k| a[k][r] * a[k][s]).sum::<f64>();
            }
            m[r][3] = 1.0;
            m[3][r] = 1.0;
            rhs[r] = 2.0 * (0..3).map(|k| a[k][r] * q[k]).sum::<f64>();
        }
        rhs[3] = c;
        let x = gauss_solve(m, rhs);
        [x[0], x[1], x[2]]
    }

    #[test]
    fn eq7_matches_kkt_and_keeps_the_barycentre() {
        let mut rng = Rng(0x9e3779b97f4a7c15);
        for case in 0..2000 {
            // Uniform weights from random valences, and every fourth case general weights
            // (eq 7 holds for any invertible A).
            let a = if case % 4 == 3 {
                std::array::from_fn(|r| {
                    std::array::from_fn(|c| if r == c { 1.0 } else { -rng.range(0.0, 0.45) })
                })
            } else {
                let n = [0; 3].map(|_| 3 + (rng.next() * 12.0) as usize);
                umbrella_local_matrix(n)
            };
            let op = LocalOperator::from_matrix(&a).expect("diagonally dominant");
            let q: Matrix3 = std::array::from_fn(|_| std::array::from_fn(|_| rng.range(-5.0, 5.0)));
            let c: [f64; 3] = std::array::from_fn(|_| rng.range(-5.0, 5.0));
            let p = op.solve(&q, c);
            for k in 0..3 {
                let direct = kkt_solve(&a, [q[0][k], q[1][k], q[2][k]], c[k]);
                let scale = direct.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                for r in 0..3 {
                    let error = (p[r][k] - direct[r]).abs() / scale;
                    assert!(error < 1e-9, "case {case}: relative error {error}");
                }
                let barycentre_error = (p[0][k] + p[1][k] + p[2][k] - c[k]).abs();
                assert!(barycentre_error < 1e-12, "case {case}: {barycentre_error}");
            }
        }
    }

    #[test]
    fn a_triangle_solved_with_a_crease_corner_held_keeps_its_free_pairs_midpoint() {
        // The free corners a, b of a triangle whose corner h is held at x_h minimise ‖AP − Q‖²
        // with P_a + P_b = anchor_a + anchor_b; solved directly (Lagrange) against the weights.
        let mut rng = Rng(0x2545f4914f6cdd1d);
        for case in 0..600 {
            let n = [0; 3].map(|_| 3 + (rng.next() * 12.0) as usize);
            let held = case % 3;
            let weights = held_corner_weights(n, held);
            let a = umbrella_local_matrix(n);
            let (fa, fb) = match held {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            let m: [f64; 3] = std::array::from_fn(|_| rng.range(-5.0, 5.0));
            let x: [f64; 3] = std::array::from_fn(|_| rng.range(-5.0, 5.0));
            let anchor: [f64; 3] = std::array::from_fn(|_| rng.range(-5.0, 5.0));
            let q: [f64; 3] = std::array::from_fn(|r| {
                m[r] - (0..3).filter(|&c| c != r).map(|c| x[c]).sum::<f64>() / n[r] as f64
            });
            // Unknowns P_a, P_b, λ: 2·MᵀM·P + λ·1 = 2·Mᵀ(Q − A_h·x_h), P_a + P_b = K.
            let column = |c: usize| [a[0][c], a[1][c], a[2][c]];
            let (ma, mb, mh) = (column(fa), column(fb), column(held));
            let rest: [f64; 3] = std::array::from_fn(|k| q[k] - mh[k] * x[held]);
            let dot = |u: [f64; 3], v: [f64; 3]| (0..3).map(|k| u[k] * v[k]).sum::<f64>();
            let system = [
                [2.0 * dot(ma, ma), 2.0 * dot(ma, mb), 1.0],
                [2.0 * dot(mb, ma), 2.0 * dot(mb, mb), 1.0],
                [1.0, 1.0, 0.0],
            ];
            let rhs = [
                2.0 * dot(ma, rest),
                2.0 * dot(mb, rest),
                anchor[fa] + anchor[fb],
            ];
            let direct = gauss_solve(system, rhs);
            for (r, expected) in [(fa, direct[0]), (fb, direct[1])] {
                let solved: f64 = (0..3)
                    .map(|c| {
                        weights[r][c][0] * m[c]
                            + weights[r][c][1] * x[c]
                            + weights[r][c][2] * anchor[c]
                    })
                    .sum();
                let error = (solved - expected).abs() / expected.abs().max(1.0);
                assert!(
                    error < 1e-9,
                    "case {case}, corner {r}: {solved} against {expected}"
                );
            }
            // The held corner gets no solution from the triangle.
            assert_eq!(weights[held], [[0.0; 3]; 3]);
        }
    }

    #[test]
    fn a_row_between_two_creases_is_smoothed_with_its_triangles_solved_beside_them() {
        // A flat grid with noise along z, and two straight creases along the rows y = 4 and
        // y = 6. Every triangle of row 5 touches one of them: left unsolved (as the boundary's
        // are) they would leave row 5's noise as it is.
        let n = 10usize;
        let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
        let mut mesh = crate::mesh::fixtures::grid(n);
        for (v, p) in mesh.positions.iter_mut().enumerate() {
            let (x, y) = (v % (n + 1), v / (n + 1));
            p[2] = (((x * 7 + y * 13) % 11) as f32 - 5.0) * 0.04;
        }
        let topology = Topology::build(&mesh);
        let mut class = vec![FeatureClass::Smooth; mesh.positions.len()];
        let mut edges = Vec::new();
        for y in [4, 6] {
            for x in 0..=n {
                let end = x == 0 || x == n;
                class[at(x, y) as usize] = if end {
                    FeatureClass::Corner
                } else {
                    FeatureClass::Crease
                };
                if x < n {
                    edges.push([at(x, y), at(x + 1, y)]);
                }
            }
        }
        let creases = Creases::from_classified(edges, class);
        let row_noise = |positions: &[[f32; 3]]| -> f32 {
            (1..n)
                .map(|x| positions[at(x, 5) as usize][2].abs())
                .sum::<f32>()
                / (n - 1) as f32
        };
        let mut positions = mesh.positions.clone();
        let before = row_noise(&positions);
        let mut fairing = ConstrainedFairing::with_creases(
            &mesh,
            &topology,
            FairVariant::NormalProjected,
            BoundaryMode::Fixed,
            &creases,
        );
        let options = FairOptions {
            iterations: 10,
            rounds: 5,
            variant: FairVariant::NormalProjected,
            ..Default::default()
        };
        fairing.run(&mut positions, &options);
        let after = row_noise(&positions);
        assert!(before > 0.05, "the row starts noisy: {before}");
        assert!(after < 0.5 * before, "row 5: mean |z| {before} -> {after}");
    }

    #[test]
    fn eq7_literal_form_equals_precomputed_form() {
        // P = A⁻¹Q + A⁻¹A⁻ᵀBᵀ(C − BA⁻¹Q)/‖BA⁻¹‖², evaluated literally, one coordinate.
        let n = [5, 6, 7];
        let a = umbrella_local_matrix(n);
        let inv = invert3(&a).unwrap();
        let q = [0.3, -1.2, 2.5];
        let c = 0.7;
        let ainv_q: [f64; 3] = std::array::from_fn(|r| (0..3).map(|k| inv[r][k] * q[k]).sum());
        let b_ainv: [f64; 3] = std::array::from_fn(|k| (0..3).map(|r| inv[r][k]).sum());
        let norm2: f64 = b_ainv.iter().map(|x| x * x).sum();
        let ainv_ainvt_bt: [f64; 3] =
            std::array::from_fn(|r| (0..3).map(|k| inv[r][k] * b_ainv[k]).sum());
        let residual = c - ainv_q.iter().sum::<f64>();
        let literal: [f64; 3] =
            std::array::from_fn(|r| ainv_q[r] + ainv_ainvt_bt[r] * residual / norm2);
        let q3 = [[q[0], 0.0, 0.0], [q[1], 0.0, 0.0], [q[2], 0.0, 0.0]];
        let p = LocalOperator::umbrella(n)
            .unwrap()
            .solve(&q3, [c, 0.0, 0.0]);
        for r in 0..3 {
            assert!((p[r][0] - literal[r]).abs() < 1e-14);
        }
    }

    /// A small irregular closed mesh: an octahedron subdivided irregularly, with bumps.
    fn irregular_sphere() -> TriMesh {
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
    fn fan_order_follows_the_faces() {
        let mesh = irregular_sphere();
        let topology = Topology::build(&mesh);
        for v in 0..mesh.positions.len() as u32 {
            let mut fan = vec![0u32; topology.valence(v)];
            assert!(
                closed_fan(v, &topology, &mesh.triangles, &mut fan),
                "closed manifold"
            );
            for k in 0..fan.len() {
                let (a, b) = (fan[k], fan[(k + 1) % fan.len()]);
                assert!(mesh.triangles.iter().any(
                    |t| (0..3).any(|r| t[r] == v && t[(r + 1) % 3] == a && t[(r + 2) % 3] == b)
                ));
            }
        }
    }

    /// The set-up deduplicates the weight rows in the mesh's order and renumbers them in the
    /// internal order: that must be exactly what deduplicating the permuted rows gives (the
    /// same table, in the same order, and the same index), with narrow and wide indices.
    #[test]
    fn rows_deduplicated_then_renumbered_are_the_permuted_rows_deduplicated() {
        let mut rng = Rng(7);
        for distinct in [37usize, 70_001] {
            let rows: Vec<[f32; 4]> = (0..150_000)
                .map(|_| {
                    let i = (rng.next() * distinct as f64) as usize;
                    [i as f32, 0.25 * i as f32, -(i as f32), 0.0]
                })
                .collect();
            // A permutation of the entries (the internal order moves whole rings; any
            // permutation must do).
            let mut order: Vec<usize> = (0..rows.len()).collect();
            for i in (1..order.len()).rev() {
                order.swap(i, (rng.next() * (i + 1) as f64) as usize);
            }
            let permuted: Vec<[f32; 4]> = order.iter().map(|&e| rows[e]).collect();
            let expected = deduplicate_rows(&permuted);

            let (mesh_rows, mesh_index) = deduplicate_rows(&rows);
            let wide = |index: &EntryWeightIndex| -> Vec<u32> {
                match index {
                    EntryWeightIndex::Narrow(i) => i.iter().map(|&k| k as u32).collect(),
                    EntryWeightIndex::Wide(i) => i.clone(),
                }
            };
            let mesh_index = wide(&mesh_index);
            let permuted_index = order.iter().map(|&e| mesh_index[e]).collect();
            let got = renumber_by_first_use(&mesh_rows, permuted_index);
            // The mesh-order table is in another order (else the renumbering would be moot).
            assert_ne!(mesh_rows, expected.0);
            assert_eq!(got.0, expected.0, "{distinct} distinct rows");
            assert_eq!(got.1, expected.1, "{distinct} distinct rows");
        }
    }

    #[test]
    fn deduplicated_rows_map_back_to_every_row_with_either_index_width() {
        let row = |i: usize| [i as f32, 0.5 * i as f32, -(i as f32), 0.0];
        // Few distinct rows, repeated across the parallel chunks: two-byte indices.
        let rows: Vec<[f32; 4]> = (0..200_000).map(|i| row(i % 37)).collect();
        let (distinct, index) = deduplicate_rows(&rows);
        assert_eq!(distinct.len(), 37);
        // First appearance order.
        assert!(distinct.iter().enumerate().all(|(i, d)| *d == row(i)));
        let EntryWeightIndex::Narrow(index) = index else {
            panic!("37 rows need no wide index");
        };
        assert!(rows
            .iter()
            .zip(&index)
            .all(|(r, &i)| distinct[i as usize] == *r));
        // More than 65536 distinct rows: four-byte indices.
        let rows: Vec<[f32; 4]> = (0..150_000).map(|i| row((i * 7) % 70_001)).collect();
        let (distinct, index) = deduplicate_rows(&rows);
        assert_eq!(distinct.len(), 70_001);
        let EntryWeightIndex::Wide(index) = index else {
            panic!("70001 rows need a wide index");
        };
        assert!(rows
            .iter()
            .zip(&index)
            .all(|(r, &i)| distinct[i as usize] == *r));
    }

    #[test]
    fn a_vertex_with_no_interior_triangle_keeps_its_position() {
        // A fan of 6 triangles around a centre: every triangle touches the boundary, so the centre
        // has no local solution and must stay (the pseudocode would move it to the origin).
        let mut positions = vec![[0.3f32, 0.2, 0.5]];
        for i in 0..6 {
            let a = i as f32 / 6.0 * std::f32::consts::TAU;
            positions.push([a.cos(), a.sin(), 0.0]);
        }
        let triangles = (0..6u32).map(|i| [0, 1 + i, 1 + (i + 1) % 6]).collect();
        let mut mesh = TriMesh::new(positions, triangles);
        let topology = Topology::build(&mesh);
        for variant in [FairVariant::Paper, FairVariant::NormalProjected] {
            let before = mesh.positions.clone();
            fair_constrained(
                &mut mesh,
                &topology,
                &FairOptions {
                    boundary: BoundaryMode::Fixed,
                    variant,
                    ..Default::default()
                },
            );
            assert_eq!(mesh.positions, before);
        }
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
        for variant in [FairVariant::Paper, FairVariant::NormalProjected] {
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

    #[test]
    fn edges_changed_counts_the_edges_in_one_set_only_in_any_order() {
        let a = [[3, 9], [0, 1], [2, 5], [1, 4]];
        let b = [[1, 4], [7, 8], [0, 1], [2, 6], [9, 10]];
        // Only in a: [3, 9], [2, 5]; only in b: [7, 8], [2, 6], [9, 10].
        assert_eq!(edges_changed(&a, &b), 5);
        assert_eq!(edges_changed(&b, &a), 5);
        assert_eq!(edges_changed(&a, &a), 0);
        assert_eq!(edges_changed(&a, &[]), 4);
    }

    #[test]
    fn a_run_in_the_locality_order_sees_the_mesh_renumbered_and_gives_back_its_positions() {
        // The irregular sphere with its vertices shuffled, so the locality order is not the
        // input's.
        let sphere = irregular_sphere();
        let n = sphere.positions.len();
        let shuffle: Vec<u32> = (0..n as u32).map(|i| (i * 37 + 11) % n as u32).collect();
        let mut sorted = shuffle.clone();
        sorted.sort_unstable();
        assert!(
            sorted.iter().enumerate().all(|(i, &v)| v == i as u32),
            "37 divides {n}"
        );
        let mut positions = vec![[0.0f32; 3]; n];
        for (old, &new) in shuffle.iter().enumerate() {
            positions[new as usize] = sphere.positions[old];
        }
        let triangles = sphere
            .triangles
            .iter()
            .map(|t| t.map(|v| shuffle[v as usize]))
            .collect();
        let mesh = TriMesh::new(positions, triangles);
        let topology = Topology::build(&mesh);
        // Vertices are told apart by their positions (all distinct on this sphere).
        let key = |p: [f32; 3]| p.map(f32::to_bits);
        let pinned: Vec<bool> = (0..n).map(|v| v % 7 == 0).collect();
        let file_edges: Vec<[u32; 2]> = (0..n as u32)
            .step_by(5)
            .flat_map(|a| topology.neighbors(a).iter().map(move |&b| [a, b]))
            .filter(|[a, b]| a < b)
            .collect();
        let edge_keys = |mesh: &TriMesh, edges: &[[u32; 2]]| {
            let mut keys: Vec<_> = edges
                .iter()
                .map(|e| {
                    let [a, b] = e.map(|v| key(mesh.positions[v as usize]));
                    [a.min(b), a.max(b)]
                })
                .collect();
            keys.sort_unstable();
            keys
        };
        let triangle_keys = |mesh: &TriMesh| {
            let mut keys: Vec<_> = mesh
                .triangles
                .iter()
                .map(|t| {
                    // Rotated to start at the least corner: the winding is kept.
                    let k = t.map(|v| key(mesh.positions[v as usize]));
                    let first = (0..3).min_by_key(|&i| k[i]).unwrap();
                    [k[first], k[(first + 1) % 3], k[(first + 2) % 3]]
                })
                .collect();
            keys.sort_unstable();
            keys
        };
        let options = FairOptions::default().with_creases(Some(
            CreaseOptions::default().with_file_edges(file_edges.clone()),
        ));
        let moved = |p: [f32; 3]| [p[0] * 2.0, p[1] + 1.0, -p[2]];
        let mut faired = mesh.clone();
        let report = in_local_order(
            &mut faired,
            &topology,
            &options,
            &pinned,
            |local, local_topology, local_options, local_pinned| {
                assert_ne!(local.positions, mesh.positions, "the order changed nothing");
                assert_eq!(triangle_keys(local), triangle_keys(&mesh));
                let from = |p: [f32; 3]| mesh.positions.iter().position(|&q| key(q) == key(p));
                for (v, &p) in local.positions.iter().enumerate() {
                    assert_eq!(
                        local_pinned[v],
                        pinned[from(p).unwrap()],
                        "pinned flag of {v}"
                    );
                }
                let local_edges = &local_options.creases.as_ref().unwrap().file_edges;
                assert!(local_edges.iter().all(|[a, b]| a < b));
                assert_eq!(edge_keys(local, local_edges), edge_keys(&mesh, &file_edges));
                assert_eq!(
                    local_topology.neighbor_csr(),
                    Topology::build(local).neighbor_csr()
                );
                // Faces in order of their lowest corner.
                let lowest = |t: &[u32; 3]| t[0].min(t[1]).min(t[2]);
                assert!(local
                    .triangles
                    .windows(2)
                    .all(|w| lowest(&w[0]) <= lowest(&w[1])));
                for p in &mut local.positions {
                    *p = moved(*p);
                }
                FairReport {
                    rounds_run: 7,
                    ..FairReport::default()
                }
            },
        );
        assert_eq!(report.rounds_run, 7);
        for (after, &before) in faired.positions.iter().zip(&mesh.positions) {
            assert_eq!(*after, moved(before));
        }
        assert_eq!(faired.triangles, mesh.triangles);
    }

    #[test]
    fn an_operator_set_up_again_for_other_creases_is_the_one_set_up_afresh() {
        use crate::fairing::creases::{detect_creases, CreaseOptions};
        let mesh = crate::mesh::shapes::cylinder(1.0, 1.0, 0.1);
        let topology = Topology::build(&mesh);
        let fans = FanRings::new(&mesh.triangles, &topology);
        let options = |angle_degrees| CreaseOptions {
            angle_degrees,
            ..CreaseOptions::default()
        };
        // The rims only, and the rims with the side's facet edges too.
        let sharp = detect_creases(&mesh, &topology, &options(40.0));
        let faint = detect_creases(&mesh, &topology, &options(3.0));
        assert!(!sharp.is_empty() && faint.edges.len() > sharp.edges.len());
        let noisy: Vec<[f32; 3]> = mesh
            .positions
            .iter()
            .enumerate()
            .map(|(v, p)| {
                let bump = ((v * 29) % 13) as f32 * 0.004 - 0.024;
                [p[0] + bump, p[1] - bump, p[2] + 0.5 * bump]
            })
            .collect();
        for variant in [FairVariant::Paper, FairVariant::NormalProjected] {
            let run_options = FairOptions {
                iterations: 3,
                rounds: 1,
                variant,
                ..Default::default()
            };
            let set_up = |creases: Option<&Creases>| {
                let mut fairing = ConstrainedFairing::with_fans(
                    &mesh,
                    &topology,
                    &fans,
                    variant,
                    BoundaryMode::Curve,
                    creases,
                    &[],
                );
                fairing.set_tangential_relaxation(0.3);
                fairing
            };
            // Every entry's weight row, whatever the numbering of the distinct rows.
            let entry_rows = |fairing: &ConstrainedFairing| -> Vec<[f32; 4]> {
                let row = |i: usize| fairing.entry_weights[i];
                match &fairing.entry_weight_index {
                    EntryWeightIndex::Narrow(index) => {
                        index.iter().map(|&i| row(i.into())).collect()
                    }
                    EntryWeightIndex::Wide(index) => {
                        index.iter().map(|&i| row(i as usize)).collect()
                    }
                }
            };
            // Updated in place (fraction 1: whatever changed) and set up whole (0).
            for fraction in [1, 0] {
                let mut again = set_up(Some(&sharp));
                for creases in [Some(&faint), None, Some(&sharp), Some(&faint)] {
                    let mut afresh = set_up(creases);
                    again = again.for_other_creases_within(
                        &mesh,
                        &topology,
                        &fans,
                        creases,
                        &[],
                        fraction,
                    );
                    assert_eq!(again.held, afresh.held);
                    assert_eq!(again.order, afresh.order);
                    assert_eq!(again.ring_offsets, afresh.ring_offsets);
                    assert_eq!(again.ring, afresh.ring);
                    assert_eq!(entry_rows(&again), entry_rows(&afresh));
                    if fraction == 0 {
                        assert_eq!(again.entry_weight_index, afresh.entry_weight_index);
                        assert_eq!(again.entry_weights, afresh.entry_weights);
                    }
                    assert_eq!(again.self_weights, afresh.self_weights);
                    assert_eq!(again.closed_fan, afresh.closed_fan);
                    assert_eq!(again.solved_vertices, afresh.solved_vertices);
                    assert_eq!(again.curves, afresh.curves);
                    let (mut a, mut b) = (noisy.clone(), noisy.clone());
                    again.run(&mut a, &run_options);
                    afresh.run(&mut b, &run_options);
                    assert_eq!(a, b);
                    assert_ne!(a, noisy);
                }
            }
        }
    }
}
