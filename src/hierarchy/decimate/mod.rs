//! Building the decimation hierarchy (paper section 4.1).
//!
//! One level is one pass over the current mesh's vertices in increasing
//! `cost(v) = alpha * min_edge(v) + beta * max_edge(v)` (edge lengths on the current level, ties
//! by vertex id); on levels of 32k vertices or more, in increasing cost *within regions* of the
//! mesh visited in parallel (see "Regions" below, not in the paper). A vertex adjacent to one
//! already removed in this pass is skipped, so the removed vertices of a level form an
//! independent set. A visited vertex `v` tries its neighbours `k` in
//! increasing `(|cone volume|, k)` and performs the first valid half-edge collapse `v -> k`:
//! `x_k` does not move, `v`'s faces that contain `k` disappear, `v` is replaced by `k` in the
//! others. Positions never change during the build.
//!
//! Interpretations (see the repository's `docs/paper.md`):
//! - Cone volume of `v -> k`: `sum over v's faces (v, a, b), in their own orientation, of
//!   ((x_a - x_k) x (x_b - x_k)) . (x_v - x_k)`; faces containing `k` add 0 (the paper's
//!   "⊗" is a cross product). The signed value is six times the volume the matching vertex split
//!   adds back, so on a closed mesh `|cone| = 6 |volume change|` of the collapse. It is kept
//!   (as f32) in the collapse record: the improved multiresolution fairing uses it.
//! - A collapse is refused when: the link condition fails (`N(v) ∩ N(k)` must be exactly the
//!   vertices opposite the edge `vk`); `v` has valence 3 and its other two neighbours already form
//!   a face with `k` (the tetrahedron case, which would leave two coincident faces); `v` is on a
//!   boundary and `vk` is not a boundary edge; `v` is a boundary vertex of a single triangle whose
//!   third edge is also a boundary edge (the loop would vanish); a surviving face would flip or
//!   degenerate (`n_old . n_new <= 0`). These keep every level an oriented 2-manifold with the
//!   Euler characteristic and the boundary loops of M0.
//! - `keep_boundary` leaves boundary vertices in place (interior vertices may still collapse
//!   into them, which does not move them).
//! - A pass stops removing once the level would drop below `min_vertices`; the build stops when a
//!   pass removes nothing, the level has at most `min_vertices` vertices, or `max_levels` is
//!   reached. A pass (after the first) that removes less than one vertex in 20 is dropped and ends
//!   the build: only kept creases make such passes (see below).
//! - Creases (`HierarchyOptions::creases`, not in the paper): a corner never collapses, a crease
//!   vertex collapses only into one of its two neighbours along the crease (the crease then runs
//!   from its other neighbour to that one), and not when those two neighbours are already joined
//!   by an edge (a loop of three would close on itself; where a face holds the three, the split
//!   would put the vertex back on their line and leave the face with no area). So every level
//!   keeps M0's corners and its crease edges, relabelled, and a coarse level of a CAD part still
//!   has its edges. Each vertex's crease neighbours are kept per level in `Level::crease`.
//!
//! - Where the input is not an oriented 2-manifold (found on the first pass's fans: a vertex
//!   whose faces are not one consistently oriented fan: an edge with more than two faces, two
//!   fans meeting at the vertex, faces of opposite orientation), that vertex and its neighbours
//!   stay in every level, so no face at it ever changes and every collapse is between manifold
//!   vertices; the rest of the mesh is decimated as usual (`Hierarchy::non_manifold_vertices`).
//!   Before, one such vertex refused the whole build (a cow from PyMeshLab's test meshes has one).
//!
//! Speed. Each level is a compact mesh: vertices `0..V`, faces `0..F`, positions and M0 ids in
//! flat arrays. M0 enters in Morton order of its positions (faces by their first corner), since
//! visiting in cost order jumps all over the mesh and this keeps a vertex's neighbours near it
//! in memory; every later level keeps the order of the one below, so it stays local, and a pass
//! only touches arrays of its own level's size. Ties in the visiting order and among equal cone
//! volumes go by M0's ids, so the result does not depend on this ordering. A pass:
//! - builds the fans of the level in CSR form (for every face `(v, a, b)` the pair `(a, b)` at
//!   `v`, in face order) by a counting sort;
//! - computes every vertex's cost and whether its fan is open, in parallel: min and max are
//!   taken over squared lengths (square root and rounding to f32 are monotone, so they commute
//!   with min and max), and a fan is open exactly when the sums of its `a`s and its `b`s differ
//!   (see `vertex_costs`); with it, the least and greatest vertex of its one-ring, from which
//!   one more pass gives those of its two-ring (what a region's interior test reads);
//! - visits them (in regions, below), each list of visits sorted by cost (a radix sort on the
//!   cost's bits, ties by M0 id). No face is rewritten during the pass: the removed vertices are
//!   independent, so their collapses touch disjoint face sets and compose as one simultaneous
//!   relabelling `v -> target[v]`. A vertex that is not locked
//!   still has exactly its pass-start fan; the current faces of a collapse target `k` are its
//!   pass-start fan relabelled through this pass's removals (a face that degenerates is gone) plus
//!   the fans of the vertices collapsed into it, chained in `absorbed` lists. The cone volume of
//!   a candidate `k` is `-N . (x_k - x_v)`, with `N` the sum of `v`'s faces' normals taken from
//!   `x_v` (the same as the sum over the faces above: see `choose_collapse`), so the fan is read
//!   once for all candidates, and candidates are taken least first rather than sorted, since
//!   the first is nearly always valid. The fan and link checks compare without early exits, which
//!   would be mispredicted;
//! - writes the next level: survivors keep their order, faces are relabelled, and those that
//!   degenerate are the removed ones.
//!
//! Regions. A visit reads the state (marks, absorbed lists, crease neighbours) of its vertex's
//! two-ring and writes only that of its one-ring. A level of at least `2 * RegionSize::min`
//! vertices is cut into consecutive ranges of its Morton-ordered vertices (compact patches of the
//! surface; at least 16k vertices, at most 64 ranges, a function of the level's size only): first
//! every region visits, in cost order, its *interior* vertices (whose two-ring lies in the
//! region), all regions at once; then the same with the ranges shifted by half a region, for the
//! vertices not visited yet; then the rest (about 6 % on the 1.2M-face bunny) one at a time in
//! cost order. Interior visits of two regions of one round never touch the same state, so the
//! hierarchy is the same for any number of threads (tested). It is not the one-at-a-time
//! hierarchy: a vertex near a region's edge is visited after the interiors, whatever its cost
//! (the levels differ by a fraction of a percent in size; the quality tables in
//! `docs/measurements.md` show multires from every level as good either way). A region's arrays
//! fit in the last-level cache. If the regions alone would take the level below
//! `min_vertices`, the pass is visited again one vertex at a time. Smaller levels are visited one
//! vertex at a time.
//!
//! A level visited in regions also builds its fans and writes the next level in parallel, and M0
//! is sorted in parallel when it is. The counting sorts with many buckets (M0's faces by first
//! corner, every level's fans) run as one block of consecutive buckets per thread, each block
//! reading every item and placing only its own entries (`bucket_sort`); M0's vertices, by the
//! two 15-bit digits of their Morton codes, as one chunk of items per thread, each counting its
//! own digits (`digit_sort`: the keys are in no order, so blocks reading every key mispredicted
//! half their branches); the next level is written in chunks of a region's least size (each
//! chunk counts what it keeps, the running sums place it); the per-pass arrays are filled and
//! the removals recorded in parallel too. All give the same arrays for any number of threads.
//!
//! # Files
//! - `levels`: M0 as the first level, and the level after a pass's collapses.
//! - `collapse`: one visit, choosing and checking a vertex's collapse.
//! - `sort`: the parallel counting and radix sorts the passes and levels use.
//! - This file: the passes (costs, regions, visits, fans) and the build's output. Its pass
//!   driver (`passes`) and the level and collapse kernels stay long where one loop reads as one
//!   step over the level's arrays.

