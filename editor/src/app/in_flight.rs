//! The work in flight: the generation counters that tell a job's result from a stale one, which
//! results are on screen, the progress the panels show, the fairing workspace the slider reuses
//! and the faired result waiting to be measured.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

use fairmesh::multires::MultiresWorkspace;

use super::generation::{Generation, GenerationId};
use super::jobs::{JobCounter, SharedProgress};
use super::kept_results::KeptResults;
use super::state::HierarchyKey;
use super::tasks::measure::MeasureRequest;

/// What is running in the background for the document, and what of it has come back.
#[derive(Default)]
pub(in crate::app) struct InFlight {
    pub(in crate::app) load_generation: Generation,
    pub(in crate::app) document_generation: Generation,
    pub(in crate::app) hierarchy_generation: Generation,
    pub(in crate::app) view_generation: Generation,
    /// View generation of the faired result on screen (newer results replace it, older don't).
    pub(in crate::app) applied_view: GenerationId,
    pub(in crate::app) applied_level_view: GenerationId,
    pub(in crate::app) hierarchy_progress: SharedProgress,
    /// The hierarchy's job is still denoising (its progress is the denoise's).
    pub(in crate::app) hierarchy_denoising: Arc<AtomicBool>,
    pub(in crate::app) fair_progress: SharedProgress,
    pub(in crate::app) fair_in_flight: bool,
    /// View generation of the newest fairing asked for.
    pub(in crate::app) fair_view: GenerationId,
    pub(in crate::app) workspace: Arc<Mutex<MultiresWorkspace>>,
    /// Faired results by start level, for the slider to show again at once.
    pub(in crate::app) kept: KeptResults,
    /// A level is being faired ahead ([`crate::app::App::fair_ahead`]).
    pub(in crate::app) ahead_in_flight: bool,
    /// The jobs fairing ahead, counted apart from [`super::workers::Workers::jobs`]: nobody
    /// waits for them, so the editor is settled while they run.
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    pub(in crate::app) ahead_jobs: JobCounter,
    /// The faired result to measure next; see [`super::tasks::measure::MEASURE_DELAY`].
    pub(in crate::app) measure_wanted: Option<MeasureRequest>,
    pub(in crate::app) measures_stopped: u64,
    /// Serial number of the newest faired result (each result on screen has its own).
    pub(in crate::app) next_serial: u64,
    /// The file being loaded, while it loads.
    pub(in crate::app) loading: Option<PathBuf>,
    /// The sharp-edge settings the current hierarchy was asked for (see
    /// [`super::state::Settings::hierarchy_key`]): a change builds it again.
    pub(in crate::app) hierarchy_built_with: Option<HierarchyKey>,
}

impl InFlight {
    /// A new document replaces the old one: no result of it is on screen, no fairing of it runs.
    pub(in crate::app) fn forget_results(&mut self) {
        self.applied_view = GenerationId::default();
        self.applied_level_view = GenerationId::default();
        self.fair_in_flight = false;
        self.kept.clear();
    }

    /// Cancels whatever runs for the document (its load, its changes, its hierarchy): each job
    /// sees its generation pass and stops.
    pub(in crate::app) fn cancel_all(&self) {
        self.document_generation.bump();
        self.hierarchy_generation.bump();
        self.load_generation.bump();
    }
}
