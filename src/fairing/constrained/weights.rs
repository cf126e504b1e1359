//! The operator's set-up (section 3.2, "How it is computed" in the parent module): every
//! vertex's averaged local solutions folded into one weight row (umbrella mean, position,
//! anchor) per one-ring entry, the rows deduplicated (a mesh has few distinct ones) and renumbered
//! for the locality order ([`Layout`]); the curves the curve operator of section 3.3 moves; and
//! the update of an operator for other creases ([`ConstrainedFairing::for_other_creases`]).

use super::kernel::{EntryWeightIndex, Workspace};
use super::operator::{corner_weights, held_corner_weights, triangle_solve, LocalSolve};
use super::rows::{deduplicate_chunk, join_deduplicated, renumber_by_first_use, row_key, RowMap};
use super::ConstrainedFairing;
use crate::fairing::boundary::BoundaryCurves;
use crate::fairing::creases::{Creases, FeatureClass};
use crate::fairing::{BoundaryMode, FairVariant};
use crate::mesh::{
    breadth_first_order, inverse_permutation, split_into_vertex_blocks, FanRings, Topology,
    TriMesh, VERTEX_BLOCK,
};
use rayon::prelude::*;
use std::collections::HashMap;

/// Valences below this index a dense table of local operators; larger ones are computed on the fly.
const TABLE_VALENCE: usize = 32;
/// The locality order is sorted by valence within blocks of this many vertices, so that the
/// gather loops run the same trip count many times in a row and their exits are predicted (about
/// 40% less CPU time per iteration on a mesh of mixed valences; blocks of 64 to 512 measured
/// alike, see `docs/measurements.md`). Neighbours stay within a block of each other.
const VALENCE_SORTED_BLOCK: usize = 256;
/// Meshes with more vertices than this keep the plain breadth-first order. The sort pays while an
/// iteration's arrays (about 240 bytes a vertex) stay in the cache; beyond it, each pass streams
/// them from memory, and the gathers only keep up while consecutive vertices' neighbours lie in
/// ascending order, which the hardware prefetcher follows and the sort scrambles: an irregular
/// 450k-vertex mesh iterates twice as fast unsorted, an 83k one a quarter faster sorted
/// (`docs/measurements.md`).
const VALENCE_SORT_MAX_VERTICES: usize = 100_000;

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
    /// order, its blocks sorted by valence unless the mesh is large
    /// ([`VALENCE_SORT_MAX_VERTICES`]).
    fn new(ring_offsets: &[u32], ring: &[u32]) -> Layout {
        let vertex_count = ring_offsets.len() - 1;
        let mut order = breadth_first_order(ring_offsets, ring);
        if vertex_count <= VALENCE_SORT_MAX_VERTICES {
            for block in order.chunks_mut(VALENCE_SORTED_BLOCK) {
                block.sort_by_key(|&v| ring_offsets[v as usize + 1] - ring_offsets[v as usize]);
            }
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

impl ConstrainedFairing {
    /// [`Self::new`] for a caller that already has the mesh's fan-ordered one-rings; `creases`
    /// kept as in [`Self::with_creases`]; the vertices flagged in `pinned` (empty: none) held
    /// where they are, like fixed boundary vertices ([`crate::fairing::mask`]).
    pub(crate) fn with_fans(
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        variant: FairVariant,
        boundary: BoundaryMode,
        creases: Option<&Creases>,
        pinned: &[bool],
    ) -> Self {
        let spec = Spec {
            mesh,
            topology,
            fans,
            variant,
            boundary,
            creases,
            pinned,
        };
        Self::set_up(&spec, None)
    }

    /// Sets this operator up again for other `creases` on the same connectivity (`mesh`,
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
        &mut self,
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        creases: Option<&Creases>,
        pinned: &[bool],
    ) {
        self.for_other_creases_within(mesh, topology, fans, creases, pinned, 8);
    }

    /// [`Self::for_other_creases`], updating in place while at most 1/`fraction` of the vertices
    /// changed (0: never; the tests take both ways).
    fn for_other_creases_within(
        &mut self,
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        creases: Option<&Creases>,
        pinned: &[bool],
        fraction: usize,
    ) {
        let spec = Spec {
            mesh,
            topology,
            fans,
            variant: self.variant,
            boundary: self.boundary,
            creases: creases.filter(|c| !c.is_empty()),
            pinned,
        };
        let held = held_flags(topology, spec.creases, pinned);
        let changed: Vec<u32> = (0..held.len() as u32)
            .filter(|&v| held[v as usize] != self.held[v as usize])
            .collect();
        if fraction == 0 || changed.len() * fraction > held.len() {
            self.set_up_again(&spec);
        } else {
            self.update_rows(&spec, held, &changed);
        }
    }

    /// The whole set-up for `spec`, keeping this operator's locality order, one-rings and
    /// tangential relaxation.
    fn set_up_again(&mut self, spec: &Spec) {
        let tangential = self.tangential;
        let layout = Layout {
            order: std::mem::take(&mut self.order),
            internal: std::mem::take(&mut self.internal),
            offsets: std::mem::take(&mut self.ring_offsets),
            ring: std::mem::take(&mut self.ring),
        };
        *self = Self::set_up(spec, Some(layout));
        self.tangential = tangential;
    }

    /// This operator with `held` (the vertices `spec` holds) in place of its own held vertices:
    /// the rows of the vertices in `changed` and of their neighbours gathered again, their
    /// solved flags and fans updated, the curves made again.
    fn update_rows(&mut self, spec: &Spec, held: Vec<bool>, changed: &[u32]) {
        let Spec {
            mesh,
            topology,
            fans,
            pinned,
            ..
        } = *spec;
        let mut affected: Vec<u32> = changed
            .iter()
            .flat_map(|&v| std::iter::once(v).chain(topology.neighbors(v).iter().copied()))
            .collect();
        affected.sort_unstable();
        affected.dedup();
        let (ring_offsets, _) = topology.neighbor_csr();
        let triangles = &mesh.triangles;
        // A vertex's rows and whether it is solved, with the triangles solved as `held` says.
        let gather = |v: usize, held: &[bool], rows: &mut Vec<[f32; 4]>| {
            let ring_v = &fans.ring[ring_offsets[v] as usize..ring_offsets[v + 1] as usize];
            rows.resize(ring_v.len(), [0.0; 4]);
            let operator = |f: u32| {
                let t = &triangles[f as usize];
                let valences = t.map(|c| topology.valence(c));
                match triangle_solve(t, held, topology, pinned)? {
                    LocalSolve::AllFree => Some(corner_weights(valences)),
                    // v itself, when it is the held corner, gets no solution from the triangle.
                    LocalSolve::CornerHeld(h) => {
                        (t[h] as usize != v).then(|| held_corner_weights(valences, h))
                    }
                }
            };
            gather_rows(v, ring_v, topology, triangles, operator, rows)
        };
        let mut row_of: RowMap = self
            .entry_weights
            .iter()
            .enumerate()
            .map(|(i, row)| (row_key(row), i as u32))
            .collect();
        let mut rows = Vec::new();
        for &v in &affected {
            let v = v as usize;
            let (_, was_solved) = gather(v, &self.held, &mut rows);
            let (own, solved) = gather(v, &held, &mut rows);
            self.solved_vertices =
                self.solved_vertices + usize::from(solved) - usize::from(was_solved);
            let i = self.internal[v] as usize;
            self.self_weights[i] = own;
            self.closed_fan[i] = fans.closed_fan[v] && solved;
            let first = self.ring_offsets[i] as usize;
            for (k, row) in rows.iter().enumerate() {
                self.set_entry_row(first + k, row, &mut row_of);
            }
        }
        self.curves = fairing_curves(topology, self.boundary, spec.creases, &self.internal);
        self.held = held;
    }

    /// Gives one-ring entry `entry` the weight row `row`: its index among the distinct rows
    /// (`row_of`), added to them if it is new (the index widened past 65536 rows).
    fn set_entry_row(&mut self, entry: usize, row: &[f32; 4], row_of: &mut RowMap) {
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
            EntryWeightIndex::Narrow(narrow) => narrow[entry] = index as u16,
            EntryWeightIndex::Wide(wide) => wide[entry] = index,
        }
    }

    /// The operator `spec` asks for: every vertex's rows gathered ([`gather_all_rows`]), then
    /// moved into the locality order (`layout`, or a new one).
    fn set_up(spec: &Spec, layout: Option<Layout>) -> Self {
        let Spec {
            mesh,
            topology,
            fans,
            variant,
            boundary,
            pinned,
            ..
        } = *spec;
        let vertex_count = mesh.positions.len();
        // Crease vertices and corners, and pinned vertices, bound the surface patches like
        // boundary vertices do: they get no local solution and their triangles are not solved,
        // but for those with a single crease corner, solved with it held ([`triangle_solve`]).
        let creases = spec.creases.filter(|c| !c.is_empty());
        let held = held_flags(topology, creases, pinned);
        let ring_offsets = topology.neighbor_csr().0.to_vec();
        let (ring, closed) = (&fans.ring, &fans.closed_fan);
        let table = OperatorTable::new(&mesh.triangles, &held, topology, pinned);
        let GatheredRows {
            rows: mesh_rows,
            index: mesh_index,
            self_weights,
            solved,
        } = gather_all_rows(&table, &mesh.triangles, topology, &ring_offsets, ring);
        drop(table);
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
        // Only the rows' 4-byte index is permuted, never the 16-byte rows themselves. The
        // distinct rows are then renumbered in order of first use in the internal order, as
        // deduplicating the permuted rows numbers them, so the operator is the same bit for bit
        // and its table is read in order.
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
        let inverse_valence = inverse_valences(&order, topology);
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
}

/// 1/n_v of every vertex `order` lists, in that order (0 for unreferenced vertices).
fn inverse_valences(order: &[u32], topology: &Topology) -> Vec<f32> {
    order
        .iter()
        .map(|&v| match topology.valence(v) {
            0 => 0.0,
            n => 1.0 / n as f32,
        })
        .collect()
}

/// What an operator is set up for: the mesh's connectivity (`topology` built from `mesh`,
/// `fans` its fan-ordered one-rings), the variant and boundary mode, the creases kept (`None`:
/// none) and the vertices pinned (empty: none).
#[derive(Clone, Copy)]
struct Spec<'a> {
    mesh: &'a TriMesh,
    topology: &'a Topology,
    fans: &'a FanRings,
    variant: FairVariant,
    boundary: BoundaryMode,
    creases: Option<&'a Creases>,
    pinned: &'a [bool],
}

