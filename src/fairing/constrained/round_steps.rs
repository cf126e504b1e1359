//! One round of constrained fairing and what the rounds carry from one to the next
//! ([`RoundLoop`]): the creases found again when due ([`TrackedCreases`]), the tangential
//! relaxation's shares ([`RelaxationPlan`]) and, with automatic strength, Stein's unbiased risk
//! estimate read after every round, which keeps the best round and stops the rounds
//! ([`RiskJudge`]).

use super::weights::held_flags;
use super::ConstrainedFairing;
use crate::fairing::creases::{
    detect_creases_with_estimate, CreaseOptions, Creases, FaceRingCache, FeatureClass,
};
use crate::fairing::relaxation::{self, read_tangential_noise};
use crate::fairing::strength::{
    normal_filtering_for, RoundRisk, DOUBLED_FROM_ROUND, DOUBLED_STEP, RISK_MIN_FALL, RISK_PATIENCE,
};
use crate::fairing::volume::VolumeKeeper;
use crate::fairing::{FairOptions, FairReport, FairVariant, Relaxation};
use crate::mesh::{FanRings, Topology, TriMesh};
use glam::Vec3A;

/// Once two detections in a row found the creases unchanged (or settled, see
/// [`CREASE_SETTLED`]), [`fair_constrained`] finds them again only in every this many rounds.
pub(super) const CREASE_RECHECK_ROUNDS: usize = 4;

/// A detection whose feature edges differ from the last in at most one edge in this many (the
/// two sets' symmetric difference against the larger) counts as unchanged for
/// [`CREASE_RECHECK_ROUNDS`].
pub(super) const CREASE_SETTLED: usize = 20;

/// How many edges are in one of `a` and `b` but not the other (each a set of edges).
pub(super) fn edges_changed(a: &[[u32; 2]], b: &[[u32; 2]]) -> usize {
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

/// `work`'s value and the milliseconds it took (wall clock): the phase timer of the reports'
/// `phases` and `detection_ms`, which keeps the clock out of the algorithm's lines.
pub(super) fn timed<T>(work: impl FnOnce() -> T) -> (T, f64) {
    let started = crate::clock::Instant::now();
    let value = work();
    (value, started.elapsed().as_secs_f64() * 1e3)
}

/// What the rounds of `fair_rounds` ([`super::rounds`]) work with, set up before the first.
pub(super) struct RoundLoop<'a> {
    pub(super) topology: &'a Topology,
    pub(super) options: &'a FairOptions,
    /// Vertices a mask pins (empty: none).
    pub(super) pinned: &'a [bool],
    pub(super) fairing: ConstrainedFairing,
    /// The mesh's fans, kept only while later rounds need them (see `fair_rounds`).
    pub(super) fans: Option<FanRings>,
    pub(super) face_rings: FaceRingCache,
    /// Whether the creases are found again before later rounds.
    pub(super) redetect: bool,
    pub(super) tracked: TrackedCreases,
    pub(super) relaxation: RelaxationPlan,
    pub(super) volume: Option<VolumeKeeper>,
    pub(super) judge: Option<RiskJudge>,
}

