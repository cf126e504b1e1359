//! The driver of constrained fairing: [`fair_constrained`] decides whether and how much to fair
//! (the noise estimate, [`crate::fairing::strength`]), finds the creases
//! ([`crate::fairing::creases`]) and runs the rounds of section 3.2 ("imposing and relaxing the
//! centre constraints by turns"), with the creases found again, the tangential relaxation where
//! it is needed, the volume given back and, with automatic strength, the risk read after every
//! round and the rounds after the best one undone.

use super::round_steps::{timed, RelaxationPlan, RiskJudge, RoundLoop, TrackedCreases};
use super::ConstrainedFairing;
use crate::fairing::creases::{
    detect_creases_cached, detect_creases_with_estimate, CreaseOptions, Creases, FaceRingCache,
};
use crate::fairing::strength::{
    normal_filtering_for, read_noise, NoiseReading, CLEAN_NOISE, MAX_AUTO_ROUNDS,
};
use crate::fairing::volume::VolumeKeeper;
use crate::fairing::{FairOptions, FairReport, FairVariant, Strength};
use crate::mesh::{breadth_first_order, inverse_permutation, FanRings, Topology, TriMesh};
use crate::{Cancelled, Progress};
use rayon::prelude::*;

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
    fair_constrained_with_progress(mesh, topology, options, &mut crate::NoProgress)
        .unwrap_or_default()
}

/// [`fair_constrained`] reporting to `progress` after every round (a fraction of the rounds
/// asked for; with automatic strength, whose number of rounds is not known beforehand, a
/// fraction that rises with every round and nears 1 as the rounds run out), and stopping when it
/// returns false: [`Cancelled`] then, with `mesh` left part-way (the caller drops it). The result
/// of a run that is not cancelled is the same as [`fair_constrained`]'s, bit for bit.
pub fn fair_constrained_with_progress(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &FairOptions,
    progress: &mut dyn Progress,
) -> Result<FairReport, Cancelled> {
    match FairPlan::new(mesh, topology, options) {
        Some(plan) => plan.run(mesh, topology, options, progress),
        None => {
            progress.check(1.0)?;
            Ok(FairReport::default())
        }
    }
}

/// What a run of [`fair_constrained`] does, decided once before anything is faired: the surface it
/// fairs (the mesh, or the mesh without the triangles lying loose at its non-manifold edges), the
/// vertices the mask holds, and the vertex order the work runs in. [`Self::run`] then follows it
/// on one path.
struct FairPlan {
    /// The surface without its loose triangles, when it has some.
    without_loose: Option<WithoutLoose>,
    /// Vertices a mask pins (empty: no mask).
    pinned: Vec<bool>,
    order: RunOrder,
}

/// A non-manifold scan is faired as the surface it stands for: without the triangles its
/// reconstruction left lying loose at its non-manifold edges (overlays on a fan, fins), which
/// would make their corners boundary vertices on chains no boundary curve runs through, and so
/// hold them with their noise (`crate::mesh::loose_triangles`, `docs/measurements.md`). Same
/// vertices, nothing renumbered; a corner only loose triangles use (a fin's tip) stays where it
/// is. The normal-projected variant only: the paper's fairs the mesh as it is.
struct WithoutLoose {
    /// How many triangles are left out.
    loose: usize,
    kept: TriMesh,
    topology: Topology,
    /// The volume kept is the file's, loose triangles included: they follow their corners, and
    /// their own (cone) volume changes with them; one more uniform offset takes that back.
    volume: Option<VolumeKeeper>,
}

/// Where the work runs in the locality order ([`in_local_order`]), chosen in one place
/// ([`RunOrder::for_options`]).
#[derive(Clone, Copy, PartialEq, Eq)]
enum RunOrder {
    /// In the mesh's own order: a fixed strength of a few rounds, which would not pay for
    /// making the order.
    Mesh,
    /// All of it in the locality order, the first reading included: a fixed strength of
    /// [`LOCAL_ORDER_ROUNDS`] rounds or more.
    Local,
    /// The first reading in the mesh's order, then, when the automatic strength finds the mesh
    /// noisy (a clean one is left as it is, and costs no reordering), the rounds in the locality
    /// order.
    LocalOnceNoisy,
}

impl RunOrder {
    fn for_options(options: &FairOptions) -> Self {
        match options.strength {
            Strength::Fixed if options.rounds >= LOCAL_ORDER_ROUNDS => RunOrder::Local,
            Strength::Fixed => RunOrder::Mesh,
            Strength::Auto => RunOrder::LocalOnceNoisy,
        }
    }
}

