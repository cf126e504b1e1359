//! Fairing operators: constrained fairing (paper section 3.2) with boundary curves (3.3), and the
//! baselines it is compared against (Laplacian, Taubin, HC Laplacian).
//!
//! - [`fair_constrained`] ([`constrained`]): every interior triangle solves the local problem (6)
//!   in closed form (eq 7) with its barycentre held at its anchor; each vertex takes the mean of
//!   its triangles' solutions (Jacobi). Boundary loops are faired as closed curves ([`boundary`]).
//! - [`fair_laplacian`], [`fair_taubin`], [`fair_hc`] ([`baseline`]): the classic umbrella
//!   smoothers, with the same boundary options, for comparison.
//! - [`Method`] and [`MethodOptions`] name one of the four for the CLI and the editor;
//!   [`fair`] runs whichever is chosen.
//!
//! # The two constrained variants, and why the default is not the paper's
//!
//! With the paper's uniform weights ω_ij = 1/n_i the umbrella operator is blind to geometry: on an
//! irregular mesh a vertex is pulled towards the centroid of its neighbours even where the surface
//! is already smooth, so vertices slide along the surface.
//!
//! [`FairVariant::Improved`] (the default; it was called "normal-projected") computes exactly the paper's update x̃ (all
//! vertices, Jacobi) and keeps only the component of each move x̃_v − x_v along the normal of v's
//! fan taken at the midpoints between the positions and their umbrella means; boundary vertices
//! keep the part of the curve update orthogonal to the loop's tangent. Noise lies across the
//! surface, so removing it needs only normal motion; the tangential part of the paper's update is
//! the sliding. Which normal: the one that keeps the volume best is the volume gradient halfway
//! along the move; the midpoint fan approximates it without a third pass over the mesh (see
//! [`constrained`]).
//!
//! So the projection keeps vertices where they belong (texture coordinates, per-vertex attributes
//! and triangle shapes stay meaningful, and rounds do not accumulate drift), comes as close or
//! closer to the clean surface, keeps the volume as well, and costs a fan normal per vertex in the
//! same two passes. [`FairVariant::Paper`] remains available and is the faster of the two. The
//! measurements behind this (`examples/fairing_quality.rs`) are in the repository's
//! `docs/measurements.md`; `docs/paper.md` is the reading of the paper this follows.
//!
//! # What the default adds to the projected operator
//! [`FairOptions::default`] also
//! - leaves a clean mesh as it is and fairs a noisy one round by round while the estimated error
//!   of the result falls (Stein's unbiased risk estimate, read from a slightly moved copy of the
//!   input faired alongside), keeping the last round that lowered it clearly ([`Strength::Auto`],
//!   [`strength`]);
//! - keeps sharp creases as curves with fixed corners ([`creases`]);
//! - adds a small tangential relaxation (weight [`DEFAULT_TANGENTIAL_RELAXATION`]) where it is
//!   needed ([`Relaxation::WhereNeeded`], [`relaxation`]): everywhere when the input's noise
//!   moved its vertices along the surface too, until the mesh reads as even as a relaxed one,
//!   and at the vertices beside thin triangles, whose normals the projection alone leaves
//!   folded. This one does move vertices along the surface (unlike the projection alone);
//!   `with_tangential_relaxation(0.0)` turns it off;
//! - finds the creases again before every round (the noise left makes fewer false ones; once two
//!   detections in a row change nothing, before every fourth);
//! - gives every connected part its volume back after every round with one uniform offset along
//!   the normals ([`volume`]; `with_keep_volume(false)` turns it off).
//!
//! [`FairOptions::paper`] is the paper's method with none of these
//! (`examples/fairing_default.rs` prints the table behind them).
//!
//! Both variants use the paper's uniform weights, so the local matrices depend on the valence
//! triple alone and are precomputed once per topology.

pub mod baseline;
pub mod boundary;
pub mod choices;
pub mod constrained;
pub mod creases;
mod feature_edges;
pub mod mask;
pub mod outcome;
pub mod relaxation;
pub mod strength;
pub mod volume;

