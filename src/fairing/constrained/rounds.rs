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
    normal_filtering_for, read_noise, RoundRisk, CLEAN_NOISE, MAX_AUTO_ROUNDS, RISK_MIN_FALL,
    RISK_PATIENCE,
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
