//! The editor's state, in parts kept apart, one file each:
//! - `settings.rs`: [`Settings`], what persists between runs (fairing options, display toggles,
//!   last directory), saved through eframe's persistence, and the choices it is made of;
//! - `document.rs`: [`Document`], the loaded mesh and everything computed from it (hierarchy,
//!   faired result, level meshes, numbers), replaced as a whole when another file is loaded, and
//!   the [`DocumentSnapshot`] that undo and redo keep;
//! - `measures.rs`: [`Measures`], how far a mesh is from a reference mesh;
//! - GPU resources live in `render`, owned by the app, never here.

mod document;
mod measures;
mod settings;

pub use document::{
    bounds_of, default_export_path, DenoiseSummary, Document, DocumentSnapshot, FairedResult,
    HierarchyState, KeptHierarchy,
};
pub use measures::Measures;
pub use settings::{
    CompareView, FairingKey, FairingSettings, FileSettings, HeatReference, HierarchyKey,
    HierarchySettings, LevelChainSettings, MethodChoice, NoiseSettings, Settings, ViewMode,
    ViewSettings, MAX_DENOISE_ROUNDS, MAX_SHARP_EDGE_ANGLE, MIN_SHARP_EDGE_ANGLE, SETTINGS_VERSION,
    UNVERSIONED,
};