use crate::mesh::{Topology, TriMesh};

pub use baseline::{
    fair_hc, fair_laplacian, fair_taubin, HcOptions, LaplacianOptions, TaubinOptions,
};
pub use choices::MethodChoices;
pub use constrained::{fair_constrained, fair_constrained_with_progress, ConstrainedFairing};
pub use creases::{detect_creases, CreaseOptions, Creases, FeatureClass};
pub use mask::{Mask, MaskError};
pub use outcome::{fair_measured, FairOutcome, ReportContext};
pub use strength::estimate_noise;

/// How boundary vertices of open meshes move.
/// Exhaustive on purpose: the editor, the CLI and the Python package each name every choice, so a
/// new one is a breaking change that they all take up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum BoundaryMode {
    /// Each boundary loop is smoothed as a closed curve (section 3.3).
    #[default]
    Curve,
    /// Boundary vertices stay where they are.
    Fixed,
}

impl BoundaryMode {
    pub fn name(self) -> &'static str {
        match self {
            BoundaryMode::Curve => "curve",
            BoundaryMode::Fixed => "fixed",
        }
    }
}

/// Which constrained operator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum FairVariant {
    /// The paper's operator exactly (uniform umbrella weights, eq 7, plain average).
    Paper,
    /// The improved variant (the default): the paper's update with only its component along the
    /// normal of the midpoint fan kept (boundary vertices: the component orthogonal to the loop
    /// tangent), so vertices no longer slide along the surface; see the module docs for why.
    /// "Improved" is also what [`crate::multires::MultiresVariant`] calls its own change of the
    /// paper's recipe: every variant of fairmesh is either the paper's or the improved one.
    #[default]
    Improved,
}

impl FairVariant {
    /// The improved variant's former name (the paper's update projected on the normal).
    #[deprecated(note = "renamed FairVariant::Improved, the word the CLI and Python use")]
    #[allow(non_upper_case_globals)]
    pub const NormalProjected: FairVariant = FairVariant::Improved;

    /// The variant's name as `--variant`, Python's `variant=` and the JSON report spell it.
    pub fn name(self) -> &'static str {
        match self {
            FairVariant::Paper => "paper",
            FairVariant::Improved => "improved",
        }
    }
}

/// Options of [`fair_constrained`]; build them with `FairOptions::default()` and the `with_*`
/// setters.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct FairOptions {
    /// Iterations per round.
    pub iterations: usize,
    /// Stop a round when the largest vertex move is below this (model units); 0 disables.
    pub tolerance: f64,
    /// [`fair_constrained`] also stops a round once it has settled: once no vertex moved by more
    /// than this many mean edge lengths in an iteration, along its normal and by a tenth of its
    /// tangential relaxation (default [`ROUND_SETTLED`]; 0 runs every iteration).
    /// [`ConstrainedFairing::run`] does not read it.
    pub settled: f64,
    /// Number of rounds; each round re-imposes the constraints on the current positions. With
    /// [`Strength::Auto`] the rounds are chosen from the mesh's noise instead.
    pub rounds: usize,
    /// Whether `rounds` is used as given or chosen from the estimated noise (the default).
    pub strength: Strength,
    /// How boundary vertices move.
    pub boundary: BoundaryMode,
    /// The paper's update or its normal-projected form (the default).
    pub variant: FairVariant,
    /// Keep sharp creases ([`creases`]): `None` fairs every vertex alike, as the paper does.
    /// The normals are filtered before detection at least as much as the estimated noise asks
    /// for ([`strength::normal_filtering_for`]).
    pub creases: Option<CreaseOptions>,
    /// Normal-projected only: weight (0 to 1) of the tangential relaxation that evens out
    /// triangles jittered along the surface ([`ConstrainedFairing::set_tangential_relaxation`]).
    pub tangential_relaxation: f64,
    /// Normal-projected only: which vertices get the tangential relaxation.
    pub relaxation: Relaxation,
    /// Where to fair ([`mask`]): `None` fairs every vertex; with a mask, weight-0 vertices are
    /// held like fixed boundary vertices and the rest blended by their weights. A mask that does
    /// not fit the mesh leaves it unchanged.
    pub mask: Option<Mask>,
    /// After every round, give each connected part back the volume it had before fairing with
    /// one uniform offset along the normals ([`volume`]); the default. Off in
    /// [`FairOptions::paper`].
    pub keep_volume: bool,
}

