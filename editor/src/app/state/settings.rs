//! The settings that persist between runs ([`Settings`], saved through eframe's persistence),
//! in parts by what they are about: the fairing ([`FairingSettings`]), the hierarchy and the
//! denoise before it ([`HierarchySettings`]), the noise ([`NoiseSettings`]), the view
//! ([`ViewSettings`]), the files ([`FileSettings`]), the level chain's export
//! ([`LevelChainSettings`]) and the brush ([`crate::app::paint::PaintSettings`]); the choices
//! they are made of (method, boundary, variant, view mode, compare view, heat-map reference) and
//! the options they give the fairing, the hierarchy and the noise. They are stored as one flat
//! record, as before they had parts (`settings/stored.rs`).

#[macro_use]
mod stored;

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

settings_part! {
    /// What the fairing does: the paper's method (iterations, rounds, boundary, Fair M0, the
    /// variant) or a baseline (its iterations and step).
    pub struct FairingSettings {
        pub iterations: usize => "iterations",
        pub rounds: usize => "rounds",
        pub boundary: BoundaryMode => "boundary",
        pub fair_finest: bool => "fair_finest",
        pub variant: MultiresVariant => "variant",
        pub method: Method => "method",
        /// Iterations and step of the baseline methods.
        pub baseline_iterations: usize => "baseline_iterations",
        pub baseline_lambda: f64 => "baseline_lambda",
    }
}

settings_part! {
    /// How the hierarchy is built: the sharp edges it keeps and the denoise before it.
    pub struct HierarchySettings {
        /// Keep sharp edges: the hierarchy keeps them on every level and the fairing smooths
        /// along them, not across them.
        pub keep_sharp_edges: bool => "keep_sharp_edges",
        /// An edge is sharp when the surface folds there by more than this many degrees.
        pub sharp_edge_angle: f64 => "sharp_edge_angle",
        /// "Remove noise first": how much the mesh is denoised before the hierarchy is built on
        /// it ([`fairmesh::multires::denoise()`]): automatically (the default of `fairmesh
        /// fair`), a fixed number of rounds, or not at all (the paper's multires alone).
        pub denoise: Denoise => "denoise",
    }
}

settings_part! {
    /// The noise "Add noise" injects.
    pub struct NoiseSettings {
        /// Standard deviation as a fraction of the mean edge length.
        pub sigma: f64 => "noise_sigma",
        pub seed: u64 => "noise_seed",
        pub mode: NoiseMode => "noise_mode",
    }
}

settings_part! {
    /// What the view shows and how it draws it.
    pub struct ViewSettings {
        pub view_mode: ViewMode => "view_mode",
        pub compare: CompareView => "compare",
        /// Where the split view's divider sits, as a fraction of the view's width.
        pub split: f32 => "split",
        /// Colour the mesh by its distance from the reference.
        pub heat_map: bool => "heat_map",
        pub heat_reference: HeatReference => "heat_reference",
        pub wireframe: bool => "wireframe",
        /// Shading: Flat (every facet shows) or Smooth (vertex normals).
        pub shading: Shading => "shading",
        /// Lighting: Simple or Studio (key, fill and rim lights).
        pub lighting: Lighting => "lighting",
        /// Clay: every surface in one clay colour, the file's materials, textures and vertex
        /// colours left out.
        pub clay: bool => "clay",
        pub show_performance: bool => "show_performance",
    }
}

settings_part! {
    /// The files: where dialogs start, the Recent menu, the start level chosen for each file.
    #[derive(Default)]
    pub struct FileSettings {
        /// Directory of the last file opened or exported, where dialogs start.
        pub last_dir: Option<PathBuf> => "last_dir",
        /// The files opened last, newest first (at most [`FileSettings::RECENT_FILES`]): the
        /// Recent menu.
        pub recent_files: Vec<PathBuf> => "recent_files",
        /// The start level last chosen for each file, most recent last (at most
        /// [`FileSettings::REMEMBERED_FILES`]): a file opens at the level the user left it at.
        pub start_levels: Vec<(PathBuf, usize)> => "start_levels",
    }
}

settings_part! {
    /// Folder and level range of the level-chain export.
    pub struct LevelChainSettings {
        pub folder: String => "levels_folder",
        pub from: usize => "levels_from",
        pub to: usize => "levels_to",
    }
}