mod collapse;
mod levels;
mod sort;

use super::{HierarchyError, HierarchyOptions};
use crate::clock::Instant;
use crate::fairing::creases::{Creases, FeatureClass};
use crate::mesh::TriMesh;
use crate::Progress;
use collapse::{visit, PassView, Scratch};
use glam::DVec3;
use levels::{first_level, next_level};
use rayon::prelude::*;
use sort::{
    bucket_sort, digit_sort, running_starts, sort_by_first, split_by_lengths, SortedBuckets,
};
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering::Relaxed};

pub(super) const NEVER: u32 = u32::MAX;

/// What the build found, in M0's vertex and face numbering.
pub(super) struct BuildOutput {
    /// Pass in which each vertex was removed (`NEVER` if it survives to the coarsest level).
    pub removed_in_pass: Vec<u32>,
    /// Collapse target of each removed vertex (`NEVER` otherwise).
    pub target: Vec<u32>,
    /// Signed cone volume (six times the volume its split adds back) of each removed vertex.
    pub six_split_volume: Vec<f32>,
    /// Pass in which each face disappeared (`NEVER` if it survives).
    pub face_removed_in_pass: Vec<u32>,
    /// Milliseconds each pass took.
    pub pass_ms: Vec<f64>,
    /// M0 ids of the vertices whose faces are not one oriented fan (ascending): they and their
    /// neighbours stay in every level.
    pub non_manifold: Vec<u32>,
    /// M0's vertices that some face uses, and its faces, in the first level's order (Morton
    /// order of the positions; faces by their first corner): the order the hierarchy keeps
    /// within each level's share, so that neighbours lie near each other in memory.
    pub vertex_sequence: Vec<u32>,
    pub face_sequence: Vec<u32>,
}

