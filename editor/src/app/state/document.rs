//! The [`Document`]: the loaded mesh and everything computed from it (hierarchy, faired result,
//! level meshes, numbers), replaced as a whole when another file is loaded; the
//! [`DocumentSnapshot`] that undo and redo keep of it; and the helpers that name its export and
//! bound its mesh.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use crate::app::generation::GenerationId;
use crate::app::history::SizeInBytes;
use crate::app::sharp_edges::SharpEdgeLines;
use fairmesh::fairing::strength::CLEAN_NOISE;
use fairmesh::fairing::{FairReport, Mask, Method};
use fairmesh::hierarchy::{Hierarchy, LevelInfo};
use fairmesh::io::LoadReport;
use fairmesh::TriMesh;

use super::Measures;

/// What the denoise before the hierarchy found ([`fairmesh::multires::denoise()`]); the denoised
/// positions are the hierarchy's M0.
#[derive(Clone, Debug)]
pub struct DenoiseSummary {
    /// The fairing's report: the noise estimate, the rounds kept, the sharp edges.
    pub report: FairReport,
    pub time: Duration,
}

impl DenoiseSummary {
    /// Whether the denoise left the mesh alone although its noise estimate read above the clean
    /// threshold: all of what reads as noise lies at sharp edges or in faces that still lie flat,
    /// as in a CAD part as exporters write it.
    pub fn reads_as_cad_part(&self) -> bool {
        self.report.rounds_run == 0
            && self
                .report
                .noise_estimate
                .is_some_and(|noise| noise > CLEAN_NOISE)
    }

    /// What the denoise found, in a few words for the panel: "Noise about 0.23 edge lengths:
    /// 31 rounds; 49 sharp edges kept", or that it found none.
    pub fn describe(&self) -> String {
        let report = &self.report;
        if report.rounds_run == 0 {
            return match report.noise_estimate {
                Some(noise) if self.reads_as_cad_part() => format!(
                    "No noise to remove: what reads as noise (about {noise:.3} edge lengths) lies \
                     at sharp edges or in faces that still lie flat, as in a CAD part: the mesh \
                     is used as it is"
                ),
                Some(noise) => format!(
                    "No noise to remove (about {noise:.2} edge lengths, which reads as clean): \
                     the mesh is used as it is"
                ),
                None => "No noise to remove: the mesh is used as it is".to_owned(),
            };
        }
        let noise = report
            .noise_estimate
            .map(|noise| format!("Noise about {noise:.2} edge lengths: "))
            .unwrap_or_default();
        let rounds = match report.rounds_run {
            1 => "1 round".to_owned(),
            n => format!("{n} rounds"),
        };
        let edges = match report.crease_edges {
            0 => String::new(),
            1 => "; 1 sharp edge kept".to_owned(),
            n => format!("; {n} sharp edges kept"),
        };
        format!("{noise}{rounds}{edges}")
    }
}

/// A built hierarchy as undo keeps it (see [`HierarchyState::Ready`]).
#[derive(Clone)]
pub struct KeptHierarchy {
    pub hierarchy: Arc<Hierarchy>,
    pub build_time: Duration,
    pub base_matches_original: bool,
    pub sharp_edges: Arc<SharpEdgeLines>,
    pub denoise: Option<DenoiseSummary>,
}

/// Where the hierarchy of the current document stands.
pub enum HierarchyState {
    /// Being built, after the denoise before it.
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
        /// What the denoise found, when the hierarchy was built on the denoised mesh (its M0);
        /// `None` when on the document's mesh itself ("Remove noise first" off).
        denoise: Option<DenoiseSummary>,
    },
    Failed(String),
}

