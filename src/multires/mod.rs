//! Multiresolution fairing (paper section 4.2): fair a coarse level, refine, fair, down to M0.
//!
//! For `i` from the start level `k` down to 1: fair `M_i` with constrained fairing (section 3,
//! on `M_i`'s own connectivity and valences; the anchors are `M_i`'s positions at the start of
//! that level's fairing), then refine `M_i -> M_(i-1)` by the vertex splits of that level.
//! Vertices that are not split keep their faired positions.
//!
//! Placing a split vertex (the reading of the paper is in the repository's `docs/paper.md`):
//! - [`MultiresVariant::Paper`]: the vertex starts at the mean of its 1-ring in `M_(i-1)` (a
//!   boundary vertex at the midpoint of its two loop neighbours), then takes one Kobbelt step
//!   `x <- x - L²(x)/ν`, `L²(x_i) = (1/n_i) Σ_j L(x_j) - L(x_i)`, `ν = 1 + (1/n_i) Σ_j 1/n_j`,
//!   uniform umbrella `L`, computed for all split vertices of the level from the placed positions
//!   and applied together. Boundary vertices use the same step on their loop (curve Laplacian with
//!   weights ½, so `ν = 3/2`).
//! - [`MultiresVariant::Improved`]: two corrections of the drift the paper's recipe has on
//!   clean meshes. (Both variants fair with the paper's operator, `FairVariant::Paper`: the
//!   normal-projected one roughly doubled the normal error of multires from coarse levels.)
//!   1. Shrinkage of the level fairings. Constrained fairing of a coarse level (a few hundred
//!      vertices, thin parts a few edges around) loses volume on every level, even with one
//!      iteration: the local solves keep triangle barycentres but the averaged result pulls
//!      strongly curved, coarsely sampled parts inward, and the losses add up over the levels.
//!      Removing noise is a high-frequency normal motion; this shrinkage is a coherent one. So
//!      after each level's fairing the normal displacement `h_v = (x_v - x_v^before) . n_v`
//!      (area-weighted vertex normal) is low-passed by two area-weighted 1-ring averages and
//!      that smooth part is taken back.
//!   2. Split placement. After the paper's placement, a volume restoration: the build recorded,
//!      for every collapse `v -> k`, the signed cone volume `c_v = A_v · (x_v - x_k)` of the
//!      original geometry (`A_v = Σ (x_a - x_k) × (x_b - x_k)` over `v`'s faces `(v, a, b)` that
//!      do not contain `k`): six times the volume the split adds back. The height
//!      `t_v = (c_v - A_v · (x_v - x_k)) / |A_v|` along `A_v / |A_v|` would restore it exactly
//!      (with no fairing, a clean mesh then keeps its volume exactly). On a noisy mesh `t_v` also
//!      holds the vertex's own noise, so it is low-passed before use: each split vertex takes the
//!      `|A|`-weighted mean of the `t` of the split vertices within two rings of it (its own
//!      included). The result is held to twice the vertex's longest edge: where a level's
//!      fairing shrank a ring to a sliver (a spike's base on a noisy scan), `|A_v|` is nearly
//!      zero and the exact restoration would put the vertex far out (on the noisy Stanford
//!      dragon, one vertex 83 edge lengths).
//!
//!   The repository's `docs/measurements.md` has what these corrections gain over the paper's
//!   recipe, level by level, and how to re-run the comparison.
//!
//! Start level 0 means single-level fairing of M0. Fairing M0 after the last refinement is
//! optional (`fair_finest`; the paper's loop ends at the refinement).
//!
//! Speed: a [`MultiresWorkspace`] keeps, per level used so far, its connectivity (`TriMesh`
//! triangles and `Topology`), loop neighbours, fan-ordered one-rings and fairing operator, built
//! (levels in parallel) by the first run that needs them or by [`MultiresWorkspace::prepare_for`];
//! a run then only moves positions, and allocates nothing but its result.
//! [`MultiresWorkspace::for_one_run`] keeps instead only the level a run is at (built when the run
//! reaches it, freed when it leaves it): about a third of the memory for a single run (the command
//! line), at the cost of building levels one after another. The whole run executes on a worker of
//! the rayon pool (a run makes a dozen parallel calls per level, and each call issued from outside
//! the pool is a cross-thread hand-off); passes over the coarse levels are not split below
//! `PARALLEL_GRAIN` vertices. The per-level passes (Kobbelt step, vertex normals, low-pass filters)
//! work in f32 SIMD points; the Kobbelt step takes every vertex's umbrella Laplacian once instead
//! of once per adjacent split vertex, and closed fans give the vertex normals from their fan order
//! (one gather per neighbour instead of three per face).
//!
//! # Files
//! - `denoise`: the stage before the levels as the editor and `fairmesh multires` run them (the
//!   automatic default of constrained fairing, once; the hierarchy is built on its result).
//! - `refine`: the steps between two levels (the shrinkage taken back, the split vertices
//!   placed).
//! - `unfold`: the last step of a run from a coarser level: the faces it left turned against M0
//!   and the edges it left folded where M0 is not, unfolded.

