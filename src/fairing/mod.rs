//! Fairing operators: constrained fairing (paper section 3.2) with boundary curves (3.3), and the
//! baselines it is compared against (Laplacian, Taubin, HC Laplacian).
//! STUB: the API contract; implementation to come.

use crate::mesh::{Topology, TriMesh};

/// How boundary vertices of open meshes move.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoundaryMode {
    /// Each boundary loop is smoothed as a closed curve (section 3.3).
    #[default]
    Curve,
    /// Boundary vertices stay where they are.
    Fixed,
}

/// Which constrained operator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FairVariant {
    /// The paper's operator exactly (uniform umbrella weights).
    Paper,
    /// The improved default (see the module docs once implemented).
    #[default]
    Improved,
}

#[derive(Clone, Debug)]
pub struct FairOptions {
    /// Iterations per round.
    pub iterations: usize,
    /// Stop a round when the largest vertex move is below this (model units); 0 disables.
    pub tolerance: f64,
    /// Number of rounds; each round re-imposes the constraints on the current positions.
    pub rounds: usize,
    pub boundary: BoundaryMode,
    pub variant: FairVariant,
}

impl Default for FairOptions {
    fn default() -> Self {
        Self {
            iterations: 10,
            tolerance: 0.0,
            rounds: 1,
            boundary: BoundaryMode::Curve,
            variant: FairVariant::Improved,
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FairReport {
    pub iterations_run: usize,
    /// Largest single-vertex move in the last iteration.
    pub max_move: f64,
}

pub fn fair_constrained(
    _mesh: &mut TriMesh,
    _topology: &Topology,
    _options: &FairOptions,
) -> FairReport {
    FairReport::default()
}