impl RoundLoop<'_> {
    /// How far round `round` moves the vertices, in its iterations' moves: automatic strength
    /// doubles the rounds from [`DOUBLED_FROM_ROUND`] on, a fixed strength runs plain rounds.
    pub(super) fn step(&self, round: usize) -> f32 {
        if self.judge.is_some() && round >= DOUBLED_FROM_ROUND {
            DOUBLED_STEP
        } else {
            1.0
        }
    }

    /// Round `round` on `mesh`, counted in `report`: the creases found again when they are due
    /// (the operator set up again for them when they changed), the relaxation's shares, the
    /// operator's iterations, the volume given back, and, with automatic strength, the risk
    /// read. Whether the rounds stop.
    pub(super) fn run(
        &mut self,
        mesh: &mut TriMesh,
        round: usize,
        report: &mut FairReport,
    ) -> bool {
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
                let ((), ms) = timed(|| {
                    fairing.for_other_creases(mesh, topology, fans, creases, self.pinned);
                });
                report.phases.set_up += ms;
            }
        }
        // Imposes the constraints on the positions this round starts from.
        let ((), load_ms) = timed(|| self.fairing.load(&mesh.positions));
        let fans = self.fans.as_ref();
        let at = (&*mesh, topology);
        let ((), ms) = timed(|| {
            self.relaxation
                .before_round(&mut self.fairing, round, at, fans);
        });
        report.phases.relaxation += ms;
        let step = self.step(round);
        let (iterations, ms) = timed(|| {
            let iterations = self.fairing.run_round(self.options, report);
            if step != 1.0 {
                self.fairing.extrapolate(step);
            }
            self.fairing.store(&mut mesh.positions);
            iterations
        });
        report.phases.iterations += load_ms + ms;
        let class = self.tracked.creases.as_ref().map(|c| c.class.as_slice());
        let class = class.unwrap_or(&[]);
        let held = |v: usize| class.get(v) == Some(&FeatureClass::Corner);
        let (offsets, ms) = timed(|| {
            self.volume
                .as_ref()
                .map(|volume| volume.restore_with_normals(mesh, topology, held).1)
        });
        report.phases.volume += ms;
        let Some(judge) = &mut self.judge else {
            return false;
        };
        let (stop, ms) = timed(|| {
            judge.fair_copy(&mut self.fairing, iterations, step);
            // The copy takes the mesh's volume offsets: what its own correction would give, but
            // for a change of the distance that sums a part's volume change, of order 1/N per
            // vertex against the local response the risk reads.
            if let (Some(volume), Some(offsets)) = (&self.volume, offsets) {
                volume.offset(&mut judge.copy, &offsets, held);
                judge.normals = Some(offsets.normals);
            }
            let edges = self.tracked.creases.as_ref().map_or(0, |c| c.edges.len());
            judge.stops_after(round, (mesh, topology), edges, report)
        });
        report.phases.risk += ms;
        stop
    }
}

/// The creases the rounds fair with, found again before every round (every
/// [`CREASE_RECHECK_ROUNDS`]-th once they stop changing): the noise left after a round makes
/// fewer false creases, and a crease found on the noisy input may turn out to be noise
/// (`docs/measurements.md`). The normals are filtered as much as the current noise asks for, as
/// the estimate made in the same gather as the faces' own feature edges says
/// ([`detect_creases_with_estimate`]; once the noise is gone, that gather is the detection).
pub(super) struct TrackedCreases {
    pub(super) creases: Option<Creases>,
    /// Detections in a row that found the creases already kept (or changed in a few edges in
    /// [`CREASE_SETTLED`]): from two on, the creases are found again only every
    /// [`CREASE_RECHECK_ROUNDS`] rounds (once the noise is gone they change little).
    pub(super) unchanged: usize,
    /// Whether a detection has read the mesh clean (its estimate asked for no filtering): the
    /// rounds only smooth it further, so the later ones find the faces' own feature edges without
    /// estimating again.
    pub(super) read_clean: bool,
}

impl TrackedCreases {
    /// Whether the creases are found again before round `round` (not the first).
    pub(super) fn due(&self, round: usize) -> bool {
        self.unchanged < 2 || round.is_multiple_of(CREASE_RECHECK_ROUNDS)
    }