pub mod denoise;
mod refine;
mod unfold;

pub use denoise::{denoise, Denoise, DenoiseOptions, Denoised};
pub use unfold::{PUT_BACK_BUDGET, PUT_BACK_FAR};

use crate::fairing::{BoundaryMode, ConstrainedFairing, Creases, FairOptions, FairVariant, Mask};
use crate::hierarchy::Hierarchy;
use crate::mesh::{FanRings, Topology, TriMesh};
use crate::{Cancelled, Progress};
use glam::Vec3A;
use rayon::prelude::*;
use refine::{refine_positions, remove_low_frequency_shrinkage};

/// Which multiresolution recipe runs: `Paper`, section 4 as the paper writes it, or `Improved`
/// (the default), which also takes each level's shrinkage back.
///
/// Exhaustive on purpose: the editor, the CLI and the Python package each name every choice, so a
/// new one is a breaking change that they all take up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum MultiresVariant {
    Paper,
    #[default]
    Improved,
}

/// Options of [`fair_multires`]; build them with `MultiresOptions::default()` and the `with_*`
/// setters.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct MultiresOptions {
    /// The level fairing starts from (0 is M0 itself); beyond the coarsest, the coarsest.
    pub start_level: usize,
    /// Constrained fairing iterations per round on each level.
    pub iterations: usize,
    /// Rounds per level (each re-anchors the constraints).
    pub rounds: usize,
    /// How boundary vertices move on each level.
    pub boundary: BoundaryMode,
    /// Also fair M0 after the last refinement.
    pub fair_finest: bool,
    /// After a run from a coarser level, unfold the faces it left turned by more than 90° against
    /// M0 and the edges it left folded where M0 is not (the `unfold` step; on by default). An addition of [`MultiresVariant::Improved`]: the paper's
    /// variant never unfolds, so that it is the paper's recipe to the letter. Off, the result is
    /// the levels' fairing and placements alone.
    pub unfold: bool,
    pub variant: MultiresVariant,
    /// Where to fair ([`crate::fairing::mask`]), one weight per M0 vertex in the base mesh's
    /// numbering: the run fairs the whole mesh and blends the result back by the weights, so
    /// weight-0 vertices keep their positions exactly. A mask that does not fit M0 leaves the
    /// mesh unchanged.
    pub mask: Option<Mask>,
}

with_setters!(MultiresOptions {
    with_start_level => start_level: usize,
    with_iterations => iterations: usize,
    with_rounds => rounds: usize,
    with_boundary => boundary: BoundaryMode,
    with_fair_finest => fair_finest: bool,
    with_unfold => unfold: bool,
    with_variant => variant: MultiresVariant,
    with_mask => mask: Option<Mask>,
});

impl Default for MultiresOptions {
    fn default() -> Self {
        Self {
            start_level: 0,
            iterations: 5,
            rounds: 1,
            boundary: BoundaryMode::Curve,
            fair_finest: false,
            unfold: true,
            variant: MultiresVariant::Improved,
            mask: None,
        }
    }
}

const NONE: u32 = u32::MAX;

/// Vertices per parallel work item at least: the coarse levels have a few hundred vertices, too
/// few to share out.
const PARALLEL_GRAIN: usize = 1024;

/// Improved: 1-ring averages that low-pass a level fairing's normal displacement before it is
/// taken back: fewer leave part of the shrinkage, more remove less noise (`docs/measurements.md`).
const SHRINKAGE_SMOOTHING_ROUNDS: usize = 2;
/// Improved: two-ring averages of the split heights: none restores each vertex's noise, more
/// lose volume again (`docs/measurements.md`).
const HEIGHT_SMOOTHING_ROUNDS: usize = 1;