impl FairPlan {
    /// The plan for `mesh`, or `None` when there is nothing to do: no iteration, no vertex, no
    /// round asked for, or a mask that does not fit the mesh or pins everything.
    fn new(mesh: &TriMesh, topology: &Topology, options: &FairOptions) -> Option<Self> {
        let nothing_to_do = options.iterations == 0
            || mesh.positions.is_empty()
            || (options.strength == Strength::Fixed && options.rounds == 0)
            || options.mask.as_ref().is_some_and(|mask| {
                mask.check_fits(mesh.positions.len()).is_err() || mask.painted_count() == 0
            });
        if nothing_to_do {
            return None;
        }
        let pinned = options
            .mask
            .as_ref()
            .map(|mask| mask.pinned_flags())
            .unwrap_or_default();
        let without_loose = (options.variant == FairVariant::Improved
            && !topology.non_manifold_edges.is_empty())
        .then(|| crate::mesh::without_loose_triangles(mesh, topology))
        .flatten()
        .map(|(loose, kept, kept_topology)| WithoutLoose {
            loose: loose.len(),
            kept,
            topology: kept_topology,
            volume: options
                .keep_volume
                .then(|| VolumeKeeper::new(mesh, topology, &pinned)),
        });
        Some(FairPlan {
            without_loose,
            pinned,
            order: RunOrder::for_options(options),
        })
    }