/// Settings that persist between runs, in parts (each changed through its own methods where it
/// has them; [`Settings`] itself holds what takes more than one part).
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub fairing: FairingSettings,
    pub hierarchy: HierarchySettings,
    pub noise: NoiseSettings,
    pub view: ViewSettings,
    pub files: FileSettings,
    pub level_chain: LevelChainSettings,
    /// The brush, and the mask last painted on each file.
    pub paint: crate::app::paint::PaintSettings,
    /// Which defaults the settings were saved under (missing in files saved before there was
    /// one: [`UNVERSIONED`]). [`Settings::upgraded`] brings older files to today's defaults.
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
pub const UNVERSIONED: u32 = 0;

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

impl Default for FairingSettings {
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
            method: Method::Constrained,
            baseline_iterations: 10,
            baseline_lambda: 0.5,
        }
    }
}

impl Default for HierarchySettings {
    fn default() -> Self {
        Self {
            // As `fairmesh fair` keeps them (the hierarchy's own default leaves them out).
            keep_sharp_edges: true,
            sharp_edge_angle: DEFAULT_CREASE_ANGLE,
            denoise: Denoise::Automatic,
        }
    }
}

impl Default for NoiseSettings {
    fn default() -> Self {
        let defaults = NoiseOptions::default();
        Self {
            sigma: defaults.sigma,
            seed: defaults.seed,
            mode: defaults.mode,
        }
    }
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            view_mode: ViewMode::Faired,
            compare: CompareView::Single,
            split: 0.5,
            heat_map: false,
            heat_reference: HeatReference::Document,
            wireframe: false,
            shading: Shading::default(),
            lighting: Lighting::default(),
            clay: false,
            show_performance: false,
        }
    }
}

impl Default for LevelChainSettings {
    fn default() -> Self {
        Self {
            folder: String::new(),
            from: 0,
            to: usize::MAX,
        }
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            fairing: FairingSettings::default(),
            hierarchy: HierarchySettings::default(),
            noise: NoiseSettings::default(),
            view: ViewSettings::default(),
            files: FileSettings::default(),
            level_chain: LevelChainSettings::default(),
            paint: Default::default(),
            version: SETTINGS_VERSION,
        }
    }
}

/// The settings that change the fairing result, as [`FairingSettings::key`] takes them: two
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

