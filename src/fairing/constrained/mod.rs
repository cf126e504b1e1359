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
//!   and e = A_b·K + A_h·x_h − Q, so s = −dᵀe / dᵀd (`operator::held_corner_weights`). Left
//!   unsolved, as the paper leaves the boundary's triangles, they would leave every vertex beside
//!   a crease fewer solutions to average, and on coarse scans (where crease vertices are many)
//!   some with none, so the noise would stay there (`docs/measurements.md`, "Triangles beside a
//!   crease solved"). The triangle's own centroid is not kept instead: the free pair would then
//!   make up for the crease corner's move along its curve and push against it (a rim folds). The
//!   boundary's triangles stay unsolved, as the paper has them.
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
//!   memory), then, on meshes small enough for the cache, sorted by valence within blocks (the
//!   gather loops' exits become predictable; on larger ones the sort would hide the gathers'
//!   ascending order from the hardware prefetcher);
//!   [`ConstrainedFairing::load`] and [`ConstrainedFairing::store`] map between the mesh's
//!   numbering and this one.
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
//!
//! # Files
//! - `operator`: the local operator, eq (7) in closed form, and the corner weights it gives.
//! - `kernel`: one Jacobi iteration (two gather passes) and the workspace it runs in.
//! - `rows`: the deduplicated table of weight rows and its renumbering.
//! - `weights`: the set-up, folding the averaged local solutions into deduplicated weight rows.
//! - `round_steps`: one round and the state the rounds carry (creases, relaxation, risk).
//! - `rounds`: [`fair_constrained`], the driver: strength, creases, rounds, volume, risk.

mod kernel;
mod operator;
mod round_steps;
mod rounds;
mod rows;
mod weights;

pub use operator::{invert3, umbrella_local_matrix, LocalOperator, Matrix3};
pub use rounds::{fair_constrained, fair_constrained_with_progress};

use super::boundary::BoundaryCurves;
use super::creases::Creases;
use super::{BoundaryMode, FairOptions, FairReport, FairVariant};
use crate::mesh::{FanRings, Topology, TriMesh};
use kernel::{EntryWeightIndex, Workspace};

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
    /// with one crease corner and no other held one ([`operator::triangle_solve`]).
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
    /// `report`; how many ran.
    pub fn run_round(&mut self, options: &FairOptions, report: &mut FairReport) -> usize {
        let mut run = 0;
        for _ in 0..options.iterations {
            report.max_move = self.step();
            run += 1;
            if report.max_move < options.tolerance {
                break;
            }
        }
        report.iterations_run += run;
        report.rounds_run += 1;
        run
    }

    /// Exactly `iterations` iterations from the current anchors (one round), counted in
    /// `report`.
    pub fn run_iterations(&mut self, iterations: usize, report: &mut FairReport) {
        for _ in 0..iterations {
            report.max_move = self.step();
        }
        report.iterations_run += iterations;
        report.rounds_run += 1;
    }

    /// Frees the buffers a run works in (80 bytes per vertex: the current state, the anchors and
    /// their terms, the positions with their umbrella means); the next [`Self::load`] allocates
    /// them again. For a caller that keeps many operators and runs one at a time (the editor
    /// keeps one per level of the hierarchy, and these buffers are over half of their memory).
    pub fn release_buffers(&mut self) {
        self.workspace = Workspace::default();
    }
}
