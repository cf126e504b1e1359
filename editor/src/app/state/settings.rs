//! The settings that persist between runs ([`Settings`], saved through eframe's persistence),
//! the choices they are made of (method, boundary, variant, view mode, compare view, heat-map
//! reference) and the options they give the fairing, the hierarchy and the noise.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::render::{Lighting, Shading};
use fairmesh::fairing::creases::{CreaseOptions, DEFAULT_CREASE_ANGLE};
use fairmesh::fairing::{
    BoundaryMode, HcOptions, LaplacianOptions, Method, MethodOptions, TaubinOptions,
};
use fairmesh::hierarchy::HierarchyOptions;
use fairmesh::multires::{Denoise, DenoiseOptions, MultiresOptions, MultiresVariant};
use fairmesh::noise::{NoiseMode, NoiseOptions};

/// What the editor says about a smoothing method: the paper's (coarse to fine over the
/// hierarchy) or a baseline run on the document's mesh, to see its shrinkage next to the
/// paper's. The settings store the library's [`Method`] itself.
pub trait MethodChoice: Copy {
    /// The method's name in the fairing panel.
    fn label(self) -> &'static str;

    /// Whether the method works over the hierarchy (start level, Fair M0, variant apply).
    fn uses_hierarchy(self) -> bool;

    /// What a result of this method from `start_level` is, in words ("from M4" means nothing
    /// to a baseline, which smooths the whole input mesh).
    fn describe(self, start_level: usize) -> String {
        if self.uses_hierarchy() {
            format!("{} from M{start_level}", self.label())
        } else {
            format!("{}, whole mesh", self.label())
        }
    }
}

impl MethodChoice for Method {
    fn label(self) -> &'static str {
        match self {
            Method::Constrained => "Constrained fairing",
            Method::Laplacian => "Laplacian",
            Method::Taubin => "Taubin λ|μ",
            Method::Hc => "HC Laplacian",
        }
    }

    fn uses_hierarchy(self) -> bool {
        self == Method::Constrained
    }
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

/// Which mesh the heat map and the second column of numbers measure against.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum HeatReference {
    /// The document's mesh as loaded (or as it became after noise or an applied result).
    #[default]
    Document,
    /// The clean mesh kept when noise was injected (falls back to the document without one).
    Clean,
}

/// How before (the document's mesh) and after (the faired result) are shown.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum CompareView {
    /// One mesh; a key toggles between before and after.
    #[default]
    Single,
    /// One image, before left of a draggable divider, after right of it.
    Split,
    /// Two views next to each other, one camera.
    SideBySide,
}

/// The most rounds of denoise the editor offers.
pub const MAX_DENOISE_ROUNDS: usize = 100;

/// The range of the sharp-edge angle the editor offers, in degrees.
pub const MIN_SHARP_EDGE_ANGLE: f64 = 10.0;
pub const MAX_SHARP_EDGE_ANGLE: f64 = 90.0;