/// A pass that removes fewer than one vertex in this many ends the build, without its level.
const MIN_PASS_SHARE: usize = 20;

/// Visits between two progress reports.
const REPORT_EVERY: usize = 4096;

/// `Ok(None)`: `stop_if_non_manifold` was set and the first pass found a vertex whose faces are
/// not one oriented fan (the caller looks for loose triangles and builds again).
pub(super) fn build(
    mesh: &TriMesh,
    creases: Option<&Creases>,
    options: &HierarchyOptions,
    stop_if_non_manifold: bool,
    progress: &mut dyn Progress,
) -> Result<Option<BuildOutput>, HierarchyError> {
    // As a pass does (see `passes`), M0 is sorted in parallel when it is visited in regions.
    let parallel = options.regions.for_level(mesh.vertex_count()).is_some();
    match passes(
        mesh,
        first_level(mesh, creases, parallel),
        options,
        stop_if_non_manifold,
        progress,
    ) {
        Ok(built) => Ok(Some(built)),
        Err(BuildFailure::NonManifold) => Ok(None),
        Err(BuildFailure::Cancelled) => Err(HierarchyError::Cancelled),
    }
}

enum BuildFailure {
    Cancelled,
    /// Non-manifold vertices, and the caller asked to stop there.
    NonManifold,
}

/// One level during the build, compact: its vertices are `0..V` and its faces `0..F`. M0's
/// vertices are put in Morton order of their positions and its faces in order of their first
/// corner (see `first_level`), and a level keeps the order of the one below, so a pass only
/// touches arrays of its level's size and a vertex's neighbours are near it in memory.
#[derive(Default)]
struct Level {
    points: Vec<[f32; 3]>,
    /// M0 id of each vertex: where its collapse is recorded, and ties in the visiting order and
    /// among equal cone volumes go by it.
    vertex_id: Vec<u32>,
    corners: Vec<[u32; 3]>,
    /// M0 id of each face.
    face_id: Vec<u32>,
    /// Per vertex when creases are kept (empty otherwise): [`NO_CREASE`], [`CORNER`], or the
    /// two neighbours along its crease.
    crease: Vec<[u32; 2]>,
}

/// `Level::crease` of a vertex on no crease.
const NO_CREASE: [u32; 2] = [NEVER; 2];
/// `Level::crease` of a corner, which never collapses.
const CORNER: [u32; 2] = [NEVER - 1; 2];

/// `mark` of a vertex that is neither removed nor locked in the current pass.
const FREE: u32 = u32::MAX;
/// `mark` of a neighbour of a vertex removed in the current pass.
const LOCKED: u32 = u32::MAX - 1;

