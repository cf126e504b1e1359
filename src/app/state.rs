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

use crate::fairing::creases::{CreaseOptions, DEFAULT_CREASE_ANGLE};
use crate::fairing::{
    BoundaryMode, HcOptions, LaplacianOptions, Mask, MethodOptions, TaubinOptions,
};
use crate::hierarchy::{Hierarchy, HierarchyOptions, LevelInfo};
use crate::io::LoadReport;
use crate::multires::{MultiresOptions, MultiresVariant};
use crate::noise::{NoiseMode, NoiseOptions};
use crate::render::{Lighting, Shading};
use crate::TriMesh;

use super::history::SizeInBytes;
use super::sharp_edges::SharpEdgeLines;

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

/// The smoothing method of the fairing panel: the paper's (coarse to fine over the hierarchy) or
/// a baseline run on the document's mesh, to see its shrinkage next to the paper's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum MethodSetting {
    #[default]
    Constrained,
    Laplacian,
    Taubin,
    Hc,
}

impl MethodSetting {
    pub const ALL: [MethodSetting; 4] = [
        MethodSetting::Constrained,
        MethodSetting::Laplacian,
        MethodSetting::Taubin,
        MethodSetting::Hc,
    ];

    pub fn label(self) -> &'static str {
        match self {
            MethodSetting::Constrained => "Constrained fairing",
            MethodSetting::Laplacian => "Laplacian",
            MethodSetting::Taubin => "Taubin λ|μ",
            MethodSetting::Hc => "HC Laplacian",
        }
    }

    /// Whether the method works over the hierarchy (start level, Fair M0, variant apply).
    pub fn uses_hierarchy(self) -> bool {
        self == MethodSetting::Constrained
    }

    /// What a result of this method from `start_level` is, in words ("from M4" means nothing
    /// to a baseline, which smooths the whole input mesh).
    pub fn describe(self, start_level: usize) -> String {
        if self.uses_hierarchy() {
            format!("{} from M{start_level}", self.label())
        } else {
            format!("{}, whole mesh", self.label())
        }
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

/// The range of the sharp-edge angle the editor offers, in degrees.
pub const MIN_SHARP_EDGE_ANGLE: f64 = 10.0;
pub const MAX_SHARP_EDGE_ANGLE: f64 = 90.0;

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
    pub method: MethodSetting,
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
    pub paint: super::paint::PaintSettings,
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
            noise_sigma: NoiseOptions::default().sigma,
            noise_seed: NoiseOptions::default().seed,
            noise_mode: NoiseOptions::default().mode,
            heat_map: false,
            heat_reference: HeatReference::Document,
            compare: CompareView::Single,
            split: 0.5,
            method: MethodSetting::Constrained,
            baseline_iterations: 10,
            baseline_lambda: 0.5,
            levels_folder: String::new(),
            levels_from: 0,
            levels_to: usize::MAX,
            start_levels: Vec::new(),
            paint: Default::default(),
            keep_sharp_edges: HierarchyOptions::default().creases.is_some(),
            sharp_edge_angle: DEFAULT_CREASE_ANGLE,
            recent_files: Vec::new(),
            shading: Shading::default(),
            lighting: Lighting::default(),
        }
    }
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
    /// it, or a middle level (level 0 would show the input unchanged as the result).
    pub fn start_level_for(&self, path: &Path, level_count: usize) -> usize {
        let top = level_count.saturating_sub(1);
        self.start_levels
            .iter()
            .rev()
            .find(|(remembered, _)| remembered == path)
            .map_or(top / 2, |&(_, level)| level)
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
    #[allow(clippy::type_complexity)]
    pub fn fairing_key(
        &self,
    ) -> (
        usize,
        usize,
        BoundarySetting,
        bool,
        VariantSetting,
        MethodSetting,
        usize,
        u64,
    ) {
        (
            self.iterations,
            self.rounds,
            self.boundary,
            self.fair_finest,
            self.variant,
            self.method,
            self.baseline_iterations,
            self.baseline_lambda.to_bits(),
        )
    }

    /// The baseline method's options, or `None` for the paper's method.
    pub fn baseline_options(&self) -> Option<MethodOptions> {
        let iterations = self.baseline_iterations.clamp(1, 1000);
        let lambda = if self.baseline_lambda.is_finite() {
            self.baseline_lambda.clamp(0.01, 1.0)
        } else {
            0.5
        };
        let boundary = match self.boundary {
            BoundarySetting::Curve => BoundaryMode::Curve,
            BoundarySetting::Fixed => BoundaryMode::Fixed,
        };
        match self.method {
            MethodSetting::Constrained => None,
            MethodSetting::Laplacian => Some(MethodOptions::Laplacian(LaplacianOptions {
                iterations,
                lambda,
                boundary,
            })),
            // Taubin's pass band k_PB = 0.1: 1/λ + 1/μ = 0.1.
            MethodSetting::Taubin => Some(MethodOptions::Taubin(TaubinOptions {
                iterations,
                lambda,
                mu: -lambda / (1.0 - 0.1 * lambda),
                boundary,
            })),
            MethodSetting::Hc => Some(MethodOptions::Hc(HcOptions {
                iterations,
                boundary,
                ..HcOptions::default()
            })),
        }
    }

    /// The noise these settings ask for (sigma clamped to a sane range).
    pub fn noise_options(&self) -> NoiseOptions {
        NoiseOptions {
            sigma: if self.noise_sigma.is_finite() {
                self.noise_sigma.clamp(0.0, 10.0)
            } else {
                0.0
            },
            seed: self.noise_seed,
            mode: self.noise_mode,
        }
    }

    /// The settings that change the hierarchy (a change means: build it again).
    pub fn hierarchy_key(&self) -> (bool, u64) {
        (self.keep_sharp_edges, self.sharp_edge_angle.to_bits())
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
            mask: None,
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
        /// The sharp edges the hierarchy keeps, to draw over the mesh.
        sharp_edges: Arc<SharpEdgeLines>,
    },
    Failed(String),
}