/// Connectivity of one level, built by the first run that needs it.
struct LevelData {
    mesh: TriMesh,
    topology: Topology,
    /// Previous and next vertex along the boundary loop or the crease (`NONE` for other
    /// vertices); empty when the level has neither.
    loop_neighbors: Vec<[u32; 2]>,
    /// The level's creases, when the hierarchy kept them.
    creases: Option<Creases>,
    /// One-rings in fan order (closed fans), for the fairing operator and the vertex normals of
    /// the shrinkage correction; only on levels that are faired.
    fans: Option<FanRings>,
    /// The precomputed fairing operator of this connectivity, for the variant and boundary mode
    /// it was made with.
    fairing: Option<ConstrainedFairing>,
    /// M0 only, once a run from a coarser level needed them: its face normals, its edges with
    /// two faces and which of them bend to a right angle or beyond on M0 itself ([`unfold`]).
    folds: Option<unfold::FoldEdges>,
}

/// Buffers reused between runs (the editor runs this on every slider move).
#[derive(Default)]
pub struct MultiresWorkspace {
    hierarchy_id: u64,
    /// Build each level when a run reaches it and free it when the run leaves it
    /// ([`Self::for_one_run`]).
    release_levels: bool,
    levels: Vec<Option<LevelData>>,
    /// Working positions in the hierarchy's internal order (level i: the first V_i).
    positions: Vec<[f32; 3]>,
    /// Umbrella Laplacian of every vertex of the level being refined, from the placed positions.
    laplacians: Vec<Vec3A>,
    /// Per split vertex of the level being refined: Kobbelt displacement, then (Improved) the
    /// unit normal, the height that would restore the split's volume, its weight `|A|` and the
    /// most height the split may take (twice its longest edge).
    displacements: Vec<Vec3A>,
    heights: Vec<(Vec3A, f64, f64, f64)>,
    /// Per vertex of the finer level: weighted sum of heights of adjacent split vertices, weights.
    height_sums: Vec<[f64; 2]>,
    /// Positions of the level before its fairing, vertex normals and areas, normal displacement
    /// of the fairing and its low-passed copy (Improved's shrinkage correction).
    before_fairing: Vec<[f32; 3]>,
    normals: Vec<Vec3A>,
    normal_moves: Vec<[f32; 2]>,
    smoothed_moves: Vec<[f32; 2]>,
    /// What the last run's unfolding left ([`Self::folds_left`]).
    folds_left: usize,
    /// The unfolding's budget when not [`PUT_BACK_BUDGET`]: the tests lower it to reach, on a
    /// small mesh, what only the coarsest levels of a large one reach.
    put_back_budget: Option<f32>,
}

impl MultiresWorkspace {
    pub fn new() -> Self {
        Self::default()
    }

    /// A workspace for a single run: it builds each level's connectivity and fairing operator
    /// when the run reaches the level and frees them when the run moves to the next finer one,
    /// so that at most two levels are held at a time instead of every level from the start
    /// level down. The result is the same; a second run builds every level again.
    pub fn for_one_run() -> Self {
        Self {
            release_levels: true,
            ..Self::default()
        }
    }

    /// Frees the buffers a run reuses from level to level (every pass writes them whole before
    /// reading them): a single run does this before each level's set-up, so that a level's
    /// operator is never built beside the buffers the previous level's passes left, sized for
    /// that level.
    fn free_scratch(&mut self) {
        for buffer in [
            &mut self.laplacians,
            &mut self.displacements,
            &mut self.normals,
        ] {
            *buffer = Vec::new();
        }
        self.heights = Vec::new();
        self.height_sums = Vec::new();
        self.before_fairing = Vec::new();
        self.normal_moves = Vec::new();
        self.smoothed_moves = Vec::new();
    }

    /// How many faces turned against M0 (by more than 90°) and edges folded where M0 is not the
    /// last run left: none, but from the coarsest levels of a large mesh, where undoing them would
    /// have put more than [`PUT_BACK_BUDGET`] of the vertices back from farther than
    /// [`PUT_BACK_FAR`] edge lengths (see the `unfold` step). Callers should say so
    /// ([`folds_left_warning`]).
    pub fn folds_left(&self) -> usize {
        self.folds_left
    }

    /// How many levels' connectivity the workspace holds now.
    pub fn levels_held(&self) -> usize {
        self.levels.iter().filter(|level| level.is_some()).count()
    }