    /// Finds the creases again (with `fans`, the crease options and the faces around each face
    /// the detection keeps), counting the time in `report`; whether they changed.
    pub(super) fn detect_again(
        &mut self,
        mesh: &TriMesh,
        topology: &Topology,
        (fans, crease_options, face_rings): (&FanRings, &CreaseOptions, &mut FaceRingCache),
        report: &mut FairReport,
    ) -> bool {
        let ((noise, found), ms) = timed(|| {
            detect_creases_with_estimate(
                mesh,
                topology,
                fans,
                crease_options,
                face_rings,
                !self.read_clean,
            )
        });
        report.detection_ms += ms;
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
pub(super) struct RelaxationPlan {
    /// The share every vertex gets (`None`: the relaxation acts everywhere in full, or not at
    /// all).
    pub(super) everywhere: Option<f32>,
    /// Which thin triangles get the whole relaxation: without creases the surface is taken for a
    /// smooth one, whose thin triangles may lie along a bend, so only the folded ones.
    pub(super) slivers: relaxation::Slivers,
    /// The input's noise along the surface, when it was read (reported).
    pub(super) tangential_noise: Option<f64>,
}

impl RelaxationPlan {
    /// The plan for `options` on the input `mesh` (its noise along the surface read from `fans`
    /// where the relaxation is only where needed; `estimate` the noise across it).
    pub(super) fn read(
        mesh: &TriMesh,
        topology: &Topology,
        fans: &FanRings,
        options: &FairOptions,
        estimate: Option<f64>,
    ) -> RelaxationPlan {
        let tangential_noise = (options.variant == FairVariant::Improved
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
    /// `fans`.
    pub(super) fn before_round(
        &mut self,
        fairing: &mut ConstrainedFairing,
        round: usize,
        (mesh, topology): (&TriMesh, &Topology),
        fans: Option<&FanRings>,
    ) {
        let Some(share) = &mut self.everywhere else {
            return;
        };
        if round > 0 && *share > 0.0 {
            if let Some(fans) = fans {
                let reading = read_tangential_noise(mesh, topology, fans);
                *share = share.min(relaxation::still_needed_share(reading));
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
pub(super) struct RiskJudge {
    /// The input's mean edge length.
    pub(super) edge: f64,
    pub(super) risk: RoundRisk,
    /// The risk's copy of the mesh, faired round by round beside it.
    pub(super) copy: Vec<[f32; 3]>,
    pub(super) copy_report: FairReport,
    /// The mesh's unit vertex normals from this round's volume correction, if it ran.
    pub(super) normals: Option<Vec<Vec3A>>,
    /// The last round kept: its number and risk, its positions and crease count.
    pub(super) kept_round: Option<(usize, f64)>,
    pub(super) kept_positions: Vec<[f32; 3]>,
    pub(super) kept_creases: usize,
    /// What the second round lowered the risk by.
    pub(super) first_fall: f64,
}

impl RiskJudge {
    /// The judge for the input `mesh` with noise `noise` (mean edge lengths); σ is read away
    /// from the first detection's `creases` and the boundary.
    pub(super) fn new(
        mesh: &TriMesh,
        topology: &Topology,
        noise: f64,
        creases: Option<&Creases>,
    ) -> Self {
        let held = held_flags(topology, creases, &[]);
        let edge = crate::metrics::mean_edge_length(mesh);
        let (risk, copy) = RoundRisk::new(mesh, topology, edge, noise, &held);
        RiskJudge {
            edge,
            risk,
            copy,
            copy_report: FairReport::default(),
            normals: None,
            kept_round: None,
            kept_positions: Vec::new(),
            kept_creases: 0,
            first_fall: 0.0,
        }
    }

    /// The copy's round, with the same operator (and creases) as the mesh's, its `iterations`
    /// (the mesh's round settled after that many: the copy goes through the same map) and its
    /// `step` ([`ConstrainedFairing::extrapolate`]).
    pub(super) fn fair_copy(
        &mut self,
        fairing: &mut ConstrainedFairing,
        iterations: usize,
        step: f32,
    ) {
        fairing.load(&self.copy);
        fairing.run_iterations(iterations, &mut self.copy_report);
        if step != 1.0 {
            fairing.extrapolate(step);
        }
        fairing.store(&mut self.copy);
    }

    /// Reads the risk after round `round` (the mesh with `crease_edges` crease edges) into
    /// `report` and keeps the round when it lowers the risk below the last kept round's by
    /// [`RISK_MIN_FALL`] of what the second round lowered it by (the falls after a kept round
    /// add up until they pass that); whether the rounds stop ([`RISK_PATIENCE`] rounds after the
    /// last kept one, or on a risk that is no number).
    pub(super) fn stops_after(
        &mut self,
        round: usize,
        (mesh, topology): (&TriMesh, &Topology),
        crease_edges: usize,
        report: &mut FairReport,
    ) -> bool {
        let normals = self.normals.take();
        let now = self
            .risk
            .read(mesh, topology, &self.copy, normals.as_deref());
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
    pub(super) fn roll_back(
        self,
        mesh: &mut TriMesh,
        report: &mut FairReport,
        crease_edges: &mut usize,
    ) {
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
}