/// How far one mesh is from a reference mesh (computed on the worker with every result).
#[derive(Clone, Debug)]
pub struct Measures {
    /// Enclosed volume change in percent (`None` when the reference encloses no volume).
    pub volume_change_percent: Option<f64>,
    /// Mean (area-weighted, both ways) and maximum (Hausdorff) surface distance, model units.
    pub mean_distance: f64,
    pub max_distance: f64,
    /// Per-vertex comparisons, present when both meshes share their triangles.
    pub vertex_rms: Option<f64>,
    pub barycenter_drift: Option<f64>,
    /// Distance of every vertex from the reference surface (the heat map), model units.
    pub vertex_distances: Arc<Vec<f32>>,
}

impl Measures {
    /// `other` measured against `reference`.
    pub fn of(reference: &TriMesh, other: &TriMesh) -> Self {
        Self::of_unless(reference, other, &|| false).expect("never stopped")
    }

    /// [`Self::of`], giving up (`None`) soon after `stop` says so.
    pub fn of_unless(
        reference: &TriMesh,
        other: &TriMesh,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Option<Self> {
        let reference_index = crate::metrics::ClosestPointIndex::new(reference);
        let other_index = crate::metrics::ClosestPointIndex::new(other);
        let (forth, vertex_distances) =
            reference_index.distance_and_vertex_distances_unless(other, stop)?;
        let (back, _) = other_index.distance_and_vertex_distances_unless(reference, stop)?;
        let vertices = crate::metrics::compare_vertices(reference, other);
        let vertex_distances = vertex_distances.into_iter().map(|d| d as f32).collect();
        Some(Self {
            volume_change_percent: crate::metrics::volume_change_percent(reference, other),
            mean_distance: 0.5 * (forth.mean + back.mean),
            max_distance: forth.max.max(back.max),
            vertex_rms: vertices.map(|v| v.rms),
            barycenter_drift: vertices.map(|v| v.barycenter_drift),
            vertex_distances: Arc::new(vertex_distances),
        })
    }
}

/// The latest faired result shown for the document.
pub struct FairedResult {
    pub positions: Arc<Vec<[f32; 3]>>,
    pub level: usize,
    pub method: MethodSetting,
    pub volume_change: f64,
    pub rms_displacement: f64,
    pub elapsed: Duration,
    /// Distinguishes results, so the viewport knows when to upload.
    pub serial: u64,
    /// Against the document's mesh.
    pub against_document: Option<Measures>,
    /// Against the clean mesh, when noise was injected.
    pub against_clean: Option<Measures>,
    /// Seconds the measuring took on the worker.
    pub measure_time: Duration,
    /// The measures above are the previous result's, kept on screen (numbers and heat map)
    /// until this result's own arrive from the measuring worker.
    pub measures_pending: bool,
}

/// One loaded mesh and everything derived from it.
pub struct Document {
    pub path: PathBuf,
    /// Bumped for every document; jobs for older documents are stale.
    pub generation: u64,
    /// The document's mesh: as loaded, or as noise or an applied result made it.
    pub original: Arc<TriMesh>,
    /// The mesh before noise was injected (the clean reference), when there is one.
    pub clean: Option<Arc<TriMesh>>,
    /// The document mesh measured against the clean mesh (same connectivity).
    pub against_clean: Option<Measures>,
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
    /// The file the mesh was loaded from: Export writes it back with the new positions.
    pub source: Arc<crate::io::Source>,
    /// The mesh is an applied result: it is shown and exported as it is, not faired again with
    /// the settings that made it, until the user changes the start level or a fairing option.
    pub applied: bool,
    /// The file was just opened: once the hierarchy is ready, the start level is the one
    /// remembered for the file, or a middle one.
    pub pick_start_level: bool,
    /// Where to fair (painted with the brush): `None` fairs the whole mesh.
    pub mask: Option<Mask>,
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
        let source = Arc::new(crate::io::Source::plain(&original));
        Self {
            source,
            path,
            generation,
            original: Arc::new(original),
            clean: None,
            against_clean: None,
            report,
            load_time,
            bounds,
            hierarchy: HierarchyState::Building,
            level: 0,
            faired: None,
            level_mesh: None,
            export_path,
            applied: false,
            pick_start_level: false,
            mask: None,
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

/// A document's content as undo and redo keep it: the meshes, and the hierarchy already built
/// for them (so going back does not rebuild it).
#[derive(Clone)]
pub struct DocumentSnapshot {
    pub path: PathBuf,
    pub mesh: Arc<TriMesh>,
    pub clean: Option<Arc<TriMesh>>,
    pub against_clean: Option<Measures>,
    pub report: LoadReport,
    pub load_time: Duration,
    pub level: usize,
    pub export_path: String,
    pub source: Arc<crate::io::Source>,
    /// The hierarchy, its build time, and whether its M0 has the mesh's triangles.
    pub hierarchy: Option<(Arc<Hierarchy>, Duration, bool, Arc<SharpEdgeLines>)>,
    /// See [`Document::applied`].
    pub applied: bool,
    /// The view of this document when it was left (set by the app, which owns the camera), so
    /// that undo and redo across an Open bring back the view with the mesh.
    pub camera: Option<super::camera::OrbitCamera>,
    /// See [`Document::mask`].
    pub mask: Option<Mask>,
}

fn mesh_bytes(mesh: &TriMesh) -> usize {
    std::mem::size_of_val(mesh.positions.as_slice())
        + std::mem::size_of_val(mesh.triangles.as_slice())
}

impl SizeInBytes for DocumentSnapshot {
    fn size_in_bytes(&self) -> usize {
        // Shared meshes are counted once per snapshot: an over-estimate, on the safe side.
        mesh_bytes(&self.mesh)
            + self.clean.as_deref().map_or(0, mesh_bytes)
            + self.hierarchy.as_ref().map_or(0, |(h, _, _, _)| {
                h.record_bytes() + mesh_bytes(h.base_mesh())
            })
            + self
                .against_clean
                .as_ref()
                .map_or(0, |m| m.vertex_distances.len() * 4)
            + self.mask.as_ref().map_or(0, |m| m.len() * 4)
    }
}

impl Document {
    /// What undo needs to bring this document back.
    pub fn snapshot(&self) -> DocumentSnapshot {
        DocumentSnapshot {
            path: self.path.clone(),
            mesh: self.original.clone(),
            clean: self.clean.clone(),
            against_clean: self.against_clean.clone(),
            report: self.report.clone(),
            load_time: self.load_time,
            level: self.level,
            export_path: self.export_path.clone(),
            source: self.source.clone(),
            hierarchy: match &self.hierarchy {
                HierarchyState::Ready {
                    hierarchy,
                    build_time,
                    base_matches_original,
                    sharp_edges,
                    ..
                } => Some((
                    hierarchy.clone(),
                    *build_time,
                    *base_matches_original,
                    sharp_edges.clone(),
                )),
                _ => None,
            },
            applied: self.applied,
            camera: None,
            mask: self.mask.clone(),
        }
    }

    /// A document made from a snapshot; its hierarchy is ready when the snapshot kept one
    /// (otherwise `Building`: the caller starts the build).
    pub fn from_snapshot(snapshot: DocumentSnapshot, generation: u64) -> Self {
        let bounds = bounds_of(&snapshot.mesh.positions);
        let hierarchy = match snapshot.hierarchy {
            Some((hierarchy, build_time, base_matches_original, sharp_edges)) => {
                HierarchyState::Ready {
                    levels: (0..hierarchy.level_count())
                        .map(|l| hierarchy.level_info(l))
                        .collect(),
                    base_matches_original,
                    hierarchy,
                    build_time,
                    sharp_edges,
                }
            }
            None => HierarchyState::Building,
        };
        Self {
            path: snapshot.path,
            generation,
            original: snapshot.mesh,
            clean: snapshot.clean,
            against_clean: snapshot.against_clean,
            report: snapshot.report,
            load_time: snapshot.load_time,
            bounds,
            hierarchy,
            level: snapshot.level,
            faired: None,
            level_mesh: None,
            export_path: snapshot.export_path,
            source: snapshot.source,
            applied: snapshot.applied,
            pick_start_level: false,
            mask: snapshot.mask,
        }
    }
}

/// `<stem>_faired.<extension>` next to `input`, in the input's format.
pub fn default_export_path(input: &Path) -> PathBuf {
    let stem = input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh".to_owned());
    // The input's own format, so that the export keeps everything the file holds (materials,
    // UVs, colours, the scene); GLB for a name with no known format.
    let extension = crate::io::Format::from_path(input).map_or("glb", |f| f.extension());
    input.with_file_name(format!("{stem}_faired.{extension}"))
}

/// Axis-aligned bounds of `positions` (zeros when empty).
pub fn bounds_of(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    // Branch-free, non-finite coordinates left out one by one: the UI thread runs this for
    // every document (600k vertices: 2.3 ms with a branch per coordinate).
    use glam::Vec3A;
    let (lo, hi) = positions
        .iter()
        .fold((Vec3A::INFINITY, Vec3A::NEG_INFINITY), |(lo, hi), &p| {
            let p = Vec3A::from_array(p);
            let finite = p.is_finite_mask();
            (
                lo.min(Vec3A::select(finite, p, Vec3A::INFINITY)),
                hi.max(Vec3A::select(finite, p, Vec3A::NEG_INFINITY)),
            )
        });
    if lo.cmpgt(hi).any() {
        return ([0.0; 3], [0.0; 3]);
    }
    (lo.to_array(), hi.to_array())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn export_name_sits_next_to_the_input_in_its_format() {
        assert_eq!(
            default_export_path(Path::new("/scans/bunny00.obj")),
            PathBuf::from("/scans/bunny00_faired.obj")
        );
        assert_eq!(
            default_export_path(Path::new("/art/scene.GLB")),
            PathBuf::from("/art/scene_faired.glb")
        );
        assert_eq!(
            default_export_path(Path::new("/art/dropped")),
            PathBuf::from("/art/dropped_faired.glb")
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
    fn start_level_is_the_files_last_choice_or_a_middle_one() {
        let mut settings = Settings::default();
        let (bunny, scan) = (Path::new("/a/bunny.obj"), Path::new("/b/scan.ply"));
        assert_eq!(settings.start_level_for(bunny, 20), 9);
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
            9,
            "the oldest are forgotten"
        );
    }

    #[test]
    fn bounds_skip_non_finite_values() {
        let (lo, hi) = bounds_of(&[[0.0, 1.0, 2.0], [f32::NAN, -1.0, 5.0], [3.0, 0.0, 2.0]]);
        assert_eq!(lo, [0.0, -1.0, 2.0]);
        assert_eq!(hi, [3.0, 1.0, 5.0]);
    }
}