    /// Builds every level a run from `options.start_level` needs, with the fairing operators of
    /// the levels it fairs, so that the runs after it only fair. The editor calls this in the
    /// background for each level once the hierarchy is built, so that moving the level slider
    /// never waits for a level's set-up.
    pub fn prepare_for(&mut self, hierarchy: &Hierarchy, options: &MultiresOptions) {
        let start = options.start_level.min(hierarchy.coarsest_level());
        let fair_last = start == 0 || options.fair_finest;
        let fair_options = level_fair_options(options);
        let operator = (fair_options.variant, fair_options.boundary);
        let faired = move |level: usize| (level >= 1 || fair_last).then_some(operator);
        self.prepare_levels(hierarchy, 0..=start, faired);
        if unfolds(options, start) {
            self.prepare_unfolding(hierarchy);
        }
    }

    /// What the unfolding reads of M0 besides its mesh ([`unfold::FoldEdges`]: its edges, its
    /// faces' normals, its volumes), made once for the runs from coarser levels: set up with the
    /// levels, the editor's first slider step does not wait for it (0.45-0.6 s on a 1.2M-face
    /// scan).
    fn prepare_unfolding(&mut self, hierarchy: &Hierarchy) {
        let level = self.levels[0].get_or_insert_with(|| LevelData::build(hierarchy, 0));
        let folds = level
            .folds
            .get_or_insert_with(|| unfold::FoldEdges::new(&level.mesh));
        folds.keep_volume_of(&level.mesh, &level.topology);
    }

    /// Builds the missing levels of `levels` in parallel (one level per task; each build is
    /// parallel inside too), with a fairing operator where `operator(level)` names one.
    fn prepare_levels(
        &mut self,
        hierarchy: &Hierarchy,
        levels: std::ops::RangeInclusive<usize>,
        operator: impl Fn(usize) -> Option<(FairVariant, BoundaryMode)> + Sync,
    ) {
        if self.hierarchy_id != hierarchy.id() || self.levels.len() != hierarchy.level_count() {
            self.hierarchy_id = hierarchy.id();
            self.levels.clear();
            self.levels.resize_with(hierarchy.level_count(), || None);
        }
        let missing: Vec<usize> = levels
            .filter(|&level| {
                self.levels[level].as_ref().is_none_or(|data| {
                    operator(level).is_some_and(|(variant, boundary)| {
                        !data
                            .fairing
                            .as_ref()
                            .is_some_and(|f| f.variant() == variant && f.boundary() == boundary)
                    })
                })
            })
            .collect();
        let mut cached: Vec<Option<LevelData>> = missing
            .iter()
            .map(|&level| self.levels[level].take())
            .collect();
        let built: Vec<LevelData> = missing
            .par_iter()
            .zip(cached.par_iter_mut())
            .map(|(&level, cached)| {
                let mut data = cached
                    .take()
                    .unwrap_or_else(|| LevelData::build(hierarchy, level));
                if let Some((variant, boundary)) = operator(level) {
                    let LevelData {
                        mesh,
                        topology,
                        fans,
                        creases,
                        ..
                    } = &mut data;
                    let fans = fans.get_or_insert_with(|| FanRings::new(&mesh.triangles, topology));
                    data.fairing = Some(ConstrainedFairing::with_fans(
                        mesh,
                        topology,
                        fans,
                        variant,
                        boundary,
                        creases.as_ref(),
                        &[],
                    ));
                }
                data
            })
            .collect();
        for (level, data) in missing.into_iter().zip(built) {
            self.levels[level] = Some(data);
        }
    }
}

impl LevelData {
    fn build(hierarchy: &Hierarchy, level: usize) -> Self {
        let mesh = hierarchy.level_mesh(level);
        let topology = Topology::build(&mesh);
        let mut loop_neighbors = Vec::new();
        if !topology.boundary_loops.is_empty() {
            loop_neighbors = vec![[NONE; 2]; mesh.vertex_count()];
            for boundary_loop in &topology.boundary_loops {
                let m = boundary_loop.len();
                for (i, &v) in boundary_loop.iter().enumerate() {
                    loop_neighbors[v as usize] =
                        [boundary_loop[(i + m - 1) % m], boundary_loop[(i + 1) % m]];
                }
            }
        }
        // A crease vertex is placed like a boundary vertex, on its crease.
        let creases = hierarchy.level_creases(level);
        if let Some(creases) = &creases {
            for chain in &creases.chains {
                let m = chain.vertices.len();
                let inner = if chain.closed { 0..m } else { 1..m - 1 };
                for i in inner {
                    if loop_neighbors.is_empty() {
                        loop_neighbors = vec![[NONE; 2]; mesh.vertex_count()];
                    }
                    loop_neighbors[chain.vertices[i] as usize] =
                        [chain.vertices[(i + m - 1) % m], chain.vertices[(i + 1) % m]];
                }
            }
        }
        LevelData {
            folds: None,
            mesh,
            topology,
            loop_neighbors,
            creases,
            fans: None,
            fairing: None,
        }
    }
}

