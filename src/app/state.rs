//! The editor's state, in three parts kept apart:
//! - [`Settings`]: what persists between runs (fairing options, display toggles, last directory),
//!   saved through eframe's persistence;
//! - [`Document`]: the loaded mesh and everything computed from it (hierarchy, faired result,
//!   level meshes, numbers), replaced as a whole when another file is loaded;
//! - GPU resources live in `render`, owned by the app, never here.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use serde::{Deserialize, Serialize};

use crate::fairing::BoundaryMode;
use crate::hierarchy::{Hierarchy, LevelInfo};
use crate::io::LoadReport;
use crate::multires::{MultiresOptions, MultiresVariant};
use crate::TriMesh;

/// Boundary handling, as stored in the settings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum BoundarySetting {
    #[default]
    Curve,
    Fixed,
}

/// Fairing variant, as stored in the settings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum VariantSetting {
    Paper,
    #[default]
    Improved,
}

/// What the viewport shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ViewMode {
    /// M0 with the faired positions (falls back to the loaded mesh until the first result).
    #[default]
    Faired,
    /// The coarse mesh of the selected level itself.
    Level,
    /// The mesh as loaded.
    Original,
}

/// Settings that persist between runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    pub iterations: usize,
    pub rounds: usize,
    pub boundary: BoundarySetting,
    pub fair_finest: bool,
    pub variant: VariantSetting,
    pub wireframe: bool,
    pub view_mode: ViewMode,
    pub show_performance: bool,
    /// Directory of the last file opened or exported, where dialogs start.
    pub last_dir: Option<PathBuf>,
}

impl Default for Settings {
    fn default() -> Self {
        let defaults = MultiresOptions::default();
        Self {
            iterations: defaults.iterations,
            rounds: defaults.rounds,
            boundary: BoundarySetting::Curve,
            fair_finest: defaults.fair_finest,
            variant: VariantSetting::Improved,
            wireframe: false,
            view_mode: ViewMode::Faired,
            show_performance: false,
            last_dir: None,
        }
    }
}

impl Settings {
    pub const STORAGE_KEY: &'static str = "fairmesh.settings";

    /// The settings that change the fairing result (a change means: run again).
    pub fn fairing_key(&self) -> (usize, usize, BoundarySetting, bool, VariantSetting) {
        (
            self.iterations,
            self.rounds,
            self.boundary,
            self.fair_finest,
            self.variant,
        )
    }

    /// The multires options these settings give for `start_level`.
    pub fn multires_options(&self, start_level: usize) -> MultiresOptions {
        MultiresOptions {
            start_level,
            iterations: self.iterations.clamp(1, 1000),
            rounds: self.rounds.clamp(1, 100),
            boundary: match self.boundary {
                BoundarySetting::Curve => BoundaryMode::Curve,
                BoundarySetting::Fixed => BoundaryMode::Fixed,
            },
            fair_finest: self.fair_finest,
            variant: match self.variant {
                VariantSetting::Paper => MultiresVariant::Paper,
                VariantSetting::Improved => MultiresVariant::Improved,
            },
        }
    }
}

/// Where the hierarchy of the current document stands.
pub enum HierarchyState {
    Building,
    Ready {
        hierarchy: Arc<Hierarchy>,
        levels: Vec<LevelInfo>,
        build_time: Duration,
        /// M0 has the loaded mesh's triangles (so faired positions can replace the loaded ones
        /// on the GPU without new connectivity).
        base_matches_original: bool,
    },
    Failed(String),
}

/// The latest faired result shown for the document.
pub struct FairedResult {
    pub positions: Arc<Vec<[f32; 3]>>,
    pub level: usize,
    pub volume_change: f64,
    pub rms_displacement: f64,
    pub elapsed: Duration,
    /// Distinguishes results, so the viewport knows when to upload.
    pub serial: u64,
}

/// One loaded mesh and everything derived from it.
pub struct Document {
    pub path: PathBuf,
    /// Bumped for every document; jobs for older documents are stale.
    pub generation: u64,
    pub original: Arc<TriMesh>,
    pub report: LoadReport,
    pub load_time: Duration,
    /// Bounding box of the loaded mesh (min, max), for fitting the view.
    pub bounds: ([f32; 3], [f32; 3]),
    pub hierarchy: HierarchyState,
    /// The start level picked with the slider.
    pub level: usize,
    pub faired: Option<FairedResult>,
    /// The most recent level mesh computed for the level view.
    pub level_mesh: Option<(usize, Arc<TriMesh>)>,
    /// Where the export goes unless the user picks another place.
    pub export_path: String,
}

impl Document {
    pub fn new(
        path: PathBuf,
        generation: u64,
        original: TriMesh,
        report: LoadReport,
        load_time: Duration,
    ) -> Self {
        let bounds = bounds_of(&original.positions);
        let export_path = default_export_path(&path).display().to_string();
        Self {
            path,
            generation,
            original: Arc::new(original),
            report,
            load_time,
            bounds,
            hierarchy: HierarchyState::Building,
            level: 0,
            faired: None,
            level_mesh: None,
            export_path,
        }
    }

    /// Number of levels once the hierarchy is ready.
    pub fn level_count(&self) -> Option<usize> {
        match &self.hierarchy {
            HierarchyState::Ready { levels, .. } => Some(levels.len()),
            _ => None,
        }
    }

    /// The mesh the export writes: M0's triangles with the faired positions when there are any.
    pub fn export_mesh(&self) -> TriMesh {
        match &self.faired {
            Some(faired) if faired.positions.len() == self.original.positions.len() => TriMesh {
                positions: faired.positions.as_ref().clone(),
                triangles: self.original.triangles.clone(),
            },
            _ => self.original.as_ref().clone(),
        }
    }
}

/// `<stem>_faired.glb` next to `input`.
pub fn default_export_path(input: &Path) -> PathBuf {
    let stem = input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh".to_owned());
    input.with_file_name(format!("{stem}_faired.glb"))
}

/// Axis-aligned bounds of `positions` (zeros when empty).
pub fn bounds_of(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            if p[k].is_finite() {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    if lo.iter().zip(&hi).any(|(l, h)| l > h) {
        return ([0.0; 3], [0.0; 3]);
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn export_name_sits_next_to_the_input() {
        assert_eq!(
            default_export_path(Path::new("/scans/bunny00.obj")),
            PathBuf::from("/scans/bunny00_faired.glb")
        );
    }

    #[test]
    fn settings_round_trip_through_json_and_tolerate_missing_fields() {
        let settings = Settings {
            iterations: 7,
            wireframe: true,
            ..Default::default()
        };
        let json = serde_json::to_string(&settings).unwrap();
        let back: Settings = serde_json::from_str(&json).unwrap();
        assert_eq!(back, settings);
        let partial: Settings = serde_json::from_str(r#"{"rounds": 3}"#).unwrap();
        assert_eq!(partial.rounds, 3);
        assert_eq!(partial.iterations, Settings::default().iterations);
    }

    #[test]
    fn bounds_skip_non_finite_values() {
        let (lo, hi) = bounds_of(&[[0.0, 1.0, 2.0], [f32::NAN, -1.0, 5.0], [3.0, 0.0, 2.0]]);
        assert_eq!(lo, [0.0, -1.0, 2.0]);
        assert_eq!(hi, [3.0, 1.0, 5.0]);
    }
}