with_setters!(FairOptions {
    with_iterations => iterations: usize,
    with_tolerance => tolerance: f64,
    with_settled => settled: f64,
    with_strength => strength: Strength,
    with_boundary => boundary: BoundaryMode,
    with_variant => variant: FairVariant,
    with_creases => creases: Option<CreaseOptions>,
    with_tangential_relaxation => tangential_relaxation: f64,
    with_relaxation => relaxation: Relaxation,
    with_mask => mask: Option<Mask>,
    with_keep_volume => keep_volume: bool,
});

impl FairOptions {
    /// `self` running exactly `rounds` rounds (a fixed strength).
    #[must_use]
    pub fn with_rounds(mut self, rounds: usize) -> Self {
        self.rounds = rounds;
        self.strength = Strength::Fixed;
        self
    }

    /// The paper's method exactly: its operator, one round, every vertex alike (no creases).
    pub fn paper() -> Self {
        Self::default()
            .with_variant(FairVariant::Paper)
            .with_rounds(1)
            .with_creases(None)
            .with_tangential_relaxation(0.0)
            .with_keep_volume(false)
            .with_settled(0.0)
    }
}

impl Default for FairOptions {
    fn default() -> Self {
        Self {
            iterations: 10,
            tolerance: 0.0,
            settled: ROUND_SETTLED,
            rounds: 1,
            strength: Strength::Auto,
            boundary: BoundaryMode::Curve,
            variant: FairVariant::Improved,
            creases: Some(CreaseOptions::default()),
            tangential_relaxation: DEFAULT_TANGENTIAL_RELAXATION,
            relaxation: Relaxation::WhereNeeded,
            mask: None,
            keep_volume: true,
        }
    }
}

/// The default [`FairOptions::settled`], in mean edge lengths: a round of [`fair_constrained`]
/// ends once no vertex moves by more than this in an iteration (its tangential relaxation counted
/// at a tenth: a slow drift along the surface that the next rounds carry on). A round's
/// iterations converge to
/// its fixed point (the paper's "5 to 10 iterations"), the worst vertex last; past this the moves
/// left change the result by well under a percent, and on finely sampled meshes most rounds
/// settle in 2 to 5 iterations of the 10 (`docs/measurements.md`, "A round ends once it has
/// settled").
pub const ROUND_SETTLED: f64 = 1e-3;

/// The default [`FairOptions::tangential_relaxation`] (`docs/measurements.md`).
pub const DEFAULT_TANGENTIAL_RELAXATION: f64 = 0.1;

/// Which vertices the tangential relaxation ([`FairOptions::tangential_relaxation`]) moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Relaxation {
    /// Every vertex, with the whole weight.
    Everywhere,
    /// The default ([`relaxation`]): every vertex by the share of the weight that the input's
    /// noise along the surface asks for (all of it for noise in every direction, none for noise
    /// across the surface only) until the mesh reads as even as a relaxed one, and, before every
    /// round, the whole weight at the vertices that have a thin triangle (a sliver) among their
    /// triangles.
    #[default]
    WhereNeeded,
}

/// How many rounds constrained fairing runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Strength {
    /// Estimate the mesh's noise (a clean mesh gets no round), then run rounds while the estimated
    /// error of the result falls and keep the last round that lowered it clearly
    /// ([`strength::RISK_MIN_FALL`]). Every round runs twice (the second time on the risk
    /// estimate's copy of the input).
    #[default]
    Auto,
    /// Exactly [`FairOptions::rounds`] rounds.
    Fixed,
}