/// The latest faired result shown for the document.
pub struct FairedResult {
    pub positions: Arc<Vec<[f32; 3]>>,
    pub level: usize,
    pub method: Method,
    pub volume_change: f64,
    pub rms_displacement: f64,
    /// Faces left turned over against level 0 (from the coarsest levels of a large mesh only).
    pub folds_left: usize,
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
    pub generation: GenerationId,
    /// The document's mesh: as loaded, or as noise or an applied result made it.
    pub original: Arc<TriMesh>,
    /// The connectivity of `original`'s triangles (the same for every snapshot of one file:
    /// noise and Apply move positions only).
    pub topology: Arc<fairmesh::Topology>,
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
    pub source: Arc<fairmesh::io::Source>,
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
        generation: GenerationId,
        original: TriMesh,
        report: LoadReport,
        load_time: Duration,
    ) -> Self {
        let bounds = bounds_of(&original.positions);
        let export_path = default_export_path(&path).display().to_string();
        let source = Arc::new(fairmesh::io::Source::plain(&original));
        Self {
            source,
            topology: Arc::new(fairmesh::Topology::build(&original)),
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
    /// See [`Document::topology`].
    pub topology: Arc<fairmesh::Topology>,
    pub clean: Option<Arc<TriMesh>>,
    pub against_clean: Option<Measures>,
    pub report: LoadReport,
    pub load_time: Duration,
    pub level: usize,
    pub export_path: String,
    pub source: Arc<fairmesh::io::Source>,
    /// The hierarchy, its build time, and whether its M0 has the mesh's triangles.
    pub hierarchy: Option<KeptHierarchy>,
    /// See [`Document::applied`].
    pub applied: bool,
    /// The view of this document when it was left (set by the app, which owns the camera), so
    /// that undo and redo across an Open bring back the view with the mesh.
    pub camera: Option<crate::app::camera::OrbitCamera>,
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
            + self.hierarchy.as_ref().map_or(0, |kept| {
                kept.hierarchy.record_bytes() + mesh_bytes(kept.hierarchy.base_mesh())
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
            topology: self.topology.clone(),
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
                    denoise,
                    ..
                } => Some(KeptHierarchy {
                    hierarchy: hierarchy.clone(),
                    build_time: *build_time,
                    base_matches_original: *base_matches_original,
                    sharp_edges: sharp_edges.clone(),
                    denoise: denoise.clone(),
                }),
                _ => None,
            },
            applied: self.applied,
            camera: None,
            mask: self.mask.clone(),
        }
    }

    /// A document made from a snapshot; its hierarchy is ready when the snapshot kept one
    /// (otherwise `Building`: the caller starts the build).
    pub fn from_snapshot(snapshot: DocumentSnapshot, generation: GenerationId) -> Self {
        let bounds = bounds_of(&snapshot.mesh.positions);
        let hierarchy = match snapshot.hierarchy {
            Some(kept) => HierarchyState::Ready {
                levels: (0..kept.hierarchy.level_count())
                    .map(|l| kept.hierarchy.level_info(l))
                    .collect(),
                base_matches_original: kept.base_matches_original,
                hierarchy: kept.hierarchy,
                build_time: kept.build_time,
                sharp_edges: kept.sharp_edges,
                denoise: kept.denoise,
            },
            None => HierarchyState::Building,
        };
        Self {
            path: snapshot.path,
            generation,
            original: snapshot.mesh,
            topology: snapshot.topology,
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
    let extension = fairmesh::io::Format::from_path(input).map_or("glb", |f| f.extension());
    let name = format!("{stem}_faired.{extension}");
    // A web page downloads its exports: the name is all there is to choose.
    if cfg!(target_arch = "wasm32") {
        return PathBuf::from(name);
    }
    input.with_file_name(name)
}

/// Axis-aligned bounds of `positions` (zeros when empty).
pub fn bounds_of(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    // Branch-free, non-finite coordinates left out one by one: the UI thread runs this for
    // every document, so it stays cheap on big meshes.
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
    fn the_denoise_says_what_it_found_and_why_it_left_a_mesh_alone() {
        let summary = |rounds_run, noise_estimate, crease_edges| DenoiseSummary {
            report: FairReport {
                rounds_run,
                noise_estimate,
                crease_edges,
                ..FairReport::default()
            },
            time: Duration::ZERO,
        };
        assert_eq!(
            summary(31, Some(0.234), 49).describe(),
            "Noise about 0.23 edge lengths: 31 rounds; 49 sharp edges kept"
        );
        let clean = summary(0, Some(0.012), 0).describe();
        assert!(clean.contains("which reads as clean"), "{clean}");
        // Left alone though the estimate is above the clean level: the panel says why.
        let cad = summary(0, Some(0.251), 0).describe();
        assert!(cad.contains("0.25") && cad.contains("CAD part"), "{cad}");
        assert!(!cad.contains("reads as clean"), "{cad}");
    }

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
    fn bounds_skip_non_finite_values() {
        let (lo, hi) = bounds_of(&[[0.0, 1.0, 2.0], [f32::NAN, -1.0, 5.0], [3.0, 0.0, 2.0]]);
        assert_eq!(lo, [0.0, -1.0, 2.0]);
        assert_eq!(hi, [3.0, 1.0, 5.0]);
    }
}