/// The fairing options of every level of a run.
fn level_fair_options(options: &MultiresOptions) -> FairOptions {
    FairOptions {
        iterations: options.iterations,
        rounds: options.rounds.max(1),
        strength: crate::fairing::Strength::Fixed,
        creases: None,
        tangential_relaxation: 0.0,
        relaxation: crate::fairing::Relaxation::Everywhere,
        boundary: options.boundary,
        tolerance: 0.0,
        // Every level runs all its iterations, as it always has.
        settled: 0.0,
        mask: None,
        // Multires corrects the shrinkage per level itself.
        keep_volume: false,
        // Both variants fair with the paper's operator: measured in multires, the
        // normal-projected operator roughly doubles the normal error from coarse levels (noisy
        // bunny00 from level 8: 22 degrees against 12) because the tangential part of the paper's
        // update also evens out the coarse meshes the splits are placed on.
        variant: FairVariant::Paper,
    }
}

/// Returns M0's positions after fairing (M0's triangles are `hierarchy.base_mesh().triangles`),
/// or [`Cancelled`] when `progress` cancelled the run.
///
/// ```
/// use fairmesh::hierarchy::{build_hierarchy, HierarchyOptions};
/// use fairmesh::multires::{fair_multires, MultiresOptions, MultiresWorkspace};
/// use fairmesh::{NoProgress, TriMesh};
///
/// let mesh = fairmesh::bundled::load_bunny(&Default::default())?.mesh;
/// let hierarchy = build_hierarchy(&mesh, &HierarchyOptions::default(), &mut NoProgress)?;
/// let options = MultiresOptions::default().with_start_level(8);
/// let mut workspace = MultiresWorkspace::default(); // keep it to run again cheaply
/// let positions = fair_multires(&hierarchy, &options, &mut workspace, &mut NoProgress)
///     .expect("NoProgress never cancels");
/// let smooth = TriMesh::new(positions, mesh.triangles.clone());
/// // Detail is gone, the volume is not.
/// let change = fairmesh::metrics::volume_change_percent(&mesh, &smooth).unwrap();
/// assert!(change.abs() < 1.0, "{change}%");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn fair_multires(
    hierarchy: &Hierarchy,
    options: &MultiresOptions,
    workspace: &mut MultiresWorkspace,
    progress: &mut dyn Progress,
) -> Result<Vec<[f32; 3]>, Cancelled> {
    // A run makes a dozen small parallel calls per level. Issued from outside the pool, each one
    // is handed to a worker and waited for (a futex round trip); from a worker they run in place
    // or are stolen, so the whole run goes to the pool once.
    let original = &hierarchy.base_mesh().positions;
    workspace.folds_left = 0;
    if let Some(mask) = &options.mask {
        if mask.check_fits(original.len()).is_err() || mask.painted_count() == 0 {
            progress.check(1.0)?;
            return Ok(original.clone());
        }
    }
    let mut result =
        rayon::scope(|_| fair_multires_on_worker(hierarchy, options, workspace, progress))?;
    if let Some(mask) = &options.mask {
        mask.blend(original, &mut result);
    }
    Ok(result)
}

/// [`fair_multires`] on the calling thread: from the start level down, each level faired (and,
/// Improved, its shrinkage taken back), then refined to the next finer one; M0 last.
fn fair_multires_on_worker(
    hierarchy: &Hierarchy,
    options: &MultiresOptions,
    workspace: &mut MultiresWorkspace,
    progress: &mut dyn Progress,
) -> Result<Vec<[f32; 3]>, Cancelled> {
    let start = options.start_level.min(hierarchy.coarsest_level());
    let fair_options = level_fair_options(options);
    let operator = (fair_options.variant, fair_options.boundary);
    let release = workspace.release_levels;
    let fixed = start_run(hierarchy, options, workspace, start);
    // Progress weights: a level costs about its vertex count.
    let total: f64 = (0..=start)
        .map(|i| hierarchy.level_info(i).vertices as f64)
        .sum::<f64>()
        .max(1.0);
    let mut done = 0.0;
    for level in (1..=start).rev() {
        to_finer_level(hierarchy, options, &fair_options, workspace, level, &fixed);
        done += hierarchy.level_info(level).vertices as f64;
        progress.check((done / total) as f32)?;
    }
    if start == 0 || options.fair_finest {
        if release {
            workspace.free_scratch();
            workspace.prepare_levels(hierarchy, 0..=0, |_| Some(operator));
        }
        fair_level(workspace, 0, &fair_options);
        progress.check(1.0)?;
    }
    if unfolds(options, start) {
        unfold_new_folds(hierarchy, workspace);
    }
    if release {
        workspace.levels[0] = None;
    }
    let base_vertices = hierarchy.level_info(0).vertices;
    debug_assert_eq!(workspace.positions.len(), base_vertices);
    let mut result = vec![[0f32; 3]; base_vertices];
    for (v, p) in workspace.positions.iter().enumerate() {
        result[hierarchy.original_vertex(v as u32) as usize] = *p;
    }
    Ok(result)
}

