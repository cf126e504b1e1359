//! Keeping the viewports' GPU buffers in step with what should be shown: which mesh each
//! viewport wants (the result, a level, the input mesh), uploading it when it changed, the heat
//! map's scalars and range, the draw parameters and fitting the camera.

use std::sync::Arc;

use crate::app::camera::OrbitCamera;
use crate::app::state::{
    self, CompareView, Document, HeatReference, HierarchyState, Settings, ViewMode,
};
use crate::app::App;
use crate::hierarchy;
use crate::render::{DrawParams, MeshSource, Viewport3d};
use crate::TriMesh;

/// What the viewport has uploaded, to know when to upload again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::app) struct Shown {
    pub(in crate::app) document: u64,
    pub(in crate::app) what: ShownMesh,
    /// The heat map's reference, when the heat map is on.
    pub(in crate::app) heat: Option<HeatReference>,
    /// The painted mask's revision, when it is tinted over the mesh (instead of a heat map).
    pub(in crate::app) mask: Option<u64>,
}

/// How one viewport's image is coloured, apart from the camera and the settings: the heat map's
/// range or the painted mask's tint (see [`App::slot_look`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(in crate::app) struct SlotLook {
    pub(in crate::app) scalar_range: Option<[f32; 2]>,
    pub(in crate::app) mask_tint: bool,
}

impl SlotLook {
    /// What a renderer is asked to draw with, for an image in `rect` seen by `camera`.
    pub(in crate::app) fn draw_params(
        self,
        camera: &OrbitCamera,
        settings: &Settings,
        rect: egui::Rect,
    ) -> DrawParams {
        let aspect = rect.width() / rect.height().max(1.0);
        DrawParams {
            view_proj: camera.view_proj(aspect).to_cols_array_2d(),
            eye: camera.eye().to_array(),
            light_dir: camera.light_dir().to_array(),
            fill_dir: camera.fill_dir().to_array(),
            up: camera.basis().1.to_array(),
            shading: settings.shading,
            lighting: settings.lighting,
            wireframe: settings.wireframe,
            scalar_range: self.scalar_range,
            mask_tint: self.mask_tint,
            size: [0, 0],
        }
    }
}

/// The two viewports: the main one (the view mode's mesh: the result, a level, the original)
/// and the "before" one (the document's mesh) for the toggle, split and side-by-side views.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    Main = 0,
    Before = 1,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::app) enum ShownMesh {
    Original,
    Faired { serial: u64 },
    Level { level: usize },
}

impl ShownMesh {
    /// Meshes with the same key share connectivity, so only positions need uploading.
    pub(in crate::app) fn connectivity(self, base_matches_original: bool) -> (u8, usize) {
        match self {
            ShownMesh::Original => (0, 0),
            ShownMesh::Faired { .. } if base_matches_original => (0, 0),
            ShownMesh::Faired { .. } => (1, 0),
            ShownMesh::Level { level } => (2, level),
        }
    }
}

/// The heat map's top: the 99th percentile of the distances, so a few outliers do not turn the
/// rest of the mesh into the map's darkest colour (larger values take the top colour).
pub(in crate::app) fn heat_map_top(distances: &[f32]) -> f32 {
    let mut finite: Vec<f32> = distances
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .collect();
    if finite.is_empty() {
        return 0.0;
    }
    let rank = ((finite.len() - 1) as f64 * 0.99).round() as usize;
    let (_, value, _) = finite.select_nth_unstable_by(rank, f32::total_cmp);
    value.max(0.0)
}

/// The mesh `what` names, as a viewport takes it: its triangles (the hierarchy's M0 for a result
/// whose `base` does not match the document's mesh) and its positions. `None` when it is not
/// computed yet.
fn view_mesh(
    document: &Document,
    what: ShownMesh,
    base: Option<(Arc<hierarchy::Hierarchy>, bool)>,
) -> Option<ViewMesh> {
    Some(match what {
        ShownMesh::Original => ViewMesh {
            connectivity: SharedMesh::Mesh(document.original.clone()),
            positions: None,
        },
        ShownMesh::Faired { .. } => {
            let faired = document.faired.as_ref()?;
            let connectivity = match base {
                Some((hierarchy, false)) => SharedMesh::Base(hierarchy),
                _ => SharedMesh::Mesh(document.original.clone()),
            };
            ViewMesh {
                connectivity,
                positions: Some(faired.positions.clone()),
            }
        }
        ShownMesh::Level { .. } => {
            let (_, mesh) = document.level_mesh.as_ref()?;
            ViewMesh {
                connectivity: SharedMesh::Mesh(mesh.clone()),
                positions: None,
            }
        }
    })
}

/// A mesh held by the document, shared with a worker or the renderer without copying it.
#[derive(Clone)]
pub(in crate::app) enum SharedMesh {
    /// The hierarchy's base mesh M0 (the connectivity faired results have).
    Base(Arc<hierarchy::Hierarchy>),
    Mesh(Arc<TriMesh>),
}

impl SharedMesh {
    pub(in crate::app) fn mesh(&self) -> &TriMesh {
        match self {
            Self::Base(hierarchy) => hierarchy.base_mesh(),
            Self::Mesh(mesh) => mesh,
        }
    }
}