impl FairingSettings {
    /// The settings that change the fairing result (a change means: run again).
    pub fn key(&self) -> FairingKey {
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

impl NoiseSettings {
    /// The noise these settings ask for (sigma clamped to a sane range).
    pub fn options(&self) -> NoiseOptions {
        let sigma = if self.sigma.is_finite() {
            self.sigma.clamp(0.0, 10.0)
        } else {
            0.0
        };
        NoiseOptions::default()
            .with_sigma(sigma)
            .with_seed(self.seed)
            .with_mode(self.mode)
    }
}

impl HierarchySettings {
    /// The hierarchy these settings ask for (the angle clamped to a sane range).
    pub fn options(&self) -> HierarchyOptions {
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
}

impl FileSettings {
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
}

impl Settings {
    pub const STORAGE_KEY: &'static str = "fairmesh.settings";

    /// Settings saved under older defaults, brought to today's: before version 1 every file
    /// stored "Keep sharp edges" and "Fair M0 too" off, which were the defaults then and not a
    /// choice, and there was no denoise (its field comes in as [`Denoise::Automatic`]); sharp edges are kept now, as
    /// `fairmesh fair` keeps them.
    pub fn upgraded(mut self) -> Self {
        if self.version < 1 {
            self.hierarchy.keep_sharp_edges = true;
            self.fairing.fair_finest = true;
        }
        self.version = SETTINGS_VERSION;
        self
    }

    /// The settings that change the hierarchy, the denoise before it included (a change means:
    /// build it again).
    pub fn hierarchy_key(&self) -> HierarchyKey {
        HierarchyKey {
            keep_sharp_edges: self.hierarchy.keep_sharp_edges,
            sharp_edge_angle_bits: self.hierarchy.sharp_edge_angle.to_bits(),
            denoise: self.hierarchy.denoise,
            boundary: self.fairing.boundary,
        }
    }

    /// The denoise these settings ask for (sharp edges as the hierarchy keeps them; the caller
    /// adds the file's own hard edges, as `fairmesh fair` does).
    pub fn denoise_options(&self) -> DenoiseOptions {
        DenoiseOptions {
            denoise: match self.hierarchy.denoise {
                Denoise::Rounds(rounds) => Denoise::Rounds(rounds.min(MAX_DENOISE_ROUNDS)),
                other => other,
            },
            creases: self.hierarchy.options().creases,
            boundary: self.fairing.boundary,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_round_trip_through_json_and_tolerate_missing_fields() {
        let mut settings = Settings::default();
        settings.fairing.iterations = 7;
        settings.view.wireframe = true;
        let json = serde_json::to_string(&settings).unwrap();
        let back: Settings = serde_json::from_str(&json).unwrap();
        assert_eq!(back, settings);
        let partial: Settings = serde_json::from_str(r#"{"rounds": 3}"#).unwrap();
        assert_eq!(partial.fairing.rounds, 3);
        assert_eq!(
            partial.fairing.iterations,
            Settings::default().fairing.iterations
        );
    }

    #[test]
    fn shading_and_lighting_persist_and_old_settings_get_the_defaults() {
        let mut settings = Settings::default();
        settings.view.shading = Shading::Flat;
        settings.view.lighting = Lighting::Simple;
        let json = serde_json::to_string(&settings).unwrap();
        let back: Settings = serde_json::from_str(&json).unwrap();
        assert_eq!(
            (back.view.shading, back.view.lighting),
            (Shading::Flat, Lighting::Simple)
        );
        // A settings file written before these existed.
        let old: Settings = serde_json::from_str(r#"{"wireframe": true}"#).unwrap();
        assert_eq!(
            (old.view.shading, old.view.lighting),
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
        let fairing = &settings.fairing;
        assert_eq!(fairing.boundary, BoundaryMode::Fixed);
        assert_eq!(fairing.variant, MultiresVariant::Paper);
        assert_eq!(fairing.method, Method::Taubin);
        assert_eq!((fairing.iterations, fairing.rounds), (4, 2));
        for (json, boundary) in [
            ("Curve", BoundaryMode::Curve),
            ("Fixed", BoundaryMode::Fixed),
        ] {
            let text = format!(r#"{{"boundary": "{json}"}}"#);
            let settings: Settings = serde_json::from_str(&text).unwrap();
            assert_eq!(settings.fairing.boundary, boundary);
        }
        for (json, variant) in [
            ("Paper", MultiresVariant::Paper),
            ("Improved", MultiresVariant::Improved),
        ] {
            let text = format!(r#"{{"variant": "{json}"}}"#);
            let settings: Settings = serde_json::from_str(&text).unwrap();
            assert_eq!(settings.fairing.variant, variant);
        }
        for (json, method) in [
            ("Constrained", Method::Constrained),
            ("Laplacian", Method::Laplacian),
            ("Taubin", Method::Taubin),
            ("Hc", Method::Hc),
        ] {
            let text = format!(r#"{{"method": "{json}"}}"#);
            let settings: Settings = serde_json::from_str(&text).unwrap();
            assert_eq!(settings.fairing.method, method);
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
        assert!(upgraded.hierarchy.keep_sharp_edges && upgraded.fairing.fair_finest);
        assert_eq!(upgraded.hierarchy.denoise, Denoise::Automatic);
        assert_eq!(upgraded.fairing.iterations, 4, "the rest is kept");
        assert_eq!(upgraded.version, SETTINGS_VERSION);
        // Unticked under today's defaults, it is the user's choice and stays.
        let mut chosen = Settings::default();
        chosen.hierarchy.keep_sharp_edges = false;
        chosen.hierarchy.denoise = Denoise::Rounds(3);
        let json = serde_json::to_string(&chosen).unwrap();
        let back = serde_json::from_str::<Settings>(&json).unwrap().upgraded();
        assert_eq!(back, chosen);
        // The denoise is the default fair's unless changed, and a change rebuilds.
        let defaults = Settings::default();
        let options = defaults.denoise_options();
        assert_eq!(options.denoise, Denoise::Automatic);
        assert!(options.creases.is_some());
        assert_ne!(defaults.hierarchy_key(), chosen.hierarchy_key());
        let mut off = Settings::default();
        off.hierarchy.denoise = Denoise::Off;
        assert_ne!(defaults.hierarchy_key(), off.hierarchy_key());
        assert!(off.denoise_options().fair_options().is_none());
    }

    /// A settings value as eframe stores it (RON, through `eframe::set_value`) and as JSON, each
    /// written by the editor before the settings had parts: one flat record, every field set
    /// away from its default.
    const STORED_BEFORE_THE_PARTS: &str = r#"(iterations:7,rounds:3,boundary:Fixed,fair_finest:false,variant:Paper,wireframe:true,view_mode:Level,show_performance:true,last_dir:Some("/home/artist/scans"),noise_sigma:0.25,noise_seed:42,noise_mode:Isotropic,heat_map:true,heat_reference:Clean,compare:Split,split:0.3,method:Taubin,baseline_iterations:12,baseline_lambda:0.6,levels_folder:"/home/artist/levels",levels_from:2,levels_to:5,start_levels:[("/home/artist/scans/bunny.obj",4)],paint:(radius:25.0,softness:0.25,show_mask:false,erase:true,masks:[(path:"/home/artist/scans/bunny.obj",vertex_count:100,runs:[(3,10,255)])]),keep_sharp_edges:false,sharp_edge_angle:45.0,recent_files:["/home/artist/scans/bunny.obj","/home/artist/scans/head.ply"],shading:Flat,lighting:Simple,clay:true,denoise:Rounds(3),version:1)"#;
    const STORED_BEFORE_THE_PARTS_JSON: &str = r#"{"iterations":7,"rounds":3,"boundary":"Fixed","fair_finest":false,"variant":"Paper","wireframe":true,"view_mode":"Level","show_performance":true,"last_dir":"/home/artist/scans","noise_sigma":0.25,"noise_seed":42,"noise_mode":"Isotropic","heat_map":true,"heat_reference":"Clean","compare":"Split","split":0.3,"method":"Taubin","baseline_iterations":12,"baseline_lambda":0.6,"levels_folder":"/home/artist/levels","levels_from":2,"levels_to":5,"start_levels":[["/home/artist/scans/bunny.obj",4]],"paint":{"radius":25.0,"softness":0.25,"show_mask":false,"erase":true,"masks":[{"path":"/home/artist/scans/bunny.obj","vertex_count":100,"runs":[[3,10,255]]}]},"keep_sharp_edges":false,"sharp_edge_angle":45.0,"recent_files":["/home/artist/scans/bunny.obj","/home/artist/scans/head.ply"],"shading":"Flat","lighting":"Simple","clay":true,"denoise":{"Rounds":3},"version":1}"#;
    /// The default settings as stored then.
    const DEFAULTS_STORED_BEFORE_THE_PARTS: &str = r#"(iterations:5,rounds:1,boundary:Curve,fair_finest:true,variant:Improved,wireframe:false,view_mode:Faired,show_performance:false,last_dir:None,noise_sigma:0.3,noise_seed:1,noise_mode:Normal,heat_map:false,heat_reference:Document,compare:Single,split:0.5,method:Constrained,baseline_iterations:10,baseline_lambda:0.5,levels_folder:"",levels_from:0,levels_to:18446744073709551615,start_levels:[],paint:(radius:40.0,softness:0.5,show_mask:true,erase:false,masks:[]),keep_sharp_edges:true,sharp_edge_angle:40.0,recent_files:[],shading:Smooth,lighting:Studio,clay:false,denoise:Automatic,version:1)"#;

    /// The values [`STORED_BEFORE_THE_PARTS`] holds.
    fn stored_before_the_parts() -> Settings {
        let bunny = PathBuf::from("/home/artist/scans/bunny.obj");
        Settings {
            fairing: FairingSettings {
                iterations: 7,
                rounds: 3,
                boundary: BoundaryMode::Fixed,
                fair_finest: false,
                variant: MultiresVariant::Paper,
                method: Method::Taubin,
                baseline_iterations: 12,
                baseline_lambda: 0.6,
            },
            hierarchy: HierarchySettings {
                keep_sharp_edges: false,
                sharp_edge_angle: 45.0,
                denoise: Denoise::Rounds(3),
            },
            noise: NoiseSettings {
                sigma: 0.25,
                seed: 42,
                mode: NoiseMode::Isotropic,
            },
            view: ViewSettings {
                view_mode: ViewMode::Level,
                compare: CompareView::Split,
                split: 0.3,
                heat_map: true,
                heat_reference: HeatReference::Clean,
                wireframe: true,
                shading: Shading::Flat,
                lighting: Lighting::Simple,
                clay: true,
                show_performance: true,
            },
            files: FileSettings {
                last_dir: Some(PathBuf::from("/home/artist/scans")),
                recent_files: vec![bunny.clone(), PathBuf::from("/home/artist/scans/head.ply")],
                start_levels: vec![(bunny.clone(), 4)],
            },
            level_chain: LevelChainSettings {
                folder: "/home/artist/levels".into(),
                from: 2,
                to: 5,
            },
            paint: crate::app::paint::PaintSettings {
                radius: 25.0,
                softness: 0.25,
                show_mask: false,
                erase: true,
                masks: vec![crate::app::paint::StoredMask {
                    path: bunny,
                    vertex_count: 100,
                    runs: vec![(3, 10, 255)],
                }],
            },
            version: 1,
        }
    }

    /// eframe's storage in memory.
    #[derive(Default)]
    struct Storage(std::collections::HashMap<String, String>);

    impl eframe::Storage for Storage {
        fn get_string(&self, key: &str) -> Option<String> {
            self.0.get(key).cloned()
        }

        fn set_string(&mut self, key: &str, value: String) {
            self.0.insert(key.to_owned(), value);
        }

        fn remove_string(&mut self, key: &str) {
            self.0.remove(key);
        }

        fn flush(&mut self) {}
    }

    /// `stored` loaded through eframe, as the editor loads its settings.
    fn load_from_eframe(stored: &str) -> Option<Settings> {
        let mut storage = Storage::default();
        eframe::Storage::set_string(&mut storage, Settings::STORAGE_KEY, stored.to_owned());
        eframe::get_value(&storage, Settings::STORAGE_KEY)
    }

    /// `settings` as eframe stores them.
    fn stored_by_eframe(settings: &Settings) -> String {
        let mut storage = Storage::default();
        eframe::set_value(&mut storage, Settings::STORAGE_KEY, settings);
        eframe::Storage::get_string(&storage, Settings::STORAGE_KEY).unwrap_or_default()
    }

    #[test]
    fn settings_stored_before_the_parts_load_into_the_same_values_and_are_stored_the_same() {
        let expected = stored_before_the_parts();
        assert_eq!(
            load_from_eframe(STORED_BEFORE_THE_PARTS),
            Some(expected.clone())
        );
        let from_json: Settings = serde_json::from_str(STORED_BEFORE_THE_PARTS_JSON).unwrap();
        assert_eq!(from_json, expected);
        // Stored now, they read as before (an older editor loads them too).
        assert_eq!(stored_by_eframe(&expected), STORED_BEFORE_THE_PARTS);
        assert_eq!(
            serde_json::to_string(&expected).unwrap(),
            STORED_BEFORE_THE_PARTS_JSON
        );
        assert_eq!(
            load_from_eframe(DEFAULTS_STORED_BEFORE_THE_PARTS),
            Some(Settings::default())
        );
        assert_eq!(
            stored_by_eframe(&Settings::default()),
            DEFAULTS_STORED_BEFORE_THE_PARTS
        );
    }

    #[test]
    fn a_stored_field_missing_takes_its_default_and_one_unknown_is_skipped() {
        let stored = "(iterations:9,no_longer_known:(a:[1,2]),clay:true)";
        let settings = load_from_eframe(stored).expect("the settings load");
        let mut expected = Settings::default();
        expected.fairing.iterations = 9;
        expected.view.clay = true;
        expected.version = UNVERSIONED;
        assert_eq!(settings, expected);
        // A value of the wrong kind is an error, as it was (eframe then starts from defaults).
        assert_eq!(load_from_eframe("(iterations:\"many\")"), None);
    }

    #[test]
    fn every_field_of_every_part_is_stored_once() {
        use stored::StoredPart;
        let mut keys: Vec<&str> = [
            FairingSettings::KEYS,
            HierarchySettings::KEYS,
            NoiseSettings::KEYS,
            ViewSettings::KEYS,
            FileSettings::KEYS,
            LevelChainSettings::KEYS,
            &stored::WHOLE_FIELDS[..],
        ]
        .concat();
        keys.sort_unstable();
        let mut stored_fields = stored::STORED_FIELDS.to_vec();
        stored_fields.sort_unstable();
        assert_eq!(keys, stored_fields);
        stored_fields.dedup();
        assert_eq!(stored_fields.len(), stored::STORED_FIELDS.len());
    }

    #[test]
    fn start_level_is_the_files_last_choice_or_0() {
        let mut settings = FileSettings::default();
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
        for i in 0..FileSettings::REMEMBERED_FILES {
            settings.remember_start_level(&PathBuf::from(format!("/c/{i}.obj")), 1);
        }
        assert_eq!(settings.start_levels.len(), FileSettings::REMEMBERED_FILES);
        assert_eq!(
            settings.start_level_for(bunny, 20),
            0,
            "the oldest are forgotten"
        );
    }
}