/// Settings that persist between runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    pub iterations: usize,
    pub rounds: usize,
    pub boundary: BoundaryMode,
    pub fair_finest: bool,
    pub variant: MultiresVariant,
    pub wireframe: bool,
    pub view_mode: ViewMode,
    pub show_performance: bool,
    /// Directory of the last file opened or exported, where dialogs start.
    pub last_dir: Option<PathBuf>,
    /// Noise injection: standard deviation as a fraction of the mean edge length.
    pub noise_sigma: f64,
    pub noise_seed: u64,
    pub noise_mode: NoiseMode,
    /// Colour the mesh by its distance from the reference.
    pub heat_map: bool,
    pub heat_reference: HeatReference,
    pub compare: CompareView,
    /// Where the split view's divider sits, as a fraction of the view's width.
    pub split: f32,
    pub method: Method,
    /// Iterations and step of the baseline methods.
    pub baseline_iterations: usize,
    pub baseline_lambda: f64,
    /// Folder and level range of the level-chain export.
    pub levels_folder: String,
    pub levels_from: usize,
    pub levels_to: usize,
    /// The start level last chosen for each file, most recent last (at most
    /// [`Settings::REMEMBERED_FILES`]): a file opens at the level the user left it at.
    pub start_levels: Vec<(PathBuf, usize)>,
    /// The brush, and the mask last painted on each file.
    pub paint: crate::app::paint::PaintSettings,
    /// Keep sharp edges: the hierarchy keeps them on every level and the fairing smooths along
    /// them, not across them.
    pub keep_sharp_edges: bool,
    /// An edge is sharp when the surface folds there by more than this many degrees.
    pub sharp_edge_angle: f64,
    /// The files opened last, newest first (at most [`Settings::RECENT_FILES`]): the Recent menu.
    pub recent_files: Vec<PathBuf>,
    /// Shading: Flat (every facet shows) or Smooth (vertex normals).
    pub shading: Shading,
    /// Lighting: Simple or Studio (key, fill and rim lights).
    pub lighting: Lighting,
    /// Clay: every surface in one clay colour, the file's materials, textures and vertex
    /// colours left out.
    pub clay: bool,
    /// "Remove noise first": how much the mesh is denoised before the hierarchy is built on it
    /// ([`fairmesh::multires::denoise()`]): automatically (the default of `fairmesh fair`), a fixed
    /// number of rounds, or not at all (the paper's multires alone).
    pub denoise: Denoise,
    /// Which defaults the settings were saved under (missing in files saved before there was
    /// one: 0). [`Settings::upgraded`] brings older files to today's defaults.
    #[serde(default = "unversioned")]
    pub version: u32,
}

impl HierarchyKey {
    /// Whether `other` keeps the same sharp edges (whatever the denoise).
    pub fn same_sharp_edges(&self, other: &HierarchyKey) -> bool {
        (self.keep_sharp_edges, self.sharp_edge_angle_bits)
            == (other.keep_sharp_edges, other.sharp_edge_angle_bits)
    }
}

/// The version of a settings file saved before [`Settings::version`] existed.
fn unversioned() -> u32 {
    0
}

/// The defaults' version [`Settings::version`] records; see [`Settings::upgraded`].
pub const SETTINGS_VERSION: u32 = 1;

/// Sharp edges and the denoise as the stored fields of a [`HierarchyKey`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HierarchyKey {
    keep_sharp_edges: bool,
    sharp_edge_angle_bits: u64,
    denoise: Denoise,
    /// The denoise moves boundaries as the fairing does.
    boundary: BoundaryMode,
}

impl Default for Settings {
    fn default() -> Self {
        let defaults = MultiresOptions::default();
        Self {
            iterations: defaults.iterations,
            rounds: defaults.rounds,
            boundary: BoundaryMode::Curve,
            // The levels' vertex splits leave a few edges folded, which a light pass over M0
            // unfolds (docs/measurements.md, "Multiresolution fairing").
            fair_finest: true,
            variant: MultiresVariant::Improved,
            wireframe: false,
            view_mode: ViewMode::Faired,
            show_performance: false,
            last_dir: None,
            noise_sigma: NoiseOptions::default().sigma,
            noise_seed: NoiseOptions::default().seed,
            noise_mode: NoiseOptions::default().mode,
            heat_map: false,
            heat_reference: HeatReference::Document,
            compare: CompareView::Single,
            split: 0.5,
            method: Method::Constrained,
            baseline_iterations: 10,
            baseline_lambda: 0.5,
            levels_folder: String::new(),
            levels_from: 0,
            levels_to: usize::MAX,
            start_levels: Vec::new(),
            paint: Default::default(),
            // As `fairmesh fair` keeps them (the hierarchy's own default leaves them out).
            keep_sharp_edges: true,
            sharp_edge_angle: DEFAULT_CREASE_ANGLE,
            recent_files: Vec::new(),
            shading: Shading::default(),
            lighting: Lighting::default(),
            clay: false,
            denoise: Denoise::Automatic,
            version: SETTINGS_VERSION,
        }
    }
}