/// What a fairing run did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FairReport {
    /// Iterations actually run, summed over rounds (with [`Strength::Auto`], also over the one or
    /// two rounds run past the kept one; the risk estimate's copy not counted).
    pub iterations_run: usize,
    /// Rounds that made the result (with [`Strength::Auto`], the last round kept: the last that
    /// lowered the estimated error by [`strength::RISK_MIN_FALL`] of the second round's fall;
    /// up to [`strength::RISK_PATIENCE`] more were run and undone; from
    /// [`strength::DOUBLED_FROM_ROUND`] on, each round moved twice as far).
    pub rounds_run: usize,
    /// Largest single-vertex move in the last iteration (model units; the tangential relaxation's
    /// part of a move counted at a tenth, as a round's settling reads it).
    pub max_move: f64,
    /// The input's estimated noise in mean edge lengths ([`strength::estimate_noise`]), when the
    /// run estimated it ([`Strength::Auto`], or creases kept).
    pub noise_estimate: Option<f64>,
    /// With [`Relaxation::WhereNeeded`], how much of the input's noise lies along its surface, in
    /// mean edge lengths ([`relaxation::estimate_tangential_noise`]); `None` otherwise.
    pub tangential_noise: Option<f64>,
    /// Feature edges kept as creases (0 without creases).
    pub crease_edges: usize,
    /// Triangles left out of the smoothing because they lie loose at a non-manifold edge
    /// ([`crate::mesh::loose_triangles`]; the default variant only): their corners move with
    /// the rest of the surface.
    pub loose_triangles: usize,
    /// Milliseconds of the run spent estimating the noise and finding creases (constrained
    /// fairing; before the first round and again between rounds), part of its whole time.
    pub detection_ms: f64,
    /// Where the rest of a constrained fairing run's time went, in milliseconds (wall clock; for
    /// studying its cost: `fair --json` prints it as `phases_ms`).
    pub phases: FairPhases,
    /// With [`Strength::Auto`], the estimated risk of each round run, in order (mean squared
    /// error along the normals plus σ², squared model units: [`strength`]); the kept round reads
    /// no more than [`strength::RISK_MIN_FALL`] of the second round's fall above the least, and
    /// every round before it higher. Empty otherwise. For studying the stopping rule:
    /// `fair --json` prints it as `risk_by_round`.
    pub risk_by_round: Vec<f64>,
}

/// Milliseconds of a constrained fairing run by phase ([`FairReport::phases`]); with
/// [`FairReport::detection_ms`] they make up nearly all of the run.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct FairPhases {
    /// The operator's set-up, its updates for other creases, and the locality-ordered copy of
    /// the mesh the rounds run on.
    pub set_up: f64,
    /// The mesh's own iterations (with loading and storing the positions).
    pub iterations: f64,
    /// The volume correction after every round.
    pub volume: f64,
    /// The tangential relaxation's shares: reading the noise along the surface, and before
    /// every round the pass that finds the thin triangles.
    pub relaxation: f64,
    /// Automatic strength: the risk estimate (its copy's iterations, its reading, keeping the
    /// best round's positions).
    pub risk: f64,
}

/// The smoothing methods offered by the CLI and the editor.
/// Exhaustive on purpose: the editor, the CLI and the Python package each name every choice, so a
/// new one is a breaking change that they all take up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Method {
    /// Constrained fairing (the paper's method).
    #[default]
    Constrained,
    /// Umbrella Laplacian smoothing (shrinks).
    Laplacian,
    /// Taubin's λ|μ smoothing.
    Taubin,
    /// HC Laplacian (Vollmer et al.).
    Hc,
}

impl Method {
    pub const ALL: [Method; 4] = [
        Method::Constrained,
        Method::Laplacian,
        Method::Taubin,
        Method::Hc,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Method::Constrained => "constrained",
            Method::Laplacian => "laplacian",
            Method::Taubin => "taubin",
            Method::Hc => "hc",
        }
    }
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(text))
            .ok_or_else(|| {
                format!("unknown method `{text}`; expected constrained, laplacian, taubin or hc")
            })
    }
}