/// The per-pass arrays, sized for the level and reused from pass to pass.
#[derive(Default)]
struct PassState {
    /// The fans in CSR form: for every face `(v, a, b)` the pair `(a, b)` at `v`, in face order.
    fan_offsets: Vec<u32>,
    fans: Vec<[u32; 2]>,
    cursor: Vec<u32>,
    /// Each vertex's cost, as the bits of a non-negative f32.
    cost: Vec<u32>,
    /// Whether the vertex's fan is open (it is on a boundary).
    open: Vec<bool>,
    /// `FREE`, `LOCKED`, or the collapse target of a vertex removed in this pass. (This and
    /// the next three are atomics only so that regions can be visited at the same time: a
    /// region's visits read and write only its own vertices' entries, with relaxed loads and
    /// stores, which are plain moves.)
    mark: Vec<AtomicU32>,
    /// Vertices collapsed into a vertex during this pass, as linked lists.
    absorbed_head: Vec<AtomicU32>,
    absorbed_next: Vec<AtomicU32>,
    /// `Level::crease` during the pass (empty when creases are not kept).
    crease: Vec<[AtomicU32; 2]>,
    /// The least and the greatest vertex of each vertex's one-ring, itself included.
    ring: Vec<[u32; 2]>,
    /// The same of its two-ring, when the level is visited in regions: a vertex is interior to
    /// a region exactly when both are in it.
    reach: Vec<[u32; 2]>,
    /// Whether a vertex was visited in an earlier round of this pass.
    visited: Vec<bool>,
    /// Id in the next level of every vertex's image (its target's if removed; atomic only so
    /// that chunks of vertices can be labelled at once).
    label: Vec<AtomicU32>,
}

