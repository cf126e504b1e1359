//! The driver of constrained fairing: [`fair_constrained`] decides whether and how much to fair
//! (the noise estimate, [`crate::fairing::strength`]), finds the creases
//! ([`crate::fairing::creases`]) and runs the rounds of section 3.2 ("imposing and relaxing the
//! centre constraints by turns"), with the creases found again, the tangential relaxation where
//! it is needed, the volume given back and, with automatic strength, the risk read after every
//! round and the rounds after the best one undone.

use super::kernel::CHUNK;
use super::weights::held_flags;
use super::ConstrainedFairing;
use crate::fairing::creases::{
    detect_creases_cached, detect_creases_with_estimate, CreaseOptions, Creases, FaceRingCache,
    FeatureClass,
};
use crate::fairing::relaxation::{self, read_tangential_noise};
use crate::fairing::strength::{
    normal_filtering_for, read_noise, NoiseReading, RoundRisk, CLEAN_NOISE, MAX_AUTO_ROUNDS,
    RISK_MIN_FALL, RISK_PATIENCE,
};
use crate::fairing::volume::VolumeKeeper;
use crate::fairing::{FairOptions, FairReport, FairVariant, Relaxation, Strength};
use crate::mesh::{breadth_first_order, inverse_permutation, FanRings, Topology, TriMesh};
use rayon::prelude::*;

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
    if let Some(report) = fair_without_loose_triangles(mesh, topology, options) {
        return report;
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

/// A non-manifold scan is faired as the surface it stands for: without the triangles its
/// reconstruction left lying loose at its non-manifold edges (overlays on a fan, fins), which
/// would make their corners boundary vertices on chains no boundary curve runs through, and so
/// hold them with their noise (`crate::mesh::loose_triangles`, `docs/measurements.md`). Same
/// vertices, nothing renumbered; a corner only loose triangles use (a fin's tip) stays where it
/// is. `None` when the default variant has no loose triangles to leave out.
fn fair_without_loose_triangles(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &FairOptions,
) -> Option<FairReport> {
    if options.variant != FairVariant::NormalProjected || topology.non_manifold_edges.is_empty() {
        return None;
    }
    let (loose, mut kept, kept_topology) = crate::mesh::without_loose_triangles(mesh, topology)?;
    // The volume kept is the file's, loose triangles included: they follow their corners, and
    // their own (cone) volume changes with them; one more uniform offset takes that back.
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
    Some(report)
}

/// Rounds from which a run in the locality order pays for making it (see [`in_local_order`]).
const LOCAL_ORDER_ROUNDS: usize = 3;

/// Runs `fair` on a copy of `mesh` whose vertices are numbered breadth-first over the one-rings and
/// whose faces are sorted by their lowest corner, then puts the faired positions back in the mesh's
/// numbering. Every per-vertex pass of a round outside the operator (the crease detection and the
/// noise estimate over the fans, the volume correction's normals, the risk's normals) gathers its
/// neighbours' data; in a file's own order (a scan's, a subdivided mesh's) those sit megabytes
/// apart, here a few breadth-first fronts apart; the reordering and a second topology cost little
/// next to the rounds (`docs/measurements.md`). The operator renumbers its own vertices the same
/// way, so its iterations are unchanged. What `options` number by vertex (the file's hard edges) is
/// renumbered too; `pinned` stands for the mask, which `fair` does not see.
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
    // Without `may_reorder` the mesh is already the locality-ordered copy (`in_local_order`):
    // the filter keeps its face order (the same normals bit for bit, its lists built faster).
    let mut face_rings = if may_reorder {
        FaceRingCache::default()
    } else {
        FaceRingCache::in_mesh_order()
    };
    let started = std::time::Instant::now();
    let (estimate, found, reading) = first_reading(mesh, topology, &fans, options, &mut face_rings);
    let auto_noise = match options.strength {
        Strength::Auto => match noisy(estimate, reading.as_ref(), topology) {
            Some(noise) => Some(noise),
            None => {
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

/// The first reading of the input: the noise estimate, which decides the strength (automatic)
/// and how much the normals are filtered before creases are detected (raw normals of a noisy
/// mesh make creases of the noise). A fixed strength finds the estimate and the creases in one
/// gather (skipping the filter when the mesh is clean); automatic strength fairs only a noisy
/// mesh, so its creases are always found later on filtered normals, and it reads in the same
/// gather which vertices lie on sharp edges ([`read_noise`]).
fn first_reading(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
    options: &FairOptions,
    face_rings: &mut FaceRingCache,
) -> (Option<f64>, Option<Creases>, Option<NoiseReading>) {
    match (&options.creases, options.strength) {
        (Some(crease_options), Strength::Fixed) => {
            let (estimate, creases) = detect_creases_with_estimate(
                mesh,
                topology,
                fans,
                crease_options,
                face_rings,
                true,
            );
            (estimate, Some(creases), None)
        }
        (_, Strength::Auto) => {
            let angle = options
                .creases
                .as_ref()
                .map_or(CreaseOptions::default().angle_degrees, |c| c.angle_degrees);
            let reading = read_noise(mesh, topology, fans, angle);
            (reading.noise(topology), None, Some(reading))
        }
        (None, _) => (None, None, None),
    }
}

/// Automatic strength: the noise to fair, `None` for a mesh left as it is: a clean one, or one
/// that reads noisy only because of its sharp edges (a coarse CAD part: most of its vertices lie
/// on or beside an edge, and those make the median read noise; away from the edges it reads
/// clean).
fn noisy(
    estimate: Option<f64>,
    reading: Option<&NoiseReading>,
    topology: &Topology,
) -> Option<f64> {
    let clean_away_from_edges = || {
        reading
            .and_then(|reading| reading.away_from_edges(topology))
            .is_some_and(|away| away <= CLEAN_NOISE)
    };
    estimate.filter(|&noise| noise > CLEAN_NOISE && !clean_away_from_edges())
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
/// around each face if that detection filtered the normals. Each round finds the creases again
/// when they are due ([`Creases`]), sets the relaxation's shares ([`RelaxationPlan`]), runs the
/// operator, gives the volume back and, with automatic strength, reads the risk ([`RiskJudge`]),
/// which may stop the rounds and undo the last ones.
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
    let started = std::time::Instant::now();
    let creases =
        found.or_else(|| first_creases(mesh, topology, options, estimate, &mut face_rings));
    let first_detection_ms = milliseconds(started);
    let max_rounds = match auto_noise {
        Some(_) => MAX_AUTO_ROUNDS,
        None => options.rounds,
    };
    let redetect = options.creases.is_some() && max_rounds > 1;
    let mut fairing = ConstrainedFairing::with_fans(
        mesh,
        topology,
        &fans,
        options.variant,
        options.boundary,
        creases.as_ref(),
        pinned,
    );
    fairing.set_tangential_relaxation(options.tangential_relaxation as f32);
    let started = std::time::Instant::now();
    let relaxation = RelaxationPlan::read(mesh, topology, &fans, options, estimate);
    let reading_ms = milliseconds(started);
    // The fans serve the later rounds only to find the creases again (and estimate the noise
    // that sets the filtering for it) and to read the noise along the surface again while the
    // relaxation acts everywhere: otherwise they are freed before the iterations (the peak,
    // while the operator is set up from them, stays).
    let fans = (redetect || relaxation.everywhere.is_some_and(|share| share > 0.0)).then_some(fans);
    let volume = options
        .keep_volume
        .then(|| VolumeKeeper::new(mesh, topology, pinned));
    let mut report = FairReport {
        detection_ms: first_detection_ms + reading_ms,
        tangential_noise: relaxation.tangential_noise,
        ..FairReport::default()
    };
    let judge = auto_noise.map(|noise| RiskJudge::new(mesh, topology, noise, creases.as_ref()));
    let mut rounds = RoundLoop {
        topology,
        options,
        pinned,
        fairing,
        fans,
        face_rings,
        redetect,
        tracked: TrackedCreases {
            creases,
            unchanged: 0,
            read_clean: false,
        },
        relaxation,
        volume,
        judge,
    };
    for round in 0..max_rounds {
        if rounds.run(mesh, round, &mut report) {
            break;
        }
    }
    let tracked = rounds.tracked;
    let judge = rounds.judge;
    let mut crease_edges = tracked.creases.map_or(0, |c| c.edges.len());
    if let Some(judge) = judge {
        judge.roll_back(mesh, &mut report, &mut crease_edges);
    }
    report.noise_estimate = estimate;
    report.crease_edges = crease_edges;
    report
}

/// What the rounds of [`fair_rounds`] work with, set up before the first.
struct RoundLoop<'a> {
    topology: &'a Topology,
    options: &'a FairOptions,
    /// Vertices a mask pins (empty: none).
    pinned: &'a [bool],
    fairing: ConstrainedFairing,
    /// The mesh's fans, kept only while later rounds need them (see [`fair_rounds`]).
    fans: Option<FanRings>,
    face_rings: FaceRingCache,
    /// Whether the creases are found again before later rounds.
    redetect: bool,
    tracked: TrackedCreases,
    relaxation: RelaxationPlan,
    volume: Option<VolumeKeeper>,
    judge: Option<RiskJudge>,
}

impl RoundLoop<'_> {
    /// Round `round` on `mesh`, counted in `report`: the creases found again when they are due
    /// (the operator set up again for them when they changed), the relaxation's shares, the
    /// operator's iterations, the volume given back, and, with automatic strength, the risk
    /// read. Whether the rounds stop.
    fn run(&mut self, mesh: &mut TriMesh, round: usize, report: &mut FairReport) -> bool {
        let topology = self.topology;
        if let (true, Some(fans), Some(crease_options)) = (
            self.redetect && round > 0 && self.tracked.due(round),
            &self.fans,
            &self.options.creases,
        ) {
            let detection = (fans, crease_options, &mut self.face_rings);
            if self.tracked.detect_again(mesh, topology, detection, report) {
                let creases = self.tracked.creases.as_ref();
                let fairing = &mut self.fairing;
                fairing.for_other_creases(mesh, topology, fans, creases, self.pinned);
            }
        }
        // Imposes the constraints on the positions this round starts from.
        self.fairing.load(&mesh.positions);
        let fans = self.fans.as_ref();
        let at = (&*mesh, topology);
        self.relaxation
            .before_round(&mut self.fairing, round, at, fans, report);
        self.fairing.run_round(self.options, report);
        self.fairing.store(&mut mesh.positions);
        if let Some(volume) = &self.volume {
            if let Some(judge) = &mut self.judge {
                judge.before_restore.clone_from(&mesh.positions);
            }
            let class = self.tracked.creases.as_ref().map(|c| c.class.as_slice());
            let class = class.unwrap_or(&[]);
            volume.restore(mesh, topology, |v| {
                class.get(v) == Some(&FeatureClass::Corner)
            });
        }
        let Some(judge) = &mut self.judge else {
            return false;
        };
        let volume_kept = self.volume.is_some();
        judge.fair_copy(
            &mut self.fairing,
            self.options,
            &mesh.positions,
            volume_kept,
        );
        let edges = self.tracked.creases.as_ref().map_or(0, |c| c.edges.len());
        judge.stops_after(round, (mesh, topology), edges, report)
    }
}

/// The creases the first round fairs with, when the noise estimate's gather did not find them:
/// the normals filtered as much as the input's estimate asks for.
fn first_creases(
    mesh: &TriMesh,
    topology: &Topology,
    options: &FairOptions,
    estimate: Option<f64>,
    face_rings: &mut FaceRingCache,
) -> Option<Creases> {
    options.creases.as_ref().map(|crease_options| {
        let mut crease_options = crease_options.clone();
        crease_options.normal_filtering = crease_options
            .normal_filtering
            .max(estimate.map_or(0, normal_filtering_for));
        detect_creases_cached(mesh, topology, &crease_options, face_rings)
    })
}

/// The creases the rounds fair with, found again before every round (every
/// [`CREASE_RECHECK_ROUNDS`]-th once they stop changing): the noise left after a round makes
/// fewer false creases, and a crease found on the noisy input may turn out to be noise
/// (`docs/measurements.md`). The normals are filtered as much as the current noise asks for, as
/// the estimate made in the same gather as the faces' own feature edges says
/// ([`detect_creases_with_estimate`]; once the noise is gone, that gather is the detection).
struct TrackedCreases {
    creases: Option<Creases>,
    /// Detections in a row that found the creases already kept (or changed in a few edges in
    /// [`CREASE_SETTLED`]): from two on, the creases are found again only every
    /// [`CREASE_RECHECK_ROUNDS`] rounds (once the noise is gone they change little).
    unchanged: usize,
    /// Whether a detection has read the mesh clean (its estimate asked for no filtering): the
    /// rounds only smooth it further, so the later ones find the faces' own feature edges without
    /// estimating again.
    read_clean: bool,
}

impl TrackedCreases {
    /// Whether the creases are found again before round `round` (not the first).
    fn due(&self, round: usize) -> bool {
        self.unchanged < 2 || round.is_multiple_of(CREASE_RECHECK_ROUNDS)
    }

    /// Finds the creases again (with `fans`, the crease options and the faces around each face
    /// the detection keeps), counting the time in `report`; whether they changed.
    fn detect_again(
        &mut self,
        mesh: &TriMesh,
        topology: &Topology,
        (fans, crease_options, face_rings): (&FanRings, &CreaseOptions, &mut FaceRingCache),
        report: &mut FairReport,
    ) -> bool {
        let started = std::time::Instant::now();
        let (noise, found) = detect_creases_with_estimate(
            mesh,
            topology,
            fans,
            crease_options,
            face_rings,
            !self.read_clean,
        );
        report.detection_ms += milliseconds(started);
        self.read_clean |= noise.is_some_and(|noise| normal_filtering_for(noise) == 0);
        let found = Some(found);
        fn edges(creases: &Option<Creases>) -> &[[u32; 2]] {
            creases.as_ref().map_or(&[], |c| &c.edges)
        }
        let (before, after) = (edges(&self.creases), edges(&found));
        if before == after {
            self.unchanged += 1;
            return false;
        }
        // A change of a few edges in twenty counts as settled: the crease set is taken all the
        // same, but the detections thin out.
        let settled =
            CREASE_SETTLED * edges_changed(before, after) <= before.len().max(after.len());
        self.creases = found;
        self.unchanged = if settled { self.unchanged + 1 } else { 0 };
        true
    }
}

/// The tangential relaxation where it is needed ([`relaxation`]): the share every vertex gets,
/// from how much of the input's noise lies along its surface; the slivers' before every round.
struct RelaxationPlan {
    /// The share every vertex gets (`None`: the relaxation acts everywhere in full, or not at
    /// all).
    everywhere: Option<f32>,
    /// Which thin triangles get the whole relaxation: without creases the surface is taken for a
    /// smooth one, whose thin triangles may lie along a bend, so only the folded ones.
    slivers: relaxation::Slivers,
    /// The input's noise along the surface, when it was read (reported).
    tangential_noise: Option<f64>,
}

impl RelaxationPlan {
    /// The plan for `options` on the input `mesh` (its noise along the surface read from `fans`
    /// where the relaxation is only where needed; `estimate` the noise across it).
    fn read(
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        options: &FairOptions,
        estimate: Option<f64>,
    ) -> RelaxationPlan {
        let tangential_noise = (options.variant == FairVariant::NormalProjected
            && options.tangential_relaxation > 0.0
            && options.relaxation == Relaxation::WhereNeeded)
            .then(|| read_tangential_noise(mesh, topology, fans));
        let everywhere =
            tangential_noise.map(|reading| relaxation::everywhere_share(reading, estimate));
        let slivers = match options.creases {
            Some(_) => relaxation::Slivers::All,
            None => relaxation::Slivers::Folded,
        };
        RelaxationPlan {
            everywhere,
            slivers,
            tangential_noise: tangential_noise.flatten(),
        }
    }

    /// Gives `fairing` (loaded with the positions round `round` starts from) its shares. Once
    /// the noise along the surface is gone (the mesh reads as even as a relaxed one), the
    /// relaxation keeps to the thin triangles ([`relaxation::still_needed_share`]), read with
    /// `fans` (the time counted in `report`).
    fn before_round(
        &mut self,
        fairing: &mut ConstrainedFairing,
        round: usize,
        (mesh, topology): (&TriMesh, &Topology),
        fans: Option<&FanRings>,
        report: &mut FairReport,
    ) {
        let Some(share) = &mut self.everywhere else {
            return;
        };
        if round > 0 && *share > 0.0 {
            if let Some(fans) = fans {
                let started = std::time::Instant::now();
                let reading = read_tangential_noise(mesh, topology, fans);
                *share = share.min(relaxation::still_needed_share(reading));
                report.detection_ms += milliseconds(started);
            }
        }
        // From the mesh's state: the risk's copy is faired with the same shares.
        fairing.relax_where_needed(*share, self.slivers);
    }
}

/// Automatic strength: round by round while the estimated risk of the result falls (see
/// [`crate::fairing::strength`]): a copy of the input, moved a little along its normals, goes
/// through the same rounds, and the mesh goes back to the last round that lowered the risk
/// clearly ([`RISK_MIN_FALL`]).
struct RiskJudge {
    risk: RoundRisk,
    /// The risk's copy of the mesh, faired round by round beside it.
    copy: Vec<[f32; 3]>,
    copy_report: FairReport,
    /// The mesh's positions before this round's volume correction.
    before_restore: Vec<[f32; 3]>,
    /// The last round kept: its number and risk, its positions and crease count.
    kept_round: Option<(usize, f64)>,
    kept_positions: Vec<[f32; 3]>,
    kept_creases: usize,
    /// What the second round lowered the risk by.
    first_fall: f64,
}

impl RiskJudge {
    /// The judge for the input `mesh` with noise `noise` (mean edge lengths); σ is read away
    /// from the first detection's `creases` and the boundary.
    fn new(mesh: &TriMesh, topology: &Topology, noise: f64, creases: Option<&Creases>) -> Self {
        let held = held_flags(topology, creases, &[]);
        let edge = crate::metrics::mean_edge_length(mesh);
        let (risk, copy) = RoundRisk::new(mesh, topology, edge, noise, &held);
        RiskJudge {
            risk,
            copy,
            copy_report: FairReport::default(),
            before_restore: Vec::new(),
            kept_round: None,
            kept_positions: Vec::new(),
            kept_creases: 0,
            first_fall: 0.0,
        }
    }

    /// The copy's round, with the same operator (and creases) as the mesh's. The volume
    /// correction (when `volume_kept`) offsets every vertex by one distance per part along its
    /// normal; the copy takes the mesh's offsets (`after` less the positions before the
    /// correction): what its own correction would give, but for a change of the distance that
    /// sums a part's volume change, of order 1/N per vertex against the local response the risk
    /// reads.
    fn fair_copy(
        &mut self,
        fairing: &mut ConstrainedFairing,
        options: &FairOptions,
        after: &[[f32; 3]],
        volume_kept: bool,
    ) {
        fairing.load(&self.copy);
        fairing.run_round(options, &mut self.copy_report);
        fairing.store(&mut self.copy);
        if volume_kept {
            self.copy
                .par_chunks_mut(CHUNK)
                .zip(after.par_chunks(CHUNK))
                .zip(self.before_restore.par_chunks(CHUNK))
                .for_each(|((copy, after), before)| {
                    for ((c, a), b) in copy.iter_mut().zip(after).zip(before) {
                        for k in 0..3 {
                            c[k] += a[k] - b[k];
                        }
                    }
                });
        }
    }

    /// Reads the risk after round `round` (the mesh with `crease_edges` crease edges) into
    /// `report` and keeps the round when it lowers the risk below the last kept round's by
    /// [`RISK_MIN_FALL`] of what the second round lowered it by (the falls after a kept round
    /// add up until they pass that); whether the rounds stop ([`RISK_PATIENCE`] rounds after the
    /// last kept one, or on a risk that is no number).
    fn stops_after(
        &mut self,
        round: usize,
        (mesh, topology): (&TriMesh, &Topology),
        crease_edges: usize,
        report: &mut FairReport,
    ) -> bool {
        let now = self.risk.read(mesh, topology, &self.copy);
        report.risk_by_round.push(now);
        if round == 1 {
            if let Some((_, first)) = self.kept_round {
                self.first_fall = (first - now).max(0.0);
            }
        }
        let fall = RISK_MIN_FALL * self.first_fall;
        if self
            .kept_round
            .is_none_or(|(_, kept_risk)| now < kept_risk - fall)
        {
            self.kept_round = Some((round, now));
            self.kept_positions.clone_from(&mesh.positions);
            self.kept_creases = crease_edges;
        } else if now.is_nan() {
            return true;
        }
        self.kept_round
            .is_some_and(|(kept, _)| round - kept >= RISK_PATIENCE)
    }

    /// Puts `mesh` back to the last kept round (its positions, its round count in `report` and
    /// its `crease_edges`), when later rounds ran.
    fn roll_back(self, mesh: &mut TriMesh, report: &mut FairReport, crease_edges: &mut usize) {
        if let Some((round, _)) = self.kept_round {
            if round + 1 != report.rounds_run {
                mesh.positions = self.kept_positions;
                report.rounds_run = round + 1;
                *crease_edges = self.kept_creases;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fairing::BoundaryMode;
    use crate::mesh::fixtures::irregular_sphere;

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
}