/// One method with its options.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum MethodOptions {
    Constrained(FairOptions),
    Laplacian(LaplacianOptions),
    Taubin(TaubinOptions),
    Hc(HcOptions),
}

impl MethodOptions {
    /// The method with its default options.
    pub fn default_for(method: Method) -> Self {
        match method {
            Method::Constrained => MethodOptions::Constrained(FairOptions::default()),
            Method::Laplacian => MethodOptions::Laplacian(LaplacianOptions::default()),
            Method::Taubin => MethodOptions::Taubin(TaubinOptions::default()),
            Method::Hc => MethodOptions::Hc(HcOptions::default()),
        }
    }

    pub fn method(&self) -> Method {
        match self {
            MethodOptions::Constrained(_) => Method::Constrained,
            MethodOptions::Laplacian(_) => Method::Laplacian,
            MethodOptions::Taubin(_) => Method::Taubin,
            MethodOptions::Hc(_) => Method::Hc,
        }
    }

    /// The constrained variant's name ([`FairVariant::name`]); `None` for a baseline.
    pub fn variant_name(&self) -> Option<&'static str> {
        match self {
            MethodOptions::Constrained(o) => Some(o.variant.name()),
            _ => None,
        }
    }
}

/// Runs whichever method `options` names.
pub fn fair(mesh: &mut TriMesh, topology: &Topology, options: &MethodOptions) -> FairReport {
    match options {
        MethodOptions::Constrained(o) => fair_constrained(mesh, topology, o),
        MethodOptions::Laplacian(o) => fair_laplacian(mesh, topology, o),
        MethodOptions::Taubin(o) => fair_taubin(mesh, topology, o),
        MethodOptions::Hc(o) => fair_hc(mesh, topology, o),
    }
}

/// [`fair`], or [`fair_masked`] with a `mask`, reporting to `progress` and stopping when it
/// returns false ([`Cancelled`](crate::Cancelled) then, with `mesh` left part-way: the caller
/// drops it). Constrained fairing reports after every round ([`fair_constrained_with_progress`]);
/// a baseline, whose iterations take a fraction of that, reports when it is done. Not cancelled, the result is
/// the same as [`fair`]'s or [`fair_masked`]'s, bit for bit.
pub fn fair_with_progress(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &MethodOptions,
    mask: Option<&Mask>,
    progress: &mut dyn crate::Progress,
) -> Result<FairReport, crate::Cancelled> {
    if let (MethodOptions::Constrained(o), Some(mask)) = (options, mask) {
        if mask.check_fits(mesh.positions.len()).is_err() {
            progress.check(1.0)?;
            return Ok(FairReport::default());
        }
        let masked = o.clone().with_mask(Some(mask.clone()));
        return fair_constrained_with_progress(mesh, topology, &masked, progress);
    }
    if let MethodOptions::Constrained(o) = options {
        return fair_constrained_with_progress(mesh, topology, o, progress);
    }
    let report = match mask {
        Some(mask) => fair_masked(mesh, topology, options, mask),
        None => fair(mesh, topology, options),
    };
    progress.check(1.0)?;
    Ok(report)
}

/// [`fair`] changing the mesh only where `mask` allows ([`mask`]): constrained fairing holds the
/// weight-0 vertices like fixed boundary vertices ([`FairOptions::mask`]); the baselines smooth
/// the whole mesh and the result is blended back by the weights. Either way weight-0 vertices
/// keep their positions exactly. A mask that does not fit the mesh leaves it unchanged.
pub fn fair_masked(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &MethodOptions,
    mask: &Mask,
) -> FairReport {
    if mask.check_fits(mesh.positions.len()).is_err() {
        return FairReport::default();
    }
    if let MethodOptions::Constrained(o) = options {
        let masked = o.clone().with_mask(Some(mask.clone()));
        return fair_constrained(mesh, topology, &masked);
    }
    let original = mesh.positions.clone();
    let report = fair(mesh, topology, options);
    mask.blend(&original, &mut mesh.positions);
    report
}