/// What to tell a user whose run from `start_level` left `folds_left` faces turned or edges
/// folded ([`MultiresWorkspace::folds_left`]): the command line prints it, Python warns with it.
pub fn folds_left_warning(start_level: usize, folds_left: usize) -> String {
    format!(
        "from level {start_level}, {folds_left} faces turned over or edges folded against level \
         0 are left: undoing them would have put level 0's detail back in patches with seams \
         (over {:.0} % of the vertices from more than {PUT_BACK_FAR} edge lengths away); a finer \
         level leaves none",
        100.0 * PUT_BACK_BUDGET
    )
}

/// Whether a run from `start` with `options` ends by unfolding ([`unfold_new_folds`]): the
/// improved variant from a coarser level, with the unfolding on. The paper's variant is the
/// paper's recipe alone: no unfolding.
fn unfolds(options: &MultiresOptions, start: usize) -> bool {
    start > 0 && options.unfold && options.variant == MultiresVariant::Improved
}

/// The last step of a run from a coarser level ([`unfold`]): the faces it left turned against
/// M0 and the edges it left folded where M0 was not are unfolded.
fn unfold_new_folds(hierarchy: &Hierarchy, workspace: &mut MultiresWorkspace) {
    workspace.prepare_unfolding(hierarchy);
    let level = workspace.levels[0]
        .as_mut()
        .expect("prepare_unfolding builds M0");
    let LevelData {
        mesh,
        topology,
        folds,
        creases,
        loop_neighbors,
        ..
    } = level;
    let folds = folds.as_mut().expect("prepare_unfolding makes them");
    let level = unfold::Level {
        mesh,
        topology,
        creases: creases.as_ref(),
        loop_neighbors,
        keep_volume: true,
        put_back_budget: workspace.put_back_budget.unwrap_or(unfold::PUT_BACK_BUDGET),
    };
    workspace.folds_left = unfold::unfold(&mut workspace.positions, &level, folds).left;
}

/// Sets `workspace` up for a run from level `start`: the levels it needs now (all it touches, or
/// with [`MultiresWorkspace::for_one_run`] only M0 for a fixed boundary), and the start level's
/// positions. Returns, for a fixed boundary, M0's boundary vertices (internal ids, ascending):
/// they are put back at their own positions after every step that could move them (the
/// shrinkage correction, the split placement), so that they are fixed at every level, not only
/// on the levels' own boundaries.
fn start_run(
    hierarchy: &Hierarchy,
    options: &MultiresOptions,
    workspace: &mut MultiresWorkspace,
    start: usize,
) -> Vec<u32> {
    let release = workspace.release_levels;
    if release {
        // A single run builds each level when it gets there; M0's connectivity is needed now
        // only for a fixed boundary (below), and is freed again once that is read.
        if options.boundary == BoundaryMode::Fixed {
            workspace.prepare_levels(hierarchy, 0..=0, |_| None);
        }
    } else {
        // Every level this run touches, with the operators of those it fairs.
        workspace.prepare_for(hierarchy, options);
    }
    workspace.positions.clear();
    workspace
        .positions
        .extend_from_slice(hierarchy.level_positions(start));
    let fixed: Vec<u32> = match options.boundary {
        BoundaryMode::Fixed => original_boundary(hierarchy, workspace),
        _ => Vec::new(),
    };
    if release && start > 0 {
        // Held while the coarser levels are set up, M0's mesh and connectivity would be a large
        // share of the run's peak; it is built again when the run reaches it.
        if let Some(m0) = workspace.levels.get_mut(0) {
            *m0 = None;
        }
    }
    fixed
}