/// The local operators of the valence triples that occur, and each triangle's slot among them
/// (`u32::MAX`: not solved), found once per triangle rather than once per corner. Triples below
/// [`TABLE_VALENCE`] are looked up in a dense table, larger ones get an operator of their own, and
/// so do the (few) triangles solved with a crease corner held, per triple and held corner.
struct OperatorTable {
    /// Per operator, the weights corner r's solution gives corner c's umbrella mean, position
    /// and anchor: G_rc, G_rc/n_c − Σ_c' G_rc'/n_c' and h_r (see "How it is computed" in the
    /// parent module).
    operators: Vec<[[[f64; 3]; 3]; 3]>,
    /// Per operator, the corner it holds (3: none).
    operator_held: Vec<u8>,
    /// Per triangle, its operator (`u32::MAX`: not solved).
    triangle_operator: Vec<u32>,
}

impl OperatorTable {
    /// The operators of `triangles` with the vertices flagged in `held` held (see
    /// [`triangle_solve`]).
    fn new(
        triangles: &[[u32; 3]],
        held: &[bool],
        topology: &Topology,
        pinned: &[bool],
    ) -> OperatorTable {
        let valence = |v: u32| topology.valence(v);
        let table_index = |n: [usize; 3]| (n[0] * TABLE_VALENCE + n[1]) * TABLE_VALENCE + n[2];
        let triangle_valences: Vec<Option<([usize; 3], LocalSolve)>> = triangles
            .par_iter()
            .map(|t| triangle_solve(t, held, topology, pinned).map(|h| (t.map(valence), h)))
            .collect();
        let mut table_slot = vec![u32::MAX; TABLE_VALENCE * TABLE_VALENCE * TABLE_VALENCE];
        let mut held_corner_slot: HashMap<([usize; 3], usize), u32> = HashMap::new();
        let mut operators: Vec<[[[f64; 3]; 3]; 3]> = Vec::new();
        let mut operator_held: Vec<u8> = Vec::new();
        let mut operator_slot = |(n, solve): ([usize; 3], LocalSolve)| -> u32 {
            if let LocalSolve::CornerHeld(h) = solve {
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
        OperatorTable {
            operators,
            operator_held,
            triangle_operator,
        }
    }

    /// Face `f`'s corner weights for its corner `v`, `None` when the face is not solved or `v`
    /// is its held corner (which gets no solution from it).
    fn for_corner(&self, triangles: &[[u32; 3]], f: u32, v: usize) -> Option<&[[[f64; 3]; 3]; 3]> {
        let slot = self.triangle_operator[f as usize];
        (slot != u32::MAX
            && triangles[f as usize].get(self.operator_held[slot as usize] as usize)
                != Some(&(v as u32)))
        .then(|| &self.operators[slot as usize])
    }
}

/// Every vertex's weight rows (mesh numbering), deduplicated: see [`gather_all_rows`].
struct GatheredRows {
    /// The distinct rows, in order of first appearance.
    rows: Vec<[f32; 4]>,
    /// Per one-ring entry (laid out by the topology's one-ring offsets), its row's index.
    index: Vec<u32>,
    /// Per vertex: the weights of its own umbrella mean, position and anchor.
    self_weights: Vec<[f32; 3]>,
    /// Per vertex: whether it gets at least one local solution.
    solved: Vec<bool>,
}

/// Per vertex, the weights of its triangles' solutions (f64, then rounded; [`gather_rows`]), one
/// row (mean, position, anchor, 0) per one-ring entry (`ring`, laid out by `ring_offsets`). In
/// blocks of vertices, each block's rows deduplicated as soon as they are gathered: the 16-byte
/// rows of the whole mesh are never held at once, only a 4-byte index per entry and the few
/// distinct rows (the rows are a function of the valences around the vertex, so they repeat).
fn gather_all_rows(
    table: &OperatorTable,
    triangles: &[[u32; 3]],
    topology: &Topology,
    ring_offsets: &[u32],
    ring: &[u32],
) -> GatheredRows {
    let vertex_count = ring_offsets.len() - 1;
    let mut self_weights = vec![[0.0f32; 3]; vertex_count];
    let mut solved = vec![false; vertex_count];
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
                let ring_v = &ring[ring_offsets[v] as usize..ring_offsets[v + 1] as usize];
                let entries = ring_offsets[v] as usize - base..ring_offsets[v + 1] as usize - base;
                let operator = |f: u32| table.for_corner(triangles, f, v);
                (*own_out, *solved_out) =
                    gather_rows(v, ring_v, topology, triangles, operator, &mut rows[entries]);
            }
            deduplicate_chunk(&rows)
        })
        .collect();
    let (rows, index) = join_deduplicated(blocks);
    GatheredRows {
        rows,
        index,
        self_weights,
        solved,
    }
}