/// What the viewport shows: a mesh's triangles with its own positions or other ones (a faired
/// result) over them.
pub(in crate::app) struct ViewMesh {
    pub(in crate::app) connectivity: SharedMesh,
    pub(in crate::app) positions: Option<Arc<Vec<[f32; 3]>>>,
}

impl MeshSource for ViewMesh {
    fn positions(&self) -> &[[f32; 3]] {
        match &self.positions {
            Some(positions) => positions,
            None => &self.connectivity.mesh().positions,
        }
    }
    fn triangles(&self) -> &[[u32; 3]] {
        &self.connectivity.mesh().triangles
    }
}

impl App {
    /// The heat map's reference now: `None` when it is off; the clean mesh only when there is one.
    pub(super) fn heat_reference(&self) -> Option<HeatReference> {
        if !self.settings.heat_map {
            return None;
        }
        let has_clean = self.document.as_ref().is_some_and(|d| d.clean.is_some());
        Some(match self.settings.heat_reference {
            HeatReference::Clean if has_clean => HeatReference::Clean,
            _ => HeatReference::Document,
        })
    }

    /// Whether the before viewport is on screen.
    pub(super) fn before_needed(&self) -> bool {
        self.settings.compare != CompareView::Single || self.show_before
    }

    /// What a viewport should show now: for the main one the view mode's mesh when it exists,
    /// otherwise the last good mesh of this document, otherwise the loaded mesh; for the before
    /// one the document's mesh.
    pub(super) fn wanted_mesh(&self, slot: Slot) -> Option<Shown> {
        let document = self.document.as_ref()?;
        let mask = self.mask_tint();
        // The tint and the heat map share the mesh's scalars: the mask wins while it is shown.
        let heat = self.heat_reference().filter(|_| mask.is_none());
        if slot == Slot::Before {
            return Some(Shown {
                document: document.generation,
                what: ShownMesh::Original,
                heat,
                mask,
            });
        }
        let previous = self
            .shown
            .filter(|s| s.document == document.generation)
            .map(|s| s.what);
        let what = match self.settings.view_mode {
            ViewMode::Original => ShownMesh::Original,
            ViewMode::Faired => match &document.faired {
                Some(faired) => ShownMesh::Faired {
                    serial: faired.serial,
                },
                None => ShownMesh::Original,
            },
            ViewMode::Level => match &document.level_mesh {
                Some((level, _)) => ShownMesh::Level { level: *level },
                None => previous.unwrap_or(ShownMesh::Original),
            },
        };
        let mask = mask.filter(|_| !matches!(what, ShownMesh::Level { .. }));
        Some(Shown {
            document: document.generation,
            what,
            heat,
            mask,
        })
    }

    /// Distance of each vertex of `what` from the heat map's reference (`None`: no heat map for
    /// that mesh, as for level meshes, or not computed yet).
    pub(super) fn heat_scalars(
        &self,
        what: ShownMesh,
        reference: HeatReference,
    ) -> Option<Arc<Vec<f32>>> {
        let document = self.document.as_ref()?;
        match what {
            ShownMesh::Faired { .. } => {
                let faired = document.faired.as_ref()?;
                let measures = match reference {
                    HeatReference::Clean => faired.against_clean.as_ref(),
                    HeatReference::Document => faired.against_document.as_ref(),
                }?;
                Some(measures.vertex_distances.clone())
            }
            ShownMesh::Original => match reference {
                HeatReference::Clean => document
                    .against_clean
                    .as_ref()
                    .map(|m| m.vertex_distances.clone()),
                // The document's mesh is its own reference: zero everywhere.
                HeatReference::Document => {
                    Some(Arc::new(vec![0.0; document.original.vertex_count()]))
                }
            },
            ShownMesh::Level { .. } => None,
        }
    }

    pub(super) fn sync_viewport(&mut self) {
        self.sync_slot(Slot::Main);
        if self.before_needed() {
            self.sync_slot(Slot::Before);
        }
    }

    /// Uploads the wanted mesh (and heat-map scalars) when they differ from what is on the GPU.
    pub(super) fn sync_slot(&mut self, slot: Slot) {
        let Some(wanted) = self.wanted_mesh(slot) else {
            return;
        };
        let shown = match slot {
            Slot::Main => self.shown,
            Slot::Before => self.shown_before,
        };
        if shown == Some(wanted) || self.document.is_none() {
            return;
        }
        let mesh_changed =
            shown.is_none_or(|s| (s.document, s.what) != (wanted.document, wanted.what));
        let mut counts = None;
        if mesh_changed {
            let Some(uploaded) = self.upload_mesh(slot, shown, wanted) else {
                return;
            };
            counts = Some(uploaded);
        }
        self.heat_max[slot as usize] = self.upload_tint(slot, wanted);
        match slot {
            Slot::Main => {
                if let Some(counts) = counts {
                    self.shown_counts = counts;
                }
                self.shown = Some(wanted);
            }
            Slot::Before => self.shown_before = Some(wanted),
        }
    }

