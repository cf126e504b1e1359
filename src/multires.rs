//! Multiresolution fairing (paper section 4.2): fair a coarse level, refine, fair, down to M0.
//! STUB: the API contract; implementation to come.

use crate::fairing::BoundaryMode;
use crate::hierarchy::Hierarchy;
use crate::Progress;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MultiresVariant {
    Paper,
    #[default]
    Improved,
}

#[derive(Clone, Debug)]
pub struct MultiresOptions {
    pub start_level: usize,
    pub iterations: usize,
    pub rounds: usize,
    pub boundary: BoundaryMode,
    /// Also fair M0 after the last refinement.
    pub fair_finest: bool,
    pub variant: MultiresVariant,
}

impl Default for MultiresOptions {
    fn default() -> Self {
        Self {
            start_level: 0,
            iterations: 5,
            rounds: 1,
            boundary: BoundaryMode::Curve,
            fair_finest: false,
            variant: MultiresVariant::Improved,
        }
    }
}

/// Buffers reused between runs (the editor runs this on every slider move).
#[derive(Default)]
pub struct MultiresWorkspace {}

/// Returns M0's positions after fairing (M0's triangles are `hierarchy.base_mesh().triangles`),
/// or `None` when `progress` cancelled the run.
pub fn fair_multires(
    hierarchy: &Hierarchy,
    _options: &MultiresOptions,
    _workspace: &mut MultiresWorkspace,
    _progress: &mut dyn Progress,
) -> Option<Vec<[f32; 3]>> {
    Some(hierarchy.base_mesh().positions.clone())
}