/// The vertices (mesh numbering) that bound the surface patches like boundary vertices do: the
/// boundary's, the creases' (their vertices and corners) and the pinned ones.
pub(super) fn held_flags(
    topology: &Topology,
    creases: Option<&Creases>,
    pinned: &[bool],
) -> Vec<bool> {
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

/// Vertex `v`'s weights: the mean of its solved triangles' corner weights (f64, then rounded),
/// one row (mean, position, anchor, 0) per entry of its one-ring `ring_v` into
/// `ring_weights_v`; returns its own weights and whether it is solved. `operator(f)` gives face
/// f's corner weights, `None` for a face that is not solved. A vertex with no solved face keeps
/// its position (own weights (0, 1, 0), ring weights 0) and is not solved.
fn gather_rows<W>(
    v: usize,
    ring_v: &[u32],
    topology: &Topology,
    triangles: &[[u32; 3]],
    operator: impl Fn(u32) -> Option<W>,
    ring_weights_v: &mut [[f32; 4]],
) -> ([f32; 3], bool)
where
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
    if count == 0 {
        // No local solution: the vertex keeps its position (ring weights stay 0).
        ring_weights_v.fill([0.0; 4]);
        return ([0.0, 1.0, 0.0], false);
    }
    let inv = 1.0 / count as f64;
    for (out, e) in ring_weights_v.iter_mut().zip(entries.iter()) {
        *out = [
            (e[0] * inv) as f32,
            (e[1] * inv) as f32,
            (e[2] * inv) as f32,
            0.0,
        ];
    }
    (own.map(|w| (w * inv) as f32), true)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fairing::FairOptions;

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
            FairVariant::Improved,
            BoundaryMode::Fixed,
            &creases,
        );
        let options = FairOptions {
            iterations: 10,
            rounds: 5,
            variant: FairVariant::Improved,
            ..Default::default()
        };
        fairing.run(&mut positions, &options);
        let after = row_noise(&positions);
        assert!(before > 0.05, "the row starts noisy: {before}");
        assert!(after < 0.5 * before, "row 5: mean |z| {before} -> {after}");
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
        for variant in [FairVariant::Paper, FairVariant::Improved] {
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
                    again.for_other_creases_within(&mesh, &topology, &fans, creases, &[], fraction);
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