/// The passes, from M0 (given as its first level) up.
fn passes(
    mesh: &TriMesh,
    mut level: Level,
    options: &HierarchyOptions,
    stop_if_non_manifold: bool,
    progress: &mut dyn Progress,
) -> Result<BuildOutput, BuildFailure> {
    let n = mesh.vertex_count();
    let mut out = BuildOutput {
        removed_in_pass: Vec::new(),
        target: Vec::new(),
        six_split_volume: Vec::new(),
        face_removed_in_pass: Vec::new(),
        pass_ms: Vec::new(),
        non_manifold: Vec::new(),
        vertex_sequence: level.vertex_id.clone(),
        face_sequence: level.face_id.clone(),
    };
    // Written by the removals of a pass at once (each vertex is removed once), then moved into
    // `out`; the six split volumes as f32 bits.
    let removed_in_pass = atomics(n, NEVER);
    let target = atomics(n, NEVER);
    let six_split_volume = atomics(n, 0f32.to_bits());
    // M0 ids of the vertices that stay: those whose faces are not one oriented fan, and their
    // neighbours (so no face at such a vertex ever changes, and every collapse is between
    // manifold vertices).
    let mut pinned: Vec<bool> = Vec::new();
    let face_removed_in_pass = atomics(mesh.face_count(), NEVER);
    let isolated = n - level.points.len();
    let mut next = Level::default();
    let mut state = PassState::default();
    let start_vertices = level.points.len() as f64;
    let goal = (start_vertices - options.min_vertices as f64).max(1.0);
    let mut vertex_count = n;
    // M0's area-weighted vertex normals by M0 id, when no collapse may turn a face against them.
    let m0_normals: Vec<[f32; 3]> = if options.keep_orientation {
        mesh.vertex_normals()
            .iter()
            .map(|n| n.as_vec3().to_array())
            .collect()
    } else {
        Vec::new()
    };

    for pass in 0..options.max_levels.max(1) as u32 {
        // Pass 0 always builds its fans, to check the input.
        if pass > 0 && (vertex_count <= options.min_vertices || pass as usize >= options.max_levels)
        {
            break;
        }
        let started = Instant::now();
        let level_vertices = level.points.len();
        // A level visited in regions builds its fans and the next level in parallel too, in
        // chunks of a region's least size.
        let chunk = options
            .regions
            .for_level(level_vertices)
            .map(|_| options.regions.min.max(1));
        build_fans(&level.corners, level_vertices, chunk.is_some(), &mut state);
        if pass == 0 {
            let non_manifold = non_manifold_vertices(&state.fan_offsets, &state.fans);
            if stop_if_non_manifold && !non_manifold.is_empty() {
                return Err(BuildFailure::NonManifold);
            }
            if !non_manifold.is_empty() {
                pinned = vec![false; n];
                for &v in &non_manifold {
                    pinned[level.vertex_id[v] as usize] = true;
                    let fan = &state.fans
                        [state.fan_offsets[v] as usize..state.fan_offsets[v + 1] as usize];
                    for &[a, b] in fan {
                        pinned[level.vertex_id[a as usize] as usize] = true;
                        pinned[level.vertex_id[b as usize] as usize] = true;
                    }
                }
                out.non_manifold = non_manifold.iter().map(|&v| level.vertex_id[v]).collect();
                out.non_manifold.sort_unstable();
            }
            if vertex_count <= options.min_vertices || options.max_levels == 0 {
                break;
            }
        }
        vertex_costs(&level, options, &mut state);

        // How many vertices this pass may remove before the level reaches `min_vertices`.
        let budget = vertex_count.saturating_sub(options.min_vertices);
        let removals = visit_level(
            &mut level,
            &mut state,
            &pinned,
            &m0_normals,
            options,
            budget,
            &mut |removed| {
                let done =
                    (start_vertices - (vertex_count - removed) as f64 + isolated as f64) / goal;
                progress.report(done.clamp(0.0, 1.0) as f32)
            },
        )?;
        let removed = removals.len();
        if removed == 0 {
            break;
        }
        if removed * MIN_PASS_SHARE < level_vertices
            && pass > 0
            && vertex_count - removed > options.min_vertices
        {
            // A level that barely differs from the one below: left out, and the build ends (a
            // last pass cut short by `min_vertices` is kept).
            // (Kept creases make these: once the smooth parts are coarse, only crease vertices
            // can still collapse, a few per pass, and multires from such levels lost volume.)
            break;
        }
        removals
            .par_iter()
            .with_min_len(4096)
            .for_each(|&(v, k, six_volume)| {
                let id = level.vertex_id[v as usize] as usize;
                removed_in_pass[id].store(pass, Relaxed);
                target[id].store(level.vertex_id[k as usize], Relaxed);
                six_split_volume[id].store(six_volume.to_bits(), Relaxed);
            });
        vertex_count -= removed;
        // The next level is written without the fans: they go first, so the two levels' arrays
        // and the fans are never held at once (the next pass builds its own, smaller fans).
        state.fans = Vec::new();
        next_level(
            &mut level,
            &mut state,
            pass,
            removed,
            &face_removed_in_pass,
            chunk,
            &mut next,
        );
        // The level just left goes too, rather than wait as the buffers of the one after next:
        // at any time at most two levels and one set of fans are held, never two levels and
        // fans (the build's heap peak stays below the loader's; the fresh buffers cost no
        // measurable time).
        level = std::mem::take(&mut next);
        out.pass_ms.push(started.elapsed().as_secs_f64() * 1e3);
    }
    // (Atomics only so that the next level's chunks can record their faces at once; the same
    // layout, so this reuses the memory.)
    out.face_removed_in_pass = into_inner(face_removed_in_pass);
    out.removed_in_pass = into_inner(removed_in_pass);
    out.target = into_inner(target);
    out.six_split_volume = into_inner(six_split_volume)
        .into_iter()
        .map(f32::from_bits)
        .collect();
    Ok(out)
}

/// `n` atomics holding `value`, written in parallel.
pub(super) fn atomics(n: usize, value: u32) -> Vec<AtomicU32> {
    (0..n)
        .into_par_iter()
        .with_min_len(1 << 14)
        .map(|_| AtomicU32::new(value))
        .collect()
}

/// `cells` as `n` atomics holding `value`: in place, in parallel, where it has room (the levels
/// shrink from pass to pass), as [`atomics`] otherwise.
fn refill(cells: &mut Vec<AtomicU32>, n: usize, value: u32) {
    if cells.len() < n {
        *cells = atomics(n, value);
    } else {
        cells.truncate(n);
        cells
            .par_iter()
            .with_min_len(1 << 14)
            .for_each(|c| c.store(value, Relaxed));
    }
}

/// The values of `cells` (the same layout, so the memory is reused).
pub(super) fn into_inner(cells: Vec<AtomicU32>) -> Vec<u32> {
    cells.into_iter().map(AtomicU32::into_inner).collect()
}

/// How a level is cut into regions that are visited at the same time: consecutive ranges of its
/// vertices (which are in Morton order, so a range is a compact patch), of at least `min` vertices
/// and at most `max_count` of them. The sizes depend on the level only, never on the number of
/// threads, so the hierarchy does not either.
#[derive(Clone, Copy, Debug)]
pub(super) struct RegionSize {
    pub min: usize,
    pub max_count: usize,
}