    /// Fairs the planned surface, puts the vertices the mask fades back in proportion, and for a
    /// surface without its loose triangles, gives the whole mesh its positions and its volume.
    fn run(
        self,
        mesh: &mut TriMesh,
        topology: &Topology,
        options: &FairOptions,
        progress: &mut dyn Progress,
    ) -> Result<FairReport, Cancelled> {
        let FairPlan {
            without_loose,
            pinned,
            order,
        } = self;
        let original = options.mask.as_ref().map(|_| mesh.positions.clone());
        let mut without_loose = without_loose;
        let (surface, surface_topology) = match &mut without_loose {
            Some(without) => (&mut without.kept, &without.topology),
            None => (&mut *mesh, topology),
        };
        let mut report = match order {
            RunOrder::Local => in_local_order(
                surface,
                surface_topology,
                options,
                &pinned,
                |mesh, topology, options, pinned| {
                    decide_and_fair(mesh, topology, options, pinned, RunOrder::Local, progress)
                },
            ),
            order => decide_and_fair(surface, surface_topology, options, &pinned, order, progress),
        }?;
        // The operator held the pinned vertices; the blend fades the rest by their weights (and
        // puts back pinned boundary vertices, which the boundary curves may have moved).
        if let (Some(mask), Some(original)) = (&options.mask, &original) {
            mask.blend(original, &mut surface.positions);
        }
        if let Some(without) = without_loose {
            mesh.positions = without.kept.positions;
            if let Some(volume) = without.volume.filter(|_| report.rounds_run > 0) {
                volume.restore(mesh, topology, |v| pinned.get(v).copied().unwrap_or(false));
            }
            report.loose_triangles += without.loose;
        }
        progress.check(1.0)?;
        Ok(report)
    }
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
    fair: impl FnOnce(&mut TriMesh, &Topology, &FairOptions, &[bool]) -> Result<FairReport, Cancelled>,
) -> Result<FairReport, Cancelled> {
    let (mut local, set_up_ms) = timed(|| LocalCopy::of(mesh, topology));
    let local_pinned: Vec<bool> = if pinned.is_empty() {
        Vec::new()
    } else {
        local.order.iter().map(|&v| pinned[v as usize]).collect()
    };
    let mut local_options = options.clone();
    local_options.mask = None;
    if let Some(creases) = &mut local_options.creases {
        let position = &local.position;
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
    let mut report = fair(
        &mut local.mesh,
        &local.topology,
        &local_options,
        &local_pinned,
    )?;
    let ((), back_ms) = timed(|| {
        for (&v, p) in local.order.iter().zip(&local.mesh.positions) {
            mesh.positions[v as usize] = *p;
        }
    });
    report.phases.set_up += set_up_ms + back_ms;
    Ok(report)
}

/// A mesh renumbered in the locality order ([`in_local_order`]).
struct LocalCopy {
    /// Local vertex i is the mesh's vertex `order[i]`.
    order: Vec<u32>,
    /// The mesh's vertex v is local vertex `position[v]` (the inverse of `order`).
    position: Vec<u32>,
    mesh: TriMesh,
    topology: Topology,
}

impl LocalCopy {
    /// `mesh` with its vertices numbered breadth-first over the one-rings and its faces sorted by
    /// their lowest corner.
    fn of(mesh: &TriMesh, topology: &Topology) -> Self {
        let (offsets, neighbors) = topology.neighbor_csr();
        let order = breadth_first_order(offsets, neighbors);
        let position = inverse_permutation(&order);
        let positions: Vec<[f32; 3]> = order
            .par_iter()
            .map(|&v| mesh.positions[v as usize])
            .collect();
        // Faces relabelled (corners in their own order, so the winding stays), then placed by
        // their lowest corner with a stable counting sort.
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
        let mesh = TriMesh::new(positions, triangles);
        let topology = Topology::build(&mesh);
        LocalCopy {
            order,
            position,
            mesh,
            topology,
        }
    }
}

/// The noise estimate, the decision to fair at all (automatic strength leaves a clean mesh as it
/// is), the first creases, then the rounds. `order` says where `mesh` stands: in the locality
/// order already ([`RunOrder::Local`]: `mesh` is [`in_local_order`]'s copy), in its own order for
/// good ([`RunOrder::Mesh`]), or in its own order until the automatic strength finds it noisy
/// ([`RunOrder::LocalOnceNoisy`]), when the rounds move to the locality order. [`Cancelled`] when
/// `progress` cancelled the run.
fn decide_and_fair(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &FairOptions,
    pinned: &[bool],
    order: RunOrder,
    progress: &mut dyn Progress,
) -> Result<FairReport, Cancelled> {
    // The fan-ordered one-rings the operator is built from serve the noise estimate and the
    // crease detection first (`read_noise`, `detect_creases_with_estimate`).
    let fans = FanRings::new(&mesh.triangles, topology);
    // In the locality-ordered copy the filter keeps its face order (the same normals bit for bit,
    // its lists built faster).
    let face_rings = if order == RunOrder::Local {
        FaceRingCache::in_mesh_order()
    } else {
        FaceRingCache::default()
    };
    let ((reading, auto_noise), decided_ms) = timed(|| {
        let reading = FirstReading::of(mesh, topology, &fans, options, face_rings);
        let auto_noise = match options.strength {
            Strength::Auto => noisy(reading.estimate, reading.noise.as_ref(), topology),
            Strength::Fixed => None,
        };
        (reading, auto_noise)
    });
    if options.strength == Strength::Auto && auto_noise.is_none() {
        return Ok(FairReport {
            noise_estimate: reading.estimate,
            detection_ms: decided_ms,
            ..FairReport::default()
        });
    }
    let FirstReading {
        estimate,
        creases,
        face_rings,
        noise,
    } = reading;
    drop(noise);
    let rounds = Rounds {
        estimate,
        auto_noise,
        pinned,
    };
    let mut report = if order == RunOrder::LocalOnceNoisy {
        drop(fans);
        in_local_order(
            mesh,
            topology,
            options,
            pinned,
            |mesh, topology, options, pinned| {
                let fans = FanRings::new(&mesh.triangles, topology);
                let found = FoundCreases {
                    creases: None,
                    face_rings: FaceRingCache::in_mesh_order(),
                };
                fair_rounds(
                    mesh,
                    topology,
                    fans,
                    found,
                    options,
                    Rounds { pinned, ..rounds },
                    progress,
                )
            },
        )
    } else {
        let found = FoundCreases {
            creases,
            face_rings,
        };
        fair_rounds(mesh, topology, fans, found, options, rounds, progress)
    }?;
    report.detection_ms += decided_ms;
    Ok(report)
}

/// The first reading of the input ([`FirstReading::of`]).
struct FirstReading {
    /// The noise estimate, in mean edge lengths (`None`: no reading was asked for).
    estimate: Option<f64>,
    /// The creases, when they were found in the same gather (a fixed strength).
    creases: Option<Creases>,
    /// The faces around each face, kept from the detection for the next.
    face_rings: FaceRingCache,
    /// Automatic strength: what the reading saw (which vertices lie on sharp edges, for
    /// [`noisy`]).
    noise: Option<NoiseReading>,
}

impl FirstReading {
    /// The noise estimate, which decides the strength (automatic) and how much the normals are
    /// filtered before creases are detected (raw normals of a noisy mesh make creases of the
    /// noise). A fixed strength finds the estimate and the creases in one gather (skipping the
    /// filter when the mesh is clean); automatic strength fairs only a noisy mesh, so its creases
    /// are always found later on filtered normals, and it reads in the same gather which vertices
    /// lie on sharp edges ([`read_noise`]).
    fn of(
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        options: &FairOptions,
        mut face_rings: FaceRingCache,
    ) -> Self {
        let (estimate, creases, noise) = match (&options.creases, options.strength) {
            (Some(crease_options), Strength::Fixed) => {
                let (estimate, creases) = detect_creases_with_estimate(
                    mesh,
                    topology,
                    fans,
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
                let reading = read_noise(mesh, topology, fans, angle);
                (reading.noise(topology), None, Some(reading))
            }
            (None, _) => (None, None, None),
        };
        FirstReading {
            estimate,
            creases,
            face_rings,
            noise,
        }
    }
}

/// Automatic strength: the noise to fair, `None` for a mesh left as it is: a clean one, one
/// that reads noisy only because of its sharp edges (a coarse CAD part: most of its vertices lie
/// on or beside an edge, and those make the median read noise; away from the edges it reads
/// clean), or one that reads clean on the vertices noise could have moved (off its flat edges:
/// a CAD part written as exporters write it, every vertex on a rim).
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
    let clean_off_flat_edges =
        || reading.is_some_and(|reading| reading.clean_off_flat_edges(topology, CLEAN_NOISE));
    estimate
        .filter(|&noise| noise > CLEAN_NOISE && !clean_away_from_edges() && !clean_off_flat_edges())
}

/// The creases the first reading found (a fixed strength finds them with the noise estimate),
/// with the faces around each face that detection kept, for the next.
struct FoundCreases {
    creases: Option<Creases>,
    face_rings: FaceRingCache,
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
/// which may stop the rounds and undo the last ones. `progress` hears after every round;
/// [`Cancelled`] when it cancelled the run.
fn fair_rounds(
    mesh: &mut TriMesh,
    topology: &Topology,
    fans: FanRings,
    found: FoundCreases,
    options: &FairOptions,
    rounds: Rounds,
    progress: &mut dyn Progress,
) -> Result<FairReport, Cancelled> {
    let Rounds {
        estimate,
        auto_noise,
        pinned,
    } = rounds;
    let FoundCreases {
        creases,
        mut face_rings,
    } = found;
    let (creases, first_detection_ms) = timed(|| {
        creases.or_else(|| first_creases(mesh, topology, options, estimate, &mut face_rings))
    });
    let max_rounds = match auto_noise {
        Some(_) => MAX_AUTO_ROUNDS,
        None => options.rounds,
    };
    let redetect = options.creases.is_some() && max_rounds > 1;
    let (fairing, set_up_ms) = timed(|| {
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
        fairing
    });
    let (relaxation, reading_ms) =
        timed(|| RelaxationPlan::read(mesh, topology, &fans, options, estimate));
    // The fans serve the later rounds only to find the creases again (and estimate the noise
    // that sets the filtering for it) and to read the noise along the surface again while the
    // relaxation acts everywhere: otherwise they are freed before the iterations (the peak,
    // while the operator is set up from them, stays).
    let fans = (redetect || relaxation.everywhere.is_some_and(|share| share > 0.0)).then_some(fans);
    let (volume, volume_ms) = timed(|| {
        options
            .keep_volume
            .then(|| VolumeKeeper::new(mesh, topology, pinned))
    });
    let (judge, risk_ms) =
        timed(|| auto_noise.map(|noise| RiskJudge::new(mesh, topology, noise, creases.as_ref())));
    let mut report = FairReport {
        detection_ms: first_detection_ms,
        tangential_noise: relaxation.tangential_noise,
        ..FairReport::default()
    };
    report.phases.set_up = set_up_ms;
    report.phases.relaxation = reading_ms;
    report.phases.volume = volume_ms;
    report.phases.risk = risk_ms;
    // A round ends once it has settled (`FairOptions::settled`) or at `options.tolerance`.
    let settled = match judge.as_ref() {
        Some(judge) => judge.edge,
        None if options.settled > 0.0 => crate::metrics::mean_edge_length(mesh),
        None => 0.0,
    } * options.settled;
    let options = &options
        .clone()
        .with_tolerance(options.tolerance.max(settled));
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
    // Doubled rounds count as their step against the cap.
    let mut covered = 0.0f32;
    for round in 0..max_rounds {
        let stop = rounds.run(mesh, round, &mut report);
        covered += rounds.step(round);
        progress.check(round_fraction(round + 1, max_rounds, auto_noise.is_some()))?;
        if stop || covered >= max_rounds as f32 {
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
    Ok(report)
}

/// The progress after `done` rounds of at most `max_rounds`: their share, or with automatic
/// strength (which stops long before its cap on most meshes) a share that rises by a little less
/// with every round, `done / (done + AUTO_ROUNDS_HALF_WAY)`, so a bar keeps moving.
fn round_fraction(done: usize, max_rounds: usize, automatic: bool) -> f32 {
    /// Rounds at which an automatic run reads half done (the default stops after 10 to 60).
    const AUTO_ROUNDS_HALF_WAY: f32 = 15.0;
    if automatic {
        done as f32 / (done as f32 + AUTO_ROUNDS_HALF_WAY)
    } else {
        done as f32 / max_rounds.max(1) as f32
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
        for variant in [FairVariant::Paper, FairVariant::Improved] {
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
                Ok(FairReport {
                    rounds_run: 7,
                    ..FairReport::default()
                })
            },
        )
        .expect("the closure finished");
        assert_eq!(report.rounds_run, 7);
        for (after, &before) in faired.positions.iter().zip(&mesh.positions) {
            assert_eq!(*after, moved(before));
        }
        assert_eq!(faired.triangles, mesh.triangles);
    }

    #[test]
    fn the_report_times_the_relaxations_shares_apart() {
        let mut noisy = irregular_sphere();
        crate::noise::add_noise(&mut noisy, &crate::noise::NoiseOptions::default());
        let topology = Topology::build(&noisy);
        // A fixed strength runs the rounds asked for, none doubled and none rolled back.
        let rounds = 4;
        let options = FairOptions::default().with_rounds(rounds);
        // On the ticking clock a timed stretch (two readings; no stretch of a run reads the
        // clock inside another) lasts one step, so each phase is its stretches times the step.
        const STEP: u64 = 3;
        let _ticking = crate::clock::Ticking::start(STEP);
        let report = fair_constrained(&mut noisy, &topology, &options);
        assert_eq!(report.rounds_run, rounds);
        let phases = report.phases;
        let ms = |stretches: usize| (stretches as u64 * STEP) as f64;
        // The relaxation: reading the noise along the surface once, then its pass before every
        // round.
        assert_eq!(phases.relaxation, ms(1 + rounds), "{phases:?}");
        // The iterations: loading the positions and running the round, every round.
        assert_eq!(phases.iterations, ms(2 * rounds), "{phases:?}");
        // The volume: setting the correction up once, then giving the volume back every round.
        assert_eq!(phases.volume, ms(1 + rounds), "{phases:?}");
    }

    #[test]
    fn progress_rises_round_by_round_and_a_refusal_cancels_the_run() {
        let mut noisy = irregular_sphere();
        crate::noise::add_noise(&mut noisy, &crate::noise::NoiseOptions::default());
        let topology = Topology::build(&noisy);
        for options in [
            FairOptions::default(),
            FairOptions::default().with_rounds(4),
        ] {
            let mut plain = noisy.clone();
            let expected = fair_constrained(&mut plain, &topology, &options);
            assert!(expected.rounds_run > 0, "the noisy sphere is faired");
            let mut reported = Vec::new();
            let mut watched = noisy.clone();
            let report = fair_constrained_with_progress(
                &mut watched,
                &topology,
                &options,
                &mut |fraction: f32| {
                    reported.push(fraction);
                    true
                },
            );
            // Watching changes nothing (but the time taken).
            let untimed = |report: FairReport| FairReport {
                detection_ms: 0.0,
                phases: Default::default(),
                ..report
            };
            assert_eq!(report.map(untimed), Ok(untimed(expected)));
            assert_eq!(watched.positions, plain.positions);
            assert!(reported.len() >= 2, "{reported:?}");
            assert!(reported.windows(2).all(|w| w[0] <= w[1]), "{reported:?}");
            assert!(reported.iter().all(|f| (0.0..=1.0).contains(f)));
            assert_eq!(reported.last(), Some(&1.0));
            // Refusing after the first round stops the run there.
            let mut calls = 0;
            let cancelled = fair_constrained_with_progress(
                &mut noisy.clone(),
                &topology,
                &options,
                &mut |_: f32| {
                    calls += 1;
                    false
                },
            );
            assert_eq!(cancelled, Err(crate::Cancelled));
            assert_eq!(calls, 1, "no round runs after the refusal");
        }
    }
}