/// The settings that change the fairing result, as [`Settings::fairing_key`] takes them: two
/// keys differ exactly when the result must be computed again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FairingKey {
    iterations: usize,
    rounds: usize,
    boundary: BoundaryMode,
    fair_finest: bool,
    variant: MultiresVariant,
    method: Method,
    baseline_iterations: usize,
    /// The baseline's λ as bits, so that the key compares exactly (and NaN equals itself).
    baseline_lambda_bits: u64,
}

impl Settings {
    pub const STORAGE_KEY: &'static str = "fairmesh.settings";
    pub const REMEMBERED_FILES: usize = 64;
    pub const RECENT_FILES: usize = 8;

    /// Puts `path` first in the recent files (once), dropping the oldest beyond
    /// [`Self::RECENT_FILES`].
    pub fn remember_recent(&mut self, path: &Path) {
        self.forget_recent(path);
        self.recent_files.insert(0, path.to_path_buf());
        self.recent_files.truncate(Self::RECENT_FILES);
    }

    /// Drops `path` from the recent files.
    pub fn forget_recent(&mut self, path: &Path) {
        self.recent_files.retain(|recent| recent != path);
    }

    /// The start level to open `path` at, with `level_count` levels: the one last chosen for
    /// it, else level 0, `fair`'s result (the noise removed, the detail kept: a coarser level
    /// takes detail away, and how much is the user's choice; a middle level of a scan lay
    /// farther from its clean surface than the noisy input).
    pub fn start_level_for(&self, path: &Path, level_count: usize) -> usize {
        let top = level_count.saturating_sub(1);
        self.start_levels
            .iter()
            .rev()
            .find(|(remembered, _)| remembered == path)
            .map_or(0, |&(_, level)| level)
            .min(top)
    }

    /// Remembers `level` as the start level chosen for `path`.
    pub fn remember_start_level(&mut self, path: &Path, level: usize) {
        self.start_levels
            .retain(|(remembered, _)| remembered != path);
        self.start_levels.push((path.to_path_buf(), level));
        let excess = self
            .start_levels
            .len()
            .saturating_sub(Self::REMEMBERED_FILES);
        self.start_levels.drain(..excess);
    }

    /// The settings that change the fairing result (a change means: run again).
    pub fn fairing_key(&self) -> FairingKey {
        FairingKey {
            iterations: self.iterations,
            rounds: self.rounds,
            boundary: self.boundary,
            fair_finest: self.fair_finest,
            variant: self.variant,
            method: self.method,
            baseline_iterations: self.baseline_iterations,
            baseline_lambda_bits: self.baseline_lambda.to_bits(),
        }
    }

    /// The baseline method's options, or `None` for the paper's method.
    pub fn baseline_options(&self) -> Option<MethodOptions> {
        let iterations = self.baseline_iterations.clamp(1, 1000);
        let lambda = if self.baseline_lambda.is_finite() {
            self.baseline_lambda.clamp(0.01, 1.0)
        } else {
            0.5
        };
        let boundary = self.boundary;
        match self.method {
            Method::Constrained => None,
            Method::Laplacian => Some(MethodOptions::Laplacian(LaplacianOptions {
                iterations,
                lambda,
                boundary,
            })),
            // Taubin's pass band k_PB = 0.1: 1/λ + 1/μ = 0.1.
            Method::Taubin => Some(MethodOptions::Taubin(TaubinOptions {
                iterations,
                lambda,
                mu: -lambda / (1.0 - 0.1 * lambda),
                boundary,
            })),
            Method::Hc => Some(MethodOptions::Hc(HcOptions {
                iterations,
                boundary,
                ..HcOptions::default()
            })),
        }
    }

    /// The noise these settings ask for (sigma clamped to a sane range).
    pub fn noise_options(&self) -> NoiseOptions {
        let sigma = if self.noise_sigma.is_finite() {
            self.noise_sigma.clamp(0.0, 10.0)
        } else {
            0.0
        };
        NoiseOptions::default()
            .with_sigma(sigma)
            .with_seed(self.noise_seed)
            .with_mode(self.noise_mode)
    }