impl RegionSize {
    /// Regions of 16k vertices at least (a region's arrays then fit in the last-level cache)
    /// and at most 64 of them (the border share stays small on big meshes).
    pub const DEFAULT: RegionSize = RegionSize {
        min: 16_384,
        max_count: 64,
    };

    /// Vertices per region for a level of `vertices`, or `None` when it is too small for two.
    fn for_level(self, vertices: usize) -> Option<usize> {
        (vertices >= 2 * self.min.max(1))
            .then(|| self.min.max(vertices.div_ceil(self.max_count.max(1))))
    }
}

/// One removal of a pass: the vertex, its collapse target and its six split volume.
type Removal = (u32, u32, f32);

/// Visits the level's vertices and returns the pass's removals.
///
/// In regions (when the level has room for two): in a first round, each region visits its
/// *interior* vertices (those whose two-ring is in the region) in cost order, all regions at
/// once; a second round does the same with regions shifted by half a region, for the vertices
/// not visited yet; the rest are visited in cost order, one at a time. A visit reads the state of
/// its vertex's two-ring and writes only that of its one-ring (marks, absorbed lists, crease
/// neighbours), so interior visits of different regions of one round never meet, and the result
/// is the same for any number of threads. If the regions removed more than `budget` (the level
/// would go below `min_vertices`), the pass is visited again one vertex at a time, as a level
/// too small for regions is: every vertex in cost order, stopping once `budget` are removed.
///
/// Cost order: increasing cost, ties by M0 id. `report` is called now and then with the
/// removals so far; `false` cancels.
fn visit_level(
    level: &mut Level,
    state: &mut PassState,
    pinned: &[bool],
    m0_normals: &[[f32; 3]],
    options: &HierarchyOptions,
    budget: usize,
    report: &mut dyn FnMut(usize) -> bool,
) -> Result<Vec<Removal>, BuildFailure> {
    if !report(0) {
        return Err(BuildFailure::Cancelled);
    }
    let n = level.points.len();
    let mut removals = Vec::new();
    reset_pass(level, state);
    state.visited.clear();
    state.visited.resize(n, false);
    if let Some(size) = options.regions.for_level(n) {
        two_ring_reach(state);
        for offset in [0, size / 2] {
            let view = PassView::new(level, state, pinned, m0_normals, options.keep_boundary);
            let region_count = (n + offset).div_ceil(size);
            let range =
                |r: usize| (r * size).saturating_sub(offset)..((r + 1) * size - offset).min(n);
            let per_region: Vec<(Vec<u32>, Vec<Removal>)> = (0..region_count)
                .into_par_iter()
                .map_init(Scratch::default, |scratch, r| {
                    let range = range(r);
                    let mut order = Vec::new();
                    let interior = range.clone().filter(|&v| {
                        let [lo, hi] = state.reach[v];
                        !state.visited[v]
                            && range.contains(&(lo as usize))
                            && range.contains(&(hi as usize))
                    });
                    in_cost_order(interior, state, level, &mut order, &mut scratch.keys);
                    let removed = order
                        .iter()
                        .filter_map(|&v| visit(v, &view, scratch).map(|(k, vol)| (v, k, vol)))
                        .collect();
                    (order, removed)
                })
                .collect();
            // Each region marks its own range as visited.
            let lengths: Vec<u32> = (0..region_count).map(|r| range(r).len() as u32).collect();
            split_by_lengths(&mut state.visited, &lengths)
                .into_par_iter()
                .zip(&per_region)
                .enumerate()
                .for_each(|(r, (visited, (order, _)))| {
                    let first = range(r).start;
                    for &v in order {
                        visited[v as usize - first] = true;
                    }
                });
            for (_, removed) in per_region {
                removals.extend(removed);
            }
        }
        if removals.len() > budget {
            removals.clear();
            reset_pass(level, state);
            state.visited.fill(false);
        }
    }
    let mut order = Vec::new();
    let rest = (0..n).filter(|&v| !state.visited[v]);
    in_cost_order(rest, state, level, &mut order, &mut Vec::new());
    let view = PassView::new(level, state, pinned, m0_normals, options.keep_boundary);
    let mut scratch = Scratch::default();
    for (visits, &v) in order.iter().enumerate() {
        if visits % REPORT_EVERY == REPORT_EVERY - 1 && !report(removals.len()) {
            return Err(BuildFailure::Cancelled);
        }
        if removals.len() >= budget {
            break;
        }
        if let Some((k, vol)) = visit(v, &view, &mut scratch) {
            removals.push((v, k, vol));
        }
    }
    for (kept, during) in level.crease.iter_mut().zip(&state.crease) {
        *kept = during.each_ref().map(|c| c.load(Relaxed));
    }
    Ok(removals)
}