/// One step of the run: level `level` faired with `fair_options` (Improved: its shrinkage taken
/// back), then refined to level `level - 1`; the `fixed` vertices put back after each.
fn to_finer_level(
    hierarchy: &Hierarchy,
    options: &MultiresOptions,
    fair_options: &FairOptions,
    workspace: &mut MultiresWorkspace,
    level: usize,
    fixed: &[u32],
) {
    let release = workspace.release_levels;
    if release {
        let operator = (fair_options.variant, fair_options.boundary);
        workspace.free_scratch();
        workspace.prepare_levels(hierarchy, level..=level, |_| Some(operator));
    }
    let faired = fair_level(workspace, level, fair_options);
    if faired && options.variant == MultiresVariant::Improved {
        remove_low_frequency_shrinkage(workspace, level);
        restore_fixed(hierarchy, &mut workspace.positions, fixed);
    }
    if release {
        workspace.levels[level] = None;
        workspace.free_scratch();
        workspace.prepare_levels(hierarchy, level - 1..=level - 1, |_| None);
    }
    refine_positions(hierarchy, workspace, level - 1, options.variant);
    restore_fixed(hierarchy, &mut workspace.positions, fixed);
}

/// M0's boundary vertices in the hierarchy's internal numbering, ascending.
fn original_boundary(hierarchy: &Hierarchy, workspace: &MultiresWorkspace) -> Vec<u32> {
    let data = workspace.levels[0]
        .as_ref()
        .expect("every run prepares M0, the level it refines to");
    let flags = data.topology.boundary_flags();
    (0..hierarchy.level_info(0).vertices as u32)
        .filter(|&v| flags[v as usize])
        .collect()
}

/// Puts the `fixed` vertices that the working positions hold back at their original positions.
fn restore_fixed(hierarchy: &Hierarchy, positions: &mut [[f32; 3]], fixed: &[u32]) {
    let original = hierarchy.level_positions(0);
    for &v in fixed {
        let Some(p) = positions.get_mut(v as usize) else {
            continue;
        };
        *p = original[v as usize];
    }
}