    /// Settings saved under older defaults, brought to today's: before version 1 every file
    /// stored "Keep sharp edges" and "Fair M0 too" off, which were the defaults then and not a
    /// choice, and there was no denoise (its field comes in as [`Denoise::Automatic`]); sharp edges are kept now, as
    /// `fairmesh fair` keeps them.
    pub fn upgraded(mut self) -> Self {
        if self.version < 1 {
            self.keep_sharp_edges = true;
            self.fair_finest = true;
        }
        self.version = SETTINGS_VERSION;
        self
    }

    /// The settings that change the hierarchy, the denoise before it included (a change means:
    /// build it again).
    pub fn hierarchy_key(&self) -> HierarchyKey {
        HierarchyKey {
            keep_sharp_edges: self.keep_sharp_edges,
            sharp_edge_angle_bits: self.sharp_edge_angle.to_bits(),
            denoise: self.denoise,
            boundary: self.boundary,
        }
    }

    /// The denoise these settings ask for (sharp edges as the hierarchy keeps them; the caller
    /// adds the file's own hard edges, as `fairmesh fair` does).
    pub fn denoise_options(&self) -> DenoiseOptions {
        DenoiseOptions {
            denoise: match self.denoise {
                Denoise::Rounds(rounds) => Denoise::Rounds(rounds.min(MAX_DENOISE_ROUNDS)),
                other => other,
            },
            creases: self.hierarchy_options().creases,
            boundary: self.boundary,
        }
    }

    /// The hierarchy these settings ask for (the angle clamped to a sane range).
    pub fn hierarchy_options(&self) -> HierarchyOptions {
        let angle = if self.sharp_edge_angle.is_finite() {
            self.sharp_edge_angle
                .clamp(MIN_SHARP_EDGE_ANGLE, MAX_SHARP_EDGE_ANGLE)
        } else {
            DEFAULT_CREASE_ANGLE
        };
        HierarchyOptions::default().with_creases(
            self.keep_sharp_edges
                .then(|| CreaseOptions::default().with_angle_degrees(angle)),
        )
    }