/// `vertices` in cost order (increasing cost, ties by M0 id) into `order`; `spare` is scratch
/// space.
///
/// A least-significant-digit radix sort on the costs' bits (three digits of 11 bits; a digit
/// every cost shares is skipped), then each run of equal costs sorted by M0 id: runs are short on
/// scans, and a regular mesh's long ones cost what a comparison sort of them costs. (A comparison
/// sort of (cost, id) keys is a measurable part of a big build.)
fn in_cost_order(
    vertices: impl Iterator<Item = usize>,
    state: &PassState,
    level: &Level,
    order: &mut Vec<u32>,
    spare: &mut Vec<[u32; 2]>,
) {
    let mut keyed: Vec<[u32; 2]> = vertices.map(|v| [state.cost[v], v as u32]).collect();
    sort_by_first(&mut keyed, spare);
    for run in keyed.chunk_by_mut(|a, b| a[0] == b[0]) {
        if run.len() > 1 {
            run.sort_unstable_by_key(|&[_, v]| level.vertex_id[v as usize]);
        }
    }
    order.clear();
    order.extend(keyed.iter().map(|&[_, v]| v));
}

/// Each vertex's least and greatest two-ring vertex (into `state.reach`), from the one-rings'.
fn two_ring_reach(state: &mut PassState) {
    let (offsets, fans, ring) = (&state.fan_offsets, &state.fans, &state.ring);
    state.reach.resize(ring.len(), [0; 2]);
    state
        .reach
        .par_iter_mut()
        .enumerate()
        .with_min_len(4096)
        .for_each(|(v, reach)| {
            let fan = &fans[offsets[v] as usize..offsets[v + 1] as usize];
            *reach = fan.iter().flatten().fold(ring[v], |[lo, hi], &x| {
                let [x_lo, x_hi] = ring[x as usize];
                [lo.min(x_lo), hi.max(x_hi)]
            });
        });
}

/// Every vertex free, no absorbed lists, the crease neighbours as the level has them.
fn reset_pass(level: &Level, state: &mut PassState) {
    let n = level.points.len();
    refill(&mut state.mark, n, FREE);
    refill(&mut state.absorbed_head, n, NEVER);
    refill(&mut state.absorbed_next, n, NEVER);
    state.crease.clear();
    state
        .crease
        .extend(level.crease.iter().map(|c| c.map(AtomicU32::new)));
}

/// The fans of a level with `vertex_count` vertices in CSR form, by a counting sort of the
/// faces' corners (a vertex's pairs come in face order).
fn build_fans(corners: &[[u32; 3]], vertex_count: usize, parallel: bool, state: &mut PassState) {
    bucket_sort(
        corners.len(),
        vertex_count,
        parallel,
        |f| {
            let [x, y, z] = corners[f];
            [(x, [y, z]), (y, [z, x]), (z, [x, y])]
        },
        SortedBuckets {
            offsets: &mut state.fan_offsets,
            cursor: &mut state.cursor,
            sorted: &mut state.fans,
        },
    );
}