/// Fairs the working positions of `level`; false when there was nothing to do.
fn fair_level(workspace: &mut MultiresWorkspace, level: usize, options: &FairOptions) -> bool {
    let data = workspace.levels[level]
        .as_mut()
        .expect("prepared before fairing");
    if options.iterations == 0 || options.rounds == 0 || data.mesh.positions.is_empty() {
        return false;
    }
    let fairing = data
        .fairing
        .as_mut()
        .expect("prepare_for set up the operator of every level a run fairs");
    let n = data.mesh.positions.len();
    workspace.before_fairing.clear();
    workspace
        .before_fairing
        .extend_from_slice(&workspace.positions[..n]);
    fairing.run(&mut workspace.positions[..n], options);
    // The levels are faired one at a time: the operators kept for the next runs (the editor
    // keeps every level's) hold no working buffers between runs.
    fairing.release_buffers();
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hierarchy::{build_hierarchy, HierarchyOptions};

    /// The bundled bunny's hierarchy, with the default options.
    fn bunny_hierarchy() -> Hierarchy {
        let mesh = crate::bundled::load_bunny(&Default::default())
            .unwrap()
            .mesh;
        build_hierarchy(&mesh, &HierarchyOptions::default(), &mut crate::NoProgress).unwrap()
    }

    #[test]
    fn what_the_unfolding_leaves_is_counted_and_every_run_counts_again() {
        // The bundled bunny with noise (0.3 mean edge lengths), its hierarchy built on the noisy
        // mesh itself: on the clean one, the unfolding leaves nothing even with no budget.
        let mut mesh = crate::bundled::load_bunny(&Default::default())
            .unwrap()
            .mesh;
        let noise = crate::noise::NoiseOptions::default()
            .with_sigma(0.3)
            .with_seed(1);
        crate::noise::add_noise(&mut mesh, &noise);
        let hierarchy =
            build_hierarchy(&mesh, &HierarchyOptions::default(), &mut crate::NoProgress).unwrap();
        let base = hierarchy.base_mesh();
        // Faces of a result turned by more than 90 degrees against the same face of M0.
        let turned = |positions: &[[f32; 3]]| {
            let result = TriMesh::new(positions.to_vec(), base.triangles.clone());
            (0..base.face_count())
                .filter(|&f| result.face_normal(f).dot(base.face_normal(f)) < 0.0)
                .count()
        };
        let options = MultiresOptions::default().with_start_level(hierarchy.coarsest_level());
        let run = |workspace: &mut MultiresWorkspace| {
            let result = fair_multires(&hierarchy, &options, workspace, &mut crate::NoProgress);
            turned(&result.unwrap())
        };
        // With no budget, every place where a corner went back from far away is taken back to
        // what the relaxation left, and what is still turned there is left: every face turned
        // is counted (edges folded count too).
        let mut workspace = MultiresWorkspace {
            put_back_budget: Some(0.0),
            ..Default::default()
        };
        let left_turned = run(&mut workspace);
        assert!(
            left_turned > 0,
            "nothing left turned: the test needs another level"
        );
        assert!(
            workspace.folds_left() >= left_turned,
            "{} counted, {left_turned} faces turned",
            workspace.folds_left()
        );
        // Within the budget nothing is left, and the same workspace no longer reports the last
        // run's count.
        workspace.put_back_budget = None;
        assert_eq!(run(&mut workspace), 0);
        assert_eq!(workspace.folds_left(), 0);
    }

    #[test]
    fn setting_a_coarser_level_up_sets_up_the_unfolding_and_the_run_gives_what_a_fresh_one_does() {
        // The editor sets the levels up in the background (`prepare_for`) so that the slider's
        // first step only fairs: what the unfolding reads of M0 is part of that set-up, for the
        // improved variant from a coarser level, and not for level 0 or the paper's variant.
        let hierarchy = bunny_hierarchy();
        let set_up = |options: &MultiresOptions| {
            let mut workspace = MultiresWorkspace::default();
            workspace.prepare_for(&hierarchy, options);
            let m0 = workspace.levels[0].as_ref().expect("M0 is set up");
            let folds = m0.folds.as_ref().map(|f| f.has_volume());
            (workspace, folds)
        };
        let coarse = MultiresOptions::default().with_start_level(3);
        let (mut workspace, folds) = set_up(&coarse);
        assert_eq!(folds, Some(true), "the edges and the volumes set up");
        let paper = coarse.clone().with_variant(MultiresVariant::Paper);
        assert_eq!(set_up(&paper).1, None, "the paper's variant never unfolds");
        let finest = MultiresOptions::default().with_start_level(0);
        assert_eq!(set_up(&finest).1, None, "level 0 never unfolds");
        // A run on the set-up workspace gives what a run on a fresh one does.
        let run = |workspace: &mut MultiresWorkspace| {
            fair_multires(&hierarchy, &coarse, workspace, &mut crate::NoProgress).unwrap()
        };
        assert_eq!(run(&mut workspace), run(&mut MultiresWorkspace::default()));
    }

    #[test]
    fn a_split_over_a_shrunken_ring_rises_no_more_than_twice_its_longest_edge() {
        // A level's fairing can shrink a split vertex's ring to a sliver (a spike's base on a
        // noisy scan); the volume the split adds back, spread over that sliver, asks for a
        // tower. Stand-in: level 1 shrunk a thousandfold about its centre, then refined.
        // Without the bound the splits went 500 times the level's size out.
        let hierarchy = bunny_hierarchy();
        let mut workspace = MultiresWorkspace::default();
        workspace.prepare_levels(&hierarchy, 0..=1, |_| None);
        let coarse = hierarchy.level_positions(1);
        let centre =
            coarse.iter().map(|&p| Vec3A::from_array(p)).sum::<Vec3A>() / coarse.len() as f32;
        let size = coarse
            .iter()
            .map(|&p| Vec3A::from_array(p).distance(centre))
            .fold(0f32, f32::max);
        workspace.positions = coarse
            .iter()
            .map(|&p| (centre + (Vec3A::from_array(p) - centre) * 1e-3).to_array())
            .collect();
        refine_positions(&hierarchy, &mut workspace, 0, MultiresVariant::Improved);
        let split = hierarchy.level_info(1).vertices..hierarchy.level_info(0).vertices;
        assert!(split.len() > 1000, "{split:?}");
        // Placed in the shrunken ring (within its size, 1e-3 of the level's), then at most
        // twice an edge of it higher.
        let farthest = split
            .map(|v| Vec3A::from_array(workspace.positions[v]).distance(centre))
            .fold(0f32, f32::max);
        assert!(farthest.is_finite());
        assert!(
            farthest <= 4e-3 * size,
            "a split went {farthest} from the centre of a level shrunk to {}",
            1e-3 * size
        );
    }
}