    /// The multires options these settings give for `start_level`.
    pub fn multires_options(&self, start_level: usize) -> MultiresOptions {
        MultiresOptions::default()
            .with_start_level(start_level)
            .with_iterations(self.iterations.clamp(1, 1000))
            .with_rounds(self.rounds.clamp(1, 100))
            .with_boundary(self.boundary)
            .with_fair_finest(self.fair_finest)
            .with_unfold(true)
            .with_variant(self.variant)
            .with_mask(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn shading_and_lighting_persist_and_old_settings_get_the_defaults() {
        let settings = Settings {
            shading: Shading::Flat,
            lighting: Lighting::Simple,
            ..Default::default()
        };
        let json = serde_json::to_string(&settings).unwrap();
        let back: Settings = serde_json::from_str(&json).unwrap();
        assert_eq!(
            (back.shading, back.lighting),
            (Shading::Flat, Lighting::Simple)
        );
        // A settings file written before these existed.
        let old: Settings = serde_json::from_str(r#"{"wireframe": true}"#).unwrap();
        assert_eq!(
            (old.shading, old.lighting),
            (Shading::Smooth, Lighting::Studio)
        );
    }

    #[test]
    fn settings_written_with_the_old_copy_enums_still_load() {
        // Boundary, variant and method were once stored through editor copies of the library's
        // enums (`BoundarySetting`, `VariantSetting`, `MethodSetting`); a file saved then spells
        // them the same way the library's enums do now.
        let old = r#"{"iterations": 4, "rounds": 2, "boundary": "Fixed", "fair_finest": true,
            "variant": "Paper", "method": "Taubin", "baseline_iterations": 12}"#;
        let settings: Settings = serde_json::from_str(old).unwrap();
        assert_eq!(settings.boundary, BoundaryMode::Fixed);
        assert_eq!(settings.variant, MultiresVariant::Paper);
        assert_eq!(settings.method, Method::Taubin);
        assert_eq!((settings.iterations, settings.rounds), (4, 2));
        for (json, boundary) in [
            ("Curve", BoundaryMode::Curve),
            ("Fixed", BoundaryMode::Fixed),
        ] {
            let text = format!(r#"{{"boundary": "{json}"}}"#);
            let settings: Settings = serde_json::from_str(&text).unwrap();
            assert_eq!(settings.boundary, boundary);
        }
        for (json, variant) in [
            ("Paper", MultiresVariant::Paper),
            ("Improved", MultiresVariant::Improved),
        ] {
            let text = format!(r#"{{"variant": "{json}"}}"#);
            let settings: Settings = serde_json::from_str(&text).unwrap();
            assert_eq!(settings.variant, variant);
        }
        for (json, method) in [
            ("Constrained", Method::Constrained),
            ("Laplacian", Method::Laplacian),
            ("Taubin", Method::Taubin),
            ("Hc", Method::Hc),
        ] {
            let text = format!(r#"{{"method": "{json}"}}"#);
            let settings: Settings = serde_json::from_str(&text).unwrap();
            assert_eq!(settings.method, method);
            // And they are written the same way again.
            let written = serde_json::to_value(&settings).unwrap();
            assert_eq!(written["method"], json);
        }
        let written = serde_json::to_value(Settings::default()).unwrap();
        assert_eq!(
            (&written["boundary"], &written["variant"]),
            (&serde_json::json!("Curve"), &serde_json::json!("Improved"))
        );
    }

    #[test]
    fn settings_saved_before_the_denoise_get_sharp_edges_and_the_automatic_denoise() {
        // What every settings file stored before version 1 (sharp edges off was the default).
        let old: Settings =
            serde_json::from_str(r#"{"keep_sharp_edges": false, "iterations": 4}"#).unwrap();
        assert_eq!(old.version, 0);
        let upgraded = old.upgraded();
        assert!(upgraded.keep_sharp_edges && upgraded.fair_finest);
        assert_eq!(upgraded.denoise, Denoise::Automatic);
        assert_eq!(upgraded.iterations, 4, "the rest is kept");
        assert_eq!(upgraded.version, SETTINGS_VERSION);
        // Unticked under today's defaults, it is the user's choice and stays.
        let chosen = Settings {
            keep_sharp_edges: false,
            denoise: Denoise::Rounds(3),
            ..Settings::default()
        };
        let json = serde_json::to_string(&chosen).unwrap();
        let back = serde_json::from_str::<Settings>(&json).unwrap().upgraded();
        assert_eq!(back, chosen);
        // The denoise is the default fair's unless changed, and a change rebuilds.
        let defaults = Settings::default();
        let options = defaults.denoise_options();
        assert_eq!(options.denoise, Denoise::Automatic);
        assert!(options.creases.is_some());
        assert_ne!(defaults.hierarchy_key(), chosen.hierarchy_key());
        let off = Settings {
            denoise: Denoise::Off,
            ..Settings::default()
        };
        assert_ne!(defaults.hierarchy_key(), off.hierarchy_key());
        assert!(off.denoise_options().fair_options().is_none());
    }

    #[test]
    fn start_level_is_the_files_last_choice_or_0() {
        let mut settings = Settings::default();
        let (bunny, scan) = (Path::new("/a/bunny.obj"), Path::new("/b/scan.ply"));
        assert_eq!(settings.start_level_for(bunny, 20), 0);
        assert_eq!(settings.start_level_for(bunny, 1), 0);
        settings.remember_start_level(bunny, 3);
        settings.remember_start_level(scan, 12);
        settings.remember_start_level(bunny, 5);
        assert_eq!(settings.start_level_for(bunny, 20), 5);
        assert_eq!(
            settings.start_level_for(scan, 8),
            7,
            "clamped to the levels there are"
        );
        for i in 0..Settings::REMEMBERED_FILES {
            settings.remember_start_level(&PathBuf::from(format!("/c/{i}.obj")), 1);
        }
        assert_eq!(settings.start_levels.len(), Settings::REMEMBERED_FILES);
        assert_eq!(
            settings.start_level_for(bunny, 20),
            0,
            "the oldest are forgotten"
        );
    }
}