/// Every vertex's cost (as the bits of a non-negative f32, which order like the value) into
/// `state.cost`, whether it is on a boundary into `state.open`, and its one-ring's least and
/// greatest vertex into `state.ring`.
fn vertex_costs(level: &Level, options: &HierarchyOptions, state: &mut PassState) {
    let vertex_count = level.points.len();
    let (offsets, fans, points) = (&state.fan_offsets, &state.fans, &level.points);
    state.cost.resize(vertex_count, 0);
    state.open.resize(vertex_count, false);
    state.ring.resize(vertex_count, [0; 2]);
    state
        .cost
        .par_iter_mut()
        .zip(state.open.par_iter_mut())
        .zip(state.ring.par_iter_mut())
        .enumerate()
        .with_min_len(1024)
        .for_each(|(v, ((key, open), ring))| {
            let fan = &fans[offsets[v] as usize..offsets[v + 1] as usize];
            // In a fan of a manifold level (checked on pass 0, kept by the collapse rules) the
            // `a`s are distinct and so are the `b`s. A closed fan has the same `a`s as `b`s; an
            // open one swaps its start (an `a` that is no `b`) for its end (a `b` that is no
            // `a`, so a different vertex): the sums differ exactly when the fan is open.
            let (mut sum_a, mut sum_b) = (0u32, 0u32);
            let (mut lo, mut hi) = (v as u32, v as u32);
            for &[a, b] in fan {
                (sum_a, sum_b) = (sum_a.wrapping_add(a), sum_b.wrapping_add(b));
                (lo, hi) = (lo.min(a).min(b), hi.max(a).max(b));
            }
            *open = sum_a != sum_b;
            *ring = [lo, hi];
            // Squared lengths: the square root and the rounding to f32 are monotone, so they
            // commute with min and max and only the two extremes need them.
            let xv = point(points, v as u32);
            let (mut shortest, mut longest) = (f64::INFINITY, 0f64);
            let mut edge = |c: u32| {
                let squared = xv.distance_squared(point(points, c));
                shortest = shortest.min(squared);
                longest = longest.max(squared);
            };
            for &[a, b] in fan {
                edge(a);
                if *open {
                    edge(b);
                }
            }
            let (shortest, longest) = (shortest.sqrt() as f32, longest.sqrt() as f32);
            let cost = (options.alpha * shortest as f64 + options.beta * longest as f64) as f32;
            // Non-negative finite f32s order like their bit patterns.
            let bits = if cost.is_finite() && cost >= 0.0 {
                cost.to_bits()
            } else {
                f32::INFINITY.to_bits()
            };
            *key = bits;
        });
}

#[inline]
fn point(points: &[[f32; 3]], v: u32) -> DVec3 {
    let p = points[v as usize];
    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

/// The vertices whose faces are not a single consistently oriented fan, ascending: with the
/// faces `(v, a, b)` of `v`, every `a` and every `b` must be distinct and following `a -> b` from
/// the fan's start (an `a` that is no `b`, or any `a` when the fan is closed) must visit every
/// face.
fn non_manifold_vertices(fan_offsets: &[u32], fans: &[[u32; 2]]) -> Vec<usize> {
    let n = fan_offsets.len() - 1;
    (0..n)
        .into_par_iter()
        .with_min_len(1024)
        .map_init(Vec::new, |next, v| {
            let fan = &fans[fan_offsets[v] as usize..fan_offsets[v + 1] as usize];
            (v, !is_one_fan(fan, next))
        })
        .filter(|&(_, bad)| bad)
        .map(|(v, _)| v)
        .collect()
}

/// Whether `fan` (the `(a, b)` of the faces `(v, a, b)` of one vertex) is one consistently
/// oriented fan; `next` is scratch space. The comparisons are all made, without early exits, so
/// that they compile to straight-line code.
fn is_one_fan(fan: &[[u32; 2]], next: &mut Vec<usize>) -> bool {
    let len = fan.len();
    if len == 0 {
        return true;
    }
    // Distinct `a`s and distinct `b`s; the face following each face (whose `a` is its `b`) and
    // the start, a face whose `a` is no `b`.
    let mut repeated = false;
    let mut start = NONE;
    next.clear();
    for (i, &[a, b]) in fan.iter().enumerate() {
        let mut follower = NONE;
        let mut preceded = false;
        for (j, &[c, d]) in fan.iter().enumerate() {
            repeated |= j > i && (a == c || b == d);
            follower = if c == b { j } else { follower };
            preceded |= d == a;
        }
        next.push(follower);
        start = if !preceded && start == NONE { i } else { start };
    }
    if repeated {
        return false;
    }
    let start = if start == NONE { 0 } else { start };
    let mut current = start;
    for step in 1..=len {
        match next[current] {
            NONE => return step == len,
            following if following == start => return step == len,
            following => current = following,
        }
    }
    false
}

/// No face (in `is_one_fan`).
const NONE: usize = usize::MAX;

#[cfg(test)]
mod tests;