    /// The slot's renderer handle, when there is a wgpu renderer.
    fn slot_viewport(&self, slot: Slot) -> Option<&Viewport3d> {
        match slot {
            Slot::Main => self.viewport.as_ref(),
            Slot::Before => self.viewport_before.as_ref(),
        }
    }

    /// Uploads the wanted mesh to the slot's viewport (only its positions when the GPU holds its
    /// triangles already, from `shown`); its vertex and face counts, or `None` when that mesh
    /// is not there (yet).
    fn upload_mesh(
        &self,
        slot: Slot,
        shown: Option<Shown>,
        wanted: Shown,
    ) -> Option<(usize, usize)> {
        let document = self.document.as_ref()?;
        let base = match &document.hierarchy {
            HierarchyState::Ready {
                hierarchy,
                base_matches_original,
                ..
            } => Some((hierarchy.clone(), *base_matches_original)),
            _ => None,
        };
        let matches = base.as_ref().is_none_or(|b| b.1);
        let same_connectivity = shown.is_some_and(|shown| {
            shown.document == wanted.document
                && shown.what.connectivity(matches) == wanted.what.connectivity(matches)
        });
        let source = view_mesh(document, wanted.what, base)?;
        let counts = (source.positions().len(), source.triangles().len());
        if let Some(viewport) = self.slot_viewport(slot) {
            let source: Arc<dyn MeshSource> = Arc::new(source);
            if !(same_connectivity && viewport.set_positions(source.clone())) {
                viewport.set_mesh(source);
            }
        }
        Some(counts)
    }

    /// Uploads what the wanted view tints the mesh with: the heat map's scalars or the painted
    /// mask's weights. The heat map's top when its scalars went up.
    fn upload_tint(&self, slot: Slot, wanted: Shown) -> Option<f32> {
        let viewport = self.slot_viewport(slot);
        let mut heat_max = None;
        if let Some(reference) = wanted.heat {
            if let Some(scalars) = self.heat_scalars(wanted.what, reference) {
                if viewport.is_none_or(|v| v.set_scalars(&scalars)) {
                    heat_max = Some(heat_map_top(&scalars));
                }
            }
        }
        if wanted.mask.is_some() {
            let mask = self.document.as_ref().and_then(|d| d.mask.as_ref());
            if let (Some(mask), Some(viewport)) = (mask, viewport) {
                viewport.set_scalars(mask.weights());
            }
        }
        heat_max
    }

    /// The heat map's top value for the slots on screen (shared, so the colours compare).
    pub(super) fn heat_top(&self) -> Option<f32> {
        self.heat_reference()?;
        let main = self.heat_max[Slot::Main as usize];
        let before = self
            .before_needed()
            .then(|| self.heat_max[Slot::Before as usize])
            .flatten();
        match (main, before) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        }
        .map(|top| top.max(f32::MIN_POSITIVE))
    }

    /// What the main viewport's renderer is asked to draw with now (tests).
    pub fn main_draw_params(&self) -> Option<DrawParams> {
        Some(self.draw_params(self.viewport_rect?, Slot::Main))
    }

    /// The vertex normals uploaded to a viewport's GPU buffer for the mesh it shows (tests;
    /// waits for the GPU).
    pub fn uploaded_normals(&self, slot: Slot) -> Option<Vec<[f32; 3]>> {
        match slot {
            Slot::Main => self.viewport.as_ref(),
            Slot::Before => self.viewport_before.as_ref(),
        }?
        .read_back_normals()
    }

    pub(super) fn draw_params(&self, rect: egui::Rect, slot: Slot) -> DrawParams {
        self.slot_look(slot)
            .draw_params(&self.camera, &self.settings, rect)
    }

    /// How a viewport's image is coloured now (the heat map's range, or the mask's tint).
    pub(super) fn slot_look(&self, slot: Slot) -> SlotLook {
        let top = self.heat_top();
        let scalar_range = self.heat_max[slot as usize].and(top).map(|top| [0.0, top]);
        let shown = match slot {
            Slot::Main => self.shown,
            Slot::Before => self.shown_before,
        };
        let mask_tint = scalar_range.is_none() && shown.is_some_and(|s| s.mask.is_some());
        SlotLook {
            scalar_range,
            mask_tint,
        }
    }

    pub(super) fn fit_view(&mut self) {
        let Some(document) = &self.document else {
            return;
        };
        let (lo, hi) = match (self.settings.view_mode, &document.level_mesh) {
            (ViewMode::Level, Some((_, mesh))) => state::bounds_of(&mesh.positions),
            _ => document.bounds,
        };
        // Each side-by-side half is half the view's width.
        let aspect = self.viewport_rect.map_or(1.0, |rect| {
            let width = match self.settings.compare {
                CompareView::SideBySide => rect.width() * 0.5,
                CompareView::Single | CompareView::Split => rect.width(),
            };
            width / rect.height().max(1.0)
        });
        self.camera.fit(
            glam::Vec3::from_array(lo),
            glam::Vec3::from_array(hi),
            aspect,
        );
        self.fitted_camera = Some(self.camera);
    }
}
